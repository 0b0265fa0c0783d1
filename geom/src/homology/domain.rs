//! The canonical fundamental domain (Carner et al. section 3.3): the disk cut along a canonical
//! basis, mapped onto the regular 4g-gon with mean-value weights (Floater 2003; the paper's
//! harmonic map with mean-value coordinates). Side `k` of the polygon carries the `k`-th letter
//! of `a1 b1 a1⁻¹ b1⁻¹ …` by arc length; the two sides of one loop are laid out from the same
//! fractions, so points of a cut loop get mirror-image positions on both copies exactly.
//! With a convex polygon, positive weights and no chord inside a side (the basis splits them),
//! Floater's theorem makes the map bijective; the report checks it.

use super::basis::CanonicalBasisResult;
use crate::error::{Error, Result};
use crate::linalg::{FixedBoundarySystem, Weights, directed_weights};
use crate::mesh::Mesh;
use crate::mesh::VertexId;
use crate::param::{InjectivityReport, StretchOptions, Uv, minimize_stretch};

/// The planar image of a cut disk.
#[derive(Debug, Clone)]
pub struct FundamentalDomainResult {
    /// Per vertex of the cut disk.
    pub uv: Vec<Uv>,
    /// The regular polygon, counter-clockwise; corner `k` starts side `k`.
    pub polygon: Vec<Uv>,
    pub injectivity: InjectivityReport,
    /// Relative residual of the solve.
    pub residual: f64,
}

/// Corner `k` of the regular `m`-gon of circumradius 1 (corner 0 at angle π/m below the x-axis,
/// so side 0 is vertical on the right for every `m`).
pub fn polygon_corner(m: usize, k: usize) -> Uv {
    let t = std::f64::consts::TAU * (k as f64 - 0.5) / m as f64;
    [t.cos(), t.sin()]
}

/// Maps the cut disk of `basis` onto the regular 4g-gon.
///
/// # Errors
/// `Numerical` when the solve fails or the result folds; `Internal` for a malformed basis.
pub fn fundamental_domain(basis: &CanonicalBasisResult, stretch_iterations: usize) -> Result<FundamentalDomainResult> {
    let r = domain_unchecked(basis, stretch_iterations)?;
    if !r.injectivity.is_injective() {
        return Err(Error::Numerical(format!(
            "fundamental domain: {} flipped and {} degenerate triangles",
            r.injectivity.flipped, r.injectivity.degenerate
        )));
    }
    Ok(r)
}

/// [`fundamental_domain`] without the bijectivity verdict (the report is still filled in).
///
/// # Errors
/// As [`fundamental_domain`], except for folds.
pub fn domain_unchecked(basis: &CanonicalBasisResult, stretch_iterations: usize) -> Result<FundamentalDomainResult> {
    let disk = &basis.disk.mesh;
    let walk = &basis.walk;
    let corners = &basis.corners;
    let m = corners.len();
    if m < 4 || m != 2 * basis.loops.len() {
        return Err(Error::Internal(format!("fundamental domain: {m} corners for {} loops", basis.loops.len())));
    }
    let polygon: Vec<Uv> = (0..m).map(|k| polygon_corner(m, k)).collect();
    let n = walk.len();
    let side = |k: usize| -> Vec<usize> {
        let (s, e) = (corners[k], if k + 1 < m { corners[k + 1] } else { n });
        (s..=e).map(|i| i % n).collect()
    };
    let mut fixed = vec![[f64::NAN; 2]; disk.n_vertices()];
    for j in 0..m / 4 {
        for k in [4 * j, 4 * j + 1] {
            // Side k and its partner k + 2 (the same loop, read backwards).
            let s = side(k);
            let len: Vec<f64> =
                s.windows(2).map(|w| (disk.position(walk[w[1]]) - disk.position(walk[w[0]])).norm()).collect();
            let total: f64 = len.iter().sum();
            let mut t = vec![0.0; s.len()];
            for i in 1..s.len() {
                t[i] = if total > 0.0 { t[i - 1] + len[i - 1] / total } else { i as f64 / (s.len() - 1) as f64 };
            }
            let partner = side(k + 2);
            if partner.len() != s.len() {
                return Err(Error::Internal(format!("fundamental domain: sides {k} and {} differ in length", k + 2)));
            }
            let lerp = |a: Uv, b: Uv, u: f64| [a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u];
            let (p0, p1) = (polygon[k], polygon[(k + 1) % m]);
            let (q0, q1) = (polygon[k + 2], polygon[(k + 3) % m]);
            let last = s.len() - 1;
            for i in 0..s.len() {
                fixed[walk[s[i]].idx()] = lerp(p0, p1, t[i]);
                // Partner side runs from the loop's end back to its start.
                fixed[walk[partner[last - i]].idx()] = lerp(q0, q1, 1.0 - t[i]);
            }
        }
    }
    let (uv, residual) = solve_disk(disk, walk, &fixed, stretch_iterations)?;
    let injectivity = exact_orientation(disk, &uv);
    Ok(FundamentalDomainResult { uv, polygon, injectivity, residual })
}

/// The mean-value map of `disk` with `boundary` held at `fixed` (indexed by vertex), then
/// `stretch_iterations` rounds of reweighting: the harmonic map squeezes whatever lies far
/// from the boundary, and Yoshizawa–Belyaev–Seidel reweighting (positive weights, so still
/// bijective) spreads it out again. Returns the positions and the solve's relative residual.
///
/// # Errors
/// When a solve fails.
pub(super) fn solve_disk(
    disk: &Mesh,
    boundary: &[VertexId],
    fixed: &[Uv],
    stretch_iterations: usize,
) -> Result<(Vec<Uv>, f64)> {
    let mut sys = FixedBoundarySystem::new(disk, boundary)?;
    sys.prepare_lu()?;
    let w = directed_weights(disk, Weights::MeanValue);
    let (uv, residual) = sys.factor_weights(&w, false)?.solve_with_residual::<2>(&|v| fixed[v.idx()])?;
    if stretch_iterations == 0 {
        return Ok((uv, residual));
    }
    let so = StretchOptions { iterations: stretch_iterations, ..Default::default() };
    let r = minimize_stretch(disk, &sys, &w, uv, &|v| fixed[v.idx()], &so)?;
    Ok((r.uv, if r.rounds > 0 { r.residual } else { residual }))
}

/// Orientation of every face by the exact predicate: flipped below zero, degenerate at exactly
/// zero. (The harmonic map squeezes protrusions far from the cut by orders of magnitude, so a
/// threshold relative to the mean area, as [`crate::param::check_injective`] uses for patches,
/// would call valid tiny triangles degenerate.)
pub fn exact_orientation(mesh: &Mesh, uv: &[Uv]) -> InjectivityReport {
    let mut r = InjectivityReport { flipped: 0, degenerate: 0, min_signed_area2: f64::INFINITY };
    for f in mesh.faces() {
        let [a, b, c] = f.map(|v| {
            let p = uv[v.idx()];
            robust::Coord { x: p[0], y: p[1] }
        });
        let o = robust::orient2d(a, b, c);
        if o == 0.0 {
            r.degenerate += 1;
        } else if o < 0.0 {
            r.flipped += 1;
        }
        r.min_signed_area2 = r.min_signed_area2.min(o);
    }
    r
}
