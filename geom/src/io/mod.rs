//! Mesh files: format detection from content, readers (OBJ, OFF, PLY, STL, glTF) and writers.
//! This is the only module of the crate that touches bytes or files.
//!
//! Formats that split vertices at attribute seams (glTF; OBJ whose corners use several `vt` or
//! `vn` per position) are welded for the topology: [`ReadResult::layout`] keeps the input's own
//! vertices, triangles and attributes (see [`crate::mesh::layout`]).

mod glb_write;
mod gltf_accessor;
mod gltf_prims;
mod gltf_read;
mod lex;
mod obj;
mod obj_seams;
mod off;
mod options;
mod ply;
mod ply_binary;
mod png16;
mod stl;

pub use glb_write::{
    GlbMesh, LayoutGlb, write_glb, write_glb_mesh, write_glb_meshes, write_layout_glb, write_layout_glbs,
};
pub use obj::write_layout as write_obj_layout;
pub use obj::write_uv_patches as write_obj_uv_patches;
pub use options::{Format, ReadOptions};
pub use ply::write_with_face_ints as write_ply_with_face_ints;
pub use png16::{read_rgb16, write_rgb16};

use crate::error::{InputError, Result};
use crate::mesh::{InputLayout, Mesh, RawMesh, Warning, layout};
use std::path::Path;

/// Detects the format from the bytes; the hint breaks ties (e.g. an OBJ without `v` lines).
///
/// # Errors
/// `InputError::Empty` for empty input, `UnknownFormat` when nothing matches.
pub fn detect(b: &[u8], hint: Option<Format>) -> Result<Format> {
    if b.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(InputError::Empty("the file is empty".into()).into());
    }
    if gltf_read::sniff(b) {
        return Ok(Format::Gltf);
    }
    if ply::sniff(b) {
        return Ok(Format::Ply);
    }
    if stl::is_binary(b) || stl::sniff_ascii(b) {
        return Ok(Format::Stl);
    }
    if off::sniff(b) {
        return Ok(Format::Off);
    }
    if obj::sniff(b) {
        return Ok(Format::Obj);
    }
    match hint {
        Some(f) => Ok(f),
        None => Err(InputError::UnknownFormat(
            "content is not glTF, PLY, STL, OFF or OBJ (first bytes: ".to_string()
                + &lex::show(&b[..b.len().min(16)])
                + ")",
        )
        .into()),
    }
}

/// Parses bytes into a raw (unvalidated) mesh, welded, with the input's own layout when the
/// format split vertices at seams.
///
/// # Errors
/// An [`InputError`] with the position of the problem.
pub fn read_raw(b: &[u8], opts: &ReadOptions) -> Result<(Format, RawMesh, Option<InputLayout>)> {
    let fmt = detect(b, opts.hint)?;
    let (raw, lay) = match fmt {
        Format::Obj => obj::read(b, opts)?,
        Format::Off => (off::read(b, opts)?, None),
        Format::Ply => (ply::read(b, opts)?, None),
        Format::Stl => (stl::read(b, opts)?, None),
        Format::Gltf => {
            let (raw, lay) = layout::weld(gltf_read::read(b, opts)?)?;
            (raw, Some(lay))
        }
    };
    Ok((fmt, raw, lay))
}

/// A mesh read from bytes, with its detected format and warnings.
#[derive(Debug, Clone)]
pub struct ReadResult {
    /// The welded mesh the mapping runs on.
    pub mesh: Mesh,
    pub format: Format,
    pub warnings: Vec<Warning>,
    /// The input's own vertices when they differ from the mesh's (seams), with its attributes.
    pub layout: Option<InputLayout>,
}

/// Reads and validates a mesh from bytes.
///
/// # Errors
/// Any [`InputError`] of parsing or of [`Mesh::from_raw`].
pub fn read(b: &[u8], opts: &ReadOptions) -> Result<ReadResult> {
    let (format, raw, layout) = read_raw(b, opts)?;
    let n_raw = raw.positions.len();
    let (mesh, mut warnings) = Mesh::from_raw(raw)?;
    // Only an OBJ with unused `v` lines is renumbered; its seams are then not kept.
    let layout = match layout {
        Some(_) if mesh.n_vertices() != n_raw => {
            warnings.push(Warning::new("uv_seams", "seams not kept: the file has unused vertices"));
            None
        }
        l => l,
    };
    Ok(ReadResult { mesh, format, warnings, layout })
}

/// Reads a mesh file; the extension is a hint only.
///
/// # Errors
/// `InputError::Invalid` if the file cannot be opened, or any read error.
pub fn read_path(path: &Path, opts: &ReadOptions) -> Result<ReadResult> {
    let bytes = std::fs::read(path).map_err(|e| InputError::Invalid(format!("cannot read {}: {e}", path.display())))?;
    let opts = ReadOptions { hint: opts.hint.or_else(|| Format::from_extension(path)), ..opts.clone() };
    read(&bytes, &opts)
}

/// Serialises a mesh.
pub fn write(mesh: &Mesh, format: Format) -> Vec<u8> {
    let mut out = Vec::new();
    match format {
        Format::Obj => obj::write(mesh, &mut out),
        Format::Off => off::write(mesh, &mut out),
        Format::Ply => ply::write(mesh, &mut out),
        Format::Stl => stl::write(mesh, &mut out),
        Format::Gltf => out = write_glb(mesh.positions(), &faces_u32(mesh), &[]),
    }
    out
}

fn faces_u32(mesh: &Mesh) -> Vec<[u32; 3]> {
    mesh.faces().iter().map(|f| f.map(|v| v.0)).collect()
}

/// Writes a mesh file in the format of its extension.
///
/// # Errors
/// `InputError::UnknownFormat` for an unknown extension; `Error::Internal` on I/O failure.
pub fn write_path(mesh: &Mesh, path: &Path) -> Result<()> {
    let fmt = Format::from_extension(path).ok_or_else(|| {
        InputError::UnknownFormat(format!("cannot tell the format of {} from its extension", path.display()))
    })?;
    write_bytes(path, &write(mesh, fmt))
}

/// Writes bytes to a file.
///
/// # Errors
/// `Error::Internal` on I/O failure.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| crate::Error::Internal(format!("cannot write {}: {e}", path.display())))
}
