//! Mesh files: format detection from content, readers (OBJ, OFF, PLY, STL) and writers.
//! This is the only module of the crate that touches bytes or files.

mod gltf;
mod lex;
mod obj;
mod off;
mod ply;
mod ply_binary;
mod png16;
mod stl;

pub use gltf::write_glb;
pub use obj::write_uv_patches as write_obj_uv_patches;
pub use ply::write_with_face_ints as write_ply_with_face_ints;
pub use png16::{read_rgb16, write_rgb16};

use crate::error::{InputError, Result};
use crate::mesh::{Mesh, MeshLimits, RawMesh, Warning};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    Obj,
    Off,
    Ply,
    Stl,
}

impl Format {
    /// Format from a file extension (case-insensitive), if known.
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "off" => Format::Off,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            _ => return None,
        })
    }
    /// Lower-case name (also the usual extension).
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Off => "off",
            Format::Ply => "ply",
            Format::Stl => "stl",
        }
    }
}

/// Options for reading.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Size limits, checked against header counts before allocating.
    pub limits: MeshLimits,
    /// Format to assume when content detection is ambiguous (e.g. from the file extension).
    pub hint: Option<Format>,
}

pub(crate) fn check_limits(opts: &ReadOptions, nv: u64, nf: u64) -> Result<()> {
    if nv > opts.limits.max_vertices {
        return Err(InputError::TooLarge { what: "vertices", count: nv, limit: opts.limits.max_vertices }.into());
    }
    if nf > opts.limits.max_faces {
        return Err(InputError::TooLarge { what: "faces", count: nf, limit: opts.limits.max_faces }.into());
    }
    Ok(())
}

/// Detects the format from the bytes; the hint breaks ties (e.g. an OBJ without `v` lines).
///
/// # Errors
/// `InputError::Empty` for empty input, `UnknownFormat` when nothing matches.
pub fn detect(b: &[u8], hint: Option<Format>) -> Result<Format> {
    if b.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(InputError::Empty("the file is empty".into()).into());
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
            "content is not PLY, STL, OFF or OBJ (first bytes: ".to_string() + &lex::show(&b[..b.len().min(16)]) + ")",
        )
        .into()),
    }
}

/// Parses bytes into a raw (unvalidated) mesh.
///
/// # Errors
/// An [`InputError`] with the position of the problem.
pub fn read_raw(b: &[u8], opts: &ReadOptions) -> Result<(Format, RawMesh)> {
    let fmt = detect(b, opts.hint)?;
    let raw = match fmt {
        Format::Obj => obj::read(b, opts)?,
        Format::Off => off::read(b, opts)?,
        Format::Ply => ply::read(b, opts)?,
        Format::Stl => stl::read(b, opts)?,
    };
    Ok((fmt, raw))
}

/// A mesh read from bytes, with its detected format and warnings.
#[derive(Debug, Clone)]
pub struct ReadResult {
    pub mesh: Mesh,
    pub format: Format,
    pub warnings: Vec<Warning>,
}

/// Reads and validates a mesh from bytes.
///
/// # Errors
/// Any [`InputError`] of parsing or of [`Mesh::from_raw`].
pub fn read(b: &[u8], opts: &ReadOptions) -> Result<ReadResult> {
    let (format, raw) = read_raw(b, opts)?;
    let (mesh, warnings) = Mesh::from_raw(raw)?;
    Ok(ReadResult { mesh, format, warnings })
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
    }
    out
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
