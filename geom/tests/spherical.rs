//! The `spherical` method end to end through `run_job`: both directions fold-free with anchors
//! exact on a twisted copy, equal connectivity of the outputs, and the spec's edges.

use geom::mesh::shapes;
use geom::pipeline::{JobReport, JobSpec, run_job};
use geom::progress::NoProgress;

#[test]
fn a_twisted_copy_maps_both_ways_without_folds_and_with_anchors_exact() {
    let (a, b) = (shapes::icosphere(3), shapes::twisted_icosphere(3));
    let spec =
        JobSpec::from_json(br#"{"method": "spherical", "anchors": [[0, 0], [7, 7], [40, 40], [300, 300]]}"#).unwrap();
    let (report, arts) = run_job(&spec, &[a.clone(), b.clone()], &mut NoProgress).unwrap();
    let JobReport::Spherical(r) = &report else { panic!("not a spherical report") };
    assert_eq!(r.pair.method, "spherical");
    for m in [&r.pair.source_to_target, &r.pair.target_to_source] {
        assert_eq!(m.flipped_faces, 0);
        assert_eq!(m.degenerate_faces, 0);
        assert!(m.anchor_error_max.unwrap() < 1e-12, "{:?}", m.anchor_error_max);
        assert!((m.area_ratio - 1.0).abs() < 0.05, "{}", m.area_ratio);
    }
    assert_eq!(r.spherical.source_to_target.turned_over, 0);
    assert_eq!(r.spherical.target_to_source.turned_over, 0);
    // The outputs keep each input's connectivity.
    let on_target = arts.iter().find(|x| x.name == "source_on_target.obj").expect("source_on_target.obj");
    let read = geom::io::read(&on_target.bytes, &Default::default()).unwrap().mesh;
    assert_eq!(read.face_indices(), a.face_indices());
    assert!(arts.iter().any(|x| x.name == "metrics.json"));
}

#[test]
fn a_torus_an_unknown_option_and_too_few_anchors_are_refused_with_their_codes() {
    let torus = shapes::torus(12, 8, 2.0, 0.5);
    let spec = JobSpec::from_json(br#"{"method": "spherical", "anchors": [[0, 0], [5, 5], [9, 9]]}"#).unwrap();
    let err = run_job(&spec, &[torus.clone(), torus], &mut NoProgress).unwrap_err();
    assert_eq!(err.code(), "topology_mismatch", "{err}");
    let err =
        JobSpec::from_json(br#"{"method": "spherical", "anchors": [], "options": {"smoothing": {}}}"#).unwrap_err();
    assert_eq!(err.code(), "invalid_spec", "{err}");
    let ico = shapes::icosphere(2);
    let spec = JobSpec::from_json(br#"{"method": "spherical", "anchors": [[0, 0], [5, 5]]}"#).unwrap();
    let err = run_job(&spec, &[ico.clone(), ico], &mut NoProgress).unwrap_err();
    assert_eq!(err.code(), "invalid_anchors", "{err}");
}

#[test]
fn a_spec_without_method_runs_spherical_on_two_closed_spheres_of_different_shapes_and_says_why() {
    // The twisted copy is stretched too (1.6 × 0.9 × 0.7): its anchors' geodesics differ from
    // the sphere's, so `auto` runs `spherical` (a copy of the same shape runs `voronoi`:
    // `plan/same_shape.rs`).
    let (a, b) = (shapes::icosphere(3), shapes::twisted_icosphere(3));
    let spec = JobSpec::from_json(br#"{"anchors": [[0, 0], [7, 7], [40, 40], [300, 300]]}"#).unwrap();
    let (report, arts) = run_job(&spec, &[a, b], &mut NoProgress).unwrap();
    let JobReport::Spherical(r) = &report else { panic!("auto did not run spherical") };
    assert_eq!(r.pair.source_to_target.flipped_faces, 0);
    assert_eq!(r.pair.target_to_source.flipped_faces, 0);
    let metrics = arts.iter().find(|x| x.name == "metrics.json").expect("metrics.json");
    let v: serde_json::Value = serde_json::from_slice(&metrics.bytes).unwrap();
    assert_eq!(v["method"], "spherical");
    assert_eq!(v["auto"]["method"], "spherical");
    assert!(v["auto"]["reason"].as_str().unwrap().contains("different shapes"), "{v}");
    // A torus pair goes to homology, and the chosen method's checks apply as if named.
    let torus = shapes::torus(12, 8, 2.0, 0.5);
    let spec = JobSpec::from_json(br#"{"method": "auto", "anchors": []}"#).unwrap();
    let err = run_job(&spec, &[torus.clone(), torus], &mut NoProgress).unwrap_err();
    assert_eq!(err.code(), "invalid_anchors", "homology needs its base anchor: {err}");
}
