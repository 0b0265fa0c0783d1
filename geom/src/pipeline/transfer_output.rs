//! `options.transfer`: `target_transferred.glb`, the target in its own layout with the named
//! attributes of the source carried through the target -> source map (`map::transfer`).

use super::common::Artifact;
use super::report::JobReport;
use crate::error::{InputError, Result};
use crate::io;
use crate::map::transfer::{SourceField, TransferOptions, transfer};
use crate::mesh::{Attributes, InputLayout, Mesh, P3, VertexId};
use crate::topology::Locator;

/// The attributes a job may carry.
pub const TRANSFERABLE: &str =
    "TEXCOORD_0 .. TEXCOORD_7, COLOR_0, JOINTS_0 and WEIGHTS_0 (skin weights travel together)";

/// Parses attribute names.
///
/// # Errors
/// `InputError::Spec` for an unknown or repeated name.
pub fn parse(names: &[String]) -> Result<TransferOptions> {
    let mut o = TransferOptions::default();
    let mut seen = std::collections::HashSet::new();
    for n in names {
        if !seen.insert(n.as_str()) {
            return Err(InputError::Spec(format!("transfer names {n} twice")).into());
        }
        match n.as_str() {
            "COLOR_0" => o.color = true,
            "JOINTS_0" | "WEIGHTS_0" => o.skin = true,
            t => match t.strip_prefix("TEXCOORD_").and_then(|k| k.parse::<usize>().ok()).filter(|&k| k < 8) {
                Some(k) => o.texcoords.push(k),
                None => {
                    return Err(InputError::Spec(format!(
                        "transfer: unknown attribute {n:?}; allowed: {TRANSFERABLE}"
                    ))
                    .into());
                }
            },
        }
    }
    Ok(o)
}

fn source_attributes(source: &Mesh, layout: Option<&InputLayout>) -> Attributes {
    layout.map_or_else(|| Attributes::from(source.attributes()), |l| l.attributes.clone())
}

/// The attribute names of a read mesh (its input layout's when it has one), as the server
/// records them in the mesh's summary.
pub fn attribute_names(mesh: &Mesh, layout: Option<&InputLayout>) -> Vec<String> {
    source_attributes(mesh, layout).names()
}

/// Checks the source has every attribute asked for.
///
/// # Errors
/// `InputError::Invalid` naming the missing attribute and those the source has.
pub fn check_source(o: &TransferOptions, source: &Mesh, layout: Option<&InputLayout>) -> Result<()> {
    check_names(o, &attribute_names(source, layout))
}

/// [`check_source`] on the source's attribute names (a summary's, before the job runs).
///
/// # Errors
/// As [`check_source`].
pub fn check_names(o: &TransferOptions, names: &[String]) -> Result<()> {
    let has = |n: &str| names.iter().any(|x| x == n);
    let missing = o
        .texcoords
        .iter()
        .find(|&&k| !has(&format!("TEXCOORD_{k}")))
        .map(|k| format!("TEXCOORD_{k}"))
        .or_else(|| (o.color && !has("COLOR_0")).then(|| "COLOR_0".to_string()))
        .or_else(|| (o.skin && !(has("JOINTS_0") && has("WEIGHTS_0"))).then(|| "JOINTS_0/WEIGHTS_0".to_string()));
    match missing {
        Some(m) => Err(InputError::Invalid(format!(
            "transfer: the source has no {m} (it has: {})",
            if names.is_empty() { "no attributes".to_string() } else { names.join(", ") }
        ))
        .into()),
        None => Ok(()),
    }
}

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
