//! Whole `voronoi` / `greedy` jobs (layout to metrics, as `surfmap map` runs them) on the
//! armadillo against a bent copy of itself with 45 farthest-point anchors, and (`voronoi`) the
//! armadillo subdivided once (58k vertices) against a 6k-vertex simplification of it.
//! `cargo bench -p surfmap-geom --bench map`

use criterion::{Criterion, criterion_group, criterion_main};
use geom::io::{ReadOptions, read_path};
use geom::pipeline::layout::run as run_map;
use geom::pipeline::{LayoutSpec, MapOptions, Method};
use geom::progress::NoProgress;

mod common;
use common::{bent, fps, shared};

fn bench(c: &mut Criterion) {
    let s = read_path(&shared("armadillo.obj"), &ReadOptions::default()).expect("armadillo").mesh;
    let t = bent(&s);
    let anchors: Vec<[u64; 2]> = fps(&s, 45).into_iter().map(|a| [a, a]).collect();
    let mut g = c.benchmark_group("map");
    g.sample_size(10);
    for method in [Method::Voronoi, Method::Greedy] {
        let spec = LayoutSpec {
            boundaries: Vec::new(),
            anchors: geom::pipeline::AnchorRow::ids(anchors.clone()),
            options: MapOptions::default(),
        };
        g.bench_function(format!("armadillo_bent_45_{}", method.name()), |b| {
            b.iter(|| run_map(method, &spec, &s, &t, &mut NoProgress).expect("map"))
        });
    }
    // 58k against 6k: every vertex of the simplification is an armadillo vertex (half-edge
    // collapses), and the subdivision keeps the armadillo's vertices first, so farthest points
    // of the 6k mesh have their partners at the same indices in the 58k one.
    let fine = geom::mesh::shapes::subdivide(&s, 1);
    let coarse =
        geom::simplify::decimate(&s, &geom::simplify::DecimateOptions { target_vertices: 6000, ..Default::default() })
            .expect("decimate");
    let anchors: Vec<[u64; 2]> =
        fps(&coarse.mesh, 45).into_iter().map(|a| [u64::from(coarse.kept[a as usize].0), a]).collect();
    let spec = LayoutSpec {
        boundaries: Vec::new(),
        anchors: geom::pipeline::AnchorRow::ids(anchors),
        options: MapOptions::default(),
    };
    g.bench_function("armadillo_58k_vs_6k_45_voronoi", |b| {
        b.iter(|| run_map(Method::Voronoi, &spec, &fine, &coarse.mesh, &mut NoProgress).expect("map"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
