//! An asset pipeline's pair: Keenan Crane's spot as a GLB split at its UV seams, mapped onto a
//! deformed, retriangulated, shuffled copy (mkcase) also sent as GLB. `morph.glb` must be the
//! source in its own layout (3225 vertices, `TEXCOORD_0` unchanged) and pass the Khronos glTF
//! validator with 0 errors; the map has 0 flipped faces both ways.

mod common;
use common::*;
use geom::io::{self, ReadOptions};
use std::path::Path;
use std::process::Command;

/// Runs the Khronos validator (installed from `tests/gltf-validator/package.json` on first use)
/// on a file; returns its summary.
fn khronos_validate(file: &Path) -> serde_json::Value {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/gltf-validator");
    if !dir.join("node_modules/gltf-validator").exists() {
        let o = Command::new("npm").args(["ci", "--no-audit", "--no-fund"]).current_dir(&dir).output().expect("npm");
        assert!(o.status.success(), "npm ci: {}", String::from_utf8_lossy(&o.stderr));
    }
    let o = Command::new("node").arg(dir.join("validate.cjs")).arg(file).output().expect("node");
    assert!(o.status.success(), "validator: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("validator JSON")
}

fn read(p: &Path) -> io::ReadResult {
    io::read_path(p, &ReadOptions::default()).expect("read")
}

#[test]
fn spot_glb_with_seams_maps_and_morph_keeps_its_layout() {
    let dir = tempdir("gltf-spot");
    let d = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let spot = mesh("spot.obj");
    // The case: a retriangulated, bent and shuffled copy, its anchors and true correspondence.
    let mk = shared().join("tools/mkcase.py");
    let o = Command::new("python3").arg(mk).arg(&spot).arg(&dir).args(["--seed", "5", "--anchors", "24"]).output();
    let o = o.expect("python3");
    assert!(o.status.success(), "mkcase: {}", String::from_utf8_lossy(&o.stderr));
    stdout_json(&surfmap(&["convert", spot.to_str().unwrap(), &d("source.glb")]));
    stdout_json(&surfmap(&["convert", &d("target.obj"), &d("target.glb")]));
    let (src, obj) = (read(&dir.join("source.glb")), read(&spot));
    let lay = src.layout.as_ref().expect("split layout");
    assert_eq!(lay.n_vertices(), 3225);
    // mkcase's anchors are OBJ `v` ids; in the GLB a vertex id counts its own (split) vertices.
    let glb_id = |v: usize| {
        let p = obj.mesh.positions()[v];
        // Nearest welded vertex (the GLB stores f32).
        let d = |k: usize| (src.mesh.positions()[k] - p).norm();
        let w = (0..src.mesh.n_vertices()).min_by(|&a, &b| d(a).total_cmp(&d(b))).unwrap() as u32;
        lay.welded.iter().position(|&x| x == w).unwrap()
    };
    let anchors: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("anchors.json")).unwrap()).unwrap();
    let rows: Vec<[usize; 2]> = anchors["anchors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| [glb_id(r[0].as_u64().unwrap() as usize), r[1].as_u64().unwrap() as usize])
        .collect();
    let spec = serde_json::json!({"method": "voronoi", "anchors": rows});
    std::fs::write(dir.join("spec.json"), spec.to_string()).unwrap();
    let out = dir.join("out");
    let report = stdout_json(&surfmap(&[
        "map",
        &d("source.glb"),
        &d("target.glb"),
        "--spec",
        &d("spec.json"),
        "--out",
        out.to_str().unwrap(),
    ]));
    for k in ["source_to_target", "target_to_source"] {
        assert_eq!(report[k]["flipped_faces"], 0, "{k}: {}", report[k]);
    }
    let morph = read(&out.join("morph.glb"));
    let ml = morph.layout.as_ref().expect("morph in the input's layout");
    assert_eq!(ml.n_vertices(), 3225);
    assert_eq!(ml.attributes.texcoords, lay.attributes.texcoords, "TEXCOORD_0 unchanged");
    assert_eq!(ml.triangles, lay.triangles);
    let v = khronos_validate(&out.join("morph.glb"));
    assert_eq!(v["errors"], 0, "{v}");
    // The morph target puts every copy of a vertex where the map sends it.
    let g = gltf::Gltf::from_slice(&std::fs::read(out.join("morph.glb")).unwrap()).unwrap();
    let prim = g.meshes().next().unwrap().primitives().next().unwrap();
    assert_eq!(prim.morph_targets().count(), 1);
}
