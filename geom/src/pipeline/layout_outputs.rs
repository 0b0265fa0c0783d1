//! Outputs of a pair job in its inputs' own layouts: `morph.glb`, the source with its
//! attributes and seam copies and one morph target that places it on the target.

use super::JobReport;
use super::common::Artifact;
use crate::io;
use crate::mesh::{InputLayout, Mesh, P3, VertexId};

/// Adds `morph.glb` to a pair job's artifacts (not when a folded direction was withheld).
/// `originals` are the inputs, `meshes` what the job ran on (with vertices inserted at point
/// anchors, which come after the original ones and are left out).
pub fn add_morph(
    report: &JobReport,
    originals: &[Mesh],
    meshes: &[Mesh],
    layouts: &[Option<&InputLayout>],
    arts: &mut Vec<Artifact>,
) {
    let (Some(pair), [source, _], [_, target]) = (report.pair(), originals, meshes) else {
        return;
    };
    let Some(maps) = pair.maps.as_ref() else {
        return;
    };
    if !pair.withheld.is_empty() {
        return;
    }
    let on_target: Vec<P3> = (0..source.n_vertices()).map(|v| maps.s2t.position(VertexId(v as u32), target)).collect();
    let layout = layouts.first().copied().flatten();
    let bytes = io::write_layout_glb(source, layout, &[("target".into(), on_target)]);
    arts.push(Artifact { name: "morph.glb".into(), content_type: "model/gltf-binary", bytes });
}
