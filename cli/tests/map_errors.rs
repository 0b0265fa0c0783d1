//! `surfmap map` refuses bad jobs with a typed error and exit code 2.

mod common;
use common::*;

fn run_map(src: &str, tgt: &str, spec: &str, tag: &str) -> (i32, String) {
    let dir = tempdir(tag);
    let spec_path = dir.join("spec.json");
    std::fs::write(&spec_path, spec).unwrap();
    let o = surfmap(&[
        "map",
        mesh(src).to_str().unwrap(),
        mesh(tgt).to_str().unwrap(),
        "--spec",
        spec_path.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn malformed_spec() {
    let (code, err) = run_map("cow.off", "cow.off", r#"{"method": "voronoi", "anchors": [[0, 0]"#, "spec1");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_spec]"), "{err}");
    let (code, err) = run_map("cow.off", "cow.off", r#"{"method": "nope", "anchors": []}"#, "spec2");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[unknown_method]") && err.contains("nope") && err.contains("voronoi, greedy"), "{err}");
    let (code, err) = run_map(
        "cow.off",
        "cow.off",
        r#"{"method": "voronoi", "anchors": [[0,0],[1,1],[2,2]], "optoins": {}}"#,
        "spec3",
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("optoins"), "{err}");
}

#[test]
fn genus_mismatch() {
    let spec = r#"{"method": "voronoi", "anchors": [[0,0],[10,10],[20,20],[30,30],[40,40],[50,50]]}"#;
    let (code, err) = run_map("cow.off", "torus.obj", spec, "genus");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[topology_mismatch]") && err.contains("genus mismatch"), "{err}");
}

#[test]
fn too_few_anchors() {
    let (code, err) = run_map("cow.off", "cow.off", r#"{"method": "greedy", "anchors": [[0,0],[100,100]]}"#, "few");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("too few anchors"), "{err}");
}

#[test]
fn inconsistent_anchors() {
    // Out of range on the target.
    let (code, err) =
        run_map("cow.off", "cow.off", r#"{"method": "voronoi", "anchors": [[0,0],[100,100],[200,999999]]}"#, "range");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("999999"), "{err}");
    // Two anchors onto one target vertex.
    let (code, err) =
        run_map("cow.off", "cow.off", r#"{"method": "voronoi", "anchors": [[0,0],[100,100],[200,100]]}"#, "dup");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("repeat target vertex 100"), "{err}");
}

#[test]
fn homology_refusals() {
    // Genus 0 without feature curves has no homology basis.
    let (code, err) = run_map("cow.off", "cow.off", r#"{"method": "homology", "anchors": [[0,0]]}"#, "hom0");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[topology_mismatch]") && err.contains("genus"), "{err}");
    // The base vertex is the first anchor: none given.
    let (code, err) = run_map("torus.obj", "torus.obj", r#"{"method": "homology", "anchors": []}"#, "hom1");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("too few anchors"), "{err}");
    // Genus mismatch.
    let (code, err) = run_map("torus.obj", "eight_lowres.off", r#"{"method": "homology", "anchors": [[0,0]]}"#, "hom2");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("genus mismatch"), "{err}");
}

#[test]
fn bad_feature_curves_and_matchings() {
    // Vertices 0 and 500 of the cow are not joined by an edge.
    let spec = r#"{"method": "homology", "anchors": [], "features": [{"source": [0, 500], "target": [0, 500]}]}"#;
    let (code, err) = run_map("cow.off", "cow.off", spec, "feat1");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_features]") && err.contains("not joined by an edge"), "{err}");
    // On a surface with handles the base vertex (first anchor) must not lie on a feature curve.
    let spec = r#"{"method": "homology", "anchors": [[0, 0]], "features": [{"source": [0, 1], "target": [0, 1]}]}"#;
    let (code, err) = run_map("torus.obj", "torus.obj", spec, "feat2");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("feature curve"), "{err}");
    // A matching that reverses orientation.
    let spec = r#"{"method": "homology", "anchors": [[0, 0]], "options": {"matching": ["a1 -> b1", "b1 -> a1"]}}"#;
    let (code, err) = run_map("torus.obj", "torus.obj", spec, "match");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_spec]") && err.contains("symplectic"), "{err}");
}
