//! Method `homology` between different shapes of genus 2 (`eight.off` ↔ the cup) and genus 1
//! (the kitten ↔ the rocker arm): two homotopy classes each, told apart by their induced maps on
//! H1, each map with 0 flipped faces both ways (the shared evaluator's rule, which `metrics`
//! reproduces) and the base anchors exact.

use geom::mesh::Mesh;
use geom::pipeline::homology::HomologyMapReport;
use geom::pipeline::homology::run as run_map;
use geom::pipeline::{HomologyOptions, HomologySpec};
use geom::progress::NoProgress;

mod common;
use common::load;

fn run(s: &Mesh, t: &Mesh, basis: [usize; 2], rotation: usize) -> HomologyMapReport {
    let spec = HomologySpec {
        features: Vec::new(),
        anchors: geom::pipeline::AnchorRow::ids(vec![[0, 0]]),
        options: HomologyOptions {
            metric_samples: 5000,
            rotation: Some(rotation),
            basis: Some(basis),
            ..Default::default()
        },
    };
    run_map(&spec, s, t, &mut NoProgress).unwrap().0
}

#[test]
fn eight_to_cup_in_two_homotopy_classes_without_flips() {
    let s = load("eight.off");
    let t = load("cup_input_simple_10000.off");
    let mut h1s = Vec::new();
    for basis in [[2, 0], [2, 2]] {
        let r = run(&s, &t, basis, 0);
        for m in [&r.pair.source_to_target, &r.pair.target_to_source] {
            assert_eq!(m.flipped_faces, 0, "basis {basis:?}: {m:?}");
            assert!(m.anchor_error_max.unwrap() <= 1e-9, "basis {basis:?}: {m:?}");
            assert!(m.off_surface_max <= 1e-9, "basis {basis:?}: {m:?}");
        }
        let h = r.homology;
        h1s.push(h.h1_reference.unwrap_or(h.h1));
    }
    assert_ne!(h1s[0], h1s[1], "two different classes");
}

/// The rocker arm has long slivers (edges 7× the median): a point mapped inside one can be
/// farther than 24 face centroids from it, so the evaluator's (and `metrics`') off-surface
/// distance reads ~2e-3 of the diagonal where the exact projection reads 0. On-surface is
/// checked exactly here.
#[test]
fn kitten_to_rocker_arm_in_two_homotopy_classes_without_flips() {
    let s = load("kitten.nf20k.off");
    let t = load("rocker_arm/rocker-arm.obj");
    let mut h1s = Vec::new();
    for rotation in [1, 2] {
        let spec = HomologySpec {
            features: Vec::new(),
            anchors: geom::pipeline::AnchorRow::ids(vec![[0, 0]]),
            options: HomologyOptions { metric_samples: 5000, rotation: Some(rotation), ..Default::default() },
        };
        let (r, arts) = run_map(&spec, &s, &t, &mut NoProgress).unwrap();
        for m in [&r.pair.source_to_target, &r.pair.target_to_source] {
            assert_eq!(m.flipped_faces, 0, "rotation {rotation}: {m:?}");
            assert!(m.anchor_error_max.unwrap() <= 1e-9, "rotation {rotation}: {m:?}");
        }
        common::source_on_target(&arts, &s, &t);
        h1s.push(r.homology.h1);
    }
    assert_ne!(h1s[0], h1s[1], "two different classes");
}
