//! Per-face singular values of the affine map from each source triangle to its mapped
//! triangle, after scaling the mapped mesh to the source's total area; L2 stretch (Sander et
//! al. 2001), L-inf stretch and the angle distortion `sigma1/sigma2 + sigma2/sigma1 - 2`,
//! area-weighted, as `meshmetrics.py` defines them.

use crate::mesh::{FaceId, Mesh, P3};
use crate::tol;
use serde::Serialize;

/// Distortion of a map between two meshes with the same faces.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Distortion {
    pub l2_stretch: f64,
    pub linf_stretch: f64,
    pub angle_distortion: f64,
    pub degenerate_faces: usize,
}

/// Coordinates of e1 and e2 in the triangle's own frame: `[[e1.x, e2.x], [e1.y, e2.y]]`.
fn frame(p: [P3; 3], scale: f64) -> [[f64; 2]; 2] {
    let e1 = (p[1] - p[0]) * scale;
    let e2 = (p[2] - p[0]) * scale;
    let x = e1 / e1.norm().max(tol::TINY);
    let n = e1.cross(&e2);
    let n = n / n.norm().max(tol::TINY);
    let y = n.cross(&x);
    [[e1.dot(&x), e2.dot(&x)], [e1.dot(&y), e2.dot(&y)]]
}

/// Singular values (descending) of a 2x2 matrix, in closed form.
pub(crate) fn singular_values(m: [[f64; 2]; 2]) -> (f64, f64) {
    let (a, b, c, d) = (m[0][0], m[0][1], m[1][0], m[1][1]);
    let e = 0.5 * (a + d);
    let f = 0.5 * (a - d);
    let g = 0.5 * (c + b);
    let h = 0.5 * (c - b);
    let q = (e * e + h * h).sqrt();
    let r = (f * f + g * g).sqrt();
    (q + r, (q - r).abs())
}

/// Distortion of the map `source -> mapped` (same faces).
pub fn distortion(source: &Mesh, mapped: &Mesh) -> Distortion {
    let nf = source.n_faces();
    let a_s: Vec<f64> = (0..nf).map(|f| source.face_area(FaceId::from_idx(f))).collect();
    let a_m: Vec<f64> = (0..nf).map(|f| mapped.face_area(FaceId::from_idx(f))).collect();
    let scale = (a_s.iter().sum::<f64>() / a_m.iter().sum::<f64>().max(tol::TINY)).sqrt();
    let amax = a_s.iter().copied().fold(0.0, f64::max);
    let thr = tol::DEGENERATE_AREA_REL * amax;
    let mut wsum = 0.0;
    let (mut l2, mut linf, mut ang) = (0.0, 0.0f64, 0.0);
    let mut degenerate = 0;
    for f in 0..nf {
        if !(a_s[f] > thr && a_m[f] * scale * scale > thr) {
            degenerate += 1;
            continue;
        }
        let fid = FaceId::from_idx(f);
        let s = frame(source.face_points(fid), 1.0);
        let m = frame(mapped.face_points(fid), scale);
        // J = M S^-1, S upper triangular-ish 2x2.
        let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        let inv = [[s[1][1] / det, -s[0][1] / det], [-s[1][0] / det, s[0][0] / det]];
        let j = [
            [m[0][0] * inv[0][0] + m[0][1] * inv[1][0], m[0][0] * inv[0][1] + m[0][1] * inv[1][1]],
            [m[1][0] * inv[0][0] + m[1][1] * inv[1][0], m[1][0] * inv[0][1] + m[1][1] * inv[1][1]],
        ];
        let (s1, s2) = singular_values(j);
        let s2 = s2.max(tol::MIN_SINGULAR_VALUE);
        let w = a_s[f];
        wsum += w;
        l2 += w * (s1 * s1 + s2 * s2) / 2.0;
        ang += w * (s1 / s2 + s2 / s1);
        linf = linf.max(s1);
    }
    let wsum = wsum.max(tol::TINY);
    Distortion {
        l2_stretch: (l2 / wsum).sqrt(),
        linf_stretch: linf,
        angle_distortion: ang / wsum - 2.0,
        degenerate_faces: degenerate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_values_of_known_matrices() {
        let (a, b) = singular_values([[3.0, 0.0], [0.0, 2.0]]);
        assert!((a - 3.0).abs() < 1e-14 && (b - 2.0).abs() < 1e-14);
        let (a, b) = singular_values([[0.0, -1.0], [1.0, 0.0]]);
        assert!((a - 1.0).abs() < 1e-14 && (b - 1.0).abs() < 1e-14);
        // Reflection keeps singular values positive.
        let (a, b) = singular_values([[1.0, 0.0], [0.0, -2.0]]);
        assert!((a - 2.0).abs() < 1e-14 && (b - 1.0).abs() < 1e-14);
    }
}
