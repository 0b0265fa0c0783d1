//! The projected Newton Hessian of a 2D isotropic energy `f(J) = |J|² h(det J)` in closed form
//! (Smith, De Goes & Kim 2019, "Analytic Eigensystems for Isotropic Distortion Energies").
//!
//! With the signed singular value decomposition `J = U diag(σ₁, σ₂) Vᵀ` (`U`, `V` rotations), the
//! four matrices `U Y Vᵀ` for `Y` = `e₁e₁ᵀ`, `e₂e₂ᵀ`, the twist `[[0, −1], [1, 0]]/√2` and the
//! flip `[[0, 1], [1, 0]]/√2` are an orthonormal basis of `vec(J)`-space in which the Hessian is
//! block diagonal: the twist and the flip are eigenvectors with eigenvalues `2h ± |J|² h′`, and
//! the two scalings span a 2 × 2 block. Clamping those four eigenvalues at zero gives the
//! nearest positive semi-definite Hessian without an iterative eigensolver (which was a fifth of
//! a sphere pair map's time).

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

/// `h(D)` and its first two derivatives at `D = det J`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    pub h: f64,
    pub h1: f64,
    pub h2: f64,
}

/// The gradient of `f` and its Hessian projected to the nearest positive semi-definite matrix,
/// in `vec(J) = (J₀₀, J₀₁, J₁₀, J₁₁)`; `None` when not finite.
pub fn projected(v: &Vector4<f64>, p: Profile) -> Option<(Vector4<f64>, Matrix4<f64>)> {
    let s = v.norm_squared();
    let cof = Vector4::new(v[3], -v[2], -v[1], v[0]);
    let grad = v * (2.0 * p.h) + cof * (s * p.h1);
    let (u, sigma, w) = signed_svd(v);
    // vec(a bᵀ) for columns a of U and b of V.
    let outer = |a: Vector2<f64>, b: Vector2<f64>| Vector4::new(a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]);
    let (u1, u2) = (u.column(0).into_owned(), u.column(1).into_owned());
    let (w1, w2) = (w.column(0).into_owned(), w.column(1).into_owned());
    let d1 = outer(u1, w1);
    let d2 = outer(u2, w2);
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let twist = (outer(u2, w1) - outer(u1, w2)) * r;
    let flip = (outer(u2, w1) + outer(u1, w2)) * r;
    // The scaling block in (D₁, D₂): J = (σ₁, σ₂), cof J = (σ₂, σ₁).
    let (j, c) = (Vector2::new(sigma[0], sigma[1]), Vector2::new(sigma[1], sigma[0]));
    let block = Matrix2::identity() * (2.0 * p.h)
        + Matrix2::new(0.0, 1.0, 1.0, 0.0) * (s * p.h1)
        + c * c.transpose() * (s * p.h2)
        + (j * c.transpose() + c * j.transpose()) * (2.0 * p.h1);
    let mut hess = Matrix4::zeros();
    let mut add = |l: f64, q: &Vector4<f64>| {
        if l > 0.0 {
            hess += q * q.transpose() * l;
        }
    };
    add(2.0 * p.h + s * p.h1, &twist);
    add(2.0 * p.h - s * p.h1, &flip);
    let (l, e) = symmetric_2x2(&block);
    for k in 0..2 {
        add(l[k], &(d1 * e[(0, k)] + d2 * e[(1, k)]));
    }
    (grad.iter().chain(hess.iter()).all(|x| x.is_finite())).then_some((grad, hess))
}

/// `J = U diag(σ) Vᵀ` with `U`, `V` rotations and `σ₁ ≥ |σ₂|` (`σ₂ < 0` when `J` reflects).
fn signed_svd(v: &Vector4<f64>) -> (Matrix2<f64>, [f64; 2], Matrix2<f64>) {
    let (a, b, c, d) = (v[0], v[1], v[2], v[3]);
    // J = [[E + F, G − H], [G + H, E − F]]: a rotation by φ plus a reflection-like part.
    let (e, f, g, h) = (0.5 * (a + d), 0.5 * (a - d), 0.5 * (c + b), 0.5 * (c - b));
    let (q, r) = (e.hypot(h), f.hypot(g));
    let (a1, a2) = (g.atan2(f), h.atan2(e));
    let (theta, phi) = (0.5 * (a2 - a1), 0.5 * (a2 + a1));
    let rot = |t: f64| Matrix2::new(t.cos(), -t.sin(), t.sin(), t.cos());
    // J = R(φ) diag(q + r, q − r) R(θ) = U Σ Vᵀ with V = R(−θ).
    (rot(phi), [q + r, q - r], rot(-theta))
}

/// Eigenvalues and unit eigenvectors (columns) of a symmetric 2 × 2 matrix.
fn symmetric_2x2(m: &Matrix2<f64>) -> ([f64; 2], Matrix2<f64>) {
    let (a, b, d) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
    let mean = 0.5 * (a + d);
    let rad = (0.5 * (a - d)).hypot(b);
    // The eigenvector of the larger eigenvalue at angle t: tan 2t = 2b / (a − d).
    let t = 0.5 * (2.0 * b).atan2(a - d);
    let (cs, sn) = (t.cos(), t.sin());
    ([mean + rad, mean - rad], Matrix2::new(cs, -sn, sn, cs))
}
