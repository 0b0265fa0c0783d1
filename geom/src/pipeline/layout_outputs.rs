//! Outputs of a pair job in its inputs' own layouts: `morph.glb`, the source with its
//! attributes and seam copies and one morph target that places it on the target; the
//! re-embedded OBJs with the inputs' `vt` / `vn`.

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

/// Rewrites `source_on_target.obj` / `target_on_source.obj` in each input's own layout when it
/// has one (seams: `vt` / `vn` kept), has per-vertex UVs or normals, or had vertices inserted at
/// point anchors (left out again): the input's own faces at the mapped positions.
pub fn rewrite_objs(
    report: &JobReport,
    originals: &[Mesh],
    meshes: &[Mesh],
    layouts: &[Option<&InputLayout>],
    arts: &mut [Artifact],
) {
    let (Some(pair), [s0, t0], [s1, t1]) = (report.pair(), originals, meshes) else {
        return;
    };
    let Some(maps) = pair.maps.as_ref() else {
        return;
    };
    let sides = [
        ("source_on_target.obj", s0, s1, &maps.s2t, t1, layouts.first().copied().flatten()),
        ("target_on_source.obj", t0, t1, &maps.t2s, s1, layouts.get(1).copied().flatten()),
    ];
    for (name, original, ran, map, onto, layout) in sides {
        let a = original.attributes();
        let inserted = ran.n_vertices() != original.n_vertices();
        if layout.is_none() && !inserted && a.uvs.is_none() && a.normals.is_none() {
            continue;
        }
        let Some(slot) = arts.iter_mut().find(|x| x.name == name) else { continue };
        let pos: Vec<P3> = (0..original.n_vertices()).map(|v| map.position(VertexId(v as u32), onto)).collect();
        let bytes = match layout {
            Some(l) => io::write_obj_layout(&pos, l),
            None => match original.with_positions(pos) {
                Ok(m) => io::write(&m, io::Format::Obj),
                Err(_) => continue,
            },
        };
        slot.bytes = bytes;
    }
}
