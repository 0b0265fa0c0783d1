//! `run_map`: layout -> refinement -> patch parameterization -> composition -> smoothing ->
//! metrics -> artifacts, with progress, cancellation and per-stage timings.

use super::artifacts;
use super::global_choice::{GlobalInputs, GlobalReport, RelaxedComparison, choose_global, relaxed_quality};
use super::spec::{JobSpec, Method};
use crate::crossparam::{compose, parameterize_patches, smooth};
use crate::domain::refine::refine;
use crate::domain::tracer::Tracer;
use crate::domain::{LayoutStats, greedy, patches_of, voronoi};
use crate::error::{Error, InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::metrics::{MapMetrics, MetricsOptions, evaluate_map};
use crate::progress::Progress;
use crate::topology;
use serde::Serialize;
use std::time::Instant;

/// One output file: its name, media type and bytes.
#[derive(Debug, Clone)]
pub struct Artifact {
    pub name: String,
    pub content_type: &'static str,
    pub bytes: Vec<u8>,
}

/// What a mapping job measured (also written as `metrics.json`).
#[derive(Debug, Clone, Serialize)]
pub struct MapReport {
    pub method: &'static str,
    pub anchors: usize,
    pub patches: usize,
    pub source_vertices: usize,
    pub target_vertices: usize,
    pub layout: LayoutStats,
    pub source_to_target: MapMetrics,
    pub target_to_source: MapMetrics,
    /// Milliseconds per stage.
    pub timings_ms: Vec<(String, f64)>,
    pub smoothing: smooth::SmoothReport,
    /// `homology` jobs: bases, rotation and the induced map on H1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub homology: Option<super::run_homology::HomologyReport>,
    /// `homology` jobs with feature curves or boundaries: the cut and how exactly features map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub features: Option<super::run_features::FeatureReport>,
    /// `voronoi` / `greedy`: the global map onto the base domain, when it was tried.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global: Option<GlobalReport>,
}

pub(super) struct Clock(pub(super) Instant, pub(super) Vec<(String, f64)>);
impl Clock {
    pub(super) fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        self.1.push((stage.to_string(), (now - self.0).as_secs_f64() * 1e3));
        self.0 = now;
    }
}

/// Runs `side` on a scoped thread while `main` runs here: the source and target halves of a
/// stage are independent. The side half reports no progress (the main half does).
pub(super) fn both<A: Send, B>(side: impl FnOnce() -> A + Send, main: impl FnOnce() -> B) -> Result<(B, A)> {
    std::thread::scope(|sc| {
        let h = sc.spawn(side);
        let b = main();
        Ok((b, h.join().map_err(|_| Error::Internal("worker thread panicked".into()))?))
    })
}

/// One direction's last stages: stretch-reducing smoothing, visibility under the evaluator's
/// rules, fold repair, re-embedding and metrics. Shared by every method.
#[allow(clippy::too_many_arguments)]
pub(super) fn finish_direction(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    anchors: &[(VertexId, VertexId)],
    o: &super::spec::MapOptions,
    progress: &mut dyn Progress,
    smoothed: &mut dyn FnMut(),
) -> Result<(SurfaceMap, smooth::SmoothReport, Mesh, MapMetrics)> {
    let (m, r) = relax_direction(from, to, map, fixed, o, progress)?;
    smoothed();
    let (embedded, metrics) = measure_direction(from, to, &m, anchors, o, progress)?;
    Ok((m, r, embedded, metrics))
}

/// One direction's relaxation: stretch-reducing smoothing, visibility under the evaluator's
/// rules, fold repair, re-embedding and boundary sliding. When the smoothing's area reward
/// leaves faces folded (opposed to the target at all three corners, a superset of the
/// evaluator's flips), the relaxation is run again without it and the map with fewer folds is
/// kept (the first on a tie).
pub(super) fn relax_direction(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    o: &super::spec::MapOptions,
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, smooth::SmoothReport)> {
    if o.smoothing.area_weight == 0.0 {
        return relax_with(from, to, map, fixed, o, &o.smoothing, progress);
    }
    let first = relax_with(from, to, map.clone(), fixed, o, &o.smoothing, progress)?;
    let folded = smooth::map_quality(from, to, &first.0).flipped;
    if folded == 0 {
        return Ok(first);
    }
    let plain = smooth::SmoothOptions { area_weight: 0.0, ..o.smoothing };
    let second = relax_with(from, to, map, fixed, o, &plain, progress)?;
    Ok(if smooth::map_quality(from, to, &second.0).flipped < folded { second } else { first })
}

/// [`relax_direction`] with the given smoothing options.
fn relax_with(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    o: &super::spec::MapOptions,
    so: &smooth::SmoothOptions,
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, smooth::SmoothReport)> {
    let (mut m, r) = smooth::smooth(from, to, map, fixed, so, progress)?;
    let newton = crate::crossparam::newton::relax_newton(from, to, &mut m, fixed, &o.newton, progress)?;
    progress.check()?;
    let mut v = crate::crossparam::visible::make_visible(from, to, &mut m, fixed, true)?;
    progress.check()?;
    let mut repaired = crate::crossparam::visible::repair_flips(from, to, &mut m, fixed, false)?;
    progress.check()?;
    let untangled = crate::crossparam::untangle::untangle(from, to, &mut m, fixed, &o.untangle, progress)?;
    progress.check()?;
    repaired += crate::crossparam::slide::slide_boundary(from, to, &mut m, fixed)?;
    // Repairs, re-embedding and sliding place images anew; any of them can land on a hidden spot.
    if repaired > 0 || untangled.regions > 0 {
        v += crate::crossparam::visible::make_visible(from, to, &mut m, fixed, false)?;
    }
    // Folds the re-embedding could not undo get one more round of one-vertex repairs, now with
    // spots spread over the target around each star (a crushed region between different shapes).
    if untangled.folded_after > 0 {
        let late = crate::crossparam::visible::repair_flips(from, to, &mut m, fixed, true)?;
        if late > 0 {
            repaired += late;
            v += crate::crossparam::visible::make_visible(from, to, &mut m, fixed, false)?;
        }
    }
    // Repairs and re-embedded regions leave distortion behind them that the sweeps before
    // could not see: the map is relaxed once more and kept if it is lower in energy and the
    // evaluator counts no more flipped faces.
    let mut energy_after = if newton.steps > 0 { newton.energy_after } else { r.energy_after };
    if repaired > 0 || untangled.regions > 0 {
        let (again, more) = relax_after_repairs(from, to, &m, fixed, so, progress)?;
        if let Some((again, energy)) = again {
            m = again;
            repaired += more;
            energy_after = energy;
        }
    }
    Ok((
        m,
        smooth::SmoothReport {
            repaired,
            made_visible: v,
            reembedded: untangled.regions,
            newton_steps: newton.steps,
            energy_after,
            ..r
        },
    ))
}

/// One more relaxation of `map` after repairs: smoothing sweeps, hidden points revealed and
/// one-vertex flip repairs (and hidden points again after them). `Some((map, energy))` when
/// that lowers the energy without more faces the evaluator counts as flipped; with the number
/// of repair moves it took.
fn relax_after_repairs(
    from: &Mesh,
    to: &Mesh,
    map: &SurfaceMap,
    fixed: &[VertexId],
    so: &smooth::SmoothOptions,
    progress: &mut dyn Progress,
) -> Result<(Option<(SurfaceMap, f64)>, usize)> {
    let (mut again, _) = smooth::smooth(from, to, map.clone(), fixed, so, progress)?;
    crate::crossparam::visible::make_visible(from, to, &mut again, fixed, false)?;
    let moves = crate::crossparam::visible::repair_flips(from, to, &mut again, fixed, false)?;
    if moves > 0 {
        crate::crossparam::visible::make_visible(from, to, &mut again, fixed, false)?;
    }
    let flips = |m: &SurfaceMap| crate::crossparam::visible::evaluator_flip_count(from, to, m);
    let energy = smooth::map_quality(from, to, &again).energy;
    let better = energy < smooth::map_quality(from, to, map).energy && flips(&again)? <= flips(map)?;
    Ok((better.then_some((again, energy)), moves))
}

/// One direction's metrics (the evaluator's definitions) of a relaxed map, and the source
/// re-embedded on the target.
pub(super) fn measure_direction(
    from: &Mesh,
    to: &Mesh,
    map: &SurfaceMap,
    anchors: &[(VertexId, VertexId)],
    o: &super::spec::MapOptions,
    progress: &mut dyn Progress,
) -> Result<(Mesh, MapMetrics)> {
    progress.check()?;
    progress.report(crate::progress::Stage::Metrics, 0.0);
    let mo = MetricsOptions { samples: o.metric_samples, ..Default::default() };
    let embedded = map.embed(from, to)?;
    let metrics = evaluate_map(from, to, &embedded, Some(anchors), None, &mo)?;
    Ok((embedded, metrics))
}

/// A layout conflict's message, naming the source anchors whose Voronoi cells are not disks
/// (where a handle or tube is not separated by the anchors, the usual cause), if any.
fn with_cell_hint(m: String, source: &Mesh, anchors: &[VertexId]) -> Error {
    let bad = crate::domain::cuts::clusters(source, anchors).map(|c| c.non_disk(source)).unwrap_or_default();
    let m = if bad.is_empty() {
        m
    } else {
        format!(
            "{m}; the source Voronoi cells of anchors {bad:?} (indices into the anchor list) are not disks \
             (each holds a handle, or wraps a tube, that no anchor lies on): add anchors on it"
        )
    };
    InputError::LayoutConflict(m).into()
}

/// The maps both ways, with what produced them.
pub struct MapResult {
    pub source_to_target: SurfaceMap,
    pub target_to_source: SurfaceMap,
}

/// Runs a `voronoi` or `greedy` job.
///
/// # Errors
/// Input errors for a spec that does not fit the meshes or anchors that admit no consistent
/// layout; `Numerical` when a patch cannot be embedded; `Cancelled`.
pub fn run_map(
    spec: &JobSpec,
    source: &Mesh,
    target: &Mesh,
    progress: &mut dyn Progress,
) -> Result<(MapReport, Vec<Artifact>)> {
    if spec.method == Method::Homology {
        return super::run_homology::run_homology(spec, source, target, progress);
    }
    let mut clock = Clock(Instant::now(), Vec::new());
    let pairs = spec.validate(source, target)?;
    let o = &spec.options;
    let chi = topology::euler_characteristic(source);
    let sa: Vec<VertexId> = pairs.iter().map(|p| p.0).collect();
    let ta: Vec<VertexId> = pairs.iter().map(|p| p.1).collect();
    clock.lap("setup");
    progress.report(crate::progress::Stage::Layout, 0.0);
    // Denser edge nodes leave more room between paths; a layout that cannot be completed at
    // the requested density is rebuilt at higher ones before giving up.
    let mut edge_nodes = o.layout.edge_nodes;
    let mut attempt = 0;
    // A `voronoi` layout that cannot be completed at any density falls back to the greedy
    // baseline's path choice (reported as `layout.fallback`), unless the options forbid it.
    let mut method = spec.method;
    let (st, tt, stats) = loop {
        let (st, tt) = both(|| Tracer::new(target, &ta, &edge_nodes), || Tracer::new(source, &sa, &edge_nodes))?;
        let (mut st, mut tt) = (st?, tt?);
        let built = match method {
            Method::Voronoi => voronoi::source_layout(&mut st, chi, &o.layout, progress).and_then(|(cl, mut s)| {
                let t = voronoi::target_layout_with_restarts(&st, &cl, &mut tt, &o.layout, 8, progress)?;
                s.postponed = t.postponed;
                s.failed_traces += t.failed_traces;
                Ok(s)
            }),
            Method::Greedy => greedy::greedy_layout(&mut st, &mut tt, chi, &o.layout, progress),
            Method::Homology => Err(Error::Internal("homology jobs do not build a layout".into())),
        };
        match built {
            Ok(mut s) => {
                s.rebuilds = attempt;
                s.edge_nodes_min = edge_nodes.min_nodes;
                s.fallback = (method != spec.method).then(|| "greedy".to_string());
                break (st, tt, s);
            }
            Err(Error::Input(InputError::LayoutConflict(m)))
                if attempt >= o.layout.rebuilds && method == Method::Voronoi && o.layout.greedy_fallback =>
            {
                if tracing::enabled!(tracing::Level::DEBUG) {
                    tracing::debug!("greedy fallback after ({:.0} ms): {m}", clock.0.elapsed().as_secs_f64() * 1e3);
                }
                method = Method::Greedy;
                edge_nodes = o.layout.edge_nodes;
                attempt = 0;
            }
            Err(Error::Input(InputError::LayoutConflict(m))) if attempt < o.layout.rebuilds => {
                if tracing::enabled!(tracing::Level::DEBUG) {
                    tracing::debug!("rebuild after ({:.0} ms): {m}", clock.0.elapsed().as_secs_f64() * 1e3);
                }
                // Rebuild schedule: without the denser anchor rings, then with them again and
                // twice (minus one) the nodes per edge, then without, and so on.
                if edge_nodes.ring_factor > 1 {
                    edge_nodes.ring_factor = 1;
                } else {
                    edge_nodes.ring_factor = o.layout.edge_nodes.ring_factor;
                    edge_nodes.min_nodes = edge_nodes.min_nodes * 2 - 1;
                    edge_nodes.max_nodes = edge_nodes.max_nodes.max(edge_nodes.min_nodes);
                }
                attempt += 1;
            }
            Err(Error::Input(InputError::LayoutConflict(m))) => return Err(with_cell_hint(m, source, &sa)),
            Err(e) => return Err(e),
        }
    };
    clock.lap("layout");
    let (mut st, mut tt, mut stats) = (st, tt, stats);
    stats.flipped = crate::domain::flip::flip_paths(&mut st, &mut tt, &o.layout.flip, progress)?.flipped;
    clock.lap("flip");
    let rounds = o.layout.straighten_rounds;
    let mut side = progress.silent();
    let (a, b) = both(
        || crate::domain::straighten::straighten(&mut tt, rounds, &mut side),
        || crate::domain::straighten::straighten(&mut st, rounds, progress),
    )?;
    stats.straightened = a? + b?;
    clock.lap("straighten");
    let patches = patches_of(&st);
    stats.patches = patches.len();
    progress.check()?;
    // The target tracer moves to the side thread (its scratch is not `Sync`).
    let (tt_ref, pr) = (&mut tt, &patches);
    let (rs, rt) = both(move || refine(tt_ref, pr), || refine(&st, &patches))?;
    let (rs, rt) = (rs?, rt?);
    clock.lap("refine");
    let mut side = progress.silent();
    let (ps, pt) = both(
        || parameterize_patches(&rt, &patches, &ta, &o.param, &mut side),
        || parameterize_patches(&rs, &patches, &sa, &o.param, progress),
    )?;
    let (ps, pt) = (ps?, pt?);
    clock.lap("parameterize");
    let rev: Vec<(VertexId, VertexId)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    progress.report(crate::progress::Stage::Compose, 0.0);
    let (s2t, t2s) =
        both(|| compose(&pt, target, &rs, &ps, source, &rev), || compose(&ps, source, &rt, &pt, target, &pairs))?;
    clock.lap("compose");
    let inputs = GlobalInputs { patches: &patches, refined: (&rs, &rt), anchors: (&sa, &ta), params: (&ps, &pt) };
    let ((s2t, t2s), contender, mut global_report) =
        choose_global(source, target, &inputs, (s2t, t2s), &pairs, &rev, &o.global, progress)?;
    clock.lap("global");
    progress.check()?;
    // The two directions are independent from here on: each thread smooths its map, makes it
    // visible to the evaluator's rules, embeds it and measures it, so the lighter direction's
    // metrics overlap the heavier direction's smoothing.
    let finish =
        |from: &Mesh,
         to: &Mesh,
         map: SurfaceMap,
         fixed: &[VertexId],
         anchors: &[(VertexId, VertexId)],
         progress: &mut dyn Progress,
         smoothed: &mut dyn FnMut()| { finish_direction(from, to, map, fixed, anchors, o, progress, smoothed) };
    let mut side = progress.silent();
    let (a, b) = match contender {
        None => both(
            || finish(target, source, t2s, &ta, &rev, &mut side, &mut || {}),
            || finish(source, target, s2t, &sa, &pairs, progress, &mut || clock.lap("smooth")),
        )?,
        Some((gs2t, gt2s)) => {
            // Both compositions are relaxed in each direction, then the better pair is measured.
            let relax_both = |from: &Mesh,
                              to: &Mesh,
                              p: SurfaceMap,
                              g: SurfaceMap,
                              fixed: &[VertexId],
                              progress: &mut dyn Progress|
             -> Result<_> {
                let p = relax_direction(from, to, p, fixed, o, progress)?;
                let g = relax_direction(from, to, g, fixed, o, progress)?;
                let (qp, qg) = (relaxed_quality(from, to, &p.0)?, relaxed_quality(from, to, &g.0)?);
                Ok((p, g, qp, qg))
            };
            let (x, y) = both(
                || relax_both(target, source, t2s, gt2s, &ta, &mut side),
                || relax_both(source, target, s2t, gs2t, &sa, progress),
            )?;
            let ((ps, gs, qps, qgs), (pt, gt, qpt, qgt)) = (x?, y?);
            clock.lap("smooth");
            let cmp = RelaxedComparison::new([qps, qpt], [qgs, qgt]);
            let use_global = global_report.as_mut().map_or(cmp.prefers_global(), |r| r.record_relaxed(cmp));
            let ((s2t, r1), (t2s, r2)) = if use_global { (gs, gt) } else { (ps, pt) };
            let measure = |from: &Mesh,
                           to: &Mesh,
                           m: SurfaceMap,
                           r: smooth::SmoothReport,
                           anchors: &[(VertexId, VertexId)],
                           progress: &mut dyn Progress|
             -> Result<_> {
                let (e, met) = measure_direction(from, to, &m, anchors, o, progress)?;
                Ok((m, r, e, met))
            };
            both(
                || measure(target, source, t2s, r2, &rev, &mut side),
                || measure(source, target, s2t, r1, &pairs, progress),
            )?
        }
    };
    let ((s2t, r1, on_target, m1), (t2s, r2, on_source, m2)) = (a?, b?);
    let result = MapResult { source_to_target: s2t, target_to_source: t2s };
    clock.lap("metrics");
    progress.check()?;
    let mut report = MapReport {
        method: spec.method.name(),
        anchors: pairs.len(),
        patches: patches.len(),
        source_vertices: source.n_vertices(),
        target_vertices: target.n_vertices(),
        layout: stats,
        source_to_target: m1,
        target_to_source: m2,
        timings_ms: Vec::new(),
        smoothing: r1.merge(r2),
        homology: None,
        features: None,
        global: global_report,
    };
    let mut arts = artifacts::map_artifacts(&st, &tt, &patches, &rs, &rt, &result, &on_target, &on_source)?;
    clock.lap("artifacts");
    let total: f64 = clock.1.iter().map(|x| x.1).sum();
    clock.1.push(("total".into(), total));
    report.timings_ms = clock.1;
    let json = serde_json::to_vec_pretty(&report).map_err(|e| Error::Internal(e.to_string()))?;
    arts.push(Artifact { name: "metrics.json".into(), content_type: "application/json", bytes: json });
    progress.report(crate::progress::Stage::Done, 1.0);
    Ok((report, arts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::pipeline::MapOptions;
    use crate::progress::NoProgress;

    /// Eight anchors around one meridian of a torus: every Voronoi cell is a band around the
    /// long way of the torus, not a disk. With completion cut short, the conflict names them.
    #[test]
    fn a_layout_conflict_names_the_cells_that_are_not_disks() {
        let m = shapes::torus(24, 8, 1.0, 0.3);
        let anchors: Vec<[u64; 2]> = (0..8).map(|j| [j, j]).collect();
        let mut options = MapOptions::default();
        options.layout.max_attempts = 1;
        options.layout.rebuilds = 0;
        options.layout.greedy_fallback = false;
        let spec = JobSpec { method: Method::Voronoi, anchors, features: Vec::new(), options };
        let Err(Error::Input(e @ InputError::LayoutConflict(_))) = run_map(&spec, &m, &m, &mut NoProgress) else {
            panic!("expected a layout conflict");
        };
        let msg = e.to_string();
        assert!(msg.contains("anchors [0, 1, 2, 3, 4, 5, 6, 7]") && msg.contains("not disks"), "{msg}");
    }
}

#[cfg(test)]
mod cancel_tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::pipeline::MapOptions;
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
        let spec = JobSpec { method: Method::Voronoi, anchors, features: Vec::new(), options: MapOptions::default() };
        let mut p = CancelAt { stage: Stage::Smooth, token: CancelToken::default(), seen: Vec::new() };
        let r = run_map(&spec, &s, &t, &mut p);
        assert!(matches!(r, Err(Error::Cancelled)), "{:?}", r.err());
        assert!(p.seen.contains(&Stage::Smooth), "{:?}", p.seen);
        assert!(
            !p.seen.iter().any(|s| matches!(s, Stage::Metrics | Stage::Done)),
            "ran on after the cancel: {:?}",
            p.seen
        );
    }
}
