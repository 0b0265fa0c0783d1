//! Every malformed-input class gives a clear message on stderr and exit code 2, never a panic.

mod common;
use common::*;
use std::path::PathBuf;

fn write(dir: &std::path::Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Runs `inspect` and returns stderr, asserting exit code 2.
fn refused(path: &std::path::Path) -> String {
    let o = surfmap(&["inspect", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{}: expected exit 2, stderr: {err}", path.display());
    assert!(!err.contains("panicked"), "{err}");
    assert!(o.stdout.is_empty());
    err
}

#[test]
fn malformed_inputs_exit_2_with_a_named_problem() {
    let d = tempdir("bad");
    let cow = std::fs::read(mesh("cow.off")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("truncated.off", cow[..cow.len() / 2].to_vec(), "parse_error"),
        ("truncated.ply", { let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec(); b.extend_from_slice(&[0u8; 40]); b }, "lying_count"),
        ("truncated_tail.off", cow[..cow.len() - 40].to_vec(), "parse_error"),
        ("lying.off", b"OFF\n1000000 2000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(), "lying_count"),
        ("lying.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 10000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0".to_vec(), "lying_count"),
        ("lying.stl", { let mut b = vec![0u8; 84 + 50]; b[80..84].copy_from_slice(&1_000_000u32.to_le_bytes()); b }, "lying_count"),
        ("bad_index.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n".to_vec(), "index_out_of_range"),
        ("bad_index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n".to_vec(), "parse_error"),
        ("negative.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n".to_vec(), "parse_error"),
        ("nan.off", b"OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n".to_vec(), "non_finite_coordinate"),
        ("inf.obj", b"v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n".to_vec(), "non_finite_coordinate"),
        // Three triangles on one edge.
        ("nonmanifold_edge.off", b"OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n".to_vec(), "non_manifold_edge"),
        // Two fans (bow tie) sharing vertex 0.
        ("nonmanifold_vertex.off", b"OFF\n5 2 0\n0 0 0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n3 0 1 2\n3 0 3 4\n".to_vec(), "non_manifold_vertex"),
        ("empty.obj", b"".to_vec(), "empty_input"),
        ("blank.off", b"   \n\n".to_vec(), "empty_input"),
        ("garbage.bin", (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect(), "unknown_format"),
        // A face line that promises 5 vertices but holds 3, among triangles and quads.
        ("mixed_sizes.off", b"OFF\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 0\n3 0 1 2\n5 0 2 3\n4 0 1 2 3\n".to_vec(), "parse_error"),
        ("small_face.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n".to_vec(), "face_too_small"),
        ("degenerate.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n".to_vec(), "degenerate_face"),
        ("duplicate.off", b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 1 2 0\n".to_vec(), "duplicate_face"),
        ("noface.obj", b"v 0 0 0\nv 1 0 0\n".to_vec(), "no_faces"),
        ("huge_count.off", b"OFF\n99999999999 1 0\n".to_vec(), "too_large"),
        // Meshes that read but cannot be mapped: coordinates whose areas overflow, no extent,
        // a zero-area face in a closed mesh (the server refuses the same at upload).
        ("overflow.obj", b"v 1e200 0 0\nv -1e200 0 0\nv 0 1e200 0\nv 0 0 1e200\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n".to_vec(), "mesh_not_finite"),
        ("one_point.obj", b"v 1 1 1\nv 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n".to_vec(), "mesh_no_extent"),
        ("flat_face.obj", b"v 0 0 0\nv 2 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n".to_vec(), "zero_area_face"),
        // glTF: a GLB header promising more bytes than the file, a Draco-only document, an
        // accessor reading past its buffer.
        ("lying.glb", { let mut b = b"glTF".to_vec(); b.extend_from_slice(&2u32.to_le_bytes()); b.extend_from_slice(&5000u32.to_le_bytes()); b.extend_from_slice(&[0u8; 20]); b }, "lying_count"),
        ("draco.gltf", br#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"], "meshes": []}"#.to_vec(), "unsupported_extension"),
        ("past_buffer.gltf", br#"{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 12, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAA"}], "bufferViews": [{"buffer": 0, "byteLength": 12}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}"#.to_vec(), "lying_count"),
    ];
    let mut wrong = Vec::new();
    for (name, bytes, code) in cases {
        let p = write(&d, name, &bytes);
        let err = refused(&p);
        if !err.contains(&format!("[{code}]")) {
            wrong.push(format!("{name}: expected [{code}], got: {err}"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn missing_file_and_bad_arguments_exit_2() {
    let o = surfmap(&["inspect", "/nonexistent/mesh.off"]);
    assert_eq!(o.status.code(), Some(2));
    let o = surfmap(&["frobnicate"]);
    assert_eq!(o.status.code(), Some(2));
    let d = tempdir("args");
    let anchors = write(&d, "a.json", b"{\"anchors\": [[0, 99999]]}");
    let cow = mesh("cow.off");
    let c = cow.to_str().unwrap();
    let o = surfmap(&["metrics", c, c, c, "--anchors", anchors.to_str().unwrap(), "--samples", "100"]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("out_of_range"));
    let bad = write(&d, "b.json", b"{\"anchor\": 3}");
    let o = surfmap(&["metrics", c, c, c, "--anchors", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    // A source whose areas overflow: refused, not a report of inf and NaN.
    let big = write(
        &d,
        "big.obj",
        b"v 1e200 0 0\nv -1e200 0 0\nv 0 1e200 0\nv 0 0 1e200\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
    );
    let o =
        surfmap(&["metrics", big.to_str().unwrap(), big.to_str().unwrap(), big.to_str().unwrap(), "--samples", "100"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("[mesh_not_finite]"));
    // Mapped mesh with other connectivity.
    let horse = mesh("horse.off");
    let o = surfmap(&["metrics", c, c, horse.to_str().unwrap(), "--samples", "100"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("topology_mismatch"));
}

#[test]
fn valid_polygons_are_triangulated_with_a_warning() {
    let d = tempdir("poly");
    let p =
        write(&d, "mixed.off", b"OFF\n6 3 0\n0 0 0\n1 0 0\n2 0 0\n2 1 0\n1 1 0\n0 1 0\n3 0 1 4\n4 1 2 3 4\n3 0 4 5\n");
    let j = stdout_json(&surfmap(&["inspect", p.to_str().unwrap()]));
    assert_eq!(j["faces"], 4);
    assert_eq!(j["boundary_loops"], 1);
    assert!(j["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "polygons_triangulated"));
    // Unreferenced vertices are removed with a warning.
    let p = write(&d, "unref.obj", b"v 0 0 0\nv 1 0 0\nv 5 5 5\nv 0 1 0\nf 1 2 4\n");
    let j = stdout_json(&surfmap(&["inspect", p.to_str().unwrap()]));
    assert_eq!(j["vertices"], 3);
    assert!(j["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "unreferenced_vertices"));
    // Inconsistent orientation is repaired with a warning.
    let p = write(&d, "orient.off", b"OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 3 2\n");
    let j = stdout_json(&surfmap(&["inspect", p.to_str().unwrap()]));
    assert!(j["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "reoriented"));
}
