//! One job, one call: a typed [`JobSpec`] and its meshes in, a report and named artifacts out.
//! Nothing here touches files or sockets; callers write the artifacts wherever they keep them.
//!
//! [`run_job`] runs three phases, each a type: the spec and meshes become a [`Plan`]
//! ([`plan`]), the plan runs one pipeline per method into a [`MethodOutput`] ([`run`]), and
//! [`finish`] turns that into the job's report and artifacts. Each method imports [`common`] and
//! the spec, never another method's file.

pub mod common;
mod finish;
pub mod homology;
pub mod layout;
pub mod plan;
pub mod quad;
mod report;
pub mod run;
mod spec;
pub mod spherical;

pub use common::{Artifact, PairReport};
pub use plan::{MethodPlan, OutputOptions, Plan};
pub use quad::{QuadReport, Remeshes};
pub use report::{JobReport, MethodOutput, PartsReport};
pub use spec::anchor_spec::{AnchorPoints, AnchorRow, FacePoint, PointRef};
pub use spec::auto::AutoChoice;
pub use spec::limits::{MAX_ANCHORS, MAX_EDGE_NODES, MAX_FEATURES, MAX_METRIC_SAMPLES, MAX_MODELS, MAX_MORPH_FRAMES};
pub use spec::quad_spec::{Interpolation, LevelSchedule, MorphDomain, MorphOptions, QuadOptions, QuadSpec};
pub use spec::transfer::attribute_names;
pub use spec::{
    AutoOptions, AutoSpec, FeatureSpec, GlobalOptions, HomologyOptions, HomologySpec, JobSpec, LayoutSpec, METHODS,
    MapOptions, Method, RelaxOptions, SphericalOptions, SphericalSpec,
};

use crate::error::Result;
use crate::mesh::{InputLayout, Mesh};
use crate::progress::Progress;

/// Runs any job on its meshes (two for pair jobs, in source, target order).
///
/// A result with flipped faces is not a success: it fails with `MapFolds` (see [`finish`]).
///
/// # Errors
/// `InputError::Spec` for the wrong number of meshes; `MapFolds`; whatever the method reports.
pub fn run_job(spec: &JobSpec, meshes: &[Mesh], progress: &mut dyn Progress) -> Result<(JobReport, Vec<Artifact>)> {
    run_with_layouts(spec, meshes, &[], progress)
}

/// [`run_job`] on inputs read with their own layouts (glTF, OBJ with seams): vertex ids of
/// the spec count each input's own vertices, and `morph.glb` is the source in its layout with
/// its attributes. `layouts` may be shorter than `meshes` (missing = none). The job's three
/// phases: [`Plan::new`], [`run::run`], [`finish::finish`].
///
/// # Errors
/// As [`run_job`]; `InputError::Anchors` for an id past an input's vertices.
pub fn run_with_layouts(
    spec: &JobSpec,
    meshes: &[Mesh],
    layouts: &[Option<InputLayout>],
    progress: &mut dyn Progress,
) -> Result<(JobReport, Vec<Artifact>)> {
    let plan = Plan::new(spec, meshes, layouts)?;
    let output = run::run(&plan, progress)?;
    finish::finish(&plan, output)
}

#[cfg(test)]
mod cancel_tests {
    use super::*;
    use crate::error::Error;
    use crate::mesh::shapes;
    use crate::progress::{CancelToken, Stage};

    /// Cancels its token when a stage starts and records every stage reported.
    struct CancelAt {
        stage: Stage,
        token: CancelToken,
        seen: Vec<Stage>,
    }

    impl Progress for CancelAt {
        fn report(&mut self, stage: Stage, _fraction: f64) {
            if stage == self.stage {
                self.token.cancel();
            }
            self.seen.push(stage);
        }
        fn cancelled(&self) -> bool {
            self.token.is_cancelled()
        }
        fn token(&self) -> Option<CancelToken> {
            Some(self.token.clone())
        }
    }

    /// A cancel inside the smoothing stage ends the job with `Cancelled` before any later stage
    /// (both halves of the parallel split see it: the side half through `Progress::silent`).
    #[test]
    fn a_cancel_inside_a_stage_stops_the_job_there() {
        let s = shapes::icosphere(3);
        let t =
            s.with_positions(s.positions().iter().map(|p| crate::mesh::P3::new(p.x * 1.4, p.y, p.z * 0.8)).collect());
        let t = t.unwrap();
        let anchors: Vec<[u64; 2]> = [0u64, 5, 9, 13, 21, 40].iter().map(|&i| [i, i]).collect();
        let spec = JobSpec::Voronoi(LayoutSpec {
            boundaries: Vec::new(),
            anchors: crate::pipeline::AnchorRow::ids(anchors),
            options: MapOptions::default(),
        });
        let mut p = CancelAt { stage: Stage::Smooth, token: CancelToken::default(), seen: Vec::new() };
        let meshes = [s, t];
        let plan = Plan::new(&spec, &meshes, &[]).unwrap();
        let r = run::run(&plan, &mut p);
        assert!(matches!(r, Err(Error::Cancelled)), "{:?}", r.err());
        assert!(p.seen.contains(&Stage::Smooth), "{:?}", p.seen);
        assert!(
            !p.seen.iter().any(|s| matches!(s, Stage::Metrics | Stage::Done)),
            "ran on after the cancel: {:?}",
            p.seen
        );
    }
}

#[cfg(test)]
mod spec_tests {
    use super::*;

    /// Every method's spec reads back from its own JSON as the same value: what the server
    /// stores is what the worker runs.
    #[test]
    fn every_spec_round_trips_through_its_json() {
        let specs = [
            r#"{"method": "voronoi", "anchors": [[0, 1], [2, 3], [4, 5]], "options": {"layout": {"rebuilds": 2}, "global": {"enabled": false}}}"#,
            r#"{"method": "greedy", "anchors": [[0, 1], [2, 3], [4, 5]]}"#,
            r#"{"method": "homology", "anchors": [[0, 0]], "features": [{"source": [1, 2], "target": [3, 4]}], "options": {"basis": [1, 0], "matching": ["a1 -> b1", "b1 -> -a1"], "dihedral_threshold_deg": 12.5}}"#,
            r#"{"method": "quad", "anchors": [[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], "options": {"level": 4, "morph": {"interpolation": "spline", "schedule": [{"start": 0.1, "speed": 2.0}]}}}"#,
        ];
        for text in specs {
            let spec = JobSpec::from_json(text.as_bytes()).unwrap();
            let again = JobSpec::from_json(spec.to_json().unwrap().as_bytes()).unwrap();
            assert_eq!(spec, again, "{text}");
        }
    }

    #[test]
    fn unknown_methods_and_fields_are_named() {
        let e = JobSpec::from_json(br#"{"method": "nope", "anchors": []}"#).unwrap_err();
        assert_eq!(e.code(), "unknown_method");
        assert!(e.to_string().contains("voronoi, greedy, homology, quad"), "{e}");
        // Options of one method are unknown fields of another.
        let e =
            JobSpec::from_json(br#"{"method": "voronoi", "anchors": [], "options": {"basis": [0, 0]}}"#).unwrap_err();
        assert_eq!(e.code(), "invalid_spec");
        assert!(e.to_string().contains("basis"), "{e}");
        let e = JobSpec::from_json(br#"{"method": "greedy", "anchors": [], "features": []}"#).unwrap_err();
        assert!(e.to_string().contains("features"), "{e}");
        // Without a method the service picks one; its fields are still checked.
        let spec = JobSpec::from_json(br#"{"anchors": []}"#).unwrap();
        assert_eq!(spec.method(), Method::Auto);
        let e = JobSpec::from_json(br#"{"anchors": [], "basis": [0, 0]}"#).unwrap_err();
        assert_eq!(e.code(), "invalid_spec");
        assert!(e.to_string().contains("basis"), "{e}");
    }
}
