//! OFF reader and writer (Geomview's `[ST][C][N]OFF` variants), with f64 precision.
//!
//! Vertex lines are `x y z [nx ny nz] [r g b [a]] [s t]`; faces are `k i1 .. ik [colour]`.
//! Header counts are checked against the bytes left before anything is allocated.

use super::lex::{Lex, parse_f64, show};
use super::options::{ReadOptions, check_limits};
use crate::error::{InputError, Result};
use crate::mesh::{Mesh, RawMesh, V3};

struct Header {
    st: bool,
    color: bool,
    normal: bool,
}

fn header_kind(t: &[u8]) -> Option<Header> {
    let s = std::str::from_utf8(t).ok()?;
    let mut rest = s.strip_suffix("OFF")?;
    let st = rest.starts_with("ST");
    if st {
        rest = &rest[2..];
    }
    let color = rest.starts_with('C');
    if color {
        rest = &rest[1..];
    }
    let normal = rest.starts_with('N');
    if normal {
        rest = &rest[1..];
    }
    rest.is_empty().then_some(Header { st, color, normal })
}

/// True when the bytes look like OFF (after comments, a `[ST][C][N]OFF` keyword).
pub(crate) fn sniff(b: &[u8]) -> bool {
    let mut lx = Lex::new(b, "OFF");
    lx.token().is_some_and(|t| header_kind(t).is_some() || (t.len() > 3 && t.ends_with(b"OFF")))
}

/// Reads an OFF file.
pub(crate) fn read(b: &[u8], opts: &ReadOptions) -> Result<RawMesh> {
    let mut lx = Lex::new(b, "OFF");
    let t = lx.token().ok_or_else(|| InputError::Empty("OFF file has no content".into()))?;
    let h = header_kind(t).ok_or_else(|| {
        if t.ends_with(b"OFF") {
            lx.err(format!("unsupported OFF variant {:?} (4D and n-dimensional OFF are not supported)", show(t)))
        } else {
            lx.err(format!("expected an OFF keyword, found {:?}", show(t)))
        }
    })?;
    let nv = lx.u64("vertex count")?;
    let nf = lx.u64("face count")?;
    let _ne = lx.u64("edge count")?;
    check_limits(opts, nv, nf)?;
    // Smallest possible vertex: "0 0 0\n" (6 bytes); face: "3 0 1 2" plus a separator
    // (7 bytes with the separator counted once); the last line may lack its newline.
    let per_v = 6 + if h.normal { 6 } else { 0 } + if h.color { 6 } else { 0 } + if h.st { 4 } else { 0 };
    let need = nv.saturating_mul(per_v).saturating_add(nf.saturating_mul(7)).saturating_sub(1);
    if need > lx.remaining() as u64 {
        return Err(InputError::LyingCount {
            format: "OFF",
            promised: format!("{nv} vertices and {nf} faces (at least {need} bytes)"),
            available: format!("{} bytes", lx.remaining()),
        }
        .into());
    }
    let (nv, nf) = (nv as usize, nf as usize);
    let mut positions = Vec::with_capacity(nv);
    let mut normals = h.normal.then(|| Vec::with_capacity(nv));
    let mut colors = h.color.then(|| Vec::with_capacity(nv));
    let mut uvs = h.st.then(|| Vec::with_capacity(nv));
    let plain = !h.normal && !h.color && !h.st;
    let mut extra: Vec<f64> = Vec::with_capacity(8);
    let mut color_is_float = None;
    for _ in 0..nv {
        let p = [lx.f64("x")?, lx.f64("y")?, lx.f64("z")?];
        positions.push(p);
        if plain {
            continue;
        }
        if let Some(n) = normals.as_mut() {
            n.push(V3::new(lx.inline_f64("nx")?, lx.inline_f64("ny")?, lx.inline_f64("nz")?));
        }
        extra.clear();
        let mut any_dot = false;
        while let Some(t) = lx.inline_token() {
            any_dot |= t.iter().any(|&c| c == b'.' || c == b'e' || c == b'E');
            extra.push(parse_f64(t).ok_or_else(|| lx.err(format!("invalid number {:?}", show(t))))?);
        }
        let mut rest = &extra[..];
        if let Some(u) = uvs.as_mut() {
            if rest.len() < 2 {
                return Err(lx.err("expected texture coordinates s t"));
            }
            u.push([rest[rest.len() - 2], rest[rest.len() - 1]]);
            rest = &rest[..rest.len() - 2];
        }
        if let Some(c) = colors.as_mut() {
            if rest.len() != 3 && rest.len() != 4 {
                return Err(lx.err(format!("expected 3 or 4 colour components, found {}", rest.len())));
            }
            let is_float = *color_is_float.get_or_insert(any_dot);
            let conv =
                |x: f64| if is_float { (x * 255.0).round().clamp(0.0, 255.0) as u8 } else { x.clamp(0.0, 255.0) as u8 };
            let a = if rest.len() == 4 { conv(rest[3]) } else { 255 };
            c.push([conv(rest[0]), conv(rest[1]), conv(rest[2]), a]);
        }
    }
    let mut indices = Vec::with_capacity(nf * 3);
    let mut sizes: Vec<u32> = Vec::new();
    let mut all_tri = true;
    for f in 0..nf {
        let k = lx.u64("face vertex count")?;
        if k < 3 {
            return Err(InputError::FaceTooSmall { face: f, count: k as usize }.into());
        }
        if k as usize > lx.remaining() / 2 + 1 {
            return Err(lx.err(format!("face {f} claims {k} vertices, more than the file holds")));
        }
        if k != 3 && all_tri {
            all_tri = false;
            sizes = vec![3; f];
        }
        for j in 0..k {
            let t = lx
                .inline_token()
                .ok_or_else(|| lx.err(format!("face {f} declares {k} vertices but its line holds {j}")))?;
            let i = super::lex::parse_u64(t)
                .filter(|&i| i <= u64::from(u32::MAX - 1))
                .ok_or_else(|| lx.err(format!("invalid vertex index {:?} in face {f}", show(t))))?;
            indices.push(i as u32);
        }
        if !all_tri {
            sizes.push(k as u32);
        }
        // Optional face colour: ignore the rest of the line.
        if !lx.at_line_end() {
            lx.skip_line();
        }
    }
    let mut raw = RawMesh { positions, indices, sizes: (!all_tri).then_some(sizes), ..Default::default() };
    raw.attributes.normals = normals;
    raw.attributes.colors = colors;
    raw.attributes.uvs = uvs;
    Ok(raw)
}

/// Writes OFF, choosing the `[ST][C][N]OFF` keyword from the attributes present.
pub(crate) fn write(mesh: &Mesh, out: &mut Vec<u8>) {
    use std::io::Write;
    let a = mesh.attributes();
    let mut kw = String::new();
    if a.uvs.is_some() {
        kw.push_str("ST");
    }
    if a.colors.is_some() {
        kw.push('C');
    }
    if a.normals.is_some() {
        kw.push('N');
    }
    kw.push_str("OFF");
    let _ = writeln!(out, "{kw}\n{} {} 0", mesh.n_vertices(), mesh.n_faces());
    for (i, p) in mesh.positions().iter().enumerate() {
        let _ = write!(out, "{} {} {}", p.x, p.y, p.z);
        if let Some(n) = &a.normals {
            let _ = write!(out, " {} {} {}", n[i].x, n[i].y, n[i].z);
        }
        if let Some(c) = &a.colors {
            let _ = write!(out, " {} {} {} {}", c[i][0], c[i][1], c[i][2], c[i][3]);
        }
        if let Some(t) = &a.uvs {
            let _ = write!(out, " {} {}", t[i][0], t[i][1]);
        }
        out.push(b'\n');
    }
    for f in mesh.faces() {
        let _ = writeln!(out, "3 {} {} {}", f[0], f[1], f[2]);
    }
}
