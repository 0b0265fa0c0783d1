//! Whole `voronoi` / `greedy` jobs (layout to metrics, as `surfmap map` runs them) on the
//! armadillo against a bent copy of itself with 45 farthest-point anchors.
//! `cargo bench -p surfmap-geom --bench map`

use criterion::{Criterion, criterion_group, criterion_main};
use geom::io::{ReadOptions, read_path};
use geom::mesh::{Mesh, P3};
use geom::pipeline::{JobSpec, MapOptions, Method, run_map};
use geom::progress::NoProgress;
use std::path::PathBuf;

fn shared(name: &str) -> PathBuf {
    std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared"))
        .join("meshes")
        .join(name)
}

fn fps(m: &Mesh, k: usize) -> Vec<u64> {
    let p = m.positions();
    let mut d: Vec<f64> = p.iter().map(|x| (x - p[0]).norm()).collect();
    let mut out = vec![0u64];
    while out.len() < k {
        let i = (0..p.len()).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap_or(0);
        out.push(i as u64);
        for (j, x) in p.iter().enumerate() {
            d[j] = d[j].min((x - p[i]).norm());
        }
    }
    out
}

fn bent(m: &Mesh) -> Mesh {
    let (lo, hi) = m.bbox();
    let r = (hi.y - lo.y) * 1.2;
    let cy = (lo.y + hi.y) / 2.0;
    let pos = m
        .positions()
        .iter()
        .map(|p| {
            let u = (p.y - cy) / r;
            P3::new(p.x, cy + r * u.sin(), p.z + r * (1.0 - u.cos()))
        })
        .collect();
    m.with_positions(pos).expect("same faces")
}

fn bench(c: &mut Criterion) {
    let s = read_path(&shared("armadillo.obj"), &ReadOptions::default()).expect("armadillo").mesh;
    let t = bent(&s);
    let anchors: Vec<[u64; 2]> = fps(&s, 45).into_iter().map(|a| [a, a]).collect();
    let mut g = c.benchmark_group("map");
    g.sample_size(10);
    for method in [Method::Voronoi, Method::Greedy] {
        let spec = JobSpec { method, anchors: anchors.clone(), options: MapOptions::default() };
        g.bench_function(format!("armadillo_bent_45_{}", method.name()), |b| {
            b.iter(|| run_map(&spec, &s, &t, &mut NoProgress).expect("map"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
