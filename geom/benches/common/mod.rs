//! Helpers shared by the benchmarks: shared meshes, farthest points, a bent copy.
#![allow(dead_code)]

use geom::mesh::{Mesh, P3};
use std::path::PathBuf;

pub fn shared(name: &str) -> PathBuf {
    std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared"))
        .join("meshes")
        .join(name)
}

pub fn fps(m: &Mesh, k: usize) -> Vec<u64> {
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

pub fn bent(m: &Mesh) -> Mesh {
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
