//! `surfmap metrics` against numbers printed by `shared/eval/meshmetrics.py` on the same files:
//! identity, an affine stretch and a locally folded map. Expected values are the evaluator's,
//! stored here; every key must agree within 1% (or exactly, for counts and zeros).
//!
//! Reproduce: `python3 shared/eval/meshmetrics.py cow.off T M --anchors cow_anchors.json --gt cow_gt.txt`.

mod common;
use common::*;
use serde_json::Value;

fn check(source: &str, target: &str, mapped: &str, expected: &[(&str, f64)]) {
    let o = surfmap(&[
        "metrics",
        source,
        target,
        mapped,
        "--anchors",
        fixture("cow_anchors.json").to_str().unwrap(),
        "--gt",
        fixture("cow_gt.txt").to_str().unwrap(),
    ]);
    let j = stdout_json(&o);
    for &(k, want) in expected {
        let got = j[k].as_f64().unwrap_or_else(|| panic!("missing key {k}"));
        let ok = if want == 0.0 { got.abs() < 1e-12 } else { ((got - want) / want).abs() <= 0.01 };
        assert!(ok, "{k}: surfmap {got} vs evaluator {want}");
    }
    // One key beyond the evaluator's: where the flipped faces are, when there are any.
    let flipped = j["flipped_faces"].as_u64().unwrap() as usize;
    let listed = j.get("flipped_face_ids").map_or(0, |ids| ids.as_array().unwrap().len());
    assert_eq!(listed, flipped.min(100), "flipped_face_ids lists the flipped faces: {j}");
    let keys = j.as_object().unwrap().len() - usize::from(listed > 0);
    assert_eq!(keys, expected.len(), "same key set as the evaluator: {j}");
    let _: &Value = &j;
}

#[test]
fn identity_map() {
    let c = mesh("cow.off");
    let c = c.to_str().unwrap();
    check(
        c,
        c,
        c,
        &[
            ("vertices", 2762.0),
            ("faces", 5520.0),
            ("off_surface_max", 0.0),
            ("off_surface_mean", 0.0),
            ("flipped_faces", 0.0),
            ("area_ratio", 1.0),
            ("l2_stretch", 1.0),
            ("linf_stretch", 1.0000000000000004),
            ("angle_distortion", 0.0),
            ("degenerate_faces", 0.0),
            ("hausdorff", 0.0013052131724197672),
            ("rms", 9.68564311190436e-06),
            ("psnr_db", 100.2774307499484),
            ("anchor_error_max", 0.0),
            ("gt_error_mean", 0.0),
            ("gt_error_max", 0.0),
        ],
    );
}

#[test]
fn affine_stretch() {
    let c = mesh("cow.off");
    let a = fixture("cow_affine.off");
    let a = a.to_str().unwrap();
    check(
        c.to_str().unwrap(),
        a,
        a,
        &[
            ("vertices", 2762.0),
            ("faces", 5520.0),
            ("off_surface_max", 0.0),
            ("off_surface_mean", 0.0),
            ("flipped_faces", 0.0),
            ("area_ratio", 1.0),
            ("l2_stretch", 1.0686889139977285),
            ("linf_stretch", 1.3692344726085246),
            ("angle_distortion", 0.3037685238121739),
            ("degenerate_faces", 0.0),
            ("hausdorff", 0.0010771065329273134),
            ("rms", 6.3091660235041334e-06),
            ("psnr_db", 104.00056088271558),
            ("anchor_error_max", 0.0),
            ("gt_error_mean", 0.0),
            ("gt_error_max", 0.0),
        ],
    );
}

#[test]
fn locally_folded_map() {
    let c = mesh("cow.off");
    let c = c.to_str().unwrap();
    let f = fixture("cow_fold.off");
    check(
        c,
        c,
        f.to_str().unwrap(),
        &[
            ("vertices", 2762.0),
            ("faces", 5520.0),
            ("off_surface_max", 0.0),
            ("off_surface_mean", 0.0),
            ("flipped_faces", 2.0),
            ("area_ratio", 1.0003774472200393),
            ("l2_stretch", 1.001209363453283),
            ("linf_stretch", 6.982522104462847),
            ("angle_distortion", 0.003411079462413813),
            ("degenerate_faces", 0.0),
            ("hausdorff", 0.004550622959473937),
            ("rms", 4.008019478320851e-05),
            ("psnr_db", 87.94140353070689),
            ("anchor_error_max", 0.026928458979658707),
            ("gt_error_mean", 1.1873204540058078e-05),
            ("gt_error_max", 0.03279379093964041),
        ],
    );
}
