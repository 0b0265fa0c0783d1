//! The flip-avoiding step bound on the sphere: the sphere's analogue of Smith & Schaefer 2015.
//!
//! A vertex moved by a tangent step `t d` lands at `normalize(p + t d)`. Normalizing scales a
//! point by a positive factor, which does not change the sign of `det(a, b, c)`, so a triangle
//! inverts on the path exactly when `f(t) = det(a + t da, b + t db, c + t dc)` reaches zero: a
//! cubic in `t`. Its smallest positive root over all triangles is the longest step that keeps
//! every triangle positive along the whole path, so the covering's degree cannot change on it.

use crate::mesh::{P3, V3};

/// The first `t` in `(0, t_max]` at which `det(a + t da, b + t db, c + t dc)` reaches zero,
/// `f64::INFINITY` if it stays positive on that interval. The triangle must start positive.
pub fn first_inversion(p: [&P3; 3], d: [&V3; 3], t_max: f64) -> f64 {
    let [a, b, c] = p.map(|q| q.coords);
    let [da, db, dc] = d;
    let det = |x: &V3, y: &V3, z: &V3| x.dot(&y.cross(z));
    let c0 = det(&a, &b, &c);
    let c1 = det(da, &b, &c) + det(&a, db, &c) + det(&a, &b, dc);
    let c2 = det(da, db, &c) + det(da, &b, dc) + det(&a, db, dc);
    let c3 = det(da, db, dc);
    first_root([c0, c1, c2, c3], t_max)
}

/// The first root in `(0, t_max]` of `c0 + c1 t + c2 t² + c3 t³` with `c0 > 0`: the interval is
/// split at the critical points (where the cubic is monotone between them), and the first piece
/// whose end is not positive is bisected.
fn first_root(c: [f64; 4], t_max: f64) -> f64 {
    let f = |t: f64| c[0] + t * (c[1] + t * (c[2] + t * c[3]));
    if c[0] <= 0.0 {
        return 0.0;
    }
    // Critical points: 3 c3 t² + 2 c2 t + c1 = 0.
    let mut breaks: Vec<f64> =
        quadratic_roots(3.0 * c[3], 2.0 * c[2], c[1]).into_iter().flatten().filter(|&t| t > 0.0 && t < t_max).collect();
    breaks.sort_by(f64::total_cmp);
    breaks.push(t_max);
    let mut lo = 0.0;
    for hi in breaks {
        if f(hi) <= 0.0 {
            let (mut l, mut h) = (lo, hi);
            for _ in 0..60 {
                let m = 0.5 * (l + h);
                if f(m) > 0.0 {
                    l = m;
                } else {
                    h = m;
                }
            }
            // The last point known positive: stepping there never inverts.
            return l;
        }
        lo = hi;
    }
    f64::INFINITY
}

/// The real roots of `a t² + b t + c` (cancellation-free), `None` where absent.
fn quadratic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 {
        return [None, None];
    }
    if a.abs() <= 1e-14 * scale {
        return [(b != 0.0).then(|| -c / b), None];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    [Some(q / a), (q != 0.0).then(|| c / q)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_pushed_across_the_opposite_side_stops_before_it() {
        let p = [P3::new(1.0, 0.0, 0.0), P3::new(0.0, 1.0, 0.0), P3::new(0.0, 0.0, 1.0)];
        let zero = V3::zeros();
        // The top corner moves straight down: it reaches the great circle through the other
        // two (the equator) at t = 1.
        let down = V3::new(0.0, 0.0, -1.0);
        let t = first_inversion([&p[0], &p[1], &p[2]], [&zero, &zero, &down], 10.0);
        assert!((t - 1.0).abs() < 1e-12, "{t}");
        // Not within the interval asked about.
        assert_eq!(first_inversion([&p[0], &p[1], &p[2]], [&zero, &zero, &down], 0.5), f64::INFINITY);
        // Moving away, or all corners rotating together, never inverts.
        let up = V3::new(0.0, 0.0, 1.0);
        assert_eq!(first_inversion([&p[0], &p[1], &p[2]], [&zero, &zero, &up], 10.0), f64::INFINITY);
        let spin = |q: &P3| V3::new(-q.y, q.x, 0.0);
        let d = [spin(&p[0]), spin(&p[1]), spin(&p[2])];
        assert_eq!(first_inversion([&p[0], &p[1], &p[2]], [&d[0], &d[1], &d[2]], 10.0), f64::INFINITY);
    }

    #[test]
    fn the_bound_is_the_first_of_several_roots() {
        // (t - 0.5)(t - 1)(t - 2) scaled to start positive: -(t³ - 3.5 t² + 3.5 t - 1).
        let t = first_root([1.0, -3.5, 3.5, -1.0], 10.0);
        assert!((t - 0.5).abs() < 1e-12, "{t}");
        // A double root touching zero (t - 1)² ≥ 0 from above: caught at the touch.
        let t = first_root([1.0, -2.0, 1.0, 0.0], 10.0);
        assert!((t - 1.0).abs() < 1e-6, "{t}");
    }
}
