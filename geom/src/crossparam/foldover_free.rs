//! Untangling a planar triangle mesh with held vertices by the method of Garanzha, Kaporin,
//! Kudryavtseva, Protais, Ray and Sokolov, "Foldover-free maps in 50 lines of code" (SIGGRAPH
//! 2021): minimize the regularized elastic energy
//!
//! `E_ε = Σ_t A_t [(1 − θ) tr(JᵀJ) / χ(det J, ε) + θ (det² J + 1) / χ(det J, ε)]`,
//! `χ(D, ε) = (D + √(ε² + D²)) / 2`,
//!
//! over the free vertices with L-BFGS (argmin), where `J` maps each reference triangle (the
//! source triangle, isometrically flattened and scaled to the region's chart area) to its
//! chart image. `χ` keeps the energy finite for inverted triangles; `ε` shrinks by the paper's
//! rule as the smallest determinant grows, so the minimizers approach a fold-free map. It
//! moves all free vertices together, which frees tangles that one-vertex repairs
//! ([`super::planar_untangle`]) cannot undo.

use argmin::core::{CostFunction, Error as ArgminError, Executor, Gradient};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;

use super::planar_untangle::signed_area;
use super::smooth::SourceFrame;
use crate::mesh::{FaceId, Mesh};
use crate::param::Uv;

/// Options of [`foldover_free`].
#[derive(Debug, Clone, Copy)]
pub struct FoldoverFreeOptions {
    /// Outer rounds (each an L-BFGS run at one ε).
    pub rounds: usize,
    /// L-BFGS iterations per round.
    pub iterations: u64,
    /// Weight of the area term (the paper's θ).
    pub theta: f64,
    /// Rounds without a 1% gain in the smallest determinant, while it is negative, before
    /// giving up.
    pub stall_rounds: usize,
}

impl Default for FoldoverFreeOptions {
    fn default() -> Self {
        Self { rounds: 40, iterations: 150, theta: 1.0 / 128.0, stall_rounds: 6 }
    }
}

/// What [`foldover_free`] did.
#[derive(Debug, Clone, Copy, Default)]
pub struct FoldoverFreeResult {
    /// All triangles positively oriented (w.r.t. the chart's sign) at the end.
    pub valid: bool,
    pub rounds: usize,
    /// Smallest determinant at the end.
    pub min_det: f64,
}

/// Per triangle: its corners, the inverse of its reference edge matrix, and its reference area.
struct Problem<'a> {
    tris: Vec<([u32; 3], [[f64; 2]; 2], f64)>,
    /// Position in the variable vector of each vertex (`u32::MAX`: held).
    var: Vec<u32>,
    fixed: &'a [Uv],
    theta: f64,
    eps: f64,
}

/// `χ(D, ε)`, without cancellation for negative `D` (`D + r = ε² / (r − D)`).
fn chi(d: f64, eps: f64) -> f64 {
    let r = (eps * eps + d * d).sqrt();
    if d >= 0.0 { (d + r) / 2.0 } else { eps * eps / (r - d) / 2.0 }
}

impl Problem<'_> {
    fn point(&self, x: &[f64], v: u32) -> Uv {
        match self.var[v as usize] {
            u32::MAX => self.fixed[v as usize],
            i => [x[2 * i as usize], x[2 * i as usize + 1]],
        }
    }

    /// The Jacobian of triangle `t` at `x`.
    fn jacobian(&self, x: &[f64], t: usize) -> [[f64; 2]; 2] {
        let (c, r, _) = &self.tris[t];
        let [p0, p1, p2] = c.map(|v| self.point(x, v));
        let e = [[p1[0] - p0[0], p2[0] - p0[0]], [p1[1] - p0[1], p2[1] - p0[1]]];
        let mut j = [[0.0; 2]; 2];
        for (a, row) in j.iter_mut().enumerate() {
            for (b, out) in row.iter_mut().enumerate() {
                *out = e[a][0] * r[0][b] + e[a][1] * r[1][b];
            }
        }
        j
    }

    fn min_det(&self, x: &[f64]) -> f64 {
        (0..self.tris.len())
            .map(|t| {
                let j = self.jacobian(x, t);
                j[0][0] * j[1][1] - j[0][1] * j[1][0]
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Energy and, if asked, its gradient.
    fn eval(&self, x: &[f64], mut grad: Option<&mut [f64]>) -> f64 {
        if let Some(g) = grad.as_deref_mut() {
            g.fill(0.0);
        }
        let th = self.theta;
        let mut e = 0.0;
        for (t, (c, r, area)) in self.tris.iter().enumerate() {
            let j = self.jacobian(x, t);
            let d = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            let tr = j[0][0] * j[0][0] + j[0][1] * j[0][1] + j[1][0] * j[1][0] + j[1][1] * j[1][1];
            let root = (self.eps * self.eps + d * d).sqrt();
            let ch = chi(d, self.eps);
            if ch.is_nan() || ch <= 0.0 {
                return f64::INFINITY;
            }
            e += area * ((1.0 - th) * tr / ch + th * (d * d + 1.0) / ch);
            let Some(g) = grad.as_deref_mut() else { continue };
            // dχ/dD = χ / √(ε² + D²).
            let dchi = ch / root;
            let dd =
                area * (-(1.0 - th) * tr / (ch * ch) * dchi + th * (2.0 * d / ch - (d * d + 1.0) / (ch * ch) * dchi));
            let cof = [[j[1][1], -j[1][0]], [-j[0][1], j[0][0]]];
            let mut gj = [[0.0; 2]; 2];
            for a in 0..2 {
                for b in 0..2 {
                    gj[a][b] = area * (1.0 - th) * 2.0 * j[a][b] / ch + dd * cof[a][b];
                }
            }
            // dE/dE_edges = dE/dJ · R⁻ᵀ; columns are the gradients at corners 1 and 2.
            let mut ge = [[0.0; 2]; 2];
            for a in 0..2 {
                for k in 0..2 {
                    ge[a][k] = gj[a][0] * r[k][0] + gj[a][1] * r[k][1];
                }
            }
            for (corner, w) in [(c[1], [1.0, 0.0]), (c[2], [0.0, 1.0]), (c[0], [-1.0, -1.0])] {
                let i = self.var[corner as usize];
                if i == u32::MAX {
                    continue;
                }
                for a in 0..2 {
                    g[2 * i as usize + a] += w[0] * ge[a][0] + w[1] * ge[a][1];
                }
            }
        }
        e
    }
}

/// The energy at a fixed ε, as an argmin problem. Cost and gradient are computed together and
/// the last pair is kept, since L-BFGS asks for both at each point it accepts.
struct Energy<'p, 'a> {
    prob: &'p Problem<'a>,
    last: std::cell::RefCell<Option<Evaluated>>,
}

/// A point with its energy and gradient.
type Evaluated = (Vec<f64>, f64, Vec<f64>);

impl Energy<'_, '_> {
    fn both(&self, x: &[f64]) -> (f64, Vec<f64>) {
        if let Some((lx, e, g)) = self.last.borrow().as_ref()
            && lx.as_slice() == x
        {
            return (*e, g.clone());
        }
        let mut g = vec![0.0; x.len()];
        let e = self.prob.eval(x, Some(&mut g));
        *self.last.borrow_mut() = Some((x.to_vec(), e, g.clone()));
        (e, g)
    }
}

impl CostFunction for Energy<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, ArgminError> {
        Ok(self.both(x).0)
    }
}

impl Gradient for Energy<'_, '_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, ArgminError> {
        Ok(self.both(x).1)
    }
}

/// Untangles `uv` (one position per vertex of `m`) in place; `held` vertices never move. `sign`
/// is the orientation the chart gives to correctly oriented faces. Reference shapes come from
/// `m`'s own 3D triangles. Leaves `uv` unchanged unless the result is valid.
pub fn foldover_free(
    m: &Mesh,
    uv: &mut [Uv],
    held: &[bool],
    sign: f64,
    opts: &FoldoverFreeOptions,
) -> FoldoverFreeResult {
    // Work in a frame where good faces are counter-clockwise.
    let flip = |p: Uv| [p[0], sign * p[1]];
    let fixed: Vec<Uv> = uv.iter().map(|&p| flip(p)).collect();
    let mut var = vec![u32::MAX; m.n_vertices()];
    let mut x = Vec::new();
    for v in 0..m.n_vertices() {
        if !held[v] {
            var[v] = (x.len() / 2) as u32;
            x.extend_from_slice(&fixed[v]);
        }
    }
    if x.is_empty() {
        return FoldoverFreeResult::default();
    }
    // Reference triangles, scaled so that their total area is the chart area of the region
    // (the area enclosed by its boundary, which does not change).
    let mut tris = Vec::with_capacity(m.n_faces());
    let mut ref_area = 0.0;
    let mut chart_area = 0.0;
    for f in 0..m.n_faces() {
        let c = m.face(FaceId::from_idx(f));
        let Some(frame) = SourceFrame::new(m.face_points(FaceId::from_idx(f))) else {
            return FoldoverFreeResult::default();
        };
        ref_area += frame.area();
        chart_area += signed_area(c.map(|v| fixed[v.idx()])) / 2.0;
        tris.push((c.map(|v| v.0), frame.inverse(), frame.area()));
    }
    if chart_area.is_nan() || chart_area <= 0.0 {
        return FoldoverFreeResult::default();
    }
    let s = (ref_area / chart_area).sqrt();
    for (_, r, area) in tris.iter_mut() {
        for row in r.iter_mut() {
            for e in row.iter_mut() {
                *e *= s;
            }
        }
        *area /= ref_area;
    }
    // A triangle with every corner held cannot be repaired.
    if tris.iter().any(|(c, _, _)| {
        c.iter().all(|&v| var[v as usize] == u32::MAX) && signed_area(c.map(|v| fixed[v as usize])) <= 0.0
    }) {
        return FoldoverFreeResult::default();
    }
    let mut prob = Problem { tris, var, fixed: &fixed, theta: opts.theta, eps: 1.0 };
    let md = prob.min_det(&x);
    prob.eps = if md > 0.0 { 1e-9 } else { (1e-12 + 0.04 * md * md).sqrt() };
    let mut res = FoldoverFreeResult { min_det: md, ..Default::default() };
    let (mut best, mut stalled) = (md, 0);
    for round in 0..opts.rounds {
        res.rounds = round + 1;
        let e_prev = prob.eval(&x, None);
        let Some(next) = lbfgs(&prob, x.clone(), opts.iterations) else { break };
        x = next;
        let e = prob.eval(&x, None);
        let sigma = (1.0 - e / e_prev).max(0.1);
        let md = prob.min_det(&x);
        if tracing::enabled!(tracing::Level::DEBUG) {
            tracing::debug!(
                "foldover_free: round {round} eps {:.2e} energy {e_prev:.4e} -> {e:.4e} min det {md:.3e}",
                prob.eps
            );
        }
        res.min_det = md;
        let mu = (1.0 - sigma) * chi(md, prob.eps);
        prob.eps = if md < mu { 2.0 * (mu * (mu - md)).max(0.0).sqrt() } else { 1e-10 };
        // Valid: keep lowering the energy (at the small ε that follows) until it settles.
        if md > 0.0 && (e_prev - e).abs() <= 1e-5 * e.abs() {
            break;
        }
        // Give up on a tangle whose worst triangle stops improving while still inverted.
        if md <= 0.0 {
            if md > best + 0.01 * best.abs() {
                (best, stalled) = (md, 0);
            } else {
                stalled += 1;
                if stalled >= opts.stall_rounds {
                    break;
                }
            }
        }
    }
    res.valid = res.min_det > 0.0;
    if res.valid {
        for (v, out) in uv.iter_mut().enumerate() {
            *out = flip(prob.point(&x, v as u32));
        }
    }
    res
}

fn lbfgs(prob: &Problem, x0: Vec<f64>, iterations: u64) -> Option<Vec<f64>> {
    let ls = MoreThuenteLineSearch::new();
    let solver = LBFGS::new(ls, 8).with_tolerance_grad(1e-10).ok()?.with_tolerance_cost(1e-14).ok()?;
    let res = Executor::new(Energy { prob, last: Default::default() }, solver)
        .configure(|s| s.param(x0).max_iters(iterations))
        .timer(false)
        .run();
    let res = res.ok()?;
    let best = res.state.best_param?;
    best.iter().all(|v| v.is_finite()).then_some(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn gradient_matches_finite_differences() {
        let m = shapes::grid(3);
        let n = m.n_vertices();
        let fixed: Vec<Uv> =
            (0..n).map(|v| [(v % 4) as f64 * 0.3 + 0.01 * (v * v % 7) as f64, (v / 4) as f64 * 0.3]).collect();
        let mut tris = Vec::new();
        for f in 0..m.n_faces() {
            tris.push((m.face(FaceId::from_idx(f)).map(|v| v.0), [[1.1, 0.2], [-0.1, 0.9]], 0.3));
        }
        let prob = Problem { tris, var: (0..n as u32).collect(), fixed: &fixed, theta: 0.1, eps: 0.05 };
        let x: Vec<f64> = fixed.iter().flat_map(|p| [p[0] + 0.05 * p[1], p[1] - 0.2 * p[0]]).collect();
        let mut g = vec![0.0; x.len()];
        prob.eval(&x, Some(&mut g));
        for i in 0..x.len() {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[i] += 1e-6;
            b[i] -= 1e-6;
            let fd = (prob.eval(&a, None) - prob.eval(&b, None)) / 2e-6;
            assert!((fd - g[i]).abs() <= 1e-5 * (1.0 + fd.abs()), "{i}: {fd} vs {}", g[i]);
        }
    }

    #[test]
    fn a_folded_grid_is_untangled_with_its_boundary_kept() {
        // A planar grid (reference = its own triangles) with a block of interior vertices
        // mirrored across the grid's centre line: several layers deep of inverted faces.
        let m = shapes::grid(8);
        let n = m.n_vertices();
        let vs = |v: usize| crate::mesh::VertexId::from_idx(v);
        let mut uv: Vec<Uv> = (0..n).map(|v| [m.position(vs(v)).x, m.position(vs(v)).y]).collect();
        let held: Vec<bool> = (0..n).map(|v| m.is_boundary_vertex(vs(v))).collect();
        let orig = uv.clone();
        for (v, p) in uv.iter_mut().enumerate() {
            if !held[v] && p[0] < 0.55 {
                p[0] = 1.1 - p[0];
            }
        }
        let inverted = |uv: &[Uv]| {
            (0..m.n_faces())
                .filter(|&f| super::signed_area(m.face(FaceId::from_idx(f)).map(|v| uv[v.idx()])) <= 0.0)
                .count()
        };
        assert!(inverted(&uv) >= 10, "the test must start tangled: {}", inverted(&uv));
        let r = foldover_free(&m, &mut uv, &held, 1.0, &Default::default());
        assert!(r.valid, "{r:?}");
        assert_eq!(inverted(&uv), 0);
        for v in 0..n {
            if held[v] {
                assert_eq!(uv[v], orig[v]);
            }
        }
    }
}
