//! `spherical`: both meshes embedded on the sphere bijectively -> each direction's map
//! optimized on the other's sphere, injective at every step -> metrics -> artifacts. No stage
//! repairs another's output: a direction whose images stay turned over fails the job as
//! folded ([`crate::pipeline::finish::folds`]).

use crate::error::Result;
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::metrics::{MetricsOptions, evaluate_map};
use crate::pipeline::common::{Artifact, Clock, PairReport, artifacts, both};
use crate::pipeline::spec::SphericalSpec;
use crate::progress::{Progress, Stage};
use crate::sphere::{
    SphereEmbedOptions, SphereEmbedReport, SphereEmbedding, SpherePair, SpherePairOptions, SpherePairReport,
    embed_sphere, sphere_pair,
};
use serde::Serialize;

/// What a `spherical` job measured (`metrics.json`).
#[derive(Debug, Clone, Serialize)]
pub struct SphericalMapReport {
    #[serde(flatten)]
    pub pair: PairReport,
    pub spherical: SphericalReport,
}

/// What a `spherical` job adds to `metrics.json`: each embedding's and each direction's figures.
#[derive(Debug, Clone, Serialize)]
pub struct SphericalReport {
    pub source_embedding: SphereEmbedReport,
    pub target_embedding: SphereEmbedReport,
    pub source_to_target: SpherePairReport,
    pub target_to_source: SpherePairReport,
}

/// Runs a `spherical` job.
///
/// # Errors
/// Input errors for a spec that does not fit the meshes; `Numerical` when an embedding or a
/// Newton system fails; `Cancelled`.
pub fn run(
    spec: &SphericalSpec,
    source: &Mesh,
    target: &Mesh,
    progress: &mut dyn Progress,
) -> Result<(SphericalMapReport, Vec<Artifact>)> {
    let mut clock = Clock::start();
    let pairs = spec.validate(source, target)?;
    clock.lap("setup");
    progress.report(Stage::Parameterize, 0.0);
    let side = progress.silent();
    let embed = |m: &Mesh, p: &dyn Progress| embed_sphere(m, &SphereEmbedOptions::default(), p);
    let (es, et) = both(|| embed(target, &side), || embed(source, &*progress))?;
    let (es, et): (SphereEmbedding, SphereEmbedding) = (es?, et?);
    clock.lap("embed");
    progress.report(Stage::Optimize, 0.0);
    let forward: Vec<(u32, u32)> = pairs.iter().map(|(s, t)| (s.0, t.0)).collect();
    let backward: Vec<(u32, u32)> = forward.iter().map(|&(s, t)| (t, s)).collect();
    let o = SpherePairOptions::default();
    let (st, ts) = both(
        || sphere_pair(target, &et.points, source, &es.points, &backward, &o, &side),
        || sphere_pair(source, &es.points, target, &et.points, &forward, &o, &*progress),
    )?;
    let (st, ts): (SpherePair, SpherePair) = (st?, ts?);
    clock.lap("optimize");
    progress.check()?;
    progress.report(Stage::Metrics, 0.0);
    let (s2t, t2s) = (surface_map(&st), surface_map(&ts));
    let mo = MetricsOptions { samples: spec.options.metric_samples, ..Default::default() };
    let rev: Vec<(VertexId, VertexId)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    let (on_target, on_source) = (s2t.embed(source, target)?, t2s.embed(target, source)?);
    let (m1, m2) = both(
        || evaluate_map(target, source, &on_source, Some(&rev), None, &mo),
        || evaluate_map(source, target, &on_target, Some(&pairs), None, &mo),
    )?;
    let (m1, m2) = (m1?, m2?);
    clock.lap("metrics");
    let arts = artifacts::maps_and_meshes(&s2t, &t2s, &on_target, &on_source);
    let spherical = SphericalReport {
        source_embedding: es.report,
        target_embedding: et.report,
        source_to_target: st.report,
        target_to_source: ts.report,
    };
    let pair = PairReport::new("spherical", pairs.len(), (source, target), (m1, m2), Default::default());
    let mut report = SphericalMapReport { pair: pair.with_maps(s2t, t2s), spherical };
    clock.lap("artifacts");
    report.pair.timings_ms = clock.finish();
    progress.report(Stage::Done, 1.0);
    Ok((report, arts))
}

/// A direction's located vertices as a vertex map.
fn surface_map(p: &SpherePair) -> SurfaceMap {
    SurfaceMap {
        face: p.located.iter().map(|l| FaceId(l.face)).collect(),
        bary: p.located.iter().map(|l| l.bary).collect(),
    }
}
