//! The planar domain of a feature cut: the disk mapped onto the unit circle with mean-value
//! weights (Floater 2003), side `k` on the arc `[θ_k, θ_{k+1}]`. Both meshes of a
//! pair use the same arcs, so the two domains share their boundary and their composition is a
//! bijection that takes every feature onto its partner. The vertices of a side sit at given
//! fractions of its arc: arc length, or the warp of [`super::curve_align`].
//!
//! A circle instead of the paper's regular polygon: the boundary vertices are then in strictly
//! convex position, so Floater's theorem holds even where an edge joins two boundary vertices
//! (a link that runs beside a feature), and no corner ever carries a degenerate triangle. Arcs
//! are sized by each side's share of its boundary's length, averaged over the two meshes.

use super::domain::{exact_orientation, solve_disk};
use super::feature_cut::FeatureCutResult;
use crate::error::{Error, Result};
use crate::param::{InjectivityReport, Uv};

/// One mesh's disk on the circle.
#[derive(Debug, Clone)]
pub struct FeatureDomainResult {
    /// Per vertex of the cut disk.
    pub uv: Vec<Uv>,
    /// Angle where each side starts; side `k` ends where `k + 1` starts (the last at 2π).
    pub angles: Vec<f64>,
    pub injectivity: InjectivityReport,
    /// Relative residual of the solve.
    pub residual: f64,
}

/// Arc per side (summing to 1): each side's share of its boundary length, averaged over the
/// two cuts.
///
/// # Errors
/// `Internal` when the cuts' boundary words differ (they are built to agree).
pub fn shared_arcs(a: &FeatureCutResult, b: &FeatureCutResult) -> Result<Vec<f64>> {
    let kinds = |c: &FeatureCutResult| c.sides.iter().map(|s| s.kind).collect::<Vec<_>>();
    if kinds(a) != kinds(b) {
        return Err(Error::Internal(format!("feature cuts disagree: {:?} against {:?}", kinds(a), kinds(b))));
    }
    let share = |c: &FeatureCutResult| {
        let t: f64 = c.sides.iter().map(|s| s.length).sum();
        c.sides.iter().map(|s| s.length / t).collect::<Vec<f64>>()
    };
    let (sa, sb) = (share(a), share(b));
    Ok(sa.iter().zip(&sb).map(|(x, y)| 0.5 * (x + y)).collect())
}

/// Maps the cut disk onto the unit circle with the given arcs, the vertices of side `k` at
/// `fractions[k]` of its arc ([`super::curve_align::arc_fractions`], or a warp of them;
/// strictly increasing in `[0, 1)`).
///
/// # Errors
/// `Numerical` when the solve fails or the map folds.
pub fn feature_domain(
    cut: &FeatureCutResult,
    arcs: &[f64],
    fractions: &[Vec<f64>],
    stretch_iterations: usize,
) -> Result<FeatureDomainResult> {
    let disk = &cut.disk.mesh;
    let walk = &cut.walk;
    if arcs.len() != cut.sides.len() || fractions.len() != cut.sides.len() {
        return Err(Error::Internal(format!(
            "{} arcs and {} fraction lists for {} sides",
            arcs.len(),
            fractions.len(),
            cut.sides.len()
        )));
    }
    let tau = std::f64::consts::TAU;
    let mut angles = Vec::with_capacity(arcs.len());
    let mut acc = 0.0;
    for a in arcs {
        angles.push(tau * acc);
        acc += a;
    }
    let mut fixed = vec![[f64::NAN; 2]; disk.n_vertices()];
    for (k, s) in cut.sides.iter().enumerate() {
        let end = if k + 1 < angles.len() { angles[k + 1] } else { tau };
        if fractions[k].len() != s.edges {
            return Err(Error::Internal(format!("side {k}: {} fractions for {} edges", fractions[k].len(), s.edges)));
        }
        for (i, t) in fractions[k].iter().enumerate() {
            let th = angles[k] + (end - angles[k]) * t;
            fixed[walk[(s.start + i) % walk.len()].idx()] = [th.cos(), th.sin()];
        }
    }
    let (uv, residual) = solve_disk(disk, walk, &fixed, stretch_iterations)?;
    let injectivity = exact_orientation(disk, &uv);
    if !injectivity.is_injective() {
        return Err(Error::Numerical(format!(
            "feature domain: {} flipped and {} degenerate triangles",
            injectivity.flipped, injectivity.degenerate
        )));
    }
    Ok(FeatureDomainResult { uv, angles, injectivity, residual })
}
