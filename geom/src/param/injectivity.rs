//! Exact check that a planar triangulation is embedded without flips: the sign of every
//! triangle by Shewchuk's adaptive orientation predicate (`robust::orient2d`).

use super::Uv;
use crate::mesh::Mesh;
use crate::tol;
use serde::Serialize;

/// Counts of inverted and degenerate triangles in the plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InjectivityReport {
    /// Triangles with negative orientation.
    pub flipped: usize,
    /// Triangles with exactly zero area.
    pub degenerate: usize,
    /// Smallest signed area (twice the area, as orient2d returns).
    pub min_signed_area2: f64,
}

impl InjectivityReport {
    /// No flipped and no degenerate triangles.
    pub fn is_injective(&self) -> bool {
        self.flipped == 0 && self.degenerate == 0
    }
}

/// Checks the orientation of every face of `mesh` at the planar positions `uv`. Signs come
/// from the exact predicate; a triangle whose |signed area| is at most
/// [`tol::PLANAR_DEGENERATE_REL`] times the mean, or at most [`tol::PLANAR_COLLINEAR_REL`] times
/// its longest edge squared, is counted as degenerate (three points on one straight boundary
/// side land there only up to the rounding of their coordinates, and so does a vertex whose
/// neighbours all lie on that side).
pub fn check_injective(mesh: &Mesh, uv: &[Uv]) -> InjectivityReport {
    let (orient, collinear): (Vec<f64>, Vec<f64>) = mesh
        .faces()
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| {
                let p = uv[v.idx()];
                robust::Coord { x: p[0], y: p[1] }
            });
            let l2 = |p: robust::Coord<f64>, q: robust::Coord<f64>| (p.x - q.x).powi(2) + (p.y - q.y).powi(2);
            let longest = l2(a, b).max(l2(b, c)).max(l2(c, a));
            (robust::orient2d(a, b, c), tol::PLANAR_COLLINEAR_REL * longest)
        })
        .unzip();
    let mean = orient.iter().map(|o| o.abs()).sum::<f64>() / orient.len().max(1) as f64;
    let thr = tol::PLANAR_DEGENERATE_REL * mean;
    let mut r = InjectivityReport { flipped: 0, degenerate: 0, min_signed_area2: f64::INFINITY };
    for (&o, &c) in orient.iter().zip(&collinear) {
        if o.abs() <= thr.max(c) {
            r.degenerate += 1;
        } else if o < 0.0 {
            r.flipped += 1;
        }
        r.min_signed_area2 = r.min_signed_area2.min(o);
    }
    r
}
