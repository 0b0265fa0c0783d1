//! `voronoi` and `greedy` on open meshes: the layout and composition on the meshes closed by
//! cones ([`super::open_loops`]), the maps restricted to the open meshes, then relaxation (which
//! keeps boundary images on the boundary) and the evaluator's metrics there.
//!
//! The base-domain global map and optimization are closed-surface stages (they move images
//! across layout paths, which here include the loops) and do not run.

use super::common::{Artifact, Clock, PairReport};
use super::open_loops::OpenPlan;
use super::spec::{MapOptions, Method};
use super::voronoi::{Composed, LayoutMapReport, Pair, compose_layout, outputs};
use crate::error::Result;
use crate::mesh::{Mesh, VertexId};
use crate::progress::Progress;

/// Runs a `voronoi` or `greedy` job whose meshes have boundary loops.
///
/// # Errors
/// As the closed job; `Error::Numerical` when a vertex maps inside a cone.
pub(super) fn run(
    method: Method,
    o: &MapOptions,
    plan: OpenPlan,
    (source, target): (&Mesh, &Mesh),
    pairs: &[(VertexId, VertexId)],
    mut clock: Clock,
    progress: &mut dyn Progress,
) -> Result<(LayoutMapReport, Vec<Artifact>)> {
    clock.lap("setup");
    let (sa, ta) = (plan.sa.clone(), plan.ta.clone());
    let closed = (&plan.source.mesh, &plan.target.mesh);
    let c = compose_layout(method, closed, (&sa, &ta), o, Some(&plan), &mut clock, progress)?;
    let Composed { st, tt, stats, patches, rs, rt, s2t, t2s, .. } = c;
    let maps = plan.restrict(&s2t, &t2s)?;
    clock.lap("restrict");
    progress.check()?;
    let rev: Vec<(VertexId, VertexId)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    // The job's own anchors are held; the loop anchors and apexes are the layout's (boundary
    // images stay on the boundary through relaxation in any case).
    let held = pairs.len();
    let pair = Pair { source, target, pairs, rev: &rev, sa: &sa[..held], ta: &ta[..held] };
    let ((s2t, r1, on_target, m1), (t2s, r2, on_source, m2)) = pair.finish(maps, &o.relax(), &mut clock, progress)?;
    // Relaxation keeps boundary images where the patch maps put them; counted anyway.
    let boundaries = plan.report(&s2t, &t2s);
    clock.lap("metrics");
    progress.check()?;
    let pr = PairReport::new(method.name(), pairs.len(), (source, target), (m1, m2), r1.merge(r2));
    let report =
        LayoutMapReport { pair: pr, patches: patches.len(), layout: stats, global: None, optimize: None, boundaries };
    let embedded = (&on_target, &on_source);
    outputs(report, (&st, &tt, &patches, &rs, &rt), (s2t, t2s), embedded, clock, progress)
}
