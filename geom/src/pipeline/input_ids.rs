//! Vertex ids of a job in its inputs' own numbering, turned into the welded meshes' ids.
//!
//! For an input whose layout counts its own vertices ([`VertexIds::Input`], glTF), every
//! anchor, feature-curve vertex and quad marker of that mesh goes through
//! [`InputLayout::welded`]; other inputs' ids are the mesh's already.

use super::anchor_spec::AnchorRow;
use super::spec::{AutoSpec, HomologySpec, JobSpec};
use crate::error::{InputError, Result};
use crate::mesh::InputLayout;
use crate::mesh::layout::VertexIds;
use std::borrow::Cow;

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

/// The spec with every vertex id in welded numbering (borrowed when nothing changes).
///
/// # Errors
/// `InputError::Anchors` for an id past the input's vertices.
pub fn to_welded<'a>(spec: &'a JobSpec, layouts: &[Option<&InputLayout>]) -> Result<Cow<'a, JobSpec>> {
    let tables: Vec<Option<&[u32]>> =
        layouts.iter().map(|l| l.filter(|l| l.ids == VertexIds::Input).map(|l| l.welded.as_slice())).collect();
    if tables.iter().all(Option::is_none) {
        return Ok(Cow::Borrowed(spec));
    }
    let table = |k: usize| tables.get(k).copied().flatten();
    let mut s = spec.clone();
    match &mut s {
        JobSpec::Voronoi(l) | JobSpec::Greedy(l) => {
            id_rows(&mut l.anchors, &table)?;
            for row in &mut l.boundaries {
                for (k, id) in row.iter_mut().enumerate() {
                    map_id(id, table(k), k)?;
                }
            }
        }
        JobSpec::Spherical(x) => id_rows(&mut x.anchors, &table)?,
        JobSpec::Homology(HomologySpec { anchors, features, .. })
        | JobSpec::Auto(AutoSpec { anchors, features, .. }) => {
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
        JobSpec::Quad(q) => {
            let rows = q.anchors.iter_mut().chain(q.options.feature_anchors.iter_mut());
            for row in rows {
                for (k, id) in row.iter_mut().enumerate() {
                    map_id(id, table(k), k)?;
                }
            }
        }
    }
    Ok(Cow::Owned(s))
}
