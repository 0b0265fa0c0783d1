//! The boundary loop of a disk and its map onto a convex polygon by arc length.

use super::Uv;
use crate::error::{InputError, Result};
use crate::mesh::{Mesh, VertexId};
use crate::topology::{boundary_loops, components, euler_characteristic};
use serde::{Deserialize, Serialize};

/// The convex polygon the boundary is mapped onto.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum BoundaryShape {
    /// The unit circle (arc length along the loop -> angle).
    #[default]
    Circle,
    /// The unit square [0,1]^2, corners at the loop vertices nearest to the quarter lengths.
    Square,
    /// Any convex polygon given counter-clockwise; its corners go to the boundary vertices at the
    /// matching fractions of arc length unless `corners` (positions in the loop) are given.
    Polygon { vertices: Vec<Uv>, corners: Option<Vec<usize>> },
}

/// The single boundary loop of a topological disk, as vertices in order (interior on the left).
///
/// # Errors
/// `InputError::NotADisk` unless the mesh has one component, genus 0 and one boundary loop.
pub fn disk_boundary(mesh: &Mesh) -> Result<Vec<VertexId>> {
    let loops = boundary_loops(mesh);
    let c = components(mesh).count;
    // V - E + F = 2C - 2g - b, with the loops already at hand.
    let g = (2 * c as i64 - loops.len() as i64 - euler_characteristic(mesh)) / 2;
    if loops.len() != 1 || c != 1 || g != 0 {
        return Err(InputError::NotADisk(format!(
            "need 1 component, genus 0 and 1 boundary loop; found {c} components, genus {g}, {} boundary loops",
            loops.len()
        ))
        .into());
    }
    Ok(loops[0].iter().map(|&h| mesh.tail(h)).collect())
}

fn is_convex_ccw(p: &[Uv]) -> bool {
    let n = p.len();
    n >= 3
        && (0..n).all(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
            robust::orient2d(
                robust::Coord { x: a[0], y: a[1] },
                robust::Coord { x: b[0], y: b[1] },
                robust::Coord { x: c[0], y: c[1] },
            ) > 0.0
        })
}

/// Positions of the loop vertices on the polygon, by arc length between corners.
///
/// # Errors
/// `InputError::Invalid` for a non-convex polygon or corners that are not increasing loop
/// positions, one per polygon vertex.
pub fn map_boundary_to_polygon(mesh: &Mesh, lp: &[VertexId], shape: &BoundaryShape) -> Result<Vec<Uv>> {
    let n = lp.len();
    if n < 3 {
        return Err(InputError::Invalid(format!("boundary loop has {n} vertices; need at least 3")).into());
    }
    let seg: Vec<f64> = (0..n).map(|i| (mesh.position(lp[(i + 1) % n]) - mesh.position(lp[i])).norm()).collect();
    let total: f64 = seg.iter().sum();
    let mut cum = Vec::with_capacity(n + 1);
    cum.push(0.0);
    for s in &seg {
        cum.push(cum.last().copied().unwrap_or(0.0) + s);
    }
    let (poly, corners) = match shape {
        BoundaryShape::Circle => {
            return Ok((0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * cum[i] / total;
                    [t.cos(), t.sin()]
                })
                .collect());
        }
        BoundaryShape::Square => (vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], None),
        BoundaryShape::Polygon { vertices, corners } => (vertices.clone(), corners.clone()),
    };
    if !is_convex_ccw(&poly) {
        return Err(InputError::Invalid("boundary polygon must be strictly convex and counter-clockwise".into()).into());
    }
    let k = poly.len();
    if n < k {
        return Err(InputError::Invalid(format!("boundary loop has {n} vertices for a {k}-gon")).into());
    }
    let corners = match corners {
        Some(c) => c,
        None => {
            // Corner j at the loop vertex nearest to arc length j/k of the total.
            let mut c = Vec::with_capacity(k);
            for j in 0..k {
                let target = total * j as f64 / k as f64;
                let i = cum[..n].partition_point(|&x| x < target).min(n - 1);
                let i = if i > 0 && (target - cum[i - 1]) < (cum[i] - target) { i - 1 } else { i };
                let lo = c.last().map_or(0, |&p: &usize| p + 1);
                c.push(i.max(lo).min(n - (k - j)));
            }
            c
        }
    };
    if corners.len() != k || corners.windows(2).any(|w| w[0] >= w[1]) || corners.last().is_some_and(|&l| l >= n) {
        return Err(InputError::Invalid(
            "polygon corners must be increasing loop positions, one per polygon vertex".into(),
        )
        .into());
    }
    let mut uv = vec![[0.0; 2]; n];
    for j in 0..k {
        let (s, e) = (corners[j], corners[(j + 1) % k]);
        let (a, b) = (poly[j], poly[(j + 1) % k]);
        let len_to = |i: usize| if i >= s { cum[i] - cum[s] } else { total - cum[s] + cum[i] };
        let side = if e > s { cum[e] - cum[s] } else { total - cum[s] + cum[e] };
        let mut i = s;
        loop {
            let t = if side > 0.0 { len_to(i) / side } else { 0.0 };
            uv[i] = [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
            i = (i + 1) % n;
            if i == e {
                break;
            }
        }
    }
    Ok(uv)
}
