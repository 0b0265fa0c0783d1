//! Reading the boundary word of a surface cut along loops through one base vertex, finding
//! the rotation that makes it canonical (`a1 b1 a1⁻¹ b1⁻¹ … ag bg ag⁻¹ bg⁻¹`), and algebraic
//! intersection numbers of loops that meet only at the base vertex.

use crate::mesh::{Mesh, VertexId};
use crate::topology::boundary_loops;

/// One side of the cut polygon: loop `loop_id`, read forwards (`+1`) or backwards (`-1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Letter {
    pub loop_id: usize,
    pub dir: i8,
}

/// The boundary of a cut surface as sides between copies of the base vertex.
#[derive(Debug, Clone)]
pub struct BoundaryWord {
    /// Boundary vertices (of the cut mesh), interior on the left, starting at a base copy.
    pub walk: Vec<VertexId>,
    /// Positions in `walk` of the copies of the base vertex.
    pub corners: Vec<usize>,
    /// The side starting at each corner.
    pub letters: Vec<Letter>,
}

/// Reads the single boundary loop of `cut` (vertex copies map to originals by `orig`) as a
/// word in `loops` (vertex sequences from `base` back to `base`, disjoint elsewhere).
pub fn read_word(cut: &Mesh, orig: &[VertexId], base: VertexId, loops: &[Vec<VertexId>]) -> Option<BoundaryWord> {
    let bl = boundary_loops(cut);
    if bl.len() != 1 {
        return None;
    }
    let raw: Vec<VertexId> = bl[0].iter().map(|&h| cut.tail(h)).collect();
    let first = raw.iter().position(|&v| orig[v.idx()] == base)?;
    let n = raw.len();
    let walk: Vec<VertexId> = (0..n).map(|i| raw[(first + i) % n]).collect();
    let corners: Vec<usize> = (0..n).filter(|&i| orig[walk[i].idx()] == base).collect();
    let mut letters = Vec::with_capacity(corners.len());
    for &c in &corners {
        let second = orig[walk[(c + 1) % n].idx()];
        let l = loops.iter().enumerate().find_map(|(i, lp)| {
            if lp.len() < 3 {
                None
            } else if lp[1] == second {
                Some(Letter { loop_id: i, dir: 1 })
            } else if lp[lp.len() - 2] == second {
                Some(Letter { loop_id: i, dir: -1 })
            } else {
                None
            }
        })?;
        letters.push(l);
    }
    Some(BoundaryWord { walk, corners, letters })
}

/// The first rotation of [`canonical_rotations`].
pub fn canonical_rotation(letters: &[Letter]) -> Option<usize> {
    canonical_rotations(letters).into_iter().next()
}

/// The rotations `r` (indices into `letters`) from which the word reads as a product of
/// commutators `x y x⁻¹ y⁻¹`, each loop used exactly twice.
pub fn canonical_rotations(letters: &[Letter]) -> Vec<usize> {
    let n = letters.len();
    if n == 0 || !n.is_multiple_of(4) {
        return Vec::new();
    }
    (0..n)
        .filter(|&r| {
            let w = |i: usize| letters[(r + i) % n];
            let mut used = std::collections::HashSet::new();
            (0..n / 4).all(|j| {
                let (x, y, xi, yi) = (w(4 * j), w(4 * j + 1), w(4 * j + 2), w(4 * j + 3));
                x.loop_id != y.loop_id
                    && xi.loop_id == x.loop_id
                    && yi.loop_id == y.loop_id
                    && xi.dir == -x.dir
                    && yi.dir == -y.dir
                    && used.insert(x.loop_id)
                    && used.insert(y.loop_id)
            })
        })
        .collect()
}

/// Algebraic intersection matrix of loops through `base` that meet nowhere else, from the
/// cyclic order of their ends around `base` (counter-clockwise). Entry `(i, j)` is `+1` when
/// loop `j` crosses loop `i` from its right to its left: `(t_i × t_j)·n > 0` in the paper's sign.
pub fn intersection_matrix(mesh: &Mesh, base: VertexId, loops: &[Vec<VertexId>]) -> Vec<Vec<i32>> {
    let ring: Vec<VertexId> = mesh.vertex_neighbors(base).collect();
    let pos = |w: VertexId| ring.iter().position(|&x| x == w);
    let ends: Vec<Option<(usize, usize)>> =
        loops.iter().map(|l| if l.len() < 3 { None } else { Some((pos(l[1])?, pos(l[l.len() - 2])?)) }).collect();
    let d = ring.len();
    let n = loops.len();
    let mut m = vec![vec![0; n]; n];
    for i in 0..n {
        for j in 0..n {
            let (Some((oi, ii)), Some((oj, ij))) = (ends[i], ends[j]) else { continue };
            if i == j {
                continue;
            }
            // Left of loop i: strictly counter-clockwise from its out-end to its in-end.
            let left = |p: usize| {
                let span = (ii + d - oi) % d;
                let at = (p + d - oi) % d;
                at > 0 && at < span
            };
            m[i][j] = match (left(oj), left(ij)) {
                (true, false) => 1,
                (false, true) => -1,
                _ => 0,
            };
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(s: &[(usize, i8)]) -> Vec<Letter> {
        s.iter().map(|&(loop_id, dir)| Letter { loop_id, dir }).collect()
    }

    #[test]
    fn canonical_rotations_find_commutator_products() {
        // b a^-1 b^-1 a: a commutator read from another corner.
        let one = w(&[(1, 1), (0, -1), (1, -1), (0, 1)]);
        assert_eq!(canonical_rotations(&one), vec![0, 1, 2, 3]);
        // a b a^-1 b^-1 c d c^-1 d^-1 rotated by 4: still canonical; by 2: not.
        let two = w(&[(2, 1), (3, 1), (2, -1), (3, -1), (0, 1), (1, 1), (0, -1), (1, -1)]);
        assert_eq!(canonical_rotations(&two), vec![0, 4]);
        // a b a b: not a commutator.
        assert!(canonical_rotations(&w(&[(0, 1), (1, 1), (0, 1), (1, 1)])).is_empty());
    }
}
