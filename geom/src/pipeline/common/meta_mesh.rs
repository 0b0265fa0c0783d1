//! Outputs of the one-patch methods (`homology`, with or without features): the meta-mesh pair
//! and its statistics, the morph, planar domains and basis loops.

use super::Artifact;
use crate::error::{Error, Result};
use crate::homology::CanonicalBasisResult;
use crate::homology::overlay::MetaMeshResult;
use crate::homology::prune::{PruneOptions, prune_meta_mesh};
use crate::io::{self, Format};
use crate::mesh::{Mesh, P3};
use serde::Serialize;
use serde_json::json;

/// Size of the meta-mesh (or why it could not be built).
#[derive(Debug, Clone, Serialize)]
pub struct MetaMeshStats {
    pub vertices: usize,
    pub faces: usize,
    pub crossings: usize,
    /// Vertices removed by pruning below `dihedral_threshold_deg`, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned_vertices: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The meta-mesh pair's artifacts (`meta_source.obj`, `meta_target.obj`), pruned below
/// `dihedral_threshold_deg` when set; its statistics, and the morph from one to the other.
/// The meta-mesh is an extra: a merge, pruning or validation that fails is reported in the
/// statistics (`error`, no meta artifacts), and the maps still succeed.
pub fn meta_outputs(
    built: Result<MetaMeshResult>,
    dihedral_threshold_deg: Option<f64>,
    arts: &mut Vec<Artifact>,
) -> (MetaMeshStats, Option<Artifact>) {
    let failed = |e: Error| {
        let stats =
            MetaMeshStats { vertices: 0, faces: 0, crossings: 0, pruned_vertices: None, error: Some(e.to_string()) };
        (stats, None)
    };
    let mut m = match built {
        Ok(m) => m,
        Err(e) => return failed(e),
    };
    let mut pruned = None;
    if let Some(deg) = dihedral_threshold_deg {
        match prune_meta_mesh(&m, &PruneOptions { dihedral_threshold_deg: deg }) {
            Ok(p) => {
                pruned = Some(p.removed_vertices);
                m = p.mesh;
            }
            Err(e) => return failed(e),
        }
    }
    let stats = MetaMeshStats {
        vertices: m.on_source.len(),
        faces: m.faces.len(),
        crossings: m.crossings,
        pruned_vertices: pruned,
        error: None,
    };
    match m.meshes() {
        Ok((ms, mt)) => {
            arts.push(Artifact {
                name: "meta_source.obj".into(),
                content_type: "model/obj",
                bytes: io::write(&ms, Format::Obj),
            });
            arts.push(Artifact {
                name: "meta_target.obj".into(),
                content_type: "model/obj",
                bytes: io::write(&mt, Format::Obj),
            });
            (stats, Some(morph_glb("meta_morph.glb", &ms, mt.positions())))
        }
        Err(e) => (MetaMeshStats { error: Some(e.to_string()), ..stats }, None),
    }
}

/// A morph: `base` with one morph target, the same vertices at `to` (glTF 2.0, binary).
pub fn morph_glb(name: &str, base: &Mesh, to: &[P3]) -> Artifact {
    Artifact {
        name: name.into(),
        content_type: "model/gltf-binary",
        bytes: io::write_glb(base.positions(), &base.face_indices(), &[("target".into(), to.to_vec())]),
    }
}

/// A planar domain (`uv` per vertex of `disk`) as an OBJ mesh at z = 0.
///
/// # Errors
/// `Input` if the disk's faces do not make a mesh at those positions.
pub fn planar_obj(name: &str, uv: &[crate::param::Uv], disk: &Mesh) -> Result<Artifact> {
    let pos: Vec<P3> = uv.iter().map(|p| P3::new(p[0], p[1], 0.0)).collect();
    let m = Mesh::from_triangles(pos, &disk.face_indices())?;
    Ok(Artifact { name: name.into(), content_type: "model/obj", bytes: io::write(&m, Format::Obj) })
}

/// A basis's loops as named 3D polylines (`a1`, `b1`, …), on its refinement.
pub fn loops_json(b: &CanonicalBasisResult) -> Vec<serde_json::Value> {
    let m = &b.refined.mesh;
    b.loops
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let name = format!("{}{}", if i % 2 == 0 { 'a' } else { 'b' }, i / 2 + 1);
            let pts: Vec<[f64; 3]> = l.iter().map(|&v| m.position(v)).map(|p| [p.x, p.y, p.z]).collect();
            json!({"name": name, "points": pts})
        })
        .collect()
}
