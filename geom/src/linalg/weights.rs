//! Edge weights of discrete Laplacians, per ordered vertex pair.
//!
//! - `Uniform` (Tutte 1963): `w_ij = 1`.
//! - `Cotan` (Pinkall & Polthier 1993; harmonic maps of Eck et al. 1995):
//!   `w_ij = (cot a_ij + cot b_ij) / 2`, symmetric, may be negative on obtuse meshes.
//! - `MeanValue` (Floater 2003): `w_ij = (tan(d1/2) + tan(d2/2)) / |x_i - x_j|` with `d1, d2`
//!   the angles at `i` beside edge `ij`; always positive, not symmetric.

use crate::mesh::{HalfedgeId, Mesh};
use serde::{Deserialize, Serialize};

/// Which Laplacian weights to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Weights {
    /// Tutte's barycentric embedding.
    Uniform,
    /// Cotangent weights (discrete harmonic).
    Cotan,
    /// Floater's mean-value weights.
    #[default]
    MeanValue,
}

impl Weights {
    /// True when `w_ij == w_ji`, so a Cholesky factorization applies.
    pub fn is_symmetric(self) -> bool {
        !matches!(self, Weights::MeanValue)
    }
}

/// Weights per half-edge: `w[h]` is the weight of `tail(h) -> head(h)` *contributed by face(h)*
/// for that direction (`fwd`) and for the reverse direction (`rev`). The full weight of an
/// ordered pair is the sum over the one or two faces beside its edge.
#[derive(Debug, Clone)]
pub struct DirectedWeights {
    pub fwd: Vec<f64>,
    pub rev: Vec<f64>,
}

/// Computes the per-half-edge weight contributions, one face at a time: the face's doubled
/// area `|e x e'|` is shared by its three corners, and `tan(theta / 2)` is taken as
/// `|u x v| / (|u| |v| + u . v)`, with no trigonometric call.
pub fn directed_weights(mesh: &Mesh, kind: Weights) -> DirectedWeights {
    let nh = mesh.n_halfedges();
    let mut fwd = vec![0.0; nh];
    let mut rev = vec![0.0; nh];
    for (f, tri) in mesh.faces().iter().enumerate() {
        let h = 3 * f;
        if kind == Weights::Uniform {
            for k in 0..3 {
                // Each edge once in total: split over its faces.
                let share = if mesh.is_boundary_halfedge(HalfedgeId::from_idx(h + k)) { 1.0 } else { 0.5 };
                fwd[h + k] = share;
                rev[h + k] = share;
            }
            continue;
        }
        let p = tri.map(|v| mesh.position(v));
        // e[k] runs from corner k to corner k+1 (half-edge h + k).
        let e = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
        let a2 = e[0].cross(&e[1]).norm();
        if a2 <= 0.0 {
            continue;
        }
        let len = [e[0].norm(), e[1].norm(), e[2].norm()];
        // At corner k the two edge vectors are e[k] and -e[k+2].
        let dot = [-e[0].dot(&e[2]), -e[1].dot(&e[0]), -e[2].dot(&e[1])];
        match kind {
            Weights::Cotan => {
                for k in 0..3 {
                    // Half-edge k is opposite corner k+2.
                    let c = 0.5 * dot[(k + 2) % 3] / a2;
                    fwd[h + k] = c;
                    rev[h + k] = c;
                }
            }
            Weights::MeanValue => {
                let half_tan = |k: usize| a2 / (len[k] * len[(k + 2) % 3] + dot[k]);
                for k in 0..3 {
                    if len[k] > 0.0 {
                        fwd[h + k] = half_tan(k) / len[k];
                        rev[h + k] = half_tan((k + 1) % 3) / len[k];
                    }
                }
            }
            Weights::Uniform => {}
        }
    }
    DirectedWeights { fwd, rev }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn cotan_weights_of_a_right_isoceles_grid() {
        let g = shapes::grid(2);
        let w = directed_weights(&g, Weights::Cotan);
        // Every angle is 45 or 90 degrees: cot is 1 or 0.
        for &x in &w.fwd {
            assert!((x - 0.5).abs() < 1e-12 || x.abs() < 1e-12);
        }
    }

    #[test]
    fn mean_value_weights_are_positive() {
        let s = shapes::icosphere(1);
        let w = directed_weights(&s, Weights::MeanValue);
        assert!(w.fwd.iter().chain(&w.rev).all(|&x| x > 0.0));
    }
}

#[cfg(test)]
mod reference {
    use super::*;
    use crate::mesh::shapes;

    fn angle_at(a: nalgebra::Point3<f64>, b: nalgebra::Point3<f64>, c: nalgebra::Point3<f64>) -> f64 {
        let (u, v) = (b - a, c - a);
        u.cross(&v).norm().atan2(u.dot(&v))
    }

    /// The per-face formulas agree with the textbook per-angle ones.
    #[test]
    fn weights_match_angle_formulas() {
        let m = shapes::torus(9, 7, 2.0, 0.7);
        let cot = directed_weights(&m, Weights::Cotan);
        let mv = directed_weights(&m, Weights::MeanValue);
        for h in 0..m.n_halfedges() {
            let he = HalfedgeId::from_idx(h);
            let (i, j, k) = (m.tail(he), m.head(he), m.tail(he.prev()));
            let (pi, pj, pk) = (m.position(i), m.position(j), m.position(k));
            let c = 0.5 / angle_at(pk, pi, pj).tan();
            assert!((cot.fwd[h] - c).abs() < 1e-12 && (cot.rev[h] - c).abs() < 1e-12);
            let l = (pj - pi).norm();
            assert!((mv.fwd[h] - (0.5 * angle_at(pi, pj, pk)).tan() / l).abs() < 1e-12);
            assert!((mv.rev[h] - (0.5 * angle_at(pj, pk, pi)).tan() / l).abs() < 1e-12);
        }
    }
}
