//! `voronoi` on open meshes (issue 34): the shared meshes with one boundary loop — a hand cut
//! at the wrist, a face mask, a genus-2 eight with a hole — onto mkcase copies (retriangulated,
//! bent and twisted, shuffled) with 24 farthest-point anchors. Both directions: 0 flipped faces,
//! anchors exact, every boundary vertex's image on the other mesh's boundary (loop onto loop),
//! and `metrics.json` reports how each loop was paired.

mod common;
use common::*;
use geom::io::{self, ReadOptions};
use geom::mesh::{Mesh, P3};
use std::path::Path;
use std::process::Command;

fn read(p: &Path) -> Mesh {
    io::read_path(p, &ReadOptions::default()).expect("read").mesh
}

/// Distance from `p` to the nearest boundary edge of `m`.
fn to_boundary(m: &Mesh, p: P3) -> f64 {
    let mut best = f64::INFINITY;
    for h in 0..m.n_halfedges() {
        let h = geom::mesh::HalfedgeId::from_idx(h);
        if !m.is_boundary_halfedge(h) {
            continue;
        }
        let (a, b) = (m.position(m.tail(h)), m.position(m.head(h)));
        let d = b - a;
        let t = ((p - a).dot(&d) / d.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        best = best.min((a + d * t - p).norm());
    }
    best
}

/// Largest distance (relative to `to`'s diagonal) of a boundary vertex of `from` mapped by
/// `mapped` (the re-embedded mesh, `from`'s vertex order) from `to`'s boundary.
fn boundary_off(from: &Mesh, to: &Mesh, mapped: &Mesh) -> f64 {
    let diag = to.bbox_diagonal();
    (0..from.n_vertices())
        .map(geom::mesh::VertexId::from_idx)
        .filter(|&v| from.is_boundary_vertex(v))
        .map(|v| to_boundary(to, mapped.position(v)) / diag)
        .fold(0.0, f64::max)
}

fn case(name: &str, seed: &str) {
    let dir = tempdir(&format!("open-{name}-{seed}"));
    let o = Command::new("python3")
        .arg(shared().join("tools/mkcase.py"))
        .arg(mesh(name))
        .arg(&dir)
        .args(["--seed", seed, "--anchors", "24"])
        .output()
        .expect("python3");
    assert!(o.status.success(), "mkcase: {}", String::from_utf8_lossy(&o.stderr));
    let anchors: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("anchors.json")).unwrap()).unwrap();
    let spec = serde_json::json!({"method": "voronoi", "anchors": anchors["anchors"]});
    std::fs::write(dir.join("spec.json"), spec.to_string()).unwrap();
    let p = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let out = dir.join("out");
    let o = surfmap(&[
        "map",
        &p("source.obj"),
        &p("target.obj"),
        "--spec",
        &p("spec.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("metrics.json")).unwrap()).unwrap();
    for d in ["source_to_target", "target_to_source"] {
        assert_eq!(m[d]["flipped_faces"], 0, "{name} {d}: {}", m[d]);
        assert!(m[d]["anchor_error_max"].as_f64().unwrap() <= 1e-9, "{name} {d}: {}", m[d]);
        assert!(m[d]["off_surface_max"].as_f64().unwrap() <= 1e-6, "{name} {d}: {}", m[d]);
    }
    let loops = m["boundaries"].as_array().expect("boundaries in metrics.json");
    assert_eq!(loops.len(), 1, "{name}: one loop pair");
    assert_eq!(loops[0]["off_loop"], serde_json::json!([0, 0]), "{name}: {}", loops[0]);
    let (s, t) = (read(&dir.join("source.obj")), read(&dir.join("target.obj")));
    let (on_t, on_s) = (read(&out.join("source_on_target.obj")), read(&out.join("target_on_source.obj")));
    let (a, b) = (boundary_off(&s, &t, &on_t), boundary_off(&t, &s, &on_s));
    assert!(a <= 1e-9 && b <= 1e-9, "{name}: boundary images off the boundary by {a:e} / {b:e}");
}

#[test]
fn a_hand_cut_at_the_wrist_maps_loop_onto_loop() {
    case("hand_lowres.obj", "3");
}

#[test]
fn a_face_mask_maps_loop_onto_loop() {
    case("face.off", "2");
}

#[test]
fn a_genus_two_eight_with_a_hole_maps_loop_onto_loop() {
    case("eight.hole.off", "1");
}
