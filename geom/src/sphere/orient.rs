//! Orientation of triangles on the unit sphere, exact, and the check that a vertex placement is
//! a bijective spherical triangulation.
//!
//! A triangle `(a, b, c)` of points on the sphere is positively oriented when it turns
//! counter-clockwise seen from outside, i.e. `det(a, b, c) > 0`: the origin lies below the plane
//! of the chord triangle. Shewchuk's adaptive `orient3d` (the `robust` crate) decides the sign
//! exactly for the floating-point inputs.
//!
//! A placement with every triangle positive is a branched covering of the sphere; its degree is
//! the total spherical area over 4π. Degree 1 leaves no branch point, so the placement is a
//! homeomorphism (a covering of the sphere by the sphere is one-sheeted). [`check`] tests both.

use crate::mesh::P3;
use rayon::prelude::*;

/// `det(a, b, c)` by the exact predicate: its sign is exact, its magnitude approximate.
#[inline]
pub fn orient(a: &P3, b: &P3, c: &P3) -> f64 {
    let k = |p: &P3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    robust::orient3d(k(a), k(b), k(c), robust::Coord3D { x: 0.0, y: 0.0, z: 0.0 })
}

/// `det(a, b, c)` in plain floating point as `a · ((b − a) × (c − a))`, which keeps its
/// relative precision on tiny triangles (fast; its sign may still be wrong within rounding).
#[inline]
pub fn det(a: &P3, b: &P3, c: &P3) -> f64 {
    a.coords.dot(&(b - a).cross(&(c - a)))
}

/// The signed area of the spherical triangle `(a, b, c)` on the unit sphere (Van Oosterom &
/// Strackee 1983): `tan(E / 2) = det(a, b, c) / (1 + a·b + b·c + c·a)`.
pub fn signed_area(a: &P3, b: &P3, c: &P3) -> f64 {
    let (a, b, c) = (a.coords, b.coords, c.coords);
    let num = a.dot(&b.cross(&c));
    let den = 1.0 + a.dot(&b) + b.dot(&c) + c.dot(&a);
    2.0 * num.atan2(den)
}

/// What [`check`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereCheck {
    /// Triangles not positively oriented under the exact predicate.
    pub negative: Vec<usize>,
    /// Total signed spherical area over 4π (1 for a bijective placement).
    pub degree: f64,
    /// Vertices off the unit sphere by more than 1e-9.
    pub off_sphere: usize,
}

impl SphereCheck {
    /// Every triangle positive, the covering one-sheeted, every point on the sphere.
    pub fn is_bijective(&self) -> bool {
        self.negative.is_empty() && (self.degree - 1.0).abs() < 1e-6 && self.off_sphere == 0
    }
}

/// Checks `positions` (one per vertex) as an embedding of the closed `triangles` on the sphere.
pub fn check(positions: &[P3], triangles: &[[u32; 3]]) -> SphereCheck {
    let p = |v: u32| &positions[v as usize];
    let negative = triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| orient(p(t[0]), p(t[1]), p(t[2])) <= 0.0)
        .map(|(i, _)| i)
        .collect();
    let area: f64 = triangles.iter().map(|t| signed_area(p(t[0]), p(t[1]), p(t[2]))).sum();
    let off_sphere = positions.iter().filter(|q| (q.coords.norm() - 1.0).abs() > 1e-9).count();
    SphereCheck { negative, degree: area / (4.0 * std::f64::consts::PI), off_sphere }
}

/// Whether every listed triangle is positively oriented under the exact predicate.
pub fn all_positive(positions: &[P3], triangles: &[[u32; 3]]) -> bool {
    let p = |v: u32| &positions[v as usize];
    triangles.par_iter().all(|t| orient(p(t[0]), p(t[1]), p(t[2])) > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counter_clockwise_from_outside_is_positive() {
        let (x, y, z) = (P3::new(1.0, 0.0, 0.0), P3::new(0.0, 1.0, 0.0), P3::new(0.0, 0.0, 1.0));
        assert!(orient(&x, &y, &z) > 0.0 && det(&x, &y, &z) > 0.0);
        assert!(orient(&y, &x, &z) < 0.0);
        // An octant has area 4π / 8.
        let e = signed_area(&x, &y, &z);
        assert!((e - std::f64::consts::FRAC_PI_2).abs() < 1e-14, "{e}");
        assert!((signed_area(&y, &x, &z) + e).abs() < 1e-14);
        // Exact on a triangle through the origin's plane (a great circle): zero, not a guess.
        let w = P3::new(-1.0, 0.0, 0.0);
        assert_eq!(orient(&x, &y, &w), 0.0);
    }

    #[test]
    fn the_octahedron_is_a_bijective_placement_and_a_mirrored_face_is_caught() {
        let p = [
            P3::new(1.0, 0.0, 0.0),
            P3::new(0.0, 1.0, 0.0),
            P3::new(-1.0, 0.0, 0.0),
            P3::new(0.0, -1.0, 0.0),
            P3::new(0.0, 0.0, 1.0),
            P3::new(0.0, 0.0, -1.0),
        ];
        let mut tris = vec![];
        for k in 0..4u32 {
            tris.push([k, (k + 1) % 4, 4]);
            tris.push([(k + 1) % 4, k, 5]);
        }
        let c = check(&p, &tris);
        assert!(c.is_bijective(), "{c:?}");
        tris[0].swap(0, 1);
        let c = check(&p, &tris);
        assert_eq!(c.negative, vec![0]);
        assert!(!c.is_bijective());
    }
}
