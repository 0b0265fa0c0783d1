//! The rotation of the sphere that best carries one set of anchor points onto another
//! (Kabsch 1976, by the SVD of the 3×3 correlation). A rotation keeps every spherical triangle
//! as it was, so it turns one bijective embedding into another and gives the pair map its start.

use crate::mesh::P3;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// The rotation `R` minimizing `Σ |R pᵢ − qᵢ|²` (the identity without anchors; for one anchor,
/// the shortest rotation taking it onto its partner).
pub fn fit_rotation(p: &[P3], q: &[P3]) -> Rotation3<f64> {
    match p.len().min(q.len()) {
        0 => Rotation3::identity(),
        1 => Rotation3::rotation_between(&p[0].coords, &q[0].coords).unwrap_or_else(|| {
            // Antipodal: a half-turn about any axis perpendicular to p.
            let axis = p[0].coords.cross(&Vector3::x()).try_normalize(1e-9).unwrap_or_else(Vector3::y);
            Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), std::f64::consts::PI)
        }),
        _ => {
            let h: Matrix3<f64> = p.iter().zip(q).map(|(a, b)| a.coords * b.coords.transpose()).sum();
            let svd = h.svd(true, true);
            let (Some(u), Some(vt)) = (svd.u, svd.v_t) else { return Rotation3::identity() };
            let v = vt.transpose();
            let d = (v * u.transpose()).determinant().signum();
            let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
            Rotation3::from_matrix_unchecked(r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_known_rotation_is_recovered_from_three_points_and_one_point_is_carried_exactly() {
        let r = Rotation3::from_euler_angles(0.3, -1.1, 2.0);
        let p = [P3::new(1.0, 0.0, 0.0), P3::new(0.0, 1.0, 0.0), P3::from(Vector3::new(0.0, 1.0, 1.0).normalize())];
        let q: Vec<P3> = p.iter().map(|x| r * x).collect();
        let fit = fit_rotation(&p, &q);
        assert!((fit.matrix() - r.matrix()).norm() < 1e-12);
        let one = fit_rotation(&p[..1], &q[..1]);
        assert!((one * p[0] - q[0]).norm() < 1e-12);
    }
}
