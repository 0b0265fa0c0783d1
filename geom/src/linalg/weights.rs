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

fn angle_at(a: nalgebra::Point3<f64>, b: nalgebra::Point3<f64>, c: nalgebra::Point3<f64>) -> f64 {
    // Angle at a between ab and ac, robust for small angles.
    let u = b - a;
    let v = c - a;
    u.cross(&v).norm().atan2(u.dot(&v))
}

/// Computes the per-half-edge weight contributions.
pub fn directed_weights(mesh: &Mesh, kind: Weights) -> DirectedWeights {
    let nh = mesh.n_halfedges();
    let mut fwd = vec![0.0; nh];
    let mut rev = vec![0.0; nh];
    for h in 0..nh {
        let he = HalfedgeId::from_idx(h);
        let i = mesh.tail(he);
        let j = mesh.head(he);
        let k = mesh.tail(he.prev());
        let (pi, pj, pk) = (mesh.position(i), mesh.position(j), mesh.position(k));
        match kind {
            Weights::Uniform => {
                // Each edge once in total: split over its faces.
                let share = if mesh.is_boundary_halfedge(he) { 1.0 } else { 0.5 };
                fwd[h] = share;
                rev[h] = share;
            }
            Weights::Cotan => {
                let u = pi - pk;
                let v = pj - pk;
                let cr = u.cross(&v).norm();
                let c = if cr > 0.0 { u.dot(&v) / cr } else { 0.0 };
                fwd[h] = 0.5 * c;
                rev[h] = 0.5 * c;
            }
            Weights::MeanValue => {
                let len = (pj - pi).norm();
                if len > 0.0 {
                    fwd[h] = (0.5 * angle_at(pi, pj, pk)).tan() / len;
                    rev[h] = (0.5 * angle_at(pj, pk, pi)).tan() / len;
                }
            }
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
