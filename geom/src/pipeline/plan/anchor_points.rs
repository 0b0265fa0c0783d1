//! Anchor rows given as surface points become vertex ids before a method runs: a position is
//! snapped to the nearest point of the surface (`topology::Locator`), a face point is taken as given; within 1e-9 of the bounding-box diagonal of a
//! vertex (or 1% of the face's shortest edge, so no sliver is made) the anchor is that vertex,
//! else a vertex is inserted there (`mesh::insert`). Each snap's distance is reported.

use super::method::MethodPlan;
use crate::error::{InputError, Result};
use crate::mesh::insert::insert_points;
use crate::mesh::{FaceId, Mesh, P3};
use crate::pipeline::spec::anchor_spec::{AnchorRow, PointRef};
use crate::topology::Locator;
use serde::Serialize;

/// Relative snapping tolerance (of the bounding-box diagonal).
pub const SNAP_TOL: f64 = 1e-9;

/// One side of a point anchor, as resolved.
#[derive(Debug, Clone, Serialize)]
pub struct SideSnap {
    /// The vertex the anchor uses (of the mesh with inserted vertices).
    pub vertex: u32,
    /// Distance from the given point (a position, or a face point) to the anchor's vertex.
    pub distance: f64,
    /// Whether a vertex was inserted for it.
    pub inserted: bool,
}

/// A point anchor row, as resolved (`metrics.json` `anchor_points`).
#[derive(Debug, Clone, Serialize)]
pub struct AnchorSnap {
    pub row: usize,
    pub source: SideSnap,
    pub target: SideSnap,
}

/// `(face, bary, the given point)` of a point on `mesh`.
fn locate(
    p: &PointRef,
    row: usize,
    side: &str,
    mesh: &Mesh,
    locator: &mut Option<Locator>,
) -> Result<(FaceId, [f64; 3], P3)> {
    p.check(row, side, mesh.n_faces())?;
    Ok(match p {
        PointRef::Face(f) => {
            let s: f64 = f.bary.iter().map(|b| b.max(0.0)).sum();
            let w = f.bary.map(|b| b.max(0.0) / s);
            let [a, b, c] = mesh.faces()[f.face as usize].map(|v| mesh.position(v));
            (FaceId(f.face as u32), w, P3::from(a.coords * w[0] + b.coords * w[1] + c.coords * w[2]))
        }
        PointRef::Position(x) => {
            if locator.is_none() {
                *locator = Some(Locator::new(mesh)?);
            }
            let given = P3::new(x[0], x[1], x[2]);
            let pr = locator.as_ref().map(|l| l.project(&given));
            let pr = pr.ok_or_else(|| crate::Error::Internal("surface locator".into()))?;
            let w = pr.bary.map(|x| x.max(0.0));
            let s: f64 = w.iter().sum();
            (pr.face, w.map(|x| x / s), given)
        }
    })
}

/// Turns the point rows of a pair job into vertex ids; returns the meshes with the inserted
/// vertices and each row's snap, or `None` when the job has no point rows.
///
/// # Errors
/// `InputError::Anchors` for a malformed point; `InputError::Spec` for a job without two meshes.
pub fn resolve(plan: &mut MethodPlan, meshes: &[Mesh]) -> Result<Option<(Vec<Mesh>, Vec<AnchorSnap>)>> {
    let Some(rows) = plan.anchor_rows_mut() else { return Ok(None) };
    let points: Vec<usize> = (0..rows.len()).filter(|&r| matches!(rows[r], AnchorRow::Points(_))).collect();
    if points.is_empty() {
        return Ok(None);
    }
    let [s, t] = meshes else {
        return Err(InputError::Spec(format!("a pair job needs 2 meshes, got {}", meshes.len())).into());
    };
    let mut out = Vec::with_capacity(2);
    let mut sides: Vec<Vec<SideSnap>> = Vec::with_capacity(2);
    for (k, (mesh, side)) in [(s, "source"), (t, "target")].into_iter().enumerate() {
        let mut locator = None;
        let mut located = Vec::with_capacity(points.len());
        for &r in &points {
            let AnchorRow::Points(p) = &rows[r] else { continue };
            let p = if k == 0 { &p.source } else { &p.target };
            located.push(locate(p, r, side, mesh, &mut locator)?);
        }
        let pts: Vec<(FaceId, [f64; 3])> = located.iter().map(|l| (l.0, l.1)).collect();
        let ins = insert_points(mesh, &pts, SNAP_TOL * mesh.bbox_diagonal())?;
        sides.push(
            located
                .iter()
                .zip(ins.vertices.iter().zip(&ins.inserted))
                .map(|(l, (v, &inserted))| SideSnap {
                    vertex: v.0,
                    distance: (ins.mesh.position(*v) - l.2).norm(),
                    inserted,
                })
                .collect(),
        );
        out.push(ins.mesh);
    }
    let mut snaps = Vec::with_capacity(points.len());
    for (i, &r) in points.iter().enumerate() {
        let (a, b) = (sides[0][i].clone(), sides[1][i].clone());
        rows[r] = AnchorRow::Ids([u64::from(a.vertex), u64::from(b.vertex)]);
        snaps.push(AnchorSnap { row: r, source: a, target: b });
    }
    Ok(Some((out, snaps)))
}
