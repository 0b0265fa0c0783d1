//! Vertex ids of a job in its inputs' own numbering, turned into the welded meshes' ids.
//!
//! For an input whose layout counts its own vertices ([`VertexIds::Input`], glTF), every
//! anchor, feature-curve vertex and quad marker of that mesh goes through
//! [`InputLayout::welded`]; other inputs' ids are the mesh's already.

use super::method::MethodPlan;
use crate::error::{InputError, Result};
use crate::mesh::InputLayout;
use crate::mesh::layout::VertexIds;
use crate::pipeline::spec::HomologySpec;
use crate::pipeline::spec::anchor_spec::AnchorRow;

fn map_id(id: &mut u64, table: Option<&[u32]>, mesh: usize) -> Result<()> {
    if let Some(t) = table {
        let w = usize::try_from(*id).ok().and_then(|i| t.get(i)).ok_or_else(|| {
            InputError::Anchors(format!(
                "vertex {id} of mesh {mesh} is out of range: the file has {} vertices",
                t.len()
            ))
        })?;
        *id = u64::from(*w);
    }
    Ok(())
}

/// Vertex-id anchor rows through the tables (point rows are not ids).
fn id_rows<'t>(rows: &mut [AnchorRow], table: &dyn Fn(usize) -> Option<&'t [u32]>) -> Result<()> {
    for row in rows {
        if let AnchorRow::Ids(ids) = row {
            for (k, id) in ids.iter_mut().enumerate() {
                map_id(id, table(k), k)?;
            }
        }
    }
    Ok(())
}

/// Turns every vertex id of the plan into welded numbering (nothing changes for inputs
/// without a layout of their own).
///
/// # Errors
/// `InputError::Anchors` for an id past the input's vertices.
pub fn to_welded(plan: &mut MethodPlan, layouts: &[Option<&InputLayout>]) -> Result<()> {
    let tables: Vec<Option<&[u32]>> =
        layouts.iter().map(|l| l.filter(|l| l.ids == VertexIds::Input).map(|l| l.welded.as_slice())).collect();
    if tables.iter().all(Option::is_none) {
        return Ok(());
    }
    let table = |k: usize| tables.get(k).copied().flatten();
    match plan {
        MethodPlan::Layout(_, l) => {
            id_rows(&mut l.anchors, &table)?;
            for row in &mut l.boundaries {
                for (k, id) in row.iter_mut().enumerate() {
                    map_id(id, table(k), k)?;
                }
            }
        }
        MethodPlan::Spherical(x) => id_rows(&mut x.anchors, &table)?,
        MethodPlan::Homology(HomologySpec { anchors, features, .. }) => {
            id_rows(anchors, &table)?;
            for f in features {
                for id in &mut f.source {
                    map_id(id, table(0), 0)?;
                }
                for id in &mut f.target {
                    map_id(id, table(1), 1)?;
                }
            }
        }
        MethodPlan::Quad(q) => {
            let rows = q.anchors.iter_mut().chain(q.options.feature_anchors.iter_mut());
            for row in rows {
                for (k, id) in row.iter_mut().enumerate() {
                    map_id(id, table(k), k)?;
                }
            }
        }
    }
    Ok(())
}
