//! A pair job's anchor rows: vertex ids `[s, t]`, or a surface point on each mesh, given as a
//! position (`[x, y, z]`, snapped to the nearest surface point) or as a face and barycentric
//! coordinates (`{"face": f, "bary": [u, v, w]}`). Point rows are resolved into vertex ids
//! (inserting a vertex where none lies close) by [`crate::pipeline::plan::anchor_points`] before a method runs.

use crate::error::{InputError, Result};
use serde::{Deserialize, Deserializer, Serialize};

/// One anchor row.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum AnchorRow {
    /// `[source_vertex, target_vertex]`.
    Ids([u64; 2]),
    /// `{"source": point, "target": point}`.
    Points(AnchorPoints),
}

/// A surface point on each mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnchorPoints {
    pub source: PointRef,
    pub target: PointRef,
}

/// A point on a mesh's surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PointRef {
    /// A position, snapped to the nearest point of the surface.
    Position([f64; 3]),
    /// A point of a face.
    Face(FacePoint),
}

/// Barycentric coordinates in one face (non-negative, summing to 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FacePoint {
    pub face: u64,
    pub bary: [f64; 3],
}

const SHAPE: &str = "an anchor row is [source_vertex, target_vertex], {\"source\": [x, y, z], \"target\": [x, y, z]} \
                     or {\"source\": {\"face\": f, \"bary\": [u, v, w]}, \"target\": ...}";

impl<'de> Deserialize<'de> for AnchorRow {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = serde_json::Value::deserialize(d)?;
        if v.is_array() {
            return serde_json::from_value(v)
                .map(AnchorRow::Ids)
                .map_err(|e| serde::de::Error::custom(format!("{e}: {SHAPE}")));
        }
        serde_json::from_value(v).map(AnchorRow::Points).map_err(|e| serde::de::Error::custom(format!("{e}: {SHAPE}")))
    }
}

impl From<[u64; 2]> for AnchorRow {
    fn from(r: [u64; 2]) -> Self {
        AnchorRow::Ids(r)
    }
}

impl AnchorRow {
    /// Rows of vertex ids.
    pub fn ids(rows: impl IntoIterator<Item = [u64; 2]>) -> Vec<AnchorRow> {
        rows.into_iter().map(AnchorRow::Ids).collect()
    }
}

impl PointRef {
    /// Checks what can be checked without the mesh: finite numbers, a face in range, barycentric
    /// coordinates that are non-negative and sum to 1 (within 1e-6).
    ///
    /// # Errors
    /// `InputError::Anchors` naming the row and side.
    pub fn check(&self, row: usize, side: &str, faces: usize) -> Result<()> {
        let bad = |m: String| Err(InputError::Anchors(format!("anchor {row}: {side} point {m}")).into());
        match self {
            PointRef::Position(p) if p.iter().any(|c| !c.is_finite()) => bad(format!("{p:?} is not finite")),
            PointRef::Position(_) => Ok(()),
            PointRef::Face(f) if f.face >= faces as u64 => {
                bad(format!("face {} is out of range ({faces} faces)", f.face))
            }
            PointRef::Face(f) => {
                let s: f64 = f.bary.iter().sum();
                if f.bary.iter().any(|b| !b.is_finite() || *b < -1e-9) || (s - 1.0).abs() > 1e-6 {
                    return bad(format!("bary {:?} must be non-negative and sum to 1", f.bary));
                }
                Ok(())
            }
        }
    }
}

/// The vertex-id rows of a resolved spec.
///
/// # Errors
/// `Internal` if a point row was not resolved (a bug: [`crate::pipeline::run_with_layouts`] resolves them).
pub fn id_rows(rows: &[AnchorRow]) -> Result<Vec<[u64; 2]>> {
    rows.iter()
        .map(|r| match r {
            AnchorRow::Ids(x) => Ok(*x),
            AnchorRow::Points(_) => Err(crate::Error::Internal("a point anchor reached a method unresolved".into())),
        })
        .collect()
}
