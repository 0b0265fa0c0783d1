//! Binary PLY payload decoding (both byte orders) straight from the byte slice, driven by the
//! header that `ply-rs-bw` parsed. Faces go into one flat index array, with no allocation per
//! element; every read is bounds-checked, so truncated data is a parse error, never a panic.

use crate::error::{Result, parse_err};
use ply_rs_bw::ply::{ElementDef, PropertyType, ScalarType};

/// The decoded payload: one entry per vertex, and faces as flat indices plus sizes.
pub(crate) struct Decoded {
    /// Vertex values in the order of `slots` (see [`decode`]).
    pub vertex_values: Vec<[f64; 12]>,
    pub face_indices: Vec<u32>,
    pub face_sizes: Vec<u32>,
}

struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
    big: bool,
}

impl Cursor<'_> {
    #[inline]
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let end = self.pos + N;
        let s = self
            .b
            .get(self.pos..end)
            .ok_or_else(|| parse_err("PLY", format!("byte {}", self.pos), "unexpected end of data"))?;
        self.pos = end;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.big {
            a.reverse();
        }
        Ok(a)
    }

    #[inline]
    fn scalar(&mut self, t: &ScalarType) -> Result<f64> {
        Ok(match t {
            ScalarType::Char => f64::from(i8::from_le_bytes(self.take::<1>()?)),
            ScalarType::UChar => f64::from(u8::from_le_bytes(self.take::<1>()?)),
            ScalarType::Short => f64::from(i16::from_le_bytes(self.take::<2>()?)),
            ScalarType::UShort => f64::from(u16::from_le_bytes(self.take::<2>()?)),
            ScalarType::Int => f64::from(i32::from_le_bytes(self.take::<4>()?)),
            ScalarType::UInt => f64::from(u32::from_le_bytes(self.take::<4>()?)),
            ScalarType::Float => f64::from(f32::from_le_bytes(self.take::<4>()?)),
            ScalarType::Double => f64::from_le_bytes(self.take::<8>()?),
        })
    }

    /// An integer scalar (list counts and indices); `None` for negative or fractional values.
    #[inline]
    fn index(&mut self, t: &ScalarType) -> Result<Option<u32>> {
        let v = self.scalar(t)?;
        Ok((v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0).then_some(v as u32))
    }
}

/// Decodes all elements of a binary payload. `slot_of(name)` maps a vertex property to its
/// index in the 12-value vertex record (or `None` to ignore it); `defaults` fills records.
pub(crate) fn decode(
    payload: &[u8],
    big_endian: bool,
    elements: &[&ElementDef],
    slot_of: &dyn Fn(&str) -> Option<usize>,
    defaults: [f64; 12],
) -> Result<Decoded> {
    let mut c = Cursor { b: payload, pos: 0, big: big_endian };
    let mut out = Decoded { vertex_values: Vec::new(), face_indices: Vec::new(), face_sizes: Vec::new() };
    for e in elements {
        let props: Vec<_> = e.properties.values().collect();
        match e.name.as_str() {
            "vertex" => {
                let slots: Vec<Option<usize>> = props.iter().map(|p| slot_of(&p.name)).collect();
                out.vertex_values.reserve(e.count);
                for _ in 0..e.count {
                    let mut rec = defaults;
                    for (p, slot) in props.iter().zip(&slots) {
                        match &p.data_type {
                            PropertyType::Scalar(t) => {
                                let v = c.scalar(t)?;
                                if let Some(s) = slot {
                                    rec[*s] = v;
                                }
                            }
                            PropertyType::List(ct, it) => skip_list(&mut c, ct, it)?,
                        }
                    }
                    out.vertex_values.push(rec);
                }
            }
            "face" => {
                out.face_indices.reserve(e.count.saturating_mul(3));
                out.face_sizes.reserve(e.count);
                for f in 0..e.count {
                    for p in &props {
                        match &p.data_type {
                            PropertyType::List(ct, it) if p.name == "vertex_indices" || p.name == "vertex_index" => {
                                let k = c
                                    .index(ct)?
                                    .ok_or_else(|| parse_err("PLY", format!("face {f}"), "invalid list length"))?;
                                if k as usize > payload.len() {
                                    return Err(parse_err(
                                        "PLY",
                                        format!("face {f}"),
                                        format!("list length {k} exceeds the data"),
                                    ));
                                }
                                for _ in 0..k {
                                    let i = c.index(it)?.ok_or_else(|| {
                                        parse_err("PLY", format!("face {f}"), "negative vertex index")
                                    })?;
                                    out.face_indices.push(i);
                                }
                                out.face_sizes.push(k);
                            }
                            PropertyType::List(ct, it) => skip_list(&mut c, ct, it)?,
                            PropertyType::Scalar(t) => {
                                c.scalar(t)?;
                            }
                        }
                    }
                }
            }
            _ => {
                for _ in 0..e.count {
                    for p in &props {
                        match &p.data_type {
                            PropertyType::Scalar(t) => {
                                c.scalar(t)?;
                            }
                            PropertyType::List(ct, it) => skip_list(&mut c, ct, it)?,
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}

fn skip_list(c: &mut Cursor, ct: &ScalarType, it: &ScalarType) -> Result<()> {
    let k = c.index(ct)?.ok_or_else(|| parse_err("PLY", format!("byte {}", c.pos), "invalid list length"))?;
    for _ in 0..k {
        c.scalar(it)?;
    }
    Ok(())
}
