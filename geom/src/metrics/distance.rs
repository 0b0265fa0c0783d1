//! Symmetric sampled Hausdorff and RMS distances between two surfaces (Metro-style, as
//! `meshmetrics.py`): area-weighted uniform samples drawn with numpy's generator and seeds
//! (1 on the first surface, 2 on the second, by default), nearest points on the other surface
//! through a [`SurfaceIndex`].

use super::numpy_rng::NumpyRng;
use super::surface_index::{SurfaceIndex, morton_order};
use crate::error::Result;
use crate::mesh::{FaceId, Mesh, P3};

/// Sampled distances (absolute, not normalised).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HausdorffResult {
    /// max over both directions of the largest sample distance.
    pub hausdorff: f64,
    /// sqrt of the larger of the two mean squared distances.
    pub rms: f64,
}

/// `n` points uniformly distributed over the surface: `sample_surface(V, F, n, seed)` of the
/// evaluator, sample for sample.
pub fn sample_surface(mesh: &Mesh, n: usize, seed: u64) -> Vec<P3> {
    let areas: Vec<f64> = (0..mesh.n_faces()).map(|f| mesh.face_area(FaceId::from_idx(f))).collect();
    let mut rng = NumpyRng::new(seed);
    let faces = rng.choice_weighted(&areas, n);
    let r1: Vec<f64> = (0..n).map(|_| rng.random()).collect();
    let r2: Vec<f64> = (0..n).map(|_| rng.random()).collect();
    faces
        .iter()
        .zip(r1.iter().zip(&r2))
        .map(|(&f, (&a1, &a2))| {
            let s = a1.sqrt();
            let (u, v, w) = (1.0 - s, s * (1.0 - a2), s * a2);
            let [a, b, c] = mesh.face_points(FaceId::from_idx(f));
            P3::new(a.x * u + b.x * v + c.x * w, a.y * u + b.y * v + c.y * w, a.z * u + b.z * v + c.z * w)
        })
        .collect()
}

/// Symmetric sampled Hausdorff / RMS between `a` and `b` with `n` samples each side and the
/// two sampling seeds.
///
/// # Errors
/// `Error::Internal` if an index cannot be built.
pub fn hausdorff(a: &Mesh, b: &Mesh, n: usize, seeds: (u64, u64)) -> Result<HausdorffResult> {
    let ia = SurfaceIndex::new(a)?;
    let ib = SurfaceIndex::new(b)?;
    let n = n.max(1);
    let side = |pts: Vec<P3>, idx: &SurfaceIndex| {
        // Query in Morton order (neighbouring queries touch the same tree nodes and faces), but
        // keep each result at its sample's index so the sum is the evaluator's, bit for bit.
        let mut mx: f64 = 0.0;
        let d = idx.distances_in_order(&pts, &morton_order(&pts));
        let sq: Vec<f64> = d.iter().map(|d| d * d).collect();
        for &d in &d {
            mx = mx.max(d);
        }
        (mx, pairwise_sum(&sq) / pts.len() as f64)
    };
    let (ma, sa) = side(sample_surface(a, n, seeds.0), &ib);
    let (mb, sb) = side(sample_surface(b, n, seeds.1), &ia);
    Ok(HausdorffResult { hausdorff: ma.max(mb), rms: sa.max(sb).sqrt() })
}

/// numpy's pairwise summation (blocks of 128 summed with 8 accumulators), so means agree to
/// the last bit.
pub(crate) fn pairwise_sum(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 8 {
        let mut s = 0.0;
        for v in x {
            s += v;
        }
        s
    } else if n <= 128 {
        let mut r = [x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]];
        let mut i = 8;
        while i < n - (n % 8) {
            for k in 0..8 {
                r[k] += x[i + k];
            }
            i += 8;
        }
        let mut s = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        while i < n {
            s += x[i];
            i += 1;
        }
        s
    } else {
        let n2 = (n / 2) - (n / 2) % 8;
        pairwise_sum(&x[..n2]) + pairwise_sum(&x[n2..])
    }
}
