//! A lifting wavelet on one patch's `(2^L + 1)²` remesh grid, for morphing in the wavelet
//! domain (Yu & Chuang, section 6.2). The paper uses Bertram et al.'s bicubic subdivision-surface
//! wavelet; we use the linear interpolating lifting wavelet (Sweldens' lifting scheme with the
//! CDF 5/3 predict and update steps) applied separably, because it has the same small support
//! and exact lifting inverse, and because it can be arranged so that shared patch sides are
//! transformed identically from either patch:
//! - at each scale every row, then every column is lifted (a tensor-product transform); the
//!   update step never changes a line's two end samples, which lie on the patch boundary;
//! - so a side (the first or last row or column) is changed only by its own 1D pass, which
//!   reads only its own samples; the 5/3 filters are symmetric, so the patch across the side,
//!   which walks it the other way and maybe as a row instead of a column, gets the same
//!   coefficients.
//!
//! Reconstruction of a shared side therefore depends on that side's coefficients alone, and the
//! patches of a remesh stay watertight whatever each level's blend. Each lifting step is undone
//! by the same arithmetic with the opposite sign, so a round trip reproduces the grid to rounding.

/// Samples along a line of the grid.
fn lift(x: &mut [[f64; 3]], idx: &[usize], forward: bool) {
    let m = idx.len();
    if m < 3 {
        return;
    }
    let predict = |x: &mut [[f64; 3]], sign: f64| {
        for k in (1..m - 1).step_by(2) {
            let (a, b) = (x[idx[k - 1]], x[idx[k + 1]]);
            for c in 0..3 {
                x[idx[k]][c] -= sign * 0.5 * (a[c] + b[c]);
            }
        }
    };
    let update = |x: &mut [[f64; 3]], sign: f64| {
        for k in (2..m - 1).step_by(2) {
            let (a, b) = (x[idx[k - 1]], x[idx[k + 1]]);
            for c in 0..3 {
                x[idx[k]][c] += sign * 0.25 * (a[c] + b[c]);
            }
        }
    };
    if forward {
        predict(x, 1.0);
        update(x, 1.0);
    } else {
        update(x, -1.0);
        predict(x, -1.0);
    }
}

/// The lines of one scale (`s` = grid step): every row, then every column, at that step.
fn lines(n: usize, s: usize) -> [Vec<Vec<usize>>; 2] {
    let w = n + 1;
    let steps: Vec<usize> = (0..=n).step_by(s).collect();
    let rows = steps.iter().map(|&j| steps.iter().map(|&i| j * w + i).collect()).collect();
    let cols = steps.iter().map(|&i| steps.iter().map(|&j| j * w + i).collect()).collect();
    [rows, cols]
}

/// In-place forward transform of a `(n + 1)²` grid (row-major, `n` a power of two).
pub fn forward(x: &mut [[f64; 3]], n: usize) {
    let mut s = 1;
    while s < n {
        for group in lines(n, s) {
            for l in group {
                lift(x, &l, true);
            }
        }
        s *= 2;
    }
}

/// In-place inverse of [`forward`].
pub fn inverse(x: &mut [[f64; 3]], n: usize) {
    let mut s = n / 2;
    while s >= 1 {
        let [rows, cols] = lines(n, s);
        for group in [cols, rows] {
            for l in group {
                lift(x, &l, false);
            }
        }
        s /= 2;
    }
}

/// Resolution level of coefficient `(i, j)`, 0 = coarsest (the corners) up to `log2 n` (the
/// finest details).
pub fn level(i: usize, j: usize, n: usize) -> u32 {
    let l = n.trailing_zeros();
    let tz = |k: usize| if k == 0 { l } else { k.trailing_zeros().min(l) };
    l - tz(i).min(tz(j))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, seed: f64) -> Vec<[f64; 3]> {
        (0..(n + 1) * (n + 1))
            .map(|k| [(k as f64 * seed).sin(), (k as f64 * 0.37).cos() * seed, k as f64 * 1e-3])
            .collect()
    }

    #[test]
    fn round_trip_reproduces_the_grid() {
        for n in [2, 4, 32, 64] {
            let x0 = grid(n, 1.3);
            let mut x = x0.clone();
            forward(&mut x, n);
            assert!(x.iter().zip(&x0).any(|(a, b)| a != b), "the transform changes something");
            inverse(&mut x, n);
            let err = x.iter().zip(&x0).flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs())).fold(0.0, f64::max);
            assert!(err < 1e-13, "n={n}: {err}");
        }
    }

    #[test]
    fn linear_data_has_zero_details_and_sides_transform_alone() {
        let n = 16;
        let mut x: Vec<[f64; 3]> =
            (0..(n + 1) * (n + 1)).map(|k| [(k % (n + 1)) as f64, (k / (n + 1)) as f64 * 2.0, 1.0]).collect();
        forward(&mut x, n);
        for j in 0..=n {
            for i in 0..=n {
                if level(i, j, n) > 0 && (i % n != 0 || j % n != 0) {
                    // Interior predictions of a linear function are exact.
                    let c = x[j * (n + 1) + i];
                    if i != 0 && j != 0 && i != n && j != n && (i % 2 == 1 || j % 2 == 1) {
                        assert!(c[0].abs() < 1e-12 && c[1].abs() < 1e-12, "({i},{j}) {c:?}");
                    }
                }
            }
        }
        // A side's coefficients depend on that side only.
        let mut a = grid(n, 0.7);
        let mut b = a.clone();
        for x in &mut b[(n + 1)..(n + 1) * n] {
            *x = [9.0, 9.0, 9.0];
        }
        forward(&mut a, n);
        forward(&mut b, n);
        for i in 0..=n {
            assert_eq!(a[i], b[i]);
        }
        // The same side as a reversed column of another patch gets the same coefficients.
        let mut c = grid(n, 0.3);
        for i in 0..=n {
            c[(n - i) * (n + 1)] = grid(n, 0.7)[i];
        }
        forward(&mut c, n);
        for i in 0..=n {
            assert_eq!(c[(n - i) * (n + 1)], a[i], "side sample {i}");
        }
        assert_eq!(level(0, 0, n), 0);
        assert_eq!(level(1, 0, n), 4);
        assert_eq!(level(8, 8, n), 1);
    }
}
