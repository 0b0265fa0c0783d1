//! Anchors given as surface points: face points and positions become vertices (inserted where
//! none lies within 1e-9 of the diagonal), the map holds them exactly, `metrics.json` reports
//! each snap, and `morph.glb` leaves the inserted vertices out.

use geom::io::ReadOptions;
use geom::mesh::{P3, shapes};
use geom::pipeline::{JobSpec, run_job};
use geom::progress::NoProgress;
use serde_json::{Value, json};

#[test]
fn point_anchors_are_inserted_held_and_reported() {
    let s = shapes::icosphere(3);
    let t = s.with_positions(s.positions().iter().map(|p| P3::new(p.x * 1.4, p.y, p.z * 0.8)).collect()).unwrap();
    let point = |m: &geom::Mesh, f: usize, b: [f64; 3]| {
        let [a, bb, c] = m.faces()[f].map(|v| m.position(v));
        let p = a.coords * b[0] + bb.coords * b[1] + c.coords * b[2];
        [p.x, p.y, p.z]
    };
    // Six face points (same face and coordinates on both: the copy has the same faces), two
    // positions slightly off the surface, and one plain id row.
    let faces = [0usize, 97, 201, 333, 517, 640, 777, 901];
    let mut rows: Vec<Value> = faces[..6]
        .iter()
        .map(|&f| json!({"source": {"face": f, "bary": [0.2, 0.3, 0.5]}, "target": {"face": f, "bary": [0.2, 0.3, 0.5]}}))
        .collect();
    for &f in &faces[6..] {
        let (ps, pt) = (point(&s, f, [0.5, 0.25, 0.25]), point(&t, f, [0.5, 0.25, 0.25]));
        rows.push(json!({"source": [ps[0] * 1.001, ps[1] * 1.001, ps[2] * 1.001], "target": pt}));
    }
    rows.push(json!([5, 5]));
    let spec = json!({"method": "voronoi", "anchors": rows, "options": {"metric_samples": 5000}});
    let spec = JobSpec::from_json(spec.to_string().as_bytes()).unwrap();
    let (report, arts) = run_job(&spec, &[s.clone(), t.clone()], &mut NoProgress).unwrap();
    let pair = report.pair().unwrap();
    assert_eq!(pair.anchor_points.len(), 8);
    for a in &pair.anchor_points {
        assert!(a.source.inserted && a.target.inserted, "{a:?}");
    }
    assert!(pair.anchor_points[6].source.distance > 1e-4 && pair.anchor_points[6].target.distance < 1e-12);
    for m in [&pair.source_to_target, &pair.target_to_source] {
        assert_eq!(m.flipped_faces, 0);
        assert!(m.anchor_error_max.unwrap() <= 1e-9, "{m:?}");
    }
    assert_eq!(pair.source_vertices, s.n_vertices() + 8);
    let metrics: Value =
        serde_json::from_slice(&arts.iter().find(|a| a.name == "metrics.json").unwrap().bytes).unwrap();
    assert_eq!(metrics["anchor_points"].as_array().unwrap().len(), 8, "{}", metrics["anchor_points"]);
    // morph.glb: the source as given (no inserted vertex).
    let glb = &arts.iter().find(|a| a.name == "morph.glb").unwrap().bytes;
    let m = geom::io::read(glb, &ReadOptions::default()).unwrap();
    assert_eq!(m.mesh.n_vertices(), s.n_vertices());
    // So do the re-embedded OBJs: the inputs' own faces at the mapped positions.
    for (name, input) in [("source_on_target.obj", &s), ("target_on_source.obj", &t)] {
        let obj = &arts.iter().find(|a| a.name == name).unwrap().bytes;
        let m = geom::io::read(obj, &ReadOptions::default()).unwrap().mesh;
        assert_eq!(m.faces(), input.faces(), "{name}");
    }
}

#[test]
fn malformed_point_anchors_are_named() {
    let bad = [
        (json!({"source": {"face": 0, "bary": [0.5, 0.6, 0.0]}, "target": [0, 0, 0]}), "sum to 1"),
        (json!({"source": {"face": 99999, "bary": [1, 0, 0]}, "target": [0, 0, 0]}), "out of range"),
        (json!({"source": [0, 0], "target": [0, 0, 0]}), "anchor row is"),
        (json!({"source": [0, 0, 0]}), "anchor row is"),
    ];
    let s = shapes::icosphere(2);
    for (row, want) in bad {
        let spec = json!({"method": "voronoi", "anchors": [row, [1, 1], [2, 2], [3, 3]]});
        let e = match JobSpec::from_json(spec.to_string().as_bytes()) {
            Err(e) => e,
            Ok(spec) => run_job(&spec, &[s.clone(), s.clone()], &mut NoProgress).unwrap_err(),
        };
        assert!(e.is_input(), "{e}");
        assert!(e.to_string().contains(want), "{e} (want {want})");
    }
}
