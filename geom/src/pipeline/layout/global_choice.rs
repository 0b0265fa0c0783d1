//! Whether the global maps onto the base domain ([`crate::crossparam::global`]) replace the
//! per-patch composition: compared before smoothing, and when neither wins on every count,
//! compared again after both are relaxed.

use crate::crossparam::smooth;
use crate::domain::refine::Refined;
use crate::error::{Error, Result};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::common::both;
use crate::progress::Progress;
use crate::topology;
use serde::Serialize;

/// What the global map onto the base domain did ([`crate::crossparam::global`]).
#[derive(Debug, Clone, Serialize)]
pub struct GlobalReport {
    /// Whether its maps were used (`false`: the per-patch maps were, see `fallback`).
    pub used: bool,
    /// Why the per-patch maps were used instead.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
    /// Source and target: triangles folded in the domain, the L2 stretch of their maps and the
    /// relative residual of their solves.
    pub domain_folded: [usize; 2],
    pub l2_stretch: [f64; 2],
    pub residual: [f64; 2],
    /// Per-patch and global composition before smoothing, both directions summed: distortion
    /// energy (symmetric Dirichlet), folded faces, and |area ratio - 1|. The global one is used
    /// when it is better on all three.
    pub energy: [f64; 2],
    pub folded: [usize; 2],
    pub area_deviation: [f64; 2],
    /// When neither composition was better on all counts before smoothing: both relaxed
    /// (smoothed and repaired), then compared again (per-patch, global).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relaxed: Option<RelaxedComparison>,
}

/// Per-patch and global maps after relaxation, both directions summed: the evaluator's L2
/// stretch, folded faces and |area ratio − 1|. The global ones are used when they fold no more,
/// stretch less, and are off in area by at most [`RELAXED_AREA_SLACK`] more.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RelaxedComparison {
    pub l2_stretch: [f64; 2],
    pub folded: [usize; 2],
    pub area_deviation: [f64; 2],
}

/// How much more the relaxed global maps' area may be off (both directions summed) than the
/// per-patch maps' when they stretch less.
pub const RELAXED_AREA_SLACK: f64 = 0.01;

impl RelaxedComparison {
    /// From [`relaxed_quality`] of the per-patch maps `p` and the global maps `g`, each
    /// (source to target, target to source).
    pub(super) fn new(p: [(f64, usize, f64); 2], g: [(f64, usize, f64); 2]) -> Self {
        Self {
            l2_stretch: [p[0].0 + p[1].0, g[0].0 + g[1].0],
            folded: [p[0].1 + p[1].1, g[0].1 + g[1].1],
            area_deviation: [p[0].2 + p[1].2, g[0].2 + g[1].2],
        }
    }

    /// The global maps fold no more, stretch less and are off in area by at most
    /// [`RELAXED_AREA_SLACK`] more.
    pub fn prefers_global(&self) -> bool {
        self.folded[1] <= self.folded[0]
            && self.l2_stretch[1] < self.l2_stretch[0]
            && self.area_deviation[1] <= self.area_deviation[0] + RELAXED_AREA_SLACK
    }
}

impl GlobalReport {
    /// Records the comparison after relaxation and the choice it makes; returns whether the
    /// global maps are used.
    pub(super) fn record_relaxed(&mut self, cmp: RelaxedComparison) -> bool {
        let global = cmp.prefers_global();
        self.relaxed = Some(cmp);
        self.used = global;
        self.fallback = (!global).then(|| "the per-patch maps are as good after relaxation".into());
        global
    }
}

/// L2 stretch, folded faces and |area ratio − 1| of a relaxed map (summed over directions by
/// the caller).
pub(super) fn relaxed_quality(from: &Mesh, to: &Mesh, map: &SurfaceMap) -> Result<(f64, usize, f64)> {
    let q = smooth::map_quality(from, to, map);
    let embedded = map.embed(from, to)?;
    let d = crate::metrics::distortion(from, &embedded);
    Ok((d.l2_stretch, q.flipped, (q.area_ratio - 1.0).abs()))
}

/// What [`choose_global`] needs of the layout: patches, both refinements, both anchor lists
/// and both per-patch parameterizations (source, target).
pub(super) struct GlobalInputs<'a> {
    pub(super) patches: &'a [crate::domain::Patch],
    pub(super) refined: (&'a Refined, &'a Refined),
    pub(super) anchors: (&'a [VertexId], &'a [VertexId]),
    pub(super) params: (&'a [crate::crossparam::PatchParam], &'a [crate::crossparam::PatchParam]),
}

/// The base domain's side lengths: each layout path's length on both meshes, each scaled by
/// √area, averaged.
pub(super) fn domain_lengths(inputs: &GlobalInputs, source: &Mesh, target: &Mesh) -> Vec<f64> {
    let path_len = |r: &Refined, m: &Mesh| -> Vec<f64> {
        let s = m.area().sqrt().max(f64::MIN_POSITIVE);
        r.path_vertices
            .iter()
            .map(|p| p.windows(2).map(|w| (r.mesh.position(w[1]) - r.mesh.position(w[0])).norm()).sum::<f64>() / s)
            .collect()
    };
    let (rs, rt) = inputs.refined;
    path_len(rs, source).iter().zip(path_len(rt, target)).map(|(a, b)| 0.5 * (a + b)).collect()
}

/// Before smoothing, a map pair's distortion energy (symmetric Dirichlet), folded faces and
/// |area ratio − 1|, both directions summed.
fn pair_quality(source: &Mesh, target: &Mesh, s2t: &SurfaceMap, t2s: &SurfaceMap) -> Result<(f64, usize, f64)> {
    let (x, y) = both(|| smooth::map_quality(target, source, t2s), || smooth::map_quality(source, target, s2t))?;
    Ok((x.energy + y.energy, x.flipped + y.flipped, (x.area_ratio - 1.0).abs() + (y.area_ratio - 1.0).abs()))
}

/// The per-patch composition `maps`, or the composition of both meshes' global maps onto the
/// base domain ([`crate::crossparam::global`]) when that is better on every count before
/// smoothing: lower distortion energy, no more folded faces, an area ratio closer to 1. Its
/// domain maps may fold near cone points, and energy alone prefers a fold-free squeeze to a
/// clean map (cat poses), hence all three. The global maps are only computed when more than
/// `min_folded_fraction` of the faces fold in the per-patch composition or its area ratios are
/// off by more than `min_area_deviation` (a clean composition costs nothing more: the 58k-vs-6k
/// armadillo has 4 folded faces of 128k and would pay 1 s for nothing), on closed meshes, and
/// when enabled; a failure of theirs keeps the per-patch maps.
#[allow(clippy::too_many_arguments)]
pub(super) fn choose_global(
    source: &Mesh,
    target: &Mesh,
    inputs: &GlobalInputs,
    maps: (SurfaceMap, SurfaceMap),
    pairs: &[(VertexId, VertexId)],
    rev: &[(VertexId, VertexId)],
    opts: &crate::crossparam::global::GlobalParamOptions,
    progress: &mut dyn Progress,
) -> Result<Chosen> {
    use crate::crossparam::global::{DomainMetric, compose as gcompose, global_param};
    if !opts.enabled || topology::boundary_loops(source).len() + topology::boundary_loops(target).len() > 0 {
        return Ok((maps, None, None));
    }
    let p = pair_quality(source, target, &maps.0, &maps.1)?;
    let mut report = GlobalReport {
        used: false,
        fallback: None,
        domain_folded: [0; 2],
        l2_stretch: [f64::NAN; 2],
        residual: [f64::NAN; 2],
        energy: [p.0, f64::NAN],
        folded: [p.1, 0],
        area_deviation: [p.2, f64::NAN],
        relaxed: None,
    };
    let faces = (source.n_faces() + target.n_faces()) as f64;
    if !opts.force && p.1 as f64 <= opts.min_folded_fraction * faces && p.2 <= opts.min_area_deviation {
        report.fallback = Some("the per-patch composition is clean".into());
        return Ok((maps, None, Some(report)));
    }
    progress.report(crate::progress::Stage::Global, 0.0);
    let (rs, rt) = inputs.refined;
    let (sa, ta) = inputs.anchors;
    let patches = inputs.patches;
    let is = crate::crossparam::compose::vertex_uv(inputs.params.0, source.n_vertices());
    let it = crate::crossparam::compose::vertex_uv(inputs.params.1, target.n_vertices());
    let lengths = domain_lengths(inputs, source, target);
    let lengths = (opts.metric == DomainMetric::PathLengths).then_some(&lengths[..]);
    let mut side = progress.silent();
    let (gs, gt) = both(
        || global_param(target, patches, ta, &it, Some(rt), lengths, opts, &mut side),
        || global_param(source, patches, sa, &is, Some(rs), lengths, opts, progress),
    )?;
    let (gs, gt) = match (gs, gt) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e @ Error::Cancelled), _) | (_, Err(e @ Error::Cancelled)) => return Err(e),
        (Err(e), _) | (_, Err(e)) => {
            report.fallback = Some(e.to_string());
            return Ok((maps, None, Some(report)));
        }
    };
    report.domain_folded = [gs.flipped, gt.flipped];
    report.l2_stretch = [gs.l2, gt.l2];
    report.residual = [gs.residual, gt.residual];
    let (s2t, t2s) = both(|| gcompose(&gt, &gs, source, rev), || gcompose(&gs, &gt, target, pairs))?;
    let (s2t, t2s) = match (s2t, t2s) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            report.fallback = Some(e.to_string());
            return Ok((maps, None, Some(report)));
        }
    };
    let g = pair_quality(source, target, &s2t, &t2s)?;
    report.energy[1] = g.0;
    report.folded[1] = g.1;
    report.area_deviation[1] = g.2;
    if (g.0 < p.0 && g.1 <= p.1 && g.2 < p.2) || opts.force {
        report.used = true;
        Ok(((s2t, t2s), None, Some(report)))
    } else if p.0 < g.0 && p.1 < g.1 && p.2 < g.2 {
        // Worse on every count: not worth a relaxation (SMPL, 12 anchors: 784 folded faces
        // against 17 and area deviation 1.54 against 0.11; relaxing both directions took 45 s and lost).
        report.fallback = Some("the per-patch composition is better on every count".into());
        Ok((maps, None, Some(report)))
    } else {
        // Folds before smoothing are often repaired after it (cow simplified: 79 folded faces
        // before, none after, and L2 1.015 against 1.052): both are relaxed and compared again.
        report.fallback = Some("the per-patch composition is as good on some count".into());
        Ok((maps, Some((s2t, t2s)), Some(report)))
    }
}

/// [`choose_global`]'s answer: the maps to finish (source to target, target to source), the
/// global ones when they are to be relaxed and compared with them, and the report.
pub(super) type Chosen = ((SurfaceMap, SurfaceMap), Option<(SurfaceMap, SurfaceMap)>, Option<GlobalReport>);
