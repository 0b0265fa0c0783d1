//! Brent's one-dimensional minimization: golden-section steps safeguarding parabolic
//! interpolation (Brent 1973; the "bracketed parabolic minimization" of Yu & Chuang 3.3.2).
//! Seventy lines do not justify a numerical-optimization dependency.

/// Minimizes `f` on `[a, b]` starting from `x0` inside it; returns `(x, f(x))`.
pub fn minimize(f: impl Fn(f64) -> f64, a: f64, x0: f64, b: f64, tol: f64, max_iter: usize) -> (f64, f64) {
    const CGOLD: f64 = 0.381_966_011_250_105_1;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let (mut x, mut w, mut v) = (x0, x0, x0);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..max_iter {
        let xm = 0.5 * (a + b);
        let tol1 = tol + 1e-12 * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let etemp = e;
            e = d;
            if p.abs() < (0.5 * q * etemp).abs() && p > q * (a - x) && p < q * (b - x) && q != 0.0 {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(xm - x);
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 { x + d } else { x + tol1.copysign(d) };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

#[cfg(test)]
mod tests {
    #[test]
    fn finds_the_minimum_of_a_parabola_and_of_a_barrier() {
        let (x, fx) = super::minimize(|t| (t - 0.3).powi(2) + 1.0, -1.0, 0.0, 1.0, 1e-9, 100);
        assert!((x - 0.3).abs() < 1e-6 && (fx - 1.0).abs() < 1e-10);
        // A barrier that is infinite outside (0, 1), like a folding triangle.
        let f = |t: f64| if t <= 0.0 || t >= 1.0 { f64::INFINITY } else { 1.0 / t + 1.0 / (1.0 - t) };
        let (x, _) = super::minimize(f, 0.0, 0.2, 1.0, 1e-9, 100);
        assert!((x - 0.5).abs() < 1e-5);
    }
}
