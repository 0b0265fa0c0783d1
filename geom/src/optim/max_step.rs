//! The flip-avoiding step bound of Smith & Schaefer 2015 (as SLIM uses it): moving a triangle's
//! corners along `d` by `t`, its doubled signed area is a quadratic in `t`; the smallest positive
//! root over all triangles is the first time any of them inverts, and a step is never longer.

use crate::param::Uv;

/// The first `t > 0` at which the triangle `x + t d` degenerates (`f64::INFINITY` if never).
pub fn first_inversion(x: [Uv; 3], d: [Uv; 3]) -> f64 {
    let e1 = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
    let e2 = [x[2][0] - x[0][0], x[2][1] - x[0][1]];
    let f1 = [d[1][0] - d[0][0], d[1][1] - d[0][1]];
    let f2 = [d[2][0] - d[0][0], d[2][1] - d[0][1]];
    let cross = |u: [f64; 2], v: [f64; 2]| u[0] * v[1] - u[1] * v[0];
    // det(t) = a t² + b t + c.
    let (a, b, c) = (cross(f1, f2), cross(e1, f2) + cross(f1, e2), cross(e1, e2));
    smallest_positive_root(a, b, c)
}

/// The smallest positive root of `a t² + b t + c` (`f64::INFINITY` if none), by the
/// cancellation-free formula.
fn smallest_positive_root(a: f64, b: f64, c: f64) -> f64 {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 {
        return f64::INFINITY;
    }
    if a.abs() <= 1e-14 * scale {
        // Linear: b t + c = 0.
        let t = -c / b;
        return if b != 0.0 && t > 0.0 { t } else { f64::INFINITY };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return f64::INFINITY;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let roots = [q / a, if q != 0.0 { c / q } else { f64::INFINITY }];
    roots.into_iter().filter(|&t| t > 0.0).fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_moving_across_the_opposite_edge_inverts_when_it_reaches_it() {
        let x = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // Corner 2 moves straight down: it reaches the edge 0-1 at t = 1.
        let t = first_inversion(x, [[0.0, 0.0], [0.0, 0.0], [0.0, -1.0]]);
        assert!((t - 1.0).abs() < 1e-15, "{t}");
        // Moving away never inverts; a translation never does.
        assert_eq!(first_inversion(x, [[0.0, 0.0], [0.0, 0.0], [0.0, 1.0]]), f64::INFINITY);
        assert_eq!(first_inversion(x, [[1.0, 2.0]; 3]), f64::INFINITY);
        // Two corners swapping through each other: quadratic, first root before the swap.
        let t = first_inversion(x, [[0.0, 0.0], [-1.0, 1.0], [1.0, -1.0]]);
        assert!((t - 0.5).abs() < 1e-12, "{t}");
    }
}
