//! Sander et al.'s geometric stretch of a parameterization (SIGGRAPH 2001) and the
//! stretch-minimizing reweighting of Yoshizawa, Belyaev & Seidel ("A fast and simple
//! stretch-minimizing mesh parameterization", SMI 2004).
//!
//! Starting from a fixed-boundary embedding with positive weights `w_ij`, each round divides
//! every weight by the stretch at its far end, `w_ij <- w_ij / sigma(v_j)`, and solves again
//! with the same boundary. Regions squeezed by the first map (protrusions, which a harmonic or
//! mean-value map compresses exponentially) have large stretch; dividing their neighbours'
//! pull by it lets them open up. The weights stay positive and the boundary convex, so every
//! round is still a Tutte embedding: bijective. Rounds stop when the L2 stretch stops falling,
//! and the best map is kept. Only the numeric factorization is repeated: the sparsity pattern
//! and the symbolic factorization of the system are reused.

use super::Uv;
use crate::error::Result;
use crate::linalg::{DirectedWeights, FixedBoundarySystem};
use crate::mesh::{Mesh, P3, V3, VertexId};

/// Options of [`minimize_stretch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StretchOptions {
    /// Reweighting rounds at most.
    pub iterations: usize,
    /// Stop when a round lowers the L2 stretch by less than this fraction.
    pub min_gain: f64,
}

impl Default for StretchOptions {
    fn default() -> Self {
        Self { iterations: 3, min_gain: 1e-3 }
    }
}

/// Output of [`minimize_stretch`].
#[derive(Debug, Clone)]
pub struct StretchResult {
    pub uv: Vec<Uv>,
    /// L2 stretch of the input map and of the result (1 is the optimum).
    pub l2_before: f64,
    pub l2_after: f64,
    /// Rounds whose result was kept.
    pub rounds: usize,
    pub residual: f64,
}

/// Sander et al.'s partial derivatives `S_s`, `S_t` of the linear map taking parameter
/// triangle `q` to surface triangle `p`, with twice the signed parameter area; `None` when that
/// area vanishes.
#[inline]
pub fn stretch_jacobian(p: [P3; 3], q: [Uv; 3]) -> Option<(V3, V3, f64)> {
    let [q1, q2, q3] = q;
    let a2 = (q2[0] - q1[0]) * (q3[1] - q1[1]) - (q3[0] - q1[0]) * (q2[1] - q1[1]);
    if a2.abs() <= f64::MIN_POSITIVE {
        return None;
    }
    let [p1, p2, p3] = p;
    let ss = (p1.coords * (q2[1] - q3[1]) + p2.coords * (q3[1] - q1[1]) + p3.coords * (q1[1] - q2[1])) / a2;
    let st = (p1.coords * (q3[0] - q2[0]) + p2.coords * (q1[0] - q3[0]) + p3.coords * (q2[0] - q1[0])) / a2;
    Some((ss, st, a2))
}

/// Per-face squared L2 stretch `(|S_s|² + |S_t|²) / 2` of the map uv -> 3D, with uv scaled to
/// the surface's total area, and each face's 3D area. `None` for a face with no uv area.
pub fn face_stretch(mesh: &Mesh, uv: &[Uv]) -> (Vec<Option<f64>>, Vec<f64>) {
    let mut uv_area = 0.0;
    let mut area = Vec::with_capacity(mesh.n_faces());
    let mut raw = Vec::with_capacity(mesh.n_faces());
    for (f, t) in mesh.faces().iter().enumerate() {
        let [p1, p2, p3] = mesh.face_points(crate::FaceId::from_idx(f));
        let [q1, q2, q3] = t.map(|v| uv[v.idx()]);
        let a2 = (q2[0] - q1[0]) * (q3[1] - q1[1]) - (q3[0] - q1[0]) * (q2[1] - q1[1]);
        uv_area += 0.5 * a2.abs();
        area.push(0.5 * (p2 - p1).cross(&(p3 - p1)).norm());
        raw.push(
            stretch_jacobian([p1, p2, p3], [q1, q2, q3])
                .map(|(ss, st, _)| 0.5 * (ss.norm_squared() + st.norm_squared())),
        );
    }
    // Scaling uv by k scales the squared stretch by 1 / k²: normalise to equal total areas.
    let total: f64 = area.iter().sum();
    let k2 = if total > 0.0 { uv_area / total } else { 1.0 };
    (raw.into_iter().map(|s| s.map(|s| s * k2)).collect(), area)
}

/// Area-weighted L2 stretch of the map and the per-vertex stretch (over incident faces).
/// A face without uv area counts as infinitely stretched.
pub fn stretch(mesh: &Mesh, uv: &[Uv]) -> (f64, Vec<f64>) {
    let (s2, area) = face_stretch(mesh, uv);
    let mut num = vec![0.0; mesh.n_vertices()];
    let mut den = vec![0.0; mesh.n_vertices()];
    let (mut tn, mut td) = (0.0, 0.0);
    for (f, t) in mesh.faces().iter().enumerate() {
        let s = s2[f].unwrap_or(f64::INFINITY);
        tn += area[f] * s;
        td += area[f];
        for v in t {
            num[v.idx()] += area[f] * s;
            den[v.idx()] += area[f];
        }
    }
    let per_vertex = num.iter().zip(&den).map(|(n, d)| if *d > 0.0 { (n / d).sqrt() } else { 1.0 }).collect();
    ((tn / td.max(f64::MIN_POSITIVE)).sqrt(), per_vertex)
}

/// Lowers the L2 stretch of `uv`, an embedding of `mesh` solved from `sys` with `weights`
/// (positive) and the boundary values `fixed`.
///
/// # Errors
/// `Numerical` if a factorization or solve fails.
pub fn minimize_stretch(
    mesh: &Mesh,
    sys: &FixedBoundarySystem,
    weights: &DirectedWeights,
    uv: Vec<Uv>,
    fixed: &dyn Fn(VertexId) -> Uv,
    opts: &StretchOptions,
) -> Result<StretchResult> {
    let (l2_before, mut sigma) = stretch(mesh, &uv);
    let mut best = StretchResult { uv, l2_before, l2_after: l2_before, rounds: 0, residual: 0.0 };
    let mut w = weights.clone();
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!("stretch: start l2 {l2_before}, sigma max {}", sigma.iter().fold(0.0f64, |a, b| a.max(*b)));
    }
    for _ in 0..opts.iterations {
        if !best.l2_after.is_finite() || sigma.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            break;
        }
        for h in 0..mesh.n_halfedges() {
            let he = crate::HalfedgeId::from_idx(h);
            // fwd: row tail, column head; rev: row head, column tail.
            w.fwd[h] /= sigma[mesh.head(he).idx()];
            w.rev[h] /= sigma[mesh.tail(he).idx()];
        }
        let fac = sys.factor_weights(&w, false)?;
        let (next, residual) = fac.solve_with_residual::<2>(fixed)?;
        let (l2, s) = stretch(mesh, &next);
        if tracing::enabled!(tracing::Level::DEBUG) {
            tracing::debug!("stretch: {} vertices, l2 {} -> {l2}", mesh.n_vertices(), best.l2_after);
        }
        let gained = l2 < best.l2_after * (1.0 - opts.min_gain);
        if !gained {
            if l2 < best.l2_after {
                best = StretchResult { uv: next, l2_after: l2, rounds: best.rounds + 1, residual, ..best };
            }
            break;
        }
        best = StretchResult { uv: next, l2_after: l2, rounds: best.rounds + 1, residual, ..best };
        sigma = s;
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::{Weights, directed_weights};
    use crate::mesh::{P3, shapes};
    use crate::param::{BoundaryShape, check_injective, disk_boundary, map_boundary_to_polygon};

    #[test]
    fn planar_identity_has_unit_stretch() {
        let m = shapes::grid(6);
        let uv: Vec<Uv> = m.positions().iter().map(|p| [p.x * 3.0, p.y * 3.0]).collect();
        let (l2, per_vertex) = stretch(&m, &uv);
        assert!((l2 - 1.0).abs() < 1e-12, "scale does not count: {l2}");
        assert!(per_vertex.iter().all(|s| (s - 1.0).abs() < 1e-12));
    }

    /// A square sheet with a tall narrow bump: the mean-value map squeezes the bump, and
    /// reweighting opens it up again without folding.
    #[test]
    fn reweighting_lowers_the_stretch_of_a_bump_and_stays_bijective() {
        let g = shapes::grid(24);
        let pos = g
            .positions()
            .iter()
            .map(|p| {
                let r2 = (p.x - 0.5).powi(2) + (p.y - 0.5).powi(2);
                P3::new(p.x, p.y, 0.8 * (-r2 / 0.01).exp())
            })
            .collect();
        let m = g.with_positions(pos).unwrap();
        let boundary = disk_boundary(&m).unwrap();
        let fixed_uv = map_boundary_to_polygon(&m, &boundary, &BoundaryShape::Square).unwrap();
        let mut fixed = vec![[f64::NAN; 2]; m.n_vertices()];
        for (v, p) in boundary.iter().zip(&fixed_uv) {
            fixed[v.idx()] = *p;
        }
        let mut sys = FixedBoundarySystem::new(&m, &boundary).unwrap();
        sys.prepare_lu().unwrap();
        let w = directed_weights(&m, Weights::MeanValue);
        let (uv, _) = sys.factor_weights(&w, false).unwrap().solve_with_residual::<2>(&|v| fixed[v.idx()]).unwrap();
        let r = minimize_stretch(&m, &sys, &w, uv, &|v| fixed[v.idx()], &StretchOptions::default()).unwrap();
        assert!(r.rounds > 0);
        assert!(r.l2_after < 0.95 * r.l2_before, "{} -> {}", r.l2_before, r.l2_after);
        assert!(r.residual < 1e-8);
        assert_eq!(check_injective(&m, &r.uv).flipped, 0);
        for v in &boundary {
            assert_eq!(r.uv[v.idx()], fixed[v.idx()], "the boundary stays put");
        }
    }
}
