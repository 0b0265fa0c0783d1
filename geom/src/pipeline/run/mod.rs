//! Phase two of a job: a [`Plan`] runs its method, once per part pair for meshes in several
//! parts (paired in `plan/parts.rs`, joined in `join.rs`). One pipeline per method, each a
//! folder that imports `common` and the spec and no other method: [`layout`] for `voronoi` and
//! `greedy`, [`homology`] (and [`features`] for `homology` with feature curves or boundaries),
//! [`quad`], [`spherical`].

use super::homology::{self, features};
use super::{layout, quad, spherical};
use crate::error::{InputError, Result};
use crate::mesh::Mesh;
mod join;

use crate::pipeline::plan::{MethodPlan, Plan};
use crate::pipeline::report::{JobReport, MethodOutput};
use crate::progress::Progress;

/// Runs the plan's method on its meshes (or on each part pair, joined).
///
/// # Errors
/// Whatever the method reports; `InputError::Spec` for a pair method without two meshes.
pub fn run(plan: &Plan, progress: &mut dyn Progress) -> Result<MethodOutput> {
    let Some(pp) = &plan.parts else { return run_method(&plan.method, &plan.meshes, progress) };
    let mut outputs = Vec::with_capacity(pp.pairs.len());
    for pair in &pp.pairs {
        let method = plan.method.for_part(&pair.anchors, &pair.boundaries);
        outputs.push(run_method(&method, &pair.meshes, progress)?);
    }
    join::join(pp, &plan.meshes, plan.method.method(), plan.output.metric_samples, outputs)
}

/// One pipeline per method.
fn run_method(plan: &MethodPlan, meshes: &[Mesh], progress: &mut dyn Progress) -> Result<MethodOutput> {
    let pair = || match meshes {
        [s, t] => Ok((s, t)),
        _ => Err(InputError::Spec(format!(
            "method {} maps a source onto a target: 2 meshes, got {}",
            plan.method().name(),
            meshes.len()
        ))),
    };
    let (report, artifacts) = match plan {
        MethodPlan::Layout(method, s) => {
            let (a, b) = pair()?;
            let (r, arts) = layout::run(*method, s, a, b, progress)?;
            (JobReport::Layout(r), arts)
        }
        MethodPlan::Homology(s) => {
            let (a, b) = pair()?;
            if features::applies(s, a) {
                let (r, arts) = features::run(s, a, b, progress)?;
                (JobReport::Features(r), arts)
            } else {
                let (r, arts) = homology::run(s, a, b, progress)?;
                (JobReport::Homology(r), arts)
            }
        }
        MethodPlan::Quad(s) => {
            let (r, arts) = quad::run(s, meshes, progress)?;
            (JobReport::Quad(r), arts)
        }
        MethodPlan::Spherical(s) => {
            let (a, b) = pair()?;
            let (r, arts) = spherical::run(s, a, b, progress)?;
            (JobReport::Spherical(r), arts)
        }
    };
    Ok(MethodOutput { report, artifacts })
}
