//! `options.transfer`: `target_transferred.glb`, the target in its own layout with the named
//! attributes of the source carried through the target -> source map (`map::transfer`).

use crate::error::Result;
use crate::io;
use crate::map::transfer::{SourceField, TransferOptions, transfer};
use crate::mesh::{InputLayout, Mesh, P3, VertexId};
use crate::pipeline::common::Artifact;
use crate::pipeline::report::JobReport;
use crate::topology::Locator;

/// Adds `target_transferred.glb` (nothing for a job without maps, or with a withheld direction).
///
/// # Errors
/// `Internal` if the surface locator cannot be built.
pub fn add(
    report: &JobReport,
    o: &TransferOptions,
    (originals, meshes): (&[Mesh], &[Mesh]),
    layouts: &[Option<&InputLayout>],
    arts: &mut Vec<Artifact>,
) -> Result<()> {
    let (Some(pair), [source, target], [src_run, _]) = (report.pair(), originals, meshes) else { return Ok(()) };
    let Some(maps) = pair.maps.as_ref().filter(|_| pair.withheld.is_empty()) else { return Ok(()) };
    let images: Vec<P3> = (0..target.n_vertices()).map(|v| maps.t2s.position(VertexId(v as u32), src_run)).collect();
    let field =
        SourceField { mesh: source, layout: layouts.first().copied().flatten(), locator: Locator::new(source)? };
    let r = transfer(&field, target, layouts.get(1).copied().flatten(), &images, o)?;
    let bytes = io::write_glb_mesh(&io::GlbMesh {
        positions: &r.positions,
        triangles: &r.triangles,
        attributes: &r.attributes,
        targets: &[],
    });
    arts.push(Artifact { name: "target_transferred.glb".into(), content_type: "model/gltf-binary", bytes });
    Ok(())
}
