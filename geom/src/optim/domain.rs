//! Where the images of a map being optimized live ([`MapDomain`]), and the simplest such
//! place, the plane ([`Plane`]).

use super::sym_dirichlet::{IDENTITY, Mat2};
use crate::param::Uv;

/// Where a map's images live and how they move. Shared across threads: triangles are
/// measured in parallel (each result kept in triangle order, so sums are the serial ones).
pub trait MapDomain: Sync {
    /// Every vertex's image (each in a chart of its own).
    type State: Clone + Sync;
    /// The corners of triangle `tri` in one chart and, per corner, the linear map that carries
    /// that vertex's own-chart displacement into it.
    fn element(&self, s: &Self::State, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]);
    /// The metric factor of triangle `tri` (its images are measured as `L J`), frozen for a
    /// step.
    fn metric(&self, _s: &Self::State, _tri: [u32; 3]) -> Mat2 {
        IDENTITY
    }
    /// The state with every vertex moved by `d` (in its own chart); `None` where a vertex
    /// cannot go.
    fn moved(&self, s: &Self::State, d: &[Uv]) -> Option<Self::State>;
    /// Sets vertex `v` of `trial` back to its image in `from`, as if its step had been zero;
    /// `false` for a domain where one vertex's move changes others' images (links carried
    /// across charts), which the line search then moves anew as a whole.
    fn restore(&self, _trial: &mut Self::State, _from: &Self::State, _v: usize) -> bool {
        false
    }
}

/// Images in the plane, one chart.
pub struct Plane;

impl MapDomain for Plane {
    type State = Vec<Uv>;
    fn element(&self, s: &Vec<Uv>, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
        (tri.map(|v| s[v as usize]), [IDENTITY; 3])
    }
    fn moved(&self, s: &Vec<Uv>, d: &[Uv]) -> Option<Vec<Uv>> {
        Some(s.iter().zip(d).map(|(p, q)| [p[0] + q[0], p[1] + q[1]]).collect())
    }
    fn restore(&self, trial: &mut Vec<Uv>, from: &Vec<Uv>, v: usize) -> bool {
        trial[v] = from[v];
        true
    }
}
