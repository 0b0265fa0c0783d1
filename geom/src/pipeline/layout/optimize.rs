//! The base-domain optimization of `voronoi` and `greedy` maps (issue 35): both directions
//! optimized as a whole in the common base domain ([`crate::crossparam::global::domain_map`]:
//! symmetric Dirichlet, injective projected Newton), before the relaxation polishes them.
//!
//! Each mesh's images start from its global (or per-patch) map onto the domain and move against
//! the other mesh's seed. An optimized direction also yields the other as its inverse: the
//! other mesh's seed located among the optimized images. Per direction the candidate of lower
//! energy replaces the composed map when it is lower in energy than the composed map; both
//! are then relaxed and, per direction, the optimized one kept when it folds less, or as much
//! and stretches less (the energy before relaxation does not see what the repairs leave).
//!
//! It runs only where the composed maps are far from isometric (normalized energy above
//! [`GATE`], seen: plane → bird 2.8 / 3.0), not on same-shape pairs or SMPL man → woman
//! (1.7–2.0), where the relaxation alone does as well and the optimized maps lost the contest
//! after seconds of work (figures in `git show 32d23d1:bench/NOTES.md`).

use crate::crossparam::global::domain_map::{DomainMapReport, DomainOptimizer};
use crate::crossparam::global::{Seed, locate, map_through, seed};
use crate::crossparam::smooth::SourceFrame;
use crate::error::Result;
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, P3, VertexId};
use crate::optim::InjectiveNewtonOptions;
use crate::pipeline::layout::global_choice::{GlobalInputs, RELAXED_AREA_SLACK, domain_lengths};
use crate::progress::{Progress, Stage};
use serde::Serialize;

/// Normalized energy (1 for an isometry, the larger of both directions) above which the
/// composed maps are optimized.
pub const GATE: f64 = 2.5;

/// A face's energy counts at most this many times the isometric energy.
const FACE_CAP: f64 = 10.0;

/// Newton iterations per direction.
const ITERATIONS: usize = 20;

/// What the optimization did, per direction (source → target, target → source).
#[derive(Debug, Clone, Serialize)]
pub struct OptimizeReport {
    /// Symmetric Dirichlet energy over four times the mapped mesh's area (1 for an isometry):
    /// the composed map, and the map kept.
    pub energy_before: [f64; 2],
    pub energy_after: [f64; 2],
    /// Which map was kept: `direct` (this direction optimized), `inverse` (the other
    /// direction's, inverted) or `composed` (neither was lower in energy, or none was injective).
    pub used: [&'static str; 2],
    pub source: DomainMapReport,
    pub target: DomainMapReport,
    /// Per direction, the composed and the optimized map after relaxation (L2 stretch, folded
    /// faces, |area ratio − 1|), when any direction changed; the optimized one is kept when it
    /// folds less, or as much and stretches less without losing area (`kept`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relaxed: Option<[[Quality; 2]; 2]>,
    pub kept: [bool; 2],
    /// The optimized maps (per direction the composed one where it stayed lower), until the
    /// relaxation takes them.
    #[serde(skip)]
    pub maps: Option<(SurfaceMap, SurfaceMap)>,
}

/// A relaxed map's L2 stretch, folded faces and |area ratio − 1|.
pub type Quality = (f64, usize, f64);

impl OptimizeReport {
    /// Records the per-direction comparison after relaxation (composed `p`, optimized `g`);
    /// returns per direction whether the optimized map is kept.
    pub(super) fn record_relaxed(&mut self, p: [Quality; 2], g: [Quality; 2]) -> [bool; 2] {
        let better = |p: Quality, g: Quality| g.1 < p.1 || (g.1 == p.1 && g.0 < p.0 && g.2 <= p.2 + RELAXED_AREA_SLACK);
        self.relaxed = Some([[p[0], g[0]], [p[1], g[1]]]);
        self.kept = [better(p[0], g[0]), better(p[1], g[1])];
        self.kept
    }
}

/// Normalized energy of `map` from `from` onto `to`: the symmetric Dirichlet energy of its
/// chords over four times the source's area, each face's share capped at [`FACE_CAP`] times the
/// isometric one, so a few faces mapped nearly flat (which the relaxation repairs) do not
/// outweigh the distortion of the whole map.
fn normalized(from: &Mesh, to: &Mesh, map: &SurfaceMap) -> f64 {
    let scale = (from.area() / to.area().max(f64::MIN_POSITIVE)).sqrt();
    let pos: Vec<P3> = (0..from.n_vertices()).map(|v| map.position(VertexId::from_idx(v), to)).collect();
    let mut sum = 0.0;
    for f in from.faces() {
        if let Some(fr) = SourceFrame::new(f.map(|w| from.position(w))) {
            let cap = 4.0 * FACE_CAP * fr.area();
            sum += fr.energy(f.map(|w| pos[w.idx()]), scale).map_or(cap, |e| e.min(cap));
        }
    }
    sum / (4.0 * from.area().max(f64::MIN_POSITIVE))
}

/// Optimizes `maps` (source → target, target → source) when their normalized energy is above
/// `gate` ([`GATE`] in jobs); `None` when it was not. The report carries the optimized maps
/// when any direction changed.
///
/// # Errors
/// `Numerical` when a Newton system cannot be solved; `Cancelled`.
pub(super) fn optimize_maps(
    (source, target): (&Mesh, &Mesh),
    inputs: &GlobalInputs,
    [pairs, rev]: [&[(VertexId, VertexId)]; 2],
    maps: &(SurfaceMap, SurfaceMap),
    gate: f64,
    progress: &mut dyn Progress,
) -> Result<Option<OptimizeReport>> {
    let before = [normalized(source, target, &maps.0), normalized(target, source, &maps.1)];
    tracing::debug!(?before, gate, "optimization gate");
    if before[0].max(before[1]) <= gate {
        return Ok(None);
    }
    progress.report(Stage::Optimize, 0.0);
    let (rs, rt) = inputs.refined;
    let (sa, ta) = inputs.anchors;
    let lengths = domain_lengths(inputs, source, target);
    let is = crate::crossparam::compose::vertex_uv(inputs.params.0, source.n_vertices());
    let it = crate::crossparam::compose::vertex_uv(inputs.params.1, target.n_vertices());
    let mut ss = seed(source, inputs.patches, sa, &is, Some(rs), Some(&lengths))?;
    let mut ts = seed(target, inputs.patches, ta, &it, Some(rt), Some(&lengths))?;
    let opts = InjectiveNewtonOptions { max_iterations: ITERATIONS, ..Default::default() };
    let (so, to) = (DomainOptimizer::new(source, &ss)?, DomainOptimizer::new(target, &ts)?);
    let locators = |m: &Mesh, x: &Seed| locate::locators(m, &x.charts, &x.state, &x.rows, &x.fixed);
    // Both seeds untangled first (each measured against the other's seed), so each mesh's
    // optimization measures against an injective map of the other.
    let (sl, tl) = (locators(source, &ss), locators(target, &ts));
    let (s_fold, t_fold) = (so.untangle(&mut ss, target, &tl, progress)?, to.untangle(&mut ts, source, &sl, progress)?);
    let sl = if s_fold.0 > 0 { locators(source, &ss) } else { sl };
    let tl = if t_fold.0 > 0 { locators(target, &ts) } else { tl };
    let (s0, t0) = (ss.state.clone(), ts.state.clone());
    let n1 = if t_fold.1 == 0 { so.minimize(&mut ss, target, &tl, &opts, progress)? } else { None };
    progress.report(Stage::Optimize, 0.5);
    let n2 = if s_fold.1 == 0 { to.minimize(&mut ts, source, &sl, &opts, progress)? } else { None };
    let r1 = DomainMapReport { newton: n1, folded_at_start: s_fold.0, folded_after_untangling: s_fold.1 };
    let r2 = DomainMapReport { newton: n2, folded_at_start: t_fold.0, folded_after_untangling: t_fold.1 };
    // A composition is bijective when both embeddings it passes through are injective: a
    // minimized direction implies both untangled seeds were.
    let mut c1 = Vec::new();
    let mut c2 = Vec::new();
    if n1.is_some() {
        c1.push(("direct", map_through(&ss.state, &tl, target, pairs)?));
        c2.push(("inverse", map_through(&t0, &locators(source, &ss), source, rev)?));
    }
    if n2.is_some() {
        c2.push(("direct", map_through(&ts.state, &sl, source, rev)?));
        c1.push(("inverse", map_through(&s0, &locators(target, &ts), target, pairs)?));
    }
    let mut out = maps.clone();
    let (e1, u1) = keep_lowest(source, target, &mut out.0, before[0], c1);
    let (e2, u2) = keep_lowest(target, source, &mut out.1, before[1], c2);
    let changed = u1 != "composed" || u2 != "composed";
    tracing::debug!(?r1, ?r2, e1, e2, u1, u2, "optimized");
    Ok(Some(OptimizeReport {
        energy_before: before,
        energy_after: [e1, e2],
        used: [u1, u2],
        source: r1,
        target: r2,
        relaxed: None,
        kept: [false; 2],
        maps: changed.then_some(out),
    }))
}

/// Replaces `map` by the candidate of lowest energy when it is lower than `energy`.
fn keep_lowest(
    from: &Mesh,
    to: &Mesh,
    map: &mut SurfaceMap,
    energy: f64,
    candidates: Vec<(&'static str, SurfaceMap)>,
) -> (f64, &'static str) {
    let best =
        candidates.into_iter().map(|(name, m)| (normalized(from, to, &m), name, m)).min_by(|a, b| a.0.total_cmp(&b.0));
    match best {
        Some((e, name, m)) if e < energy => {
            *map = m;
            (e, name)
        }
        _ => (energy, "composed"),
    }
}
