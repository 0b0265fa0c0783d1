//! Outputs of a pair job in its inputs' own layouts: `morph.glb`, the source with its
//! attributes and seam copies and one morph target that places it on the target; the
//! re-embedded OBJs with the inputs' `vt` / `vn`.

use crate::io;
use crate::mesh::{InputLayout, Mesh, P3, VertexId};
use crate::pipeline::common::Artifact;
use crate::pipeline::report::JobReport;

/// Adds `morph.glb` to a pair job's artifacts (not when a folded direction was withheld):
/// the source in its own layout with one morph target on the target and, with `inverse`, the
/// target in its own layout with one morph target on the source. `originals` are the inputs,
/// `meshes` what the job ran on (with vertices inserted at point anchors, which come after the
/// original ones and are left out).
pub fn add_morph(
    report: &JobReport,
    (originals, meshes): (&[Mesh], &[Mesh]),
    layouts: &[Option<&InputLayout>],
    inverse: bool,
    arts: &mut Vec<Artifact>,
) {
    let (Some(pair), [source, target0], [source1, target]) = (report.pair(), originals, meshes) else {
        return;
    };
    let Some(maps) = pair.maps.as_ref() else {
        return;
    };
    if !pair.withheld.is_empty() {
        return;
    }
    let on_target: Vec<P3> = (0..source.n_vertices()).map(|v| maps.s2t.position(VertexId(v as u32), target)).collect();
    let fwd = [("target".to_string(), on_target)];
    let mut parts =
        vec![io::LayoutGlb { name: "source", mesh: source, layout: layouts.first().copied().flatten(), targets: &fwd }];
    let back;
    if inverse {
        let on_source: Vec<P3> =
            (0..target0.n_vertices()).map(|v| maps.t2s.position(VertexId(v as u32), source1)).collect();
        back = [("source".to_string(), on_source)];
        parts.push(io::LayoutGlb {
            name: "target",
            mesh: target0,
            layout: layouts.get(1).copied().flatten(),
            targets: &back,
        });
    }
    let bytes = io::write_layout_glbs(&parts);
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
