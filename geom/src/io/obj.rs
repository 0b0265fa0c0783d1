//! Wavefront OBJ reader and writer with f64 precision, preserving vertex order.
//!
//! Written here rather than with `tobj`: tobj renumbers vertices by first use in each object
//! (which breaks index-based correspondences such as ground truth) and hashes every corner.
//! Reads `v` (optionally with `r g b` colours), `vt`, `vn` and `f` in every index form
//! (`v`, `v/vt`, `v//vn`, `v/vt/vn`, negative = relative); other statements are ignored.
//! Per-corner `vt`/`vn` become per-vertex attributes when each vertex uses one of each.

use super::lex::{Lex, parse_f64, parse_i64, show};
use super::obj_seams::Corners;
use super::options::{ReadOptions, check_limits};
use crate::error::{InputError, Result};
use crate::mesh::layout::VertexIds;
use crate::mesh::{InputLayout, Mesh, RawMesh, V3, Warning};

/// Cheap content check: a text file whose statements are OBJ keywords.
pub(crate) fn sniff(b: &[u8]) -> bool {
    let head = &b[..b.len().min(4096)];
    if head.contains(&0) {
        return false;
    }
    head.split(|&c| c == b'\n').any(|l| {
        let l = l.trim_ascii_start();
        l.starts_with(b"v ")
            || l.starts_with(b"f ")
            || l.starts_with(b"vn ")
            || l.starts_with(b"vt ")
            || l.starts_with(b"v\t")
            || l.starts_with(b"f\t")
    })
}

fn resolve(lx: &Lex, t: &[u8], count: usize, what: &str) -> Result<u32> {
    let i = parse_i64(t).ok_or_else(|| lx.err(format!("invalid {what} index {:?}", show(t))))?;
    let r = if i > 0 {
        i - 1
    } else if i < 0 {
        count as i64 + i
    } else {
        -1
    };
    if r < 0 || r >= i64::from(u32::MAX) {
        return Err(lx.err(format!("{what} index {i} is out of range ({count} defined so far)")));
    }
    Ok(r as u32)
}

const NONE: u32 = u32::MAX;

/// Reads an OBJ file.
///
/// When the corners of a vertex use different `vt` or `vn` (seams) and every face is a
/// triangle, the input's own layout comes back too: one input vertex per `(v, vt, vn)`.
pub(crate) fn read(b: &[u8], opts: &ReadOptions) -> Result<(RawMesh, Option<InputLayout>)> {
    let mut lx = Lex::new(b, "OBJ");
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut colors: Vec<[u8; 4]> = Vec::new();
    let mut vts: Vec<[f64; 2]> = Vec::new();
    let mut vns: Vec<V3> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut corner_vt: Vec<u32> = Vec::new();
    let mut corner_vn: Vec<u32> = Vec::new();
    let mut sizes: Vec<u32> = Vec::new();
    let mut all_tri = true;
    let mut n_faces: u64 = 0;
    let mut warnings = Vec::new();
    let mut ignored_lines = 0usize;
    loop {
        lx.skip_ws();
        let Some(kw) = lx.inline_token() else { break };
        match kw {
            b"v" => {
                let p = [lx.inline_f64("x")?, lx.inline_f64("y")?, lx.inline_f64("z")?];
                if positions.len() as u64 >= opts.limits.max_vertices {
                    check_limits(opts, positions.len() as u64 + 1, 0)?;
                }
                positions.push(p);
                // Optional w or r g b.
                let mut rest = [0.0f64; 4];
                let mut n = 0;
                while let Some(t) = lx.inline_token() {
                    if n < 4 {
                        rest[n] = parse_f64(t).ok_or_else(|| lx.err(format!("invalid number {:?}", show(t))))?;
                    }
                    n += 1;
                }
                if n == 3 {
                    if colors.len() + 1 < positions.len() {
                        colors.resize(positions.len() - 1, [255, 255, 255, 255]);
                    }
                    let c = |x: f64| (x * 255.0).round().clamp(0.0, 255.0) as u8;
                    colors.push([c(rest[0]), c(rest[1]), c(rest[2]), 255]);
                }
            }
            b"vt" => {
                let u = lx.inline_f64("u")?;
                let v = if lx.at_line_end() { 0.0 } else { lx.inline_f64("v")? };
                vts.push([u, v]);
            }
            b"vn" => {
                vns.push(V3::new(lx.inline_f64("nx")?, lx.inline_f64("ny")?, lx.inline_f64("nz")?));
            }
            b"f" => {
                let mut k = 0u32;
                while let Some(t) = lx.inline_token() {
                    let mut parts = t.splitn(3, |&c| c == b'/');
                    let v = parts.next().unwrap_or_default();
                    indices.push(resolve(&lx, v, positions.len(), "vertex")?);
                    let vt = parts.next().filter(|p| !p.is_empty());
                    let vn = parts.next().filter(|p| !p.is_empty());
                    corner_vt.push(match vt {
                        Some(t) => resolve(&lx, t, vts.len(), "texture")?,
                        None => NONE,
                    });
                    corner_vn.push(match vn {
                        Some(t) => resolve(&lx, t, vns.len(), "normal")?,
                        None => NONE,
                    });
                    k += 1;
                }
                if k < 3 {
                    return Err(InputError::FaceTooSmall { face: n_faces as usize, count: k as usize }.into());
                }
                if k != 3 && all_tri {
                    all_tri = false;
                    sizes = vec![3; n_faces as usize];
                }
                if !all_tri {
                    sizes.push(k);
                }
                n_faces += u64::from(k - 2);
                if n_faces > opts.limits.max_faces {
                    check_limits(opts, 0, n_faces)?;
                }
            }
            _ => {
                let known = [
                    &b"o"[..],
                    b"g",
                    b"s",
                    b"usemtl",
                    b"mtllib",
                    b"l",
                    b"p",
                    b"vp",
                    b"cstype",
                    b"deg",
                    b"curv",
                    b"surf",
                ];
                if !known.contains(&kw) {
                    ignored_lines += 1;
                }
            }
        }
        if !lx.at_line_end() {
            // Trailing tokens (e.g. after `vn`): ignore.
        }
        lx.skip_line();
    }
    if positions.is_empty() && indices.is_empty() {
        return Err(InputError::Empty("OBJ file has no vertices or faces".into()).into());
    }
    if ignored_lines > 0 {
        warnings
            .push(Warning::new("unknown_statements", format!("{ignored_lines} unknown OBJ statements were ignored")));
    }
    let nv = positions.len();
    let mut raw = RawMesh { positions, indices, sizes: (!all_tri).then_some(sizes), warnings, ..Default::default() };
    if !colors.is_empty() {
        colors.resize(nv, [255, 255, 255, 255]);
        raw.attributes.colors = Some(colors);
    }
    raw.attributes.uvs = per_vertex(&raw, &corner_vt, &vts, "texture coordinates");
    raw.attributes.normals = per_vertex(&raw, &corner_vn, &vns, "normals");
    let seams =
        (!vts.is_empty() && raw.attributes.uvs.is_none()) || (!vns.is_empty() && raw.attributes.normals.is_none());
    if seams && all_tri && corner_vt.len() == raw.indices.len() && corner_vn.len() == raw.indices.len() {
        let c = Corners {
            positions: &raw.positions,
            indices: &raw.indices,
            vt: &corner_vt,
            vts: &vts,
            vn: &corner_vn,
            vns: &vns,
        };
        let (welded, split) = c.split();
        let layout =
            InputLayout { welded, triangles: split.triangles, attributes: split.attributes, ids: VertexIds::Welded };
        return Ok((raw, Some(layout)));
    }
    if !vts.is_empty() && raw.attributes.uvs.is_none() {
        raw.warnings
            .push(Warning::new("uv_seams", "texture coordinates differ per corner (seams); not kept per vertex"));
    }
    if !vns.is_empty() && raw.attributes.normals.is_none() {
        raw.warnings.push(Warning::new("normal_seams", "normals differ per corner; not kept per vertex"));
    }
    Ok((raw, None))
}

/// Turns per-corner attribute indices into per-vertex values when they are consistent.
fn per_vertex<T: Clone>(raw: &RawMesh, corner: &[u32], values: &[T], _what: &str) -> Option<Vec<T>> {
    if values.is_empty() {
        return None;
    }
    let nv = raw.positions.len();
    let mut of = vec![NONE; nv];
    for (&v, &a) in raw.indices.iter().zip(corner) {
        if a == NONE || a as usize >= values.len() || v as usize >= nv {
            return None;
        }
        let slot = &mut of[v as usize];
        if *slot == NONE {
            *slot = a;
        } else if *slot != a {
            return None;
        }
    }
    if of.contains(&NONE) {
        // Unreferenced vertices: give them the first value; they are removed later anyway.
        for a in &mut of {
            if *a == NONE {
                *a = 0;
            }
        }
    }
    Some(of.iter().map(|&a| values[a as usize].clone()).collect())
}

/// Writes OBJ (`v`, optional `vt`/`vn`, 1-based `f`), shortest round-trip decimal floats.
pub(crate) fn write(mesh: &Mesh, out: &mut Vec<u8>) {
    use std::io::Write;
    let a = mesh.attributes();
    out.reserve(mesh.n_vertices() * 48 + mesh.n_faces() * 24);
    for (i, p) in mesh.positions().iter().enumerate() {
        match &a.colors {
            Some(c) => {
                let c = c[i];
                let _ = writeln!(
                    out,
                    "v {} {} {} {} {} {}",
                    p.x,
                    p.y,
                    p.z,
                    f64::from(c[0]) / 255.0,
                    f64::from(c[1]) / 255.0,
                    f64::from(c[2]) / 255.0
                );
            }
            None => {
                let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
            }
        }
    }
    if let Some(t) = &a.uvs {
        for t in t {
            let _ = writeln!(out, "vt {} {}", t[0], t[1]);
        }
    }
    if let Some(n) = &a.normals {
        for n in n {
            let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
        }
    }
    let (t, n) = (a.uvs.is_some(), a.normals.is_some());
    for f in mesh.faces() {
        let [x, y, z] = f.map(|v| v.0 + 1);
        let _ = match (t, n) {
            (false, false) => writeln!(out, "f {x} {y} {z}"),
            (true, false) => writeln!(out, "f {x}/{x} {y}/{y} {z}/{z}"),
            (false, true) => writeln!(out, "f {x}//{x} {y}//{y} {z}//{z}"),
            (true, true) => writeln!(out, "f {x}/{x}/{x} {y}/{y}/{y} {z}/{z}/{z}"),
        };
    }
}

/// Writes patches as one OBJ: every patch's vertices with their parameter coordinates as `vt`,
/// and its faces under `g patch_<p>` as `f a/a b/b c/c`.
pub fn write_uv_patches(patches: &[(&Mesh, &[[f64; 2]])]) -> Vec<u8> {
    use std::io::Write;
    let mut out = Vec::new();
    let mut base = 1usize;
    for (p, (mesh, uv)) in patches.iter().enumerate() {
        for (x, t) in mesh.positions().iter().zip(uv.iter()) {
            let _ = writeln!(out, "v {} {} {}\nvt {} {}", x.x, x.y, x.z, t[0], t[1]);
        }
        let _ = writeln!(out, "g patch_{p}");
        for f in mesh.faces() {
            let [a, b, c] = f.map(|v| v.idx() + base);
            let _ = writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}");
        }
        base += mesh.n_vertices();
    }
    out
}

/// Writes OBJ in an input's own layout: one `v` per welded vertex (`positions`), `vt` / `vn`
/// per input vertex (its first UV set and normals, when it has them) and faces `v/vt/vn`.
pub fn write_layout(positions: &[crate::mesh::P3], layout: &InputLayout) -> Vec<u8> {
    use std::io::Write;
    let mut out = Vec::with_capacity(positions.len() * 48 + layout.triangles.len() * 32);
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    let uv = layout.attributes.texcoords.first();
    for t in uv.into_iter().flatten() {
        let _ = writeln!(out, "vt {} {}", t[0], t[1]);
    }
    let nrm = layout.attributes.normals.as_ref();
    for n in nrm.into_iter().flatten() {
        let _ = writeln!(out, "vn {} {} {}", n[0], n[1], n[2]);
    }
    for t in &layout.triangles {
        let _ = write!(out, "f");
        for &i in t {
            let v = layout.welded[i as usize] + 1;
            let i = i + 1;
            let _ = match (uv.is_some(), nrm.is_some()) {
                (false, false) => write!(out, " {v}"),
                (true, false) => write!(out, " {v}/{i}"),
                (false, true) => write!(out, " {v}//{i}"),
                (true, true) => write!(out, " {v}/{i}/{i}"),
            };
        }
        let _ = writeln!(out);
    }
    out
}
