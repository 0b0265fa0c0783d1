//! Benchmarks of the geometry core (release build): reading 1M-face PLY and OBJ, multi-source
//! face Dijkstra on botijo, harmonic disk parameterization of camelhead and of a 205k-vertex
//! disk (hand_lowres subdivided four times). Medians are in
//! `target/criterion/<name>/new/estimates.json`.

use criterion::{Criterion, criterion_group, criterion_main};
use geom::geodesic::{FaceVoronoiOptions, face_voronoi};
use geom::io::{self, Format, ReadOptions};
use geom::linalg::Weights;
use geom::mesh::shapes;
use geom::param::{BoundaryShape, DiskParamOptions, parameterize_disk};
use geom::{Mesh, VertexId};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

fn shared(name: &str) -> PathBuf {
    let root = std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    root.join("meshes").join(name)
}

fn load(name: &str) -> Mesh {
    io::read_path(&shared(name), &ReadOptions::default()).expect("shared mesh").mesh
}

fn readers(c: &mut Criterion) {
    // cat-low-resolution (15,894 faces) subdivided three times: 1,017,216 faces.
    let big = shapes::subdivide(&load("cat-low-resolution.obj"), 3);
    assert_eq!(big.n_faces(), 1_017_216);
    let ply = io::write(&big, Format::Ply);
    let obj = io::write(&big, Format::Obj);
    let mut g = c.benchmark_group("read_1m_faces");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.bench_function("binary_ply", |b| b.iter(|| io::read(black_box(&ply), &ReadOptions::default()).unwrap()));
    g.bench_function("obj", |b| b.iter(|| io::read(black_box(&obj), &ReadOptions::default()).unwrap()));
    g.finish();
}

fn voronoi(c: &mut Criterion) {
    let m = load("botijo.off");
    // 50 sources spread by a fixed stride over the vertex list.
    let sources: Vec<VertexId> = (0..50).map(|i| VertexId::from_idx(i * m.n_vertices() / 50)).collect();
    c.bench_function("face_voronoi_botijo_50", |b| {
        b.iter(|| face_voronoi(black_box(&m), &sources, &FaceVoronoiOptions::default()).unwrap())
    });
}

fn harmonic(c: &mut Criterion) {
    let opts = DiskParamOptions { weights: Weights::Cotan, boundary: BoundaryShape::Circle };
    let camel = load("camelhead.off");
    let hand = shapes::subdivide(&load("hand_lowres.obj"), 4);
    assert_eq!(hand.n_vertices(), 205_185);
    let mut g = c.benchmark_group("harmonic_disk");
    g.sample_size(20);
    g.bench_function("camelhead_11k", |b| b.iter(|| parameterize_disk(black_box(&camel), &opts).unwrap()));
    g.sample_size(10);
    g.bench_function("hand_x4_205k", |b| b.iter(|| parameterize_disk(black_box(&hand), &opts).unwrap()));
    g.finish();
}

criterion_group!(benches, readers, voronoi, harmonic);
criterion_main!(benches);
