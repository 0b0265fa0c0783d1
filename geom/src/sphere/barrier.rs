//! The orientation barrier of a spherical triangle whose chord is not small.
//!
//! The symmetric Dirichlet energy of a chord triangle grows without bound as the chord
//! degenerates, which guards small triangles. A large spherical triangle can also invert with
//! a healthy chord: when its three corners come onto one great circle the chord's plane passes
//! through the centre, `det(a, b, c) = 0`, while the chord keeps its area. So each triangle also
//! pays for `ρ = det(a, b, c) / |(b − a) × (c − a)|`, the distance from the centre to the chord's
//! plane (1 − O(h²) for a small triangle, 0 when degenerate on the sphere):
//! `A (ρ₀/ρ − 1)²` below `ρ₀` and nothing above, so it leaves every ordinary triangle alone
//! (a triangle reaches `ρ₀ = 1/2` only when its circumcircle is 60° wide) and is infinite at
//! inversion. Its Hessian is taken in Gauss–Newton form (`b''(ρ) ∇ρ ∇ρᵀ`, positive semi-definite).

use crate::mesh::{P3, V3};

/// Where the barrier starts.
pub const RHO0: f64 = 0.5;

/// The barrier with weight `w`: its value, its gradient `g` in the three corners, and the
/// factor `k` of its Gauss–Newton Hessian `k g gᵀ`; all zero above `ρ₀`. `None` when the
/// triangle is inverted or degenerate on the sphere.
pub fn barrier(w: f64, p: [&P3; 3]) -> Option<(f64, [V3; 3], f64)> {
    let [a, b, c] = p.map(|q| q.coords);
    let n = (b - a).cross(&(c - a));
    let nn = n.norm();
    // det(a, b, c) = a · n, precise on tiny triangles (unlike a · (b × c)).
    let rho = a.dot(&n) / nn;
    if rho.is_nan() || rho <= 0.0 || nn <= 0.0 {
        return None;
    }
    if rho >= RHO0 {
        return Some((0.0, [V3::zeros(); 3], 0.0));
    }
    let nh = n / nn;
    let ddet = [b.cross(&c), c.cross(&a), a.cross(&b)];
    let dnorm = [nh.cross(&(c - b)), nh.cross(&(a - c)), nh.cross(&(b - a))];
    let grad_rho: [V3; 3] = std::array::from_fn(|i| (ddet[i] - dnorm[i] * rho) / nn);
    let q = RHO0 / rho - 1.0;
    let value = w * q * q;
    let d1 = -2.0 * w * q * RHO0 / (rho * rho);
    let d2 = w * (2.0 * RHO0 * RHO0 / rho.powi(4) + 4.0 * q * RHO0 / rho.powi(3));
    Some((value, grad_rho.map(|g| g * d1), d2 / (d1 * d1).max(f64::MIN_POSITIVE)))
}

/// The shrink barrier of a spherical triangle against its reference `det0`: with
/// `x = det(a, b, c) / det0`, `w (x − 1 − log x)` below `x = 1` and nothing above (the
/// `−log det` barrier of Schmidt, Pieper & Kobbelt 2023, made zero where a triangle has not
/// shrunk). It keeps a map that moves on the sphere from squashing some triangles to let
/// others through, whatever the images do. Returns the value, the gradient in the three
/// corners, and the factor `k` of its Gauss–Newton Hessian `k g gᵀ`; `None` when inverted.
pub fn shrink_barrier(w: f64, det0: f64, p: [&P3; 3]) -> Option<(f64, [V3; 3], f64)> {
    let [a, b, c] = p.map(|q| q.coords);
    let det = a.dot(&(b - a).cross(&(c - a)));
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let x = det / det0;
    if x >= 1.0 {
        return Some((0.0, [V3::zeros(); 3], 0.0));
    }
    let value = w * (x - 1.0 - x.ln());
    // d/dx = w (1 − 1/x) < 0; d²/dx² = w / x².
    let d1 = w * (1.0 - 1.0 / x) / det0;
    let d2 = w / (x * x * det0 * det0);
    let grad = [b.cross(&c), c.cross(&a), a.cross(&b)].map(|g| g * d1);
    Some((value, grad, d2 / (d1 * d1).max(f64::MIN_POSITIVE)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of `f` at `p` match the gradient `g`.
    fn agrees_with_differences(f: &dyn Fn([&P3; 3]) -> f64, p: [P3; 3], g: &[V3; 3]) {
        let h = 1e-7;
        for (i, gi) in g.iter().enumerate() {
            for (k, &gik) in gi.iter().enumerate() {
                let mut q = p;
                q[i].coords[k] += h;
                let ep = f([&q[0], &q[1], &q[2]]);
                q[i].coords[k] -= 2.0 * h;
                let em = f([&q[0], &q[1], &q[2]]);
                let fd = (ep - em) / (2.0 * h);
                assert!((fd - gik).abs() <= 1e-4 * (1.0 + fd.abs()), "corner {i} axis {k}: {fd} vs {gik}");
            }
        }
    }

    #[test]
    fn zero_on_small_triangles_infinite_toward_a_great_circle_and_its_gradient_is_right() {
        let small = [
            P3::new(0.0, 0.0, 1.0),
            P3::from(V3::new(0.1, 0.0, 1.0).normalize()),
            P3::from(V3::new(0.0, 0.1, 1.0).normalize()),
        ];
        assert_eq!(barrier(1.0, [&small[0], &small[1], &small[2]]).unwrap().0, 0.0);
        // Corners near one great circle (the equator), the middle one slightly south.
        let p = [P3::new(1.0, 0.0, 0.0), P3::from(V3::new(0.0, 1.0, -0.05).normalize()), P3::new(-1.0, 0.01, 0.0)];
        let (e, g, _) = barrier(1.0, [&p[0], &p[1], &p[2]]).unwrap();
        assert!(e > 10.0, "{e}");
        agrees_with_differences(&|q| barrier(1.0, q).unwrap().0, p, &g);
        // Inverted: refused.
        assert!(barrier(1.0, [&p[0], &p[2], &p[1]]).is_none());
    }

    #[test]
    fn the_shrink_barrier_is_zero_until_a_triangle_shrinks_and_its_gradient_is_right() {
        let p = [
            P3::new(0.0, 0.0, 1.0),
            P3::from(V3::new(0.2, 0.0, 1.0).normalize()),
            P3::from(V3::new(0.0, 0.2, 1.0).normalize()),
        ];
        let d = p[0].coords.dot(&(p[1] - p[0]).cross(&(p[2] - p[0])));
        assert_eq!(shrink_barrier(1.0, d, [&p[0], &p[1], &p[2]]).unwrap().0, 0.0);
        // Against a reference three times its size it pays, and more as it shrinks further.
        let (e, g, _) = shrink_barrier(1.0, 3.0 * d, [&p[0], &p[1], &p[2]]).unwrap();
        assert!(e > 0.0);
        agrees_with_differences(&|q| shrink_barrier(1.0, 3.0 * d, q).unwrap().0, p, &g);
        assert!(shrink_barrier(1.0, d, [&p[0], &p[2], &p[1]]).is_none());
    }
}
