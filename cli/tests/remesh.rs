//! `surfmap remesh`: a consistent quad remesh of two shared meshes end to end, and typed
//! refusals with exit code 2.

mod common;
use common::*;

fn run_remesh(meshes: &[&str], spec: &str, tag: &str) -> (i32, String, String, std::path::PathBuf) {
    let dir = tempdir(tag);
    let spec_path = dir.join("spec.json");
    std::fs::write(&spec_path, spec).unwrap();
    let out = dir.join("out");
    let paths: Vec<String> = meshes.iter().map(|m| mesh(m).to_str().unwrap().to_string()).collect();
    let mut args = vec!["remesh"];
    args.extend(paths.iter().map(String::as_str));
    args.extend(["--spec", spec_path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let o = surfmap(&args);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out,
    )
}

#[test]
fn remesh_two_cows_writes_every_artifact() {
    // cow.off against itself with another feature: the simplest consistent pair.
    let spec = r#"{"method": "quad", "anchors": [[0, 0], [1000, 1000], [2000, 2000], [2700, 2700], [500, 500]],
        "options": {"level": 4, "image_level": 3, "metric_samples": 5000, "morph": {"frames": 2}}}"#;
    let (code, out, err, dir) = run_remesh(&["cow.off", "cow.off"], spec, "rm1");
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["remesh_faces"], 4 * 16 * 16);
    for f in [
        "remesh_0.obj",
        "remesh_1.obj",
        "param_0.obj",
        "morph.glb",
        "morph_001.obj",
        "geometry_images.json",
        "normal_1_patch1.png",
        "metrics.json",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let a = std::fs::read_to_string(dir.join("remesh_0.obj")).unwrap();
    let b = std::fs::read_to_string(dir.join("remesh_1.obj")).unwrap();
    let faces = |s: &str| s.lines().filter(|l| l.starts_with("f ")).map(str::to_string).collect::<Vec<_>>();
    assert_eq!(faces(&a), faces(&b));
}

#[test]
fn remesh_refusals() {
    let (code, _, err, _) =
        run_remesh(&["cow.off", "torus.obj"], r#"{"method": "quad", "anchors": [[0,0],[1,1],[2,2],[3,3]]}"#, "rm2");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[topology_mismatch]") && err.contains("genus"), "{err}");
    let (code, _, err, _) =
        run_remesh(&["cow.off", "cow.off"], r#"{"method": "quad", "anchors": [[0,0],[1,1],[2,2]]}"#, "rm3");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_anchors]") && err.contains("4 partition points"), "{err}");
    let (code, _, err, _) =
        run_remesh(&["cow.off", "cow.off"], r#"{"method": "quad", "anchors": [[0,0],[1,1],[2,2],[3,99999]]}"#, "rm4");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("99999"), "{err}");
    let (code, _, err, _) =
        run_remesh(&["cow.off"], r#"{"method": "quad", "anchors": [[0],[1],[2],[3]], "options": {"lvl": 3}}"#, "rm5");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("[invalid_spec]") && err.contains("lvl"), "{err}");
}
