//! PLY reader (ascii, binary little and big endian; any property order and scalar types) on
//! top of `ply-rs-bw` with typed element structs, and a binary little-endian writer.
//!
//! Before the payload is parsed, the header's element counts are checked against the bytes
//! that follow it, so a lying header fails at once without allocating.

use super::options::{ReadOptions, check_limits};
use super::ply_binary;
use crate::error::{InputError, Result, parse_err};
use crate::mesh::{Mesh, RawMesh, V3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    BeginList, DefaultElement, ElementDef, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType,
    ScalarType,
};

pub(crate) fn sniff(b: &[u8]) -> bool {
    b.starts_with(b"ply\n") || b.starts_with(b"ply\r\n")
}

#[derive(Default)]
struct PVertex {
    p: [f64; 3],
    n: [f64; 3],
    c: [f64; 4],
    uv: [f64; 2],
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// Index of a vertex property in a 12-value record: x y z, nx ny nz, r g b a, u v.
fn slot_index(name: &str) -> Option<usize> {
    Some(match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        "nx" => 3,
        "ny" => 4,
        "nz" => 5,
        "red" | "r" => 6,
        "green" | "g" => 7,
        "blue" | "b" => 8,
        "alpha" | "a" => 9,
        "u" | "s" | "texture_u" | "texture_s" => 10,
        "v" | "t" | "texture_v" | "texture_t" => 11,
        _ => return None,
    })
}

impl PVertex {
    fn record(&self) -> [f64; 12] {
        let (p, n, c, t) = (self.p, self.n, self.c, self.uv);
        [p[0], p[1], p[2], n[0], n[1], n[2], c[0], c[1], c[2], c[3], t[0], t[1]]
    }

    fn slot(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "x" => &mut self.p[0],
            "y" => &mut self.p[1],
            "z" => &mut self.p[2],
            "nx" => &mut self.n[0],
            "ny" => &mut self.n[1],
            "nz" => &mut self.n[2],
            "red" | "r" => &mut self.c[0],
            "green" | "g" => &mut self.c[1],
            "blue" | "b" => &mut self.c[2],
            "alpha" | "a" => &mut self.c[3],
            "u" | "s" | "texture_u" | "texture_s" => &mut self.uv[0],
            "v" | "t" | "texture_v" | "texture_t" => &mut self.uv[1],
            _ => return None,
        })
    }
}

impl PropertyAccess for PVertex {
    fn new() -> Self {
        Self { c: [255.0; 4], ..Default::default() }
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        match (self.slot(name), scalar(&property)) {
            (Some(s), Some(v)) => {
                *s = v;
                PropertyAccessResult::Set
            }
            _ => PropertyAccessResult::Ignored,
        }
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        match self.slot(name) {
            Some(s) => {
                *s = f64::from(value);
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match self.slot(name) {
            Some(s) => {
                *s = value;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

#[derive(Default)]
struct PFace {
    idx: Vec<u32>,
    signed: Vec<i32>,
    bad: bool,
}

fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

impl PropertyAccess for PFace {
    fn new() -> Self {
        Self::default()
    }
    fn begin_list_uint(&mut self, name: &str, _len: usize) -> BeginList<'_, u32> {
        if is_index_list(name) { BeginList::Fill(&mut self.idx) } else { BeginList::UseSetter }
    }
    fn begin_list_int(&mut self, name: &str, _len: usize) -> BeginList<'_, i32> {
        if is_index_list(name) { BeginList::Fill(&mut self.signed) } else { BeginList::UseSetter }
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        match property.to_u32_list() {
            Some(l) => self.idx = l,
            None => self.bad = true,
        }
        PropertyAccessResult::Set
    }
}

impl PFace {
    fn take(&mut self) -> Option<Vec<u32>> {
        if self.bad {
            return None;
        }
        if !self.signed.is_empty() {
            return self.signed.iter().map(|&i| u32::try_from(i).ok()).collect();
        }
        Some(std::mem::take(&mut self.idx))
    }
}

fn scalar_size(s: &ScalarType) -> u64 {
    match s {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Smallest number of payload bytes an element row can take.
fn min_row_bytes(e: &ElementDef, enc: &Encoding) -> u64 {
    e.properties
        .values()
        .map(|p| match (&p.data_type, enc) {
            (_, Encoding::Ascii) => 2,
            (PropertyType::Scalar(s), _) => scalar_size(s),
            (PropertyType::List(c, _), _) => scalar_size(c),
        })
        .sum()
}

fn ply_err(e: ply_rs_bw::parser::ParseError, line: usize) -> crate::Error {
    let line = e.line().unwrap_or(line);
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        parse_err("PLY", format!("line {line}"), "unexpected end of data")
    } else {
        parse_err("PLY", format!("line {line}"), e.to_string())
    }
}

pub(crate) fn read(b: &[u8], opts: &ReadOptions) -> Result<RawMesh> {
    let vparser = Parser::<PVertex>::new();
    let fparser = Parser::<PFace>::new();
    let oparser = Parser::<DefaultElement>::new();
    let mut rd = Reader::new(b);
    let header = vparser.read_header(&mut rd).map_err(|e| ply_err(e, 0))?;
    let body_len = rd.get_ref().len() as u64;
    // Lying counts: compare what the header promises with what follows it.
    let mut need: u64 = 0;
    for e in header.elements.values() {
        need = need.saturating_add((e.count as u64).saturating_mul(min_row_bytes(e, &header.encoding)));
    }
    let count_of = |name: &str| header.elements.get(name).map_or(0, |e| e.count as u64);
    check_limits(opts, count_of("vertex"), count_of("face"))?;
    if need > body_len {
        return Err(InputError::LyingCount {
            format: "PLY",
            promised: format!(
                "{} (at least {need} bytes)",
                header.elements.values().map(|e| format!("{} {}", e.count, e.name)).collect::<Vec<_>>().join(", ")
            ),
            available: format!("{body_len} bytes after the header"),
        }
        .into());
    }
    let vdef = header.elements.get("vertex").ok_or_else(|| parse_err("PLY", "header", "no vertex element"))?;
    let has = |names: &[&str]| names.iter().all(|n| vdef.properties.contains_key(*n));
    for axis in ["x", "y", "z"] {
        if !vdef.properties.contains_key(axis) {
            return Err(parse_err("PLY", "header", format!("vertex element has no {axis} property")));
        }
    }
    let mut raw = RawMesh::default();
    let mut verts: Vec<[f64; 12]> = Vec::new();
    let mut face_indices: Vec<u32> = Vec::new();
    let mut face_sizes: Vec<u32> = Vec::new();
    if let Some(def) = header.elements.get("face")
        && !def.properties.keys().any(|k| is_index_list(k))
    {
        return Err(parse_err("PLY", "header", "face element has no vertex_indices list"));
    }
    match header.encoding {
        Encoding::Ascii => {
            for (name, def) in &header.elements {
                let line = rd.line();
                match name.as_str() {
                    "vertex" => {
                        let v: Vec<PVertex> =
                            vparser.read_payload_for_element(&mut rd, def, &header).map_err(|e| ply_err(e, line))?;
                        verts = v.iter().map(PVertex::record).collect();
                    }
                    "face" => {
                        let faces =
                            fparser.read_payload_for_element(&mut rd, def, &header).map_err(|e| ply_err(e, line))?;
                        for (f, mut face) in faces.into_iter().enumerate() {
                            let idx = face
                                .take()
                                .ok_or_else(|| parse_err("PLY", format!("face {f}"), "negative vertex index"))?;
                            face_sizes.push(idx.len() as u32);
                            face_indices.extend_from_slice(&idx);
                        }
                    }
                    _ => {
                        oparser.read_payload_for_element(&mut rd, def, &header).map_err(|e| ply_err(e, line))?;
                    }
                }
            }
        }
        Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
            let elements: Vec<&ElementDef> = header.elements.values().collect();
            let big = matches!(header.encoding, Encoding::BinaryBigEndian);
            let d = ply_binary::decode(rd.get_ref(), big, &elements, &slot_index, PVertex::new().record())?;
            verts = d.vertex_values;
            face_indices = d.face_indices;
            face_sizes = d.face_sizes;
        }
    }
    raw.positions = verts.iter().map(|v| [v[0], v[1], v[2]]).collect();
    if has(&["nx", "ny", "nz"]) {
        raw.attributes.normals = Some(verts.iter().map(|v| V3::new(v[3], v[4], v[5])).collect());
    }
    if has(&["red", "green", "blue"]) {
        let float = matches!(
            vdef.properties.get("red").map(|p| &p.data_type),
            Some(PropertyType::Scalar(ScalarType::Float | ScalarType::Double))
        );
        let conv = |x: f64| if float { (x * 255.0).round().clamp(0.0, 255.0) as u8 } else { x.clamp(0.0, 255.0) as u8 };
        raw.attributes.colors = Some(verts.iter().map(|v| [conv(v[6]), conv(v[7]), conv(v[8]), conv(v[9])]).collect());
    }
    if has(&["u", "v"]) || has(&["s", "t"]) || has(&["texture_u", "texture_v"]) {
        raw.attributes.uvs = Some(verts.iter().map(|v| [v[10], v[11]]).collect());
    }
    // Faces smaller than triangles are refused by `Mesh::from_raw`, which sees the sizes.
    let all_tri = face_sizes.iter().all(|&k| k == 3);
    raw.indices = face_indices;
    raw.sizes = (!all_tri).then_some(face_sizes);
    Ok(raw)
}

/// Writes binary little-endian PLY: double coordinates (no precision loss), optional double
/// normals, uchar RGBA colours and double `s t`; faces as `uchar`-counted `int` lists.
pub(crate) fn write(mesh: &Mesh, out: &mut Vec<u8>) {
    write_with_face_ints(mesh, &[], out);
}

/// Binary PLY with extra per-face integer properties (e.g. a patch id), each `(name, values)`.
pub fn write_with_face_ints(mesh: &Mesh, face_props: &[(&str, &[i32])], out: &mut Vec<u8>) {
    let a = mesh.attributes();
    let mut h =
        format!("ply\nformat binary_little_endian 1.0\ncomment surfmap\nelement vertex {}\n", mesh.n_vertices());
    h.push_str("property double x\nproperty double y\nproperty double z\n");
    if a.normals.is_some() {
        h.push_str("property double nx\nproperty double ny\nproperty double nz\n");
    }
    if a.colors.is_some() {
        h.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n");
    }
    if a.uvs.is_some() {
        h.push_str("property double s\nproperty double t\n");
    }
    h.push_str(&format!("element face {}\nproperty list uchar int vertex_indices\n", mesh.n_faces()));
    for (name, _) in face_props {
        h.push_str(&format!("property int {name}\n"));
    }
    h.push_str("end_header\n");
    out.reserve(h.len() + mesh.n_vertices() * 24 + mesh.n_faces() * (13 + 4 * face_props.len()));
    out.extend_from_slice(h.as_bytes());
    for (i, p) in mesh.positions().iter().enumerate() {
        for c in [p.x, p.y, p.z] {
            out.extend_from_slice(&c.to_le_bytes());
        }
        if let Some(n) = &a.normals {
            for c in [n[i].x, n[i].y, n[i].z] {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        if let Some(c) = &a.colors {
            out.extend_from_slice(&c[i]);
        }
        if let Some(t) = &a.uvs {
            out.extend_from_slice(&t[i][0].to_le_bytes());
            out.extend_from_slice(&t[i][1].to_le_bytes());
        }
    }
    for (fi, f) in mesh.faces().iter().enumerate() {
        out.push(3);
        for v in f {
            out.extend_from_slice(&(v.0 as i32).to_le_bytes());
        }
        for (_, vals) in face_props {
            out.extend_from_slice(&vals.get(fi).copied().unwrap_or(0).to_le_bytes());
        }
    }
}
