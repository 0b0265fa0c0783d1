//! A point inside the kernel of a star-shaped spherical polygon: where a vertex goes when a
//! vertex split brings it back inside its ring (Praun & Hoppe 2003 place each re-inserted
//! vertex in its ring's kernel the same way).
//!
//! The kernel is the intersection of the hemispheres left of each ring edge's great circle. Its
//! corners are where two of those circles meet inside every other hemisphere; their mean lies
//! strictly inside a kernel with an interior (a convex spherical polygon). The caller checks
//! the star with the exact predicate.

use crate::mesh::{P3, V3};

/// Candidate points for the kernel of the closed ring `ring` (counter-clockwise seen from
/// outside), best first: the ring's centroid (Tutte's position), the mean of the edges' inward
/// normals, and the mean of the kernel's corners. The caller keeps the first whose star is
/// positive under the exact predicate.
pub fn kernel_candidates(ring: &[P3]) -> Vec<P3> {
    let n = ring.len();
    // The kernel is the intersection of the hemispheres x·nᵢ > 0, nᵢ = bᵢ × bᵢ₊₁.
    let normals: Vec<V3> =
        (0..n).filter_map(|i| ring[i].coords.cross(&ring[(i + 1) % n].coords).try_normalize(0.0)).collect();
    let mut out = Vec::with_capacity(3);
    let centroid: V3 = ring.iter().map(|p| p.coords).sum();
    out.extend(centroid.try_normalize(0.0).map(P3::from));
    out.extend(normals.iter().sum::<V3>().try_normalize(0.0).map(P3::from));
    // The kernel's corners: where two of the great circles meet inside every other hemisphere.
    let inside = |x: &V3| normals.iter().all(|m| x.dot(m) >= -1e-12);
    let mut sum = V3::zeros();
    for i in 0..normals.len() {
        for j in i + 1..normals.len() {
            let Some(x) = normals[i].cross(&normals[j]).try_normalize(1e-300) else { continue };
            for x in [x, -x] {
                if inside(&x) {
                    sum += x;
                }
            }
        }
    }
    out.extend(sum.try_normalize(0.0).map(P3::from));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::orient::orient;

    fn ring_of(q: &[[f64; 2]]) -> Vec<P3> {
        q.iter().map(|p| P3::from(nalgebra::Vector3::new(p[0], p[1], 1.0).normalize())).collect()
    }

    fn star_is_positive(ring: &[P3], x: &P3) -> bool {
        (0..ring.len()).all(|i| orient(x, &ring[i], &ring[(i + 1) % ring.len()]) > 0.0)
    }

    #[test]
    fn a_convex_ring_takes_its_centroid_and_a_dented_one_its_kernel() {
        let square = ring_of(&[[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]);
        let x = kernel_candidates(&square)[0];
        assert!(star_is_positive(&square, &x));
        assert!((x - P3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
        // An arrow whose centroid lies outside its kernel: a deep notch from the right.
        let arrow = ring_of(&[[-0.1, -0.1], [0.1, -0.1], [-0.08, 0.0], [0.1, 0.1], [-0.1, 0.1]]);
        let c = kernel_candidates(&arrow);
        assert!(!star_is_positive(&arrow, &c[0]), "the centroid is outside the kernel");
        assert!(star_is_positive(&arrow, c.last().unwrap()), "{c:?}");
        // The same ring turning the other way bounds the rest of the sphere: its kernel is on
        // the far side, and a candidate that fits is there.
        let mut reversed = square.clone();
        reversed.reverse();
        let fit: Vec<P3> =
            kernel_candidates(&reversed).into_iter().filter(|x| star_is_positive(&reversed, x)).collect();
        assert!(!fit.is_empty() && fit.iter().all(|x| x.z < 0.0), "{fit:?}");
    }
}
