//! Invariants on the shared meshes: disk parameterization, Voronoi clusters, geodesic paths,
//! point location.

mod common;
use geom::geodesic::{EdgeNodeGraph, EdgeNodeOptions, FaceVoronoiOptions, PathOptions, face_voronoi, vertex_dijkstra};
use geom::linalg::Weights;
use geom::mesh::FaceId;
use geom::param::{BoundaryShape, DiskParamOptions, parameterize_disk};
use geom::{Mesh, VertexId};

/// Farthest-point sampling by vertex Dijkstra, from vertex 0.
fn farthest_points(m: &Mesh, k: usize) -> Vec<VertexId> {
    let mut pts = vec![VertexId(0)];
    while pts.len() < k {
        let srcs: Vec<_> = pts.iter().map(|&v| (v, 0.0)).collect();
        let r = vertex_dijkstra(m, &srcs, &Default::default()).unwrap();
        let far = (0..m.n_vertices()).max_by(|&a, &b| r.dist[a].total_cmp(&r.dist[b])).unwrap();
        pts.push(VertexId::from_idx(far));
    }
    pts
}

#[test]
fn disk_parameterizations_of_real_disks_are_injective() {
    for name in ["camelhead.off", "face.off", "hand_lowres.obj", "demosthenes-low-res.obj"] {
        let m = common::load(name);
        for w in [Weights::Uniform, Weights::MeanValue] {
            let r = parameterize_disk(&m, &DiskParamOptions { weights: w, boundary: BoundaryShape::Circle }).unwrap();
            assert!(r.injectivity.is_injective(), "{name} {w:?}: {:?}", r.injectivity);
            assert!(r.residual < 1e-10, "{name} {w:?}: residual {}", r.residual);
        }
        // Cotangent (harmonic) weights: the solve is exact; flips are possible on obtuse meshes
        // and are reported, not hidden.
        let r = parameterize_disk(&m, &DiskParamOptions { weights: Weights::Cotan, boundary: BoundaryShape::Circle })
            .unwrap();
        assert!(r.residual < 1e-10, "{name} cotan residual {}", r.residual);
        assert!(r.injectivity.flipped * 100 < m.n_faces(), "{name}: {:?}", r.injectivity);
    }
}

#[test]
fn non_disks_are_refused_for_disk_parameterization() {
    for name in ["eight.hole.off", "bunny.off"] {
        let e = parameterize_disk(&common::load(name), &DiskParamOptions::default()).unwrap_err();
        assert_eq!(e.code(), "not_a_disk", "{name}");
    }
}

#[test]
fn voronoi_cells_on_a_genus_5_mesh_cover_it_and_are_connected() {
    let m = common::load("botijo.off");
    let sources = farthest_points(&m, 50);
    let r = face_voronoi(&m, &sources, &FaceVoronoiOptions::default()).unwrap();
    assert!(r.label.iter().all(|&l| (l as usize) < sources.len()), "every face is in a cell");
    // Each source's own faces are in its cell, and each cell is one connected piece.
    for (i, &s) in sources.iter().enumerate() {
        assert!(m.vertex_faces(s).any(|f| r.label[f.idx()] == i as u32));
    }
    let mut seen = vec![false; m.n_faces()];
    let mut pieces = vec![0usize; sources.len()];
    for start in 0..m.n_faces() {
        if seen[start] {
            continue;
        }
        let lab = r.label[start];
        pieces[lab as usize] += 1;
        let mut stack = vec![FaceId::from_idx(start)];
        seen[start] = true;
        while let Some(f) = stack.pop() {
            for g in m.face_neighbors(f) {
                if !seen[g.idx()] && r.label[g.idx()] == lab {
                    seen[g.idx()] = true;
                    stack.push(g);
                }
            }
        }
    }
    assert!(pieces.iter().all(|&p| p == 1), "cells in pieces: {pieces:?}");
}

#[test]
fn edge_node_paths_are_shorter_than_vertex_paths_and_stay_in_the_region() {
    let m = common::load("bunny.off");
    let pts = farthest_points(&m, 6);
    let g = EdgeNodeGraph::new(&m, &EdgeNodeOptions::default());
    let vd = vertex_dijkstra(&m, &[(pts[0], 0.0)], &Default::default()).unwrap();
    for &t in &pts[1..] {
        let p = g.shortest_path(g.vertex_node(pts[0]), g.vertex_node(t), &PathOptions::default()).unwrap().unwrap();
        let straight = (m.position(t) - m.position(pts[0])).norm();
        assert!(p.length >= straight - 1e-9);
        assert!(p.length <= vd.dist[t.idx()] + 1e-9, "{} vs {}", p.length, vd.dist[t.idx()]);
        let sum: f64 = p.points.windows(2).map(|w| (w[1].position(&m) - w[0].position(&m)).norm()).sum();
        assert!((sum - p.length).abs() < 1e-9 * p.length.max(1.0));
    }
    // Restricted to the two Voronoi cells of the endpoints, the path stays inside them.
    let r = face_voronoi(&m, &pts, &Default::default()).unwrap();
    let mask: Vec<bool> = r.label.iter().map(|&l| l == 0 || l == 1).collect();
    if let Some(p) = g
        .shortest_path(g.vertex_node(pts[0]), g.vertex_node(pts[1]), &PathOptions { faces: Some(&mask), blocked: None })
        .unwrap()
    {
        for q in &p.points {
            let (f, _) = q.in_face(&m);
            let inside = mask[f.idx()] || m.face_neighbors(f).any(|g| mask[g.idx()]);
            assert!(inside);
        }
    }
}
