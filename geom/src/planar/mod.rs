//! Planar predicates and point location, shared by every method that works in a plane (patch
//! and disk parameterizations, the 4g-gon, quad charts, untangling).

pub mod locate;

use crate::param::Uv;

/// Twice the signed area of the triangle `[a, b, c]` (positive counter-clockwise).
#[inline]
pub fn area2(a: Uv, b: Uv, c: Uv) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
}

/// [`area2`] of a triangle given as its three corners.
#[inline]
pub fn triangle_area2(t: [Uv; 3]) -> f64 {
    area2(t[0], t[1], t[2])
}
