//! Phase three of a job: a method's output becomes the job's result. A folded map is refused
//! ([`folds`]); the outputs in the inputs' own layouts are added (`morph.glb`, the OBJs with
//! their seams, [`layout_outputs`]; `target_transferred.glb`, [`transfer_output`]); and
//! `metrics.json` is written, here and nowhere else, from the final report.

mod folds;
mod layout_outputs;
mod transfer_output;

use crate::error::Result;
use crate::pipeline::common::{Artifact, json_artifact};
use crate::pipeline::plan::Plan;
use crate::pipeline::report::{JobReport, MethodOutput};

/// Checks, completes and measures a method's output.
///
/// # Errors
/// `MapFolds` for a folded map, `Numerical` for images off the surface; `Internal` if a
/// report does not serialize.
pub fn finish(plan: &Plan, out: MethodOutput) -> Result<(JobReport, Vec<Artifact>)> {
    let MethodOutput { mut report, mut artifacts } = out;
    if let Some(pair) = report.pair_mut() {
        pair.anchor_points.clone_from(&plan.snaps);
        pair.auto.clone_from(&plan.auto);
    }
    folds::refuse_folds(plan, &mut report, &mut artifacts)?;
    let runs = (plan.originals, &*plan.meshes);
    layout_outputs::add_morph(&report, runs, &plan.layouts, plan.output.inverse_morph, &mut artifacts);
    layout_outputs::rewrite_objs(&report, plan.originals, &plan.meshes, &plan.layouts, &mut artifacts);
    if plan.output.wants_transfer() {
        transfer_output::add(&report, &plan.output.transfer, runs, &plan.layouts, &mut artifacts)?;
    }
    write_metrics(&report, &mut artifacts)?;
    Ok((report, artifacts))
}

/// `metrics.json`, and for meshes in several parts each part pair's report as
/// `partK_metrics.json` beside its other `partK_` artifacts.
fn write_metrics(report: &JobReport, artifacts: &mut Vec<Artifact>) -> Result<()> {
    if let JobReport::Parts(p) = report {
        for (k, part) in p.parts.iter().enumerate() {
            artifacts.push(json_artifact(&format!("part{k}_metrics.json"), part)?);
        }
    }
    artifacts.push(json_artifact("metrics.json", report)?);
    Ok(())
}
