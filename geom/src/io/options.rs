//! The mesh file formats and the options of reading, with the size limits every reader checks
//! against its header counts before allocating.

use crate::error::{InputError, Result};
use crate::mesh::MeshLimits;
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
    /// glTF 2.0: `.glb`, or `.gltf` JSON with embedded buffers.
    Gltf,
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
            "glb" | "gltf" => Format::Gltf,
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
            Format::Gltf => "gltf",
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
