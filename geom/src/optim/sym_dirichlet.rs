//! The symmetric Dirichlet energy of one triangle of a 2D map, `A (|J|² + |J⁻¹|²)` with `A`
//! the rest area and `J` the map's Jacobian, with its gradient and a positive semi-definite
//! projection of its Hessian (per-element eigenvalues clamped at zero, as projected Newton
//! methods do: Teran et al. 2005; Rabinovich et al. 2017 use the same energy).
//!
//! In 2D `|J⁻¹|² = |J|² / det(J)²`, so the energy is `A s (1 + 1/D²)` with `s = |J|²` and
//! `D = det J`; it grows without bound as a triangle degenerates, which is what keeps an
//! optimization that starts injective away from inversions (with [`super::max_step`]).
//!
//! Two generalizations serve maps between surfaces through a common domain: a *metric factor*
//! `L` (the image's metric `LᵀL`, e.g. the target surface's pulled back into the domain, frozen
//! for a step) measures `L J` instead of `J`; and each corner's unknowns may live in a chart of
//! their own, carried into the triangle's chart by a linear map `M_i` (a rigid transition).

use super::isotropic::{Profile, projected};
use crate::param::Uv;
use nalgebra::{Matrix4, SMatrix, Vector4};

/// A triangle's rest shape: the inverse of its rest edge matrix and its rest area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestTriangle {
    inv: [[f64; 2]; 2],
    area: f64,
}

/// Energy, gradient in the six image coordinates (`x0, y0, x1, y1, x2, y2`) and projected Hessian.
pub type Derivatives = (f64, [f64; 6], [[f64; 6]; 6]);

/// A 2×2 matrix, row-major.
pub type Mat2 = [[f64; 2]; 2];

/// The identity.
pub const IDENTITY: Mat2 = [[1.0, 0.0], [0.0, 1.0]];

impl RestTriangle {
    /// From rest positions in the plane (counter-clockwise); `None` for a degenerate triangle.
    pub fn new(p: [Uv; 3]) -> Option<RestTriangle> {
        let (e1, e2) = ([p[1][0] - p[0][0], p[1][1] - p[0][1]], [p[2][0] - p[0][0], p[2][1] - p[0][1]]);
        let det = e1[0] * e2[1] - e2[0] * e1[1];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        // Edge matrix [e1 e2] (columns) and its inverse.
        let inv = [[e2[1] / det, -e2[0] / det], [-e1[1] / det, e1[0] / det]];
        Some(RestTriangle { inv, area: 0.5 * det.abs() })
    }

    /// From a 3D triangle, laid out in its own plane (first edge along x).
    pub fn from_3d(p: [crate::mesh::P3; 3]) -> Option<RestTriangle> {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let l1 = e1.norm();
        if l1.is_nan() || l1 <= 0.0 {
            return None;
        }
        let x = e2.dot(&e1) / l1;
        let y = e1.cross(&e2).norm() / l1;
        RestTriangle::new([[0.0, 0.0], [l1, 0.0], [x, y]])
    }

    pub fn area(&self) -> f64 {
        self.area
    }

    /// `vec(J) = B x` with `vec(J) = (J00, J01, J10, J11)`.
    fn b(&self) -> SMatrix<f64, 4, 6> {
        let mut b = SMatrix::<f64, 4, 6>::zeros();
        for r in 0..2 {
            for c in 0..2 {
                b[(2 * r + c, r)] = -(self.inv[0][c] + self.inv[1][c]);
                b[(2 * r + c, 2 + r)] = self.inv[0][c];
                b[(2 * r + c, 4 + r)] = self.inv[1][c];
            }
        }
        b
    }

    /// `vec(L J) = B' d` for corner displacements `d` in their own charts (`dx_i = M_i d_i`).
    fn b_general(&self, l: &Mat2, m: &[Mat2; 3]) -> SMatrix<f64, 4, 6> {
        let b = self.b();
        let mut lb = SMatrix::<f64, 4, 6>::zeros();
        for r in 0..2 {
            for c in 0..2 {
                for k in 0..2 {
                    for j in 0..6 {
                        lb[(2 * r + c, j)] += l[r][k] * b[(2 * k + c, j)];
                    }
                }
            }
        }
        let mut blocks = SMatrix::<f64, 6, 6>::zeros();
        for (i, mi) in m.iter().enumerate() {
            for r in 0..2 {
                for c in 0..2 {
                    blocks[(2 * i + r, 2 * i + c)] = mi[r][c];
                }
            }
        }
        lb * blocks
    }

    /// `vec(L J)` at image corners `x`.
    fn jacobian_in(&self, x: [Uv; 3], l: &Mat2) -> Vector4<f64> {
        let ds = [[x[1][0] - x[0][0], x[2][0] - x[0][0]], [x[1][1] - x[0][1], x[2][1] - x[0][1]]];
        let j = |r: usize, c: usize| ds[r][0] * self.inv[0][c] + ds[r][1] * self.inv[1][c];
        let lj = |r: usize, c: usize| l[r][0] * j(0, c) + l[r][1] * j(1, c);
        Vector4::new(lj(0, 0), lj(0, 1), lj(1, 0), lj(1, 1))
    }

    /// `det J` at image corners `x` (negative when the image is inverted).
    pub fn jacobian_det(&self, x: [Uv; 3]) -> f64 {
        let v = self.jacobian_in(x, &IDENTITY);
        v[0] * v[3] - v[1] * v[2]
    }

    /// The energy at image positions `x`; `None` when the image is degenerate or inverted.
    pub fn energy(&self, x: [Uv; 3]) -> Option<f64> {
        self.energy_in(x, &IDENTITY)
    }

    /// The energy of `L J` at image corners `x` (all in one chart); `None` when degenerate or
    /// inverted (a metric factor must have a positive determinant).
    pub fn energy_in(&self, x: [Uv; 3], l: &Mat2) -> Option<f64> {
        let v = self.jacobian_in(x, l);
        let d = v[0] * v[3] - v[1] * v[2];
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let e = self.area * v.norm_squared() * (1.0 + 1.0 / (d * d));
        e.is_finite().then_some(e)
    }

    /// The untangling energy of Garanzha et al. 2021: `det J` replaced by the always positive
    /// `χ(D, ε) = (D + √(ε² + D²)) / 2`, finite on inverted triangles and equal to the energy
    /// above as `ε → 0` where `D > 0`.
    pub fn energy_eps(&self, x: [Uv; 3], l: &Mat2, eps: f64) -> Option<f64> {
        let v = self.jacobian_in(x, l);
        let d = v[0] * v[3] - v[1] * v[2];
        let chi = 0.5 * (d + (eps * eps + d * d).sqrt());
        let e = self.area * v.norm_squared() * (1.0 + 1.0 / (chi * chi));
        e.is_finite().then_some(e)
    }

    /// [`RestTriangle::derivatives_in`] of [`RestTriangle::energy_eps`].
    pub fn derivatives_eps(&self, x: [Uv; 3], l: &Mat2, m: &[Mat2; 3], eps: f64) -> Option<Derivatives> {
        let v = self.jacobian_in(x, l);
        let (g, h) = jacobian_derivatives_eps(&v, eps)?;
        let e = self.energy_eps(x, l, eps)?;
        Some(self.carried_to_corners(e, g, h, l, m))
    }

    /// Energy, gradient and PSD-projected Hessian at `x`; `None` when inverted or degenerate.
    pub fn derivatives(&self, x: [Uv; 3]) -> Option<Derivatives> {
        self.derivatives_in(x, &IDENTITY, &[IDENTITY; 3])
    }

    /// [`RestTriangle::derivatives`] of `L J`, with respect to each corner's displacement in
    /// its own chart (`m[i]` carries it into the chart of `x`).
    pub fn derivatives_in(&self, x: [Uv; 3], l: &Mat2, m: &[Mat2; 3]) -> Option<Derivatives> {
        let v = self.jacobian_in(x, l);
        let (g, h) = jacobian_derivatives(&v)?;
        let e = self.energy_in(x, l)?;
        Some(self.carried_to_corners(e, g, h, l, m))
    }

    /// Energy and derivatives in `vec(L J)` carried to the corners' displacements.
    fn carried_to_corners(&self, e: f64, g: Vector4<f64>, h: Matrix4<f64>, l: &Mat2, m: &[Mat2; 3]) -> Derivatives {
        let b = self.b_general(l, m);
        let gx = b.transpose() * g * self.area;
        let hx = b.transpose() * h * b * self.area;
        let mut grad = [0.0; 6];
        let mut hess = [[0.0; 6]; 6];
        for i in 0..6 {
            grad[i] = gx[i];
            for j in 0..6 {
                hess[i][j] = hx[(i, j)];
            }
        }
        (e, grad, hess)
    }
}

/// Gradient and projected Hessian of `f(J) = |J|² (1 + 1/det(J)²)` in `vec(J) = (a, b, c, d)`.
fn jacobian_derivatives(v: &Vector4<f64>) -> Option<(Vector4<f64>, Matrix4<f64>)> {
    let det = v[0] * v[3] - v[1] * v[2];
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    projected(v, Profile { h: 1.0 + det.powi(-2), h1: -2.0 * det.powi(-3), h2: 6.0 * det.powi(-4) })
}

/// Gradient and projected Hessian of `|J|² (1 + 1/χ(det J, ε)²)` in `vec(J)`.
fn jacobian_derivatives_eps(v: &Vector4<f64>, eps: f64) -> Option<(Vector4<f64>, Matrix4<f64>)> {
    let det = v[0] * v[3] - v[1] * v[2];
    let r = (eps * eps + det * det).sqrt();
    if r <= 0.0 {
        return None;
    }
    let chi = 0.5 * (det + r);
    let (c1, c2) = (0.5 * (1.0 + det / r), 0.5 * eps * eps / (r * r * r));
    // h(D) = 1 + χ⁻², and its first two derivatives in D.
    projected(
        v,
        Profile {
            h: 1.0 + chi.powi(-2),
            h1: -2.0 * chi.powi(-3) * c1,
            h2: 6.0 * chi.powi(-4) * c1 * c1 - 2.0 * chi.powi(-3) * c2,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SymmetricEigen;

    fn rest() -> RestTriangle {
        RestTriangle::new([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]]).unwrap()
    }

    #[test]
    fn the_identity_has_the_minimum_four_times_the_area() {
        let r = rest();
        let x = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]];
        let (e, g, _) = r.derivatives(x).unwrap();
        assert!((e - 4.0 * r.area()).abs() < 1e-12, "{e}");
        assert!(g.iter().all(|v| v.abs() < 1e-12), "{g:?}");
        // A rotation and translation leave it unchanged.
        let (c, s) = (0.6f64, 0.8f64);
        let y = x.map(|p| [c * p[0] - s * p[1] + 2.0, s * p[0] + c * p[1] - 1.0]);
        assert!((r.energy(y).unwrap() - e).abs() < 1e-12);
        // An inverted image has no energy.
        assert!(r.energy([[0.0, 0.0], [0.3, 0.8], [1.0, 0.0]]).is_none());
    }

    /// Gradient and Hessian against central differences where the Hessian needs no projection.
    #[test]
    fn derivatives_match_finite_differences() {
        let r = rest();
        let x = [[0.1, -0.05], [1.3, 0.2], [0.2, 1.1]];
        let flat = |x: [Uv; 3]| [x[0][0], x[0][1], x[1][0], x[1][1], x[2][0], x[2][1]];
        let unflat = |f: [f64; 6]| [[f[0], f[1]], [f[2], f[3]], [f[4], f[5]]];
        let (_, g, _) = r.derivatives(x).unwrap();
        let (_, hj) = jacobian_derivatives(&r.jacobian_in(x, &IDENTITY)).unwrap();
        let hx = r.b().transpose() * hj * r.b() * r.area();
        let h = 1e-6;
        for i in 0..6 {
            let mut p = flat(x);
            let mut m = flat(x);
            p[i] += h;
            m[i] -= h;
            let fd = (r.energy(unflat(p)).unwrap() - r.energy(unflat(m)).unwrap()) / (2.0 * h);
            assert!((fd - g[i]).abs() < 1e-6 * (1.0 + g[i].abs()), "gradient {i}: {fd} vs {}", g[i]);
            let (_, gp, _) = r.derivatives(unflat(p)).unwrap();
            let (_, gm, _) = r.derivatives(unflat(m)).unwrap();
            for j in 0..6 {
                let fd = (gp[j] - gm[j]) / (2.0 * h);
                assert!((fd - hx[(j, i)]).abs() < 1e-5 * (1.0 + fd.abs()), "hessian {j},{i}: {fd} vs {}", hx[(j, i)]);
            }
        }
    }

    /// With a metric factor and rotated corner charts, the derivatives are those of the energy
    /// of `L J` as a function of the corners' own-chart displacements.
    #[test]
    fn metric_and_chart_derivatives_match_finite_differences() {
        let r = rest();
        let x = [[0.1, -0.05], [1.3, 0.2], [0.2, 1.1]];
        let l = [[1.3, 0.2], [0.0, 0.7]];
        let rot = |a: f64| [[a.cos(), -a.sin()], [a.sin(), a.cos()]];
        let m = [IDENTITY, rot(0.4), rot(-1.1)];
        let moved = |d: [f64; 6]| {
            let mut y = x;
            for i in 0..3 {
                y[i][0] += m[i][0][0] * d[2 * i] + m[i][0][1] * d[2 * i + 1];
                y[i][1] += m[i][1][0] * d[2 * i] + m[i][1][1] * d[2 * i + 1];
            }
            r.energy_in(y, &l).unwrap()
        };
        let (e, g, _) = r.derivatives_in(x, &l, &m).unwrap();
        assert!((e - moved([0.0; 6])).abs() < 1e-12);
        let h = 1e-6;
        for i in 0..6 {
            let (mut p, mut q) = ([0.0; 6], [0.0; 6]);
            p[i] = h;
            q[i] = -h;
            let fd = (moved(p) - moved(q)) / (2.0 * h);
            assert!((fd - g[i]).abs() < 1e-6 * (1.0 + g[i].abs()), "gradient {i}: {fd} vs {}", g[i]);
        }
    }

    /// The untangling energy's gradient against central differences, on an inverted image.
    #[test]
    fn untangling_derivatives_match_finite_differences() {
        let r = rest();
        let x = [[0.0, 0.0], [0.3, 0.8], [1.0, 0.1]];
        let eps = 0.3;
        let (_, g, _) = r.derivatives_eps(x, &IDENTITY, &[IDENTITY; 3], eps).unwrap();
        let h = 1e-6;
        for i in 0..6 {
            let (mut p, mut q) = (x, x);
            p[i / 2][i % 2] += h;
            q[i / 2][i % 2] -= h;
            let fd = (r.energy_eps(p, &IDENTITY, eps).unwrap() - r.energy_eps(q, &IDENTITY, eps).unwrap()) / (2.0 * h);
            assert!((fd - g[i]).abs() < 1e-5 * (1.0 + g[i].abs()), "gradient {i}: {fd} vs {}", g[i]);
        }
        // Far from zero the two energies agree.
        let y = [[0.1, -0.05], [1.3, 0.2], [0.2, 1.1]];
        assert!((r.energy_eps(y, &IDENTITY, 1e-9).unwrap() - r.energy(y).unwrap()).abs() < 1e-9);
    }

    #[test]
    fn the_projected_hessian_is_positive_semidefinite() {
        let r = rest();
        // A strongly sheared, nearly collapsed image: the raw Hessian is indefinite there.
        let x = [[0.0, 0.0], [1.0, 0.0], [5.0, 0.05]];
        let (_, _, h) = r.derivatives(x).unwrap();
        let m = SMatrix::<f64, 6, 6>::from_fn(|i, j| h[i][j]);
        let min = SymmetricEigen::new(m).eigenvalues.min();
        assert!(min > -1e-9 * m.norm(), "smallest eigenvalue {min}");
    }
}
