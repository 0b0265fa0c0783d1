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

/// Faces whose three corners are all boundary vertices (the only ones a convex-polygon map can
/// flatten to a segment).
fn ears(m: &Mesh) -> usize {
    m.faces().iter().filter(|f| f.iter().all(|&v| m.is_boundary_vertex(v))).count()
}

#[test]
fn convex_polygon_boundaries_and_reused_symbolic_factorization() {
    use geom::linalg::FixedBoundarySystem;
    use geom::param::{check_injective, disk_boundary, map_boundary_to_polygon};
    let m = common::load("face.off");
    // A regular hexagon, corners by arc length; and a triangle with explicit corners.
    let hex: Vec<[f64; 2]> = (0..6)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            [a.cos(), a.sin()]
        })
        .collect();
    let lp = disk_boundary(&m).unwrap();
    let n = lp.len();
    let tri = BoundaryShape::Polygon {
        vertices: vec![[0.0, 0.0], [1.0, 0.0], [0.5, 0.8]],
        corners: Some(vec![0, n / 3, 2 * n / 3]),
    };
    for shape in [BoundaryShape::Polygon { vertices: hex, corners: None }, tri] {
        let buv = map_boundary_to_polygon(&m, &lp, &shape).unwrap();
        let mut fixed = vec![[0.0; 2]; m.n_vertices()];
        for (v, p) in lp.iter().zip(&buv) {
            fixed[v.idx()] = *p;
        }
        // One symbolic factorization, three numeric ones (three weight kinds).
        let mut sys = FixedBoundarySystem::new(&m, &lp).unwrap();
        for w in [Weights::Uniform, Weights::MeanValue, Weights::Cotan] {
            let f = sys.factor(&m, w).unwrap();
            let uv = f.solve::<2>(&|v| fixed[v.idx()]).unwrap();
            assert!(f.residual(&uv) < 1e-10);
            if w != Weights::Cotan {
                // Positive weights on a convex polygon: no flips (Tutte, Floater). Triangles
                // with all three corners on one straight side are degenerate, and reported so.
                let inj = check_injective(&m, &uv);
                assert_eq!(inj.flipped, 0, "{shape:?} {w:?}: {inj:?}");
                assert!(inj.degenerate <= ears(&m), "{inj:?}");
            }
        }
    }
    // A non-convex polygon is refused.
    let bad = BoundaryShape::Polygon { vertices: vec![[0.0, 0.0], [1.0, 0.0], [0.2, 0.2], [0.0, 1.0]], corners: None };
    assert_eq!(map_boundary_to_polygon(&m, &lp, &bad).unwrap_err().code(), "invalid_argument");
}

#[test]
fn large_disk_uses_the_coarsened_ordering_and_stays_exact() {
    // hand_lowres subdivided three times: 51,329 vertices, well above the coarsening threshold.
    let m = geom::mesh::shapes::subdivide(&common::load("hand_lowres.obj"), 3);
    assert!(m.n_vertices() - geom::param::disk_boundary(&m).unwrap().len() >= geom::linalg::COARSEN_MIN);
    for w in [Weights::Cotan, Weights::MeanValue] {
        let r = parameterize_disk(&m, &DiskParamOptions { weights: w, boundary: BoundaryShape::Circle }).unwrap();
        assert!(r.residual < 1e-10, "{w:?}: residual {}", r.residual);
        if w == Weights::MeanValue {
            assert!(r.injectivity.is_injective(), "{:?}", r.injectivity);
        }
    }
}
