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
/// [`tol::PLANAR_DEGENERATE_REL`] times the mean is counted as degenerate (three points on one
/// straight boundary side land there only up to the rounding of their coordinates).
pub fn check_injective(mesh: &Mesh, uv: &[Uv]) -> InjectivityReport {
    let orient: Vec<f64> = mesh
        .faces()
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| {
                let p = uv[v.idx()];
                robust::Coord { x: p[0], y: p[1] }
            });
            robust::orient2d(a, b, c)
        })
        .collect();
    let mean = orient.iter().map(|o| o.abs()).sum::<f64>() / orient.len().max(1) as f64;
    let thr = tol::PLANAR_DEGENERATE_REL * mean;
    let mut r = InjectivityReport { flipped: 0, degenerate: 0, min_signed_area2: f64::INFINITY };
    for &o in &orient {
        if o.abs() <= thr {
            r.degenerate += 1;
        } else if o < 0.0 {
            r.flipped += 1;
        }
        r.min_signed_area2 = r.min_signed_area2.min(o);
    }
    r
}
