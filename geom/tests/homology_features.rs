//! Method `homology` with feature curves and boundary loops (Carner et al. section 3.4) on
//! shared meshes: genus-0 surfaces, closed and with a boundary loop, four features each. Every
//! feature vertex lands on its partner curve, nothing folds, both outputs keep the input faces,
//! and bad curves are refused with a typed error. Two different heads with anatomically placed
//! features map without folds as well.

use geom::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
use geom::mesh::{Mesh, VertexId};
use geom::pipeline::homology::features::run as run_map;
use geom::pipeline::{FeatureSpec, HomologyOptions, HomologySpec, homology::features::FeatureMapReport};
use geom::progress::NoProgress;

mod common;
use common::{bent, load, twisted};

/// `k` feature curves of about 6% of the diagonal, two rings from the boundary and each other
/// ([`common::feature_curves`]).
fn features(m: &Mesh, k: usize) -> Vec<Vec<VertexId>> {
    common::feature_curves(m, k, 0.06, 2)
}

fn spec(curves: &[Vec<VertexId>], anchors: Vec<[u64; 2]>) -> HomologySpec {
    spec_pairs(curves.iter().zip(curves), anchors)
}

/// A job with curve pairs (source, target) on two different meshes.
fn spec_pairs<'a>(
    pairs: impl Iterator<Item = (&'a Vec<VertexId>, &'a Vec<VertexId>)>,
    anchors: Vec<[u64; 2]>,
) -> HomologySpec {
    let raw = |p: &Vec<VertexId>| p.iter().map(|v| v.0 as u64).collect::<Vec<_>>();
    HomologySpec {
        anchors: geom::pipeline::AnchorRow::ids(anchors),
        features: pairs.map(|(p, q)| FeatureSpec { source: raw(p), target: raw(q) }).collect(),
        options: HomologyOptions { metric_samples: 5000, ..Default::default() },
    }
}

/// Runs a job on a same-shape pair (vertex `i` ↔ vertex `i`) and checks what every feature job
/// must satisfy; returns the report and the mean ground-truth error over √area.
fn check(s: &Mesh, t: &Mesh, sp: &HomologySpec) -> (FeatureMapReport, f64) {
    let (r, gt, _) = check_mapped(s, t, sp);
    (r, gt)
}

/// [`check`], also returning the source re-embedded on the target.
fn check_mapped(s: &Mesh, t: &Mesh, sp: &HomologySpec) -> (FeatureMapReport, f64, Mesh) {
    let (report, arts) = run_map(sp, s, t, &mut NoProgress).unwrap();
    common::assert_artifacts(
        &arts,
        &["basis_source.json", "basis_target.json", "domain_source.obj", "domain_target.obj"],
    );
    assert!(!arts.iter().any(|a| a.name == "metrics.json"), "metrics.json is the last phase's");
    let f = &report.features;
    assert!(
        f.feature_error[0] <= 1e-9 && f.feature_error[1] <= 1e-9,
        "features off their partners: {:?}",
        f.feature_error
    );
    assert_eq!(f.domain_flips, [0, 0]);
    assert_eq!(f.doubled_genus, f.curves - 1);
    assert_eq!((report.pair.source_to_target.flipped_faces, report.pair.target_to_source.flipped_faces), (0, 0));
    let mapped = common::source_on_target(&arts, s, t);
    let gt =
        mapped.positions().iter().enumerate().map(|(i, p)| (p - t.position(VertexId(i as u32))).norm()).sum::<f64>()
            / mapped.n_vertices() as f64
            / t.area().sqrt();
    (report, gt, mapped)
}

#[test]
fn a_hand_with_four_features_and_its_wrist_maps_onto_a_bent_copy() {
    let s = load("hand_lowres.obj");
    let t = bent(&s);
    let c = features(&s, 4);
    let (r, gt) = check(&s, &t, &spec(&c, vec![]));
    let f = r.features;
    assert_eq!(f.curves, 5, "four features and the wrist");
    assert!(f.word.contains("B5"), "{}", f.word);
    assert!(gt < 0.1, "gt {gt}");
}

#[test]
fn a_closed_bunny_with_three_features_maps_onto_a_twisted_copy() {
    let s = load("bunny.off");
    let t = twisted(&s);
    let c = features(&s, 3);
    let (r, gt) = check(&s, &t, &spec(&c, vec![]));
    assert_eq!(r.features.doubled_genus, 2);
    assert!(gt < 0.1, "gt {gt}");
}

/// The face's boundary zigzags (ears between fans of triangles whose three corners are boundary
/// vertices). Placed by arc length alone, the deformed copies' boundaries drift by several
/// vertices and such triangles land on chords that turn the other way (`bench/homology_features.py`
/// measured 3 and 5 flips); aligned
/// vertex by vertex, every boundary vertex lands on its own partner and nothing folds.
#[test]
fn a_zigzag_boundary_is_aligned_vertex_by_vertex_on_bent_and_twisted_copies() {
    let s = load("face.off");
    let c = features(&s, 4);
    for (name, t) in [("bent", bent(&s)), ("twisted", twisted(&s))] {
        let (_, gt, mapped) = check_mapped(&s, &t, &spec(&c, vec![]));
        let off = (0..s.n_vertices())
            .map(VertexId::from_idx)
            .filter(|&v| s.is_boundary_vertex(v))
            .filter(|&v| (mapped.position(v) - t.position(v)).norm() > 1e-12 * t.bbox_diagonal())
            .count();
        assert_eq!(off, 0, "{name}: boundary vertices off their partners");
        assert!(gt < 0.03, "{name}: gt {gt}");
    }
}

#[test]
fn a_face_maps_onto_itself_exactly() {
    let s = load("face.off");
    let c = features(&s, 4);
    let (_, gt) = check(&s, &s, &spec(&c, vec![]));
    assert!(gt < 1e-9, "gt {gt}");
}

/// The meta-mesh of feature jobs: both cut disks overlaid in the circle (each boundary refined
/// by the other's points) and sewn along every cut: one face list, every input vertex a
/// meta-vertex, the surfaces' χ, every vertex on its own surface. Same shape (hand bent, four
/// features and the wrist) and different shapes (face ↔ hand, pruned at 10°).
#[test]
fn feature_jobs_build_the_meta_mesh() {
    let s = load("hand_lowres.obj");
    let t = bent(&s);
    let mut sp = spec(&features(&s, 4), vec![]);
    sp.options.meta_mesh = true;
    let (r, arts) = run_map(&sp, &s, &t, &mut NoProgress).unwrap();
    let stats = r.features.meta_mesh.clone().expect("meta-mesh statistics");
    assert!(stats.error.is_none() && stats.crossings > 0, "{stats:?}");
    common::meta_pair(&arts, &s, &t, "hand bent", false);

    let (a, b) = (load("face.off"), load("hand_lowres.obj"));
    let (ca, cb) = (features(&a, 4), features(&b, 4));
    let mut sp = spec_pairs(ca.iter().zip(&cb), vec![]);
    sp.options.meta_mesh = true;
    sp.options.dihedral_threshold_deg = Some(10.0);
    let (r, arts) = run_map(&sp, &a, &b, &mut NoProgress).unwrap();
    let stats = r.features.meta_mesh.clone().expect("meta-mesh statistics");
    assert!(stats.error.is_none() && stats.pruned_vertices.is_some_and(|p| p > 0), "{stats:?}");
    common::meta_pair(&arts, &a, &b, "face / hand, pruned at 10°", true);
}

/// The vertex nearest the viewer (largest z) within `r` of `(x, y)`.
fn frontmost(m: &Mesh, (x, y): (f64, f64), r: f64) -> VertexId {
    (0..m.n_vertices())
        .map(VertexId::from_idx)
        .filter(|&v| {
            let p = m.position(v);
            (p.x - x).hypot(p.y - y) < r
        })
        .max_by(|&a, &b| m.position(a).z.total_cmp(&m.position(b).z))
        .expect("a vertex near the spot")
}

/// Shortest edge paths between the front-most vertices near each pair of spots.
fn head_curves(m: &Mesh, spots: &[[(f64, f64); 2]], r: f64) -> Vec<Vec<VertexId>> {
    spots
        .iter()
        .map(|[a, b]| {
            let (a, b) = (frontmost(m, *a, r), frontmost(m, *b, r));
            let o = VertexDijkstraOptions { target: Some(b), ..Default::default() };
            vertex_dijkstra(m, &[(a, 0.0)], &o).unwrap().path_to(b).unwrap()
        })
        .collect()
}

/// Two heads, both open at the neck (the boundary loops become the fifth feature), with four
/// features at anatomically corresponding places, read off front depth renders as in
/// `bench/homology_features.py`: the eyes (inner to outer corner), the nose ridge (brow to tip)
/// and the mouth (corner to corner). Every feature lands on its partner and nothing folds
/// either way. Before the two sides of each curve were made to agree, the left eye's tip folded
/// one face of the camel on the bust.
#[test]
fn two_heads_with_anatomical_features_map_without_folds() {
    let (a, b) = (load("demosthenes-low-res.obj"), load("camelhead.off"));
    let ca = head_curves(
        &a,
        &[
            [(0.02, 1.19), (0.12, 1.19)],
            [(0.26, 1.19), (0.36, 1.19)],
            [(0.19, 1.25), (0.19, 1.0)],
            [(0.10, 0.92), (0.28, 0.92)],
        ],
        0.03,
    );
    let cb = head_curves(
        &b,
        &[
            [(-0.16, 0.10), (-0.07, 0.10)],
            [(0.07, 0.10), (0.16, 0.10)],
            [(0.0, 0.10), (0.0, -0.17)],
            [(-0.08, -0.2), (0.08, -0.2)],
        ],
        0.012,
    );
    let (r, arts) = run_map(&spec_pairs(ca.iter().zip(&cb), vec![]), &a, &b, &mut NoProgress).unwrap();
    let f = &r.features;
    assert_eq!(f.curves, 5, "four features and the neck: {}", f.word);
    assert!(f.word.contains("B5"), "{}", f.word);
    assert!(f.feature_error[0] <= 1e-9 && f.feature_error[1] <= 1e-9, "{:?}", f.feature_error);
    assert_eq!(f.domain_flips, [0, 0]);
    assert_eq!((r.pair.source_to_target.flipped_faces, r.pair.target_to_source.flipped_faces), (0, 0));
    let mapped = common::source_on_target(&arts, &a, &b);
    assert_eq!(mapped.faces(), a.faces());
    assert!(r.pair.source_to_target.off_surface_max <= 1e-9 && r.pair.target_to_source.off_surface_max <= 1e-9);
}

#[test]
fn bad_curves_and_unsupported_topologies_are_refused() {
    let s = load("face.off");
    let b = (0..s.n_vertices() as u32).find(|&v| s.is_boundary_vertex(VertexId(v))).unwrap();
    let nb = s.vertex_neighbors(VertexId(b)).find(|w| !s.is_boundary_vertex(*w)).unwrap();
    let touching = vec![vec![VertexId(b), nb]];
    let e = run_map(&spec(&touching, vec![]), &s, &s, &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "invalid_features", "{e}");
    let e = run_map(&spec(&[], vec![]), &s, &s, &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "invalid_anchors", "{e}");
    let h = load("eight.hole.off");
    let e = run_map(&spec(&[], vec![[0, 0]]), &h, &h, &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "topology_mismatch", "{e}");
    let closed = load("bunny.off");
    let e = run_map(&spec(&[], vec![[0, 0]]), &closed, &closed, &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "topology_mismatch", "{e}");
    // Only `homology` takes feature curves: on another method they are an unknown field.
    let text = br#"{"method": "voronoi", "anchors": [[0, 0], [1, 1], [2, 2]], "features": [{"source": [0, 1], "target": [0, 1]}]}"#;
    let e = geom::pipeline::JobSpec::from_json(text).unwrap_err();
    assert_eq!(e.code(), "invalid_spec", "{e}");
}
