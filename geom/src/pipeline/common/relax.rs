//! Each direction's last stages, shared by every pair method: stretch-reducing smoothing,
//! visibility under the evaluator's rules, fold repair, re-embedding of folded regions,
//! boundary sliding, and the evaluator's metrics.

use super::both;
use crate::crossparam::on_surface::{OnSurfaceOptions, optimize_on_surface};
use crate::crossparam::smooth::{self, SmoothReport};
use crate::crossparam::untangle::{UntangleOptions, untangle};
use crate::crossparam::visible::{evaluator_flip_count, make_visible, repair_flips};
use crate::error::{Error, Result};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::metrics::{MapMetrics, MetricsOptions, evaluate_map};
use crate::pipeline::spec::RelaxOptions;
use crate::progress::{Progress, Stage};
use crate::topology::SurfacePoint;

/// Source meshes above this size skip the chord Newton stage (its line search walks every
/// image per trial; at 58k vertices and more the sweeps alone are kept for time).
pub const CHORD_NEWTON_MAX_VERTICES: usize = 60_000;

/// One direction's relaxation: [`relax_local`], then [`relax_chords`].
///
/// # Errors
/// `Cancelled`; what the stages report.
pub fn relax_direction(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    o: &RelaxOptions,
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, SmoothReport)> {
    let local = relax_local(from, to, map, fixed, o, progress)?;
    relax_chords(from, to, local, fixed, progress)
}

/// The last stage of a relaxation, on a map [`relax_local`] relaxed: the whole map at once,
/// projected Newton on the chords the evaluator measures, every chord kept unfolded; kept when
/// the evaluator counts no more flipped faces. Separate so that maps contending after local
/// relaxation pay for it once, on the winner.
///
/// # Errors
/// `Cancelled`; what the stage reports besides a numerical failure (which ends it).
pub fn relax_chords(
    from: &Mesh,
    to: &Mesh,
    (mut m, r): (SurfaceMap, SmoothReport),
    fixed: &[VertexId],
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, SmoothReport)> {
    let chord_steps = chord_newton(from, to, &mut m, fixed, progress)?;
    Ok((m, SmoothReport { chord_steps, ..r }))
}

/// One direction's local relaxation: smoothing sweeps, visibility, fold repair, re-embedding and
/// boundary sliding; `fixed` vertices (anchors, held feature vertices) stay put.
///
/// # Errors
/// `Cancelled`; what the stages report.
pub fn relax_local(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    o: &RelaxOptions,
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, SmoothReport)> {
    let so = &o.smoothing;
    let (mut m, r) = smooth::smooth(from, to, map, fixed, so, progress)?;
    progress.check()?;
    let mut v = make_visible(from, to, &mut m, fixed, true)?;
    progress.check()?;
    let mut repaired = repair_flips(from, to, &mut m, fixed, false)?;
    progress.check()?;
    let untangled = untangle(from, to, &mut m, fixed, &UntangleOptions::default(), progress)?;
    progress.check()?;
    repaired += crate::crossparam::slide::slide_boundary(from, to, &mut m, fixed)?;
    // Repairs, re-embedding and sliding place images anew; any of them can land on a hidden spot.
    if repaired > 0 || untangled.regions > 0 {
        v += make_visible(from, to, &mut m, fixed, false)?;
    }
    // Folds the re-embedding could not undo get one more round of one-vertex repairs, now with
    // spots spread over the target around each star (a crushed region between different shapes).
    if untangled.folded_after > 0 {
        let late = repair_flips(from, to, &mut m, fixed, true)?;
        if late > 0 {
            repaired += late;
            v += make_visible(from, to, &mut m, fixed, false)?;
        }
    }
    // Repairs and re-embedded regions leave distortion behind them that the sweeps before
    // could not see: the map is relaxed once more and kept if it is lower in energy and the
    // evaluator counts no more flipped faces.
    let mut energy_after = r.energy_after;
    if repaired > 0 || untangled.regions > 0 {
        let (again, more) = relax_after_repairs(from, to, &m, fixed, so, progress)?;
        if let Some((again, energy)) = again {
            m = again;
            repaired += more;
            energy_after = energy;
        }
    }
    Ok((m, SmoothReport { repaired, made_visible: v, reembedded: untangled.regions, energy_after, ..r }))
}

/// [`optimize_on_surface`] on a copy of `map`, kept when the evaluator counts no more flipped
/// faces (a point the evaluator reads on another face than ours can differ) and the L2 stretch
/// is not higher; skipped above
/// [`CHORD_NEWTON_MAX_VERTICES`]. Returns the Newton steps kept.
fn chord_newton(
    from: &Mesh,
    to: &Mesh,
    map: &mut SurfaceMap,
    fixed: &[VertexId],
    progress: &mut dyn Progress,
) -> Result<usize> {
    if from.n_vertices() > CHORD_NEWTON_MAX_VERTICES {
        return Ok(0);
    }
    progress.report(Stage::Smooth, 0.9);
    let mut cand = map.clone();
    // A Newton system the solver cannot take (chords near degenerate) ends the stage, not the
    // job: the relaxed map stands, and is measured and checked as it is.
    let r = match optimize_on_surface(from, to, &mut cand, fixed, &OnSurfaceOptions::default(), &*progress) {
        Ok(r) => r,
        Err(Error::Cancelled) => return Err(Error::Cancelled),
        Err(e) => {
            tracing::debug!(error = %e, "chord Newton stopped");
            return Ok(0);
        }
    };
    if r.iterations == 0 {
        return Ok(0);
    }
    make_visible(from, to, &mut cand, fixed, false)?;
    // The energy is symmetric Dirichlet; the stretch the evaluator reports can rise where it
    // trades stretch for compression (seen: SMPL with 12 anchors), and then the map stays.
    let l2 = |m: &SurfaceMap| -> Result<f64> { Ok(crate::metrics::distortion(from, &m.embed(from, to)?).l2_stretch) };
    if evaluator_flip_count(from, to, &cand)? > evaluator_flip_count(from, to, map)? || l2(&cand)? > l2(map)? {
        return Ok(0);
    }
    *map = cand;
    Ok(r.iterations)
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
    make_visible(from, to, &mut again, fixed, false)?;
    let moves = repair_flips(from, to, &mut again, fixed, false)?;
    if moves > 0 {
        make_visible(from, to, &mut again, fixed, false)?;
    }
    let energy = smooth::map_quality(from, to, &again).energy;
    let better = energy < smooth::map_quality(from, to, map).energy
        && evaluator_flip_count(from, to, &again)? <= evaluator_flip_count(from, to, map)?;
    Ok((better.then_some((again, energy)), moves))
}

/// One direction's metrics (the evaluator's definitions) of a relaxed map, and the source
/// re-embedded on the target.
///
/// # Errors
/// `Cancelled`; what embedding and metrics report.
pub fn measure_direction(
    from: &Mesh,
    to: &Mesh,
    map: &SurfaceMap,
    anchors: &[(VertexId, VertexId)],
    o: &RelaxOptions,
    progress: &mut dyn Progress,
) -> Result<(Mesh, MapMetrics)> {
    progress.check()?;
    progress.report(Stage::Metrics, 0.0);
    let mo = MetricsOptions { samples: o.metric_samples, ..Default::default() };
    let embedded = map.embed(from, to)?;
    let metrics = evaluate_map(from, to, &embedded, Some(anchors), None, &mo)?;
    Ok((embedded, metrics))
}

/// One direction relaxed and measured: the map, what relaxing did, the source re-embedded
/// and its metrics.
pub type Direction = (SurfaceMap, SmoothReport, Mesh, MapMetrics);

/// [`relax_direction`] then [`measure_direction`]; `smoothed` runs between the two (a clock lap).
///
/// # Errors
/// As the two.
#[allow(clippy::too_many_arguments)]
pub fn finish_direction(
    from: &Mesh,
    to: &Mesh,
    map: SurfaceMap,
    fixed: &[VertexId],
    anchors: &[(VertexId, VertexId)],
    o: &RelaxOptions,
    progress: &mut dyn Progress,
    smoothed: &mut dyn FnMut(),
) -> Result<Direction> {
    let (m, r) = relax_direction(from, to, map, fixed, o, progress)?;
    smoothed();
    let (embedded, metrics) = measure_direction(from, to, &m, anchors, o, progress)?;
    Ok((m, r, embedded, metrics))
}

/// Both directions after a one-patch method's domain maps, and what they measured.
pub struct FinishedPair {
    pub s2t: SurfaceMap,
    pub t2s: SurfaceMap,
    pub on_target: Mesh,
    pub on_source: Mesh,
    pub m1: MapMetrics,
    pub m2: MapMetrics,
    pub smoothing: SmoothReport,
}

/// Places the anchors exactly, then relaxes and measures both directions on two threads
/// (anchors and `fixed` held: source vertices, target vertices).
///
/// # Errors
/// As [`finish_direction`].
pub fn finish_pair(
    source: &Mesh,
    target: &Mesh,
    maps: (&SurfaceMap, &SurfaceMap),
    pairs: &[(VertexId, VertexId)],
    fixed: (&[VertexId], &[VertexId]),
    o: &RelaxOptions,
    progress: &mut dyn Progress,
) -> Result<FinishedPair> {
    let (mut s2t, mut t2s) = (maps.0.clone(), maps.1.clone());
    for &(s, t) in pairs {
        let (f, b) = SurfacePoint::Vertex { vertex: t }.in_face(target);
        s2t.face[s.idx()] = f;
        s2t.bary[s.idx()] = b;
        let (f, b) = SurfacePoint::Vertex { vertex: s }.in_face(source);
        t2s.face[t.idx()] = f;
        t2s.bary[t.idx()] = b;
    }
    let sa: Vec<VertexId> = pairs.iter().map(|p| p.0).chain(fixed.0.iter().copied()).collect();
    let ta: Vec<VertexId> = pairs.iter().map(|p| p.1).chain(fixed.1.iter().copied()).collect();
    let rev: Vec<(VertexId, VertexId)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    progress.report(Stage::Smooth, 0.0);
    let mut side = progress.silent();
    let (a, b) = both(
        || finish_direction(target, source, t2s, &ta, &rev, o, &mut side, &mut || {}),
        || finish_direction(source, target, s2t, &sa, pairs, o, progress, &mut || {}),
    )?;
    let ((s2t, r1, on_target, m1), (t2s, r2, on_source, m2)) = (a?, b?);
    Ok(FinishedPair { s2t, t2s, on_target, on_source, m1, m2, smoothing: r1.merge(r2) })
}
