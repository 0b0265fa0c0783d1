//! The quad layout every model of a `quad` job shares: patches named by their four corners and
//! four sides, sides named by the layout curve they run along and its direction. The layout is
//! pure combinatorics, so the remesh connectivity built from it is identical for every model.

use serde::Serialize;

/// One side of a quad patch: a layout curve, walked from its start (or, `reversed`, its end).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct QuadSide {
    pub curve: u32,
    pub reversed: bool,
}

/// A quad patch: corners counter-clockwise (seen from outside the surface), side `k` from
/// corner `k` to corner `k + 1`. In the unit square corner 0 is (0,0), 1 is (1,0), 2 is (1,1)
/// and 3 is (0,1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct QuadPatchLayout {
    pub corners: [u32; 4],
    pub sides: [QuadSide; 4],
}

/// Corners, curves between corners, and quad patches bounded by the curves.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct QuadLayout {
    pub n_corners: usize,
    /// Start and end corner of every curve.
    pub curves: Vec<[u32; 2]>,
    pub patches: Vec<QuadPatchLayout>,
}

/// Unit-square position of corner `k` of a patch.
pub const SQUARE: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

impl QuadLayout {
    /// The genus-0 layout of section 3.2: four partition points joined in a loop
    /// p0 -> p1 -> p2 -> p3 -> p0 (curve k from p_k to p_{k+1}) cut the sphere into two quads,
    /// one on each side of the loop.
    pub fn genus0() -> QuadLayout {
        let side = |curve, reversed| QuadSide { curve, reversed };
        QuadLayout {
            n_corners: 4,
            curves: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
            patches: vec![
                QuadPatchLayout {
                    corners: [0, 1, 2, 3],
                    sides: [side(0, false), side(1, false), side(2, false), side(3, false)],
                },
                QuadPatchLayout {
                    corners: [0, 3, 2, 1],
                    sides: [side(3, true), side(2, true), side(1, true), side(0, true)],
                },
            ],
        }
    }

    /// Checks that every side runs between the corners it joins.
    pub fn is_consistent(&self) -> bool {
        self.patches.iter().all(|p| {
            (0..4).all(|k| {
                let s = p.sides[k];
                let Some(&[a, b]) = self.curves.get(s.curve as usize) else { return false };
                let (from, to) = if s.reversed { (b, a) } else { (a, b) };
                from == p.corners[k] && to == p.corners[(k + 1) % 4]
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn genus0_layout_sides_join_their_corners() {
        let l = QuadLayout::genus0();
        assert!(l.is_consistent());
        // Every curve borders exactly two patches, once in each direction.
        for c in 0..l.curves.len() as u32 {
            let uses: Vec<bool> =
                l.patches.iter().flat_map(|p| p.sides.iter()).filter(|s| s.curve == c).map(|s| s.reversed).collect();
            assert_eq!(uses.len(), 2);
            assert_ne!(uses[0], uses[1]);
        }
    }
}
