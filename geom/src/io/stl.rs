//! STL reader (ascii and binary, identical vertices welded by `stl_io`) and binary writer.
//!
//! Binary files are recognised by their exact size (84 + 50 n bytes), which also catches a
//! triangle count that promises more than the file holds, before anything is allocated.
//! Faces that collapse after welding are dropped with a warning.

use super::options::{ReadOptions, check_limits};
use crate::error::{InputError, Result, parse_err};
use crate::mesh::{Mesh, RawMesh, Warning};

fn binary_count(b: &[u8]) -> Option<u64> {
    (b.len() >= 84).then(|| u64::from(u32::from_le_bytes([b[80], b[81], b[82], b[83]])))
}

/// Binary when the size matches the header count exactly.
pub(crate) fn is_binary(b: &[u8]) -> bool {
    binary_count(b).is_some_and(|n| 84 + 50 * n == b.len() as u64)
}

pub(crate) fn sniff_ascii(b: &[u8]) -> bool {
    let t = b.trim_ascii_start();
    t.starts_with(b"solid") && {
        let head = &t[..t.len().min(1024)];
        head.windows(5).any(|w| w == b"facet") || head.windows(8).any(|w| w == b"endsolid")
    }
}

pub(crate) fn read(b: &[u8], opts: &ReadOptions) -> Result<RawMesh> {
    let binary = is_binary(b);
    if !binary && !sniff_ascii(b) {
        if let Some(n) = binary_count(b) {
            return Err(InputError::LyingCount {
                format: "STL",
                promised: format!("{n} triangles ({} bytes)", 84 + 50 * n),
                available: format!("{} bytes", b.len()),
            }
            .into());
        }
        return Err(parse_err("STL", "byte 0", "neither a binary STL (too short) nor an ascii one"));
    }
    let n_est = if binary { binary_count(b).unwrap_or(0) } else { b.len() as u64 / 100 };
    check_limits(opts, 0, n_est)?;
    let mut cur = std::io::Cursor::new(b);
    let mesh = if binary {
        // `stl_io` probes for ascii first; a binary header that starts with "solid" could
        // mislead it, so blank the 80-byte header in a copy when it does.
        if b.starts_with(b"solid") {
            let mut copy = b.to_vec();
            copy[..80].fill(b' ');
            stl_io::read_stl(&mut std::io::Cursor::new(copy))
        } else {
            stl_io::read_stl(&mut cur)
        }
    } else {
        stl_io::read_stl(&mut cur)
    }
    .map_err(|e| parse_err("STL", if binary { "binary body" } else { "ascii body" }, e.to_string()))?;
    let positions: Vec<[f64; 3]> = mesh.vertices.iter().map(|v| v.0.map(f64::from)).collect();
    let mut indices = Vec::with_capacity(mesh.faces.len() * 3);
    let mut dropped = 0usize;
    for f in &mesh.faces {
        let [a, b, c] = f.vertices;
        if a == b || b == c || a == c {
            dropped += 1;
            continue;
        }
        indices.extend([a as u32, b as u32, c as u32]);
    }
    let mut raw = RawMesh { positions, indices, ..Default::default() };
    if dropped > 0 {
        raw.warnings.push(Warning::new(
            "collapsed_faces",
            format!("{dropped} STL triangles collapsed after welding and were dropped"),
        ));
    }
    Ok(raw)
}

/// Writes binary STL (single precision, as the format requires; normals from the geometry).
pub(crate) fn write(mesh: &Mesh, out: &mut Vec<u8>) {
    let tris = mesh.faces().iter().enumerate().map(|(fi, f)| {
        let n = mesh.face_normal_raw(crate::mesh::FaceId::from_idx(fi));
        let n = if n.norm() > 0.0 { n.normalize() } else { n };
        let v = |i: usize| {
            let p = mesh.position(f[i]);
            stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32])
        };
        stl_io::Triangle {
            normal: stl_io::Vector::new([n.x as f32, n.y as f32, n.z as f32]),
            vertices: [v(0), v(1), v(2)],
        }
    });
    // Writing to a Vec cannot fail.
    let _ = stl_io::write_stl(out, tris);
}
