//! `"method": "auto"`, and a spec without `method`: the service picks the pair method that fits
//! the meshes, and `metrics.json` says which ran and why (`auto`).
//!
//! - Feature curves: `homology`, the one method that maps them.
//! - Closed meshes of genus ≥ 1: `homology` (canonical homology bases).
//! - Anything else (genus-0 meshes, open or closed, one part or many): `voronoi`; but two
//!   closed connected genus-0 meshes whose anchors say they are different shapes run
//!   `spherical` (decided in the plan, which has the meshes: `plan/same_shape.rs`).
//!
//! `spherical` does not yet beat `voronoi` on same-shape genus-0 cases (24 closed genus-0
//! `mkcase.py` cases of one draw: `voronoi` maps all 24, `spherical` 9; the others fold or
//! leave images where the evaluator's nearest-face rule cannot see them), while it maps the
//! peer's different shapes with less distortion and cat -> horse, which `voronoi` folds.
//!
//! The choice is made once, from the meshes' summaries; the chosen method's own checks then
//! apply as if it had been named.

use crate::error::{InputError, Result};
use crate::pipeline::spec::{AutoSpec, HomologyOptions, HomologySpec, JobSpec, LayoutSpec, MapOptions};
use crate::topology::Summary;
use serde::Serialize;

/// Which method an `auto` job ran, and why (`metrics.json`'s `auto`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AutoChoice {
    pub method: &'static str,
    pub reason: String,
}

impl AutoSpec {
    /// The job as the method that fits the meshes (`summaries`: source, target), and why.
    ///
    /// # Errors
    /// `InputError::Spec` unless there are two meshes.
    pub fn resolve(&self, summaries: &[Summary]) -> Result<(JobSpec, AutoChoice)> {
        let [s, t] = summaries else {
            return Err(InputError::Spec(format!(
                "method auto maps a source onto a target: 2 meshes, got {}",
                summaries.len()
            ))
            .into());
        };
        let o = &self.options;
        let homology = || {
            JobSpec::Homology(HomologySpec {
                anchors: self.anchors.clone(),
                features: self.features.clone(),
                options: HomologyOptions {
                    metric_samples: o.metric_samples,
                    transfer: o.transfer.clone(),
                    inverse_morph: o.inverse_morph,
                    ..HomologyOptions::default()
                },
            })
        };
        let (spec, reason) = if !self.features.is_empty() {
            (homology(), "feature curves are mapped by homology".to_string())
        } else if s.boundary_loops == 0 && t.boundary_loops == 0 && (s.genus >= 1 || t.genus >= 1) {
            (homology(), format!("closed meshes of genus {} and {}", s.genus, t.genus))
        } else {
            let options = MapOptions {
                metric_samples: o.metric_samples,
                transfer: o.transfer.clone(),
                inverse_morph: o.inverse_morph,
                ..MapOptions::default()
            };
            let spec = JobSpec::Voronoi(LayoutSpec { anchors: self.anchors.clone(), boundaries: Vec::new(), options });
            let why = format!(
                "genus-0 meshes ({} and {} components, {} and {} boundary loops, genus {} and {}, {} anchors): \
                 voronoi maps same-shape genus-0 pairs where spherical (by name) does not yet",
                s.components,
                t.components,
                s.boundary_loops,
                t.boundary_loops,
                s.genus,
                t.genus,
                self.anchors.len()
            );
            (spec, why)
        };
        let method = spec.method().name();
        Ok((spec, AutoChoice { method, reason }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::topology::summary;

    fn auto(json: &str) -> AutoSpec {
        match JobSpec::from_json(json.as_bytes()).unwrap() {
            JobSpec::Auto(a) => a,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_spec_without_method_is_auto_and_picks_by_topology() {
        let sphere = summary(&shapes::icosphere(2));
        let torus = summary(&shapes::torus(8, 6, 2.0, 0.5));
        let a = auto(r#"{"anchors": [[0, 0], [5, 5], [9, 9]], "options": {"metric_samples": 500}}"#);
        let (spec, why) = a.resolve(&[sphere.clone(), sphere.clone()]).unwrap();
        assert_eq!(why.method, "voronoi", "{why:?}");
        let JobSpec::Voronoi(s) = spec else { panic!("{spec:?}") };
        assert_eq!(s.options.metric_samples, 500, "the shared options carry over");
        let (spec, why) = a.resolve(&[torus.clone(), torus]).unwrap();
        assert_eq!((spec.method().name(), why.method), ("homology", "homology"));
        let err = a.resolve(&[sphere]).unwrap_err();
        assert_eq!(err.code(), "invalid_spec");
    }

    #[test]
    fn an_option_no_shared_method_takes_is_refused() {
        let e = JobSpec::from_json(br#"{"anchors": [[0, 0]], "options": {"layout": {}}}"#).unwrap_err();
        assert_eq!(e.code(), "invalid_spec");
        assert!(e.to_string().contains("layout"), "{e}");
    }
}
