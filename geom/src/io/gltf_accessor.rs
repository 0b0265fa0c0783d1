//! glTF accessors read into `f64` components, with every offset, stride and count checked
//! against its buffer before anything is read: component types `BYTE` .. `FLOAT`, normalized
//! integers (`KHR_mesh_quantization`), interleaved views and sparse accessors.

use crate::error::{InputError, Result, parse_err};
use gltf::accessor::{DataType, Dimensions};

/// The loaded buffers of a document, by index.
pub(crate) struct Buffers<'a>(pub Vec<&'a [u8]>);

fn size_of(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

fn dims(d: Dimensions) -> Option<usize> {
    match d {
        Dimensions::Scalar => Some(1),
        Dimensions::Vec2 => Some(2),
        Dimensions::Vec3 => Some(3),
        Dimensions::Vec4 => Some(4),
        _ => None,
    }
}

fn component(b: &[u8], t: DataType, normalized: bool) -> f64 {
    match (t, normalized) {
        (DataType::I8, false) => f64::from(b[0] as i8),
        (DataType::I8, true) => (f64::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::U8, false) => f64::from(b[0]),
        (DataType::U8, true) => f64::from(b[0]) / 255.0,
        (DataType::I16, false) => f64::from(i16::from_le_bytes([b[0], b[1]])),
        (DataType::I16, true) => (f64::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0),
        (DataType::U16, false) => f64::from(u16::from_le_bytes([b[0], b[1]])),
        (DataType::U16, true) => f64::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        (DataType::U32, _) => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        (DataType::F32, _) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

fn err(acc: usize, message: impl Into<String>) -> crate::Error {
    parse_err("glTF", format!("accessors[{acc}]"), message)
}

impl Buffers<'_> {
    /// The bytes of a buffer view, checked against its buffer.
    fn view(&self, v: &gltf::buffer::View, acc: usize) -> Result<&[u8]> {
        let buf = self.0.get(v.buffer().index()).ok_or_else(|| err(acc, "buffer view names a missing buffer"))?;
        let end = v.offset().checked_add(v.length()).ok_or_else(|| err(acc, "buffer view range overflows"))?;
        if end > buf.len() {
            return Err(InputError::LyingCount {
                format: "glTF",
                promised: format!("bufferViews[{}] ending at byte {end}", v.index()),
                available: format!("{} bytes in buffers[{}]", buf.len(), v.buffer().index()),
            }
            .into());
        }
        Ok(&buf[v.offset()..end])
    }

    /// `count` elements of `n` components of type `t` starting at `offset` of `view` with
    /// `stride` bytes between elements, appended to `out`.
    #[allow(clippy::too_many_arguments)]
    fn strided(
        &self,
        bytes: &[u8],
        offset: usize,
        stride: usize,
        count: usize,
        (t, n, normalized): (DataType, usize, bool),
        acc: usize,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        let elem = size_of(t) * n;
        if count == 0 {
            return Ok(());
        }
        let need = (count - 1).checked_mul(stride).and_then(|x| x.checked_add(offset + elem));
        match need {
            Some(need) if need <= bytes.len() => {}
            _ => {
                return Err(InputError::LyingCount {
                    format: "glTF",
                    promised: format!("accessors[{acc}]: {count} elements of {elem} bytes, stride {stride}"),
                    available: format!("{} bytes in its buffer view from offset {offset}", bytes.len()),
                }
                .into());
            }
        }
        out.reserve(count * n);
        for i in 0..count {
            let at = offset + i * stride;
            for c in 0..n {
                let s = at + c * size_of(t);
                out.push(component(&bytes[s..s + size_of(t)], t, normalized));
            }
        }
        Ok(())
    }

    /// An accessor's values as `count * n` components (`n` = 1..4), sparse substitution
    /// applied. `max_count` bounds the element count before anything is allocated.
    pub(crate) fn read(&self, a: &gltf::Accessor, max_count: usize) -> Result<(Vec<f64>, usize)> {
        let i = a.index();
        let n = dims(a.dimensions()).ok_or_else(|| err(i, "matrix accessors are not vertex data"))?;
        let (t, count) = (a.data_type(), a.count());
        if count > max_count {
            return Err(InputError::TooLarge {
                what: "accessor elements",
                count: count as u64,
                limit: max_count as u64,
            }
            .into());
        }
        let mut out = Vec::new();
        match a.view() {
            Some(v) => {
                let bytes = self.view(&v, i)?;
                let stride = v.stride().unwrap_or(size_of(t) * n);
                if stride < size_of(t) * n {
                    return Err(err(i, format!("byteStride {stride} is smaller than one element")));
                }
                self.strided(bytes, a.offset(), stride, count, (t, n, a.normalized()), i, &mut out)?;
            }
            None => out.resize(count * n, 0.0),
        }
        if let Some(sp) = a.sparse() {
            let m = sp.count();
            if m > count {
                return Err(err(i, format!("sparse count {m} exceeds the accessor count {count}")));
            }
            let it = sp.indices().index_type();
            let it = match it {
                gltf::accessor::sparse::IndexType::U8 => DataType::U8,
                gltf::accessor::sparse::IndexType::U16 => DataType::U16,
                gltf::accessor::sparse::IndexType::U32 => DataType::U32,
            };
            let mut idx = Vec::new();
            let ib = self.view(&sp.indices().view(), i)?;
            self.strided(ib, sp.indices().offset(), size_of(it), m, (it, 1, false), i, &mut idx)?;
            let mut vals = Vec::new();
            let vb = self.view(&sp.values().view(), i)?;
            self.strided(vb, sp.values().offset(), size_of(t) * n, m, (t, n, a.normalized()), i, &mut vals)?;
            for (k, &j) in idx.iter().enumerate() {
                let j = j as usize;
                if j >= count {
                    return Err(err(i, format!("sparse index {j} is out of range (count {count})")));
                }
                out[j * n..(j + 1) * n].copy_from_slice(&vals[k * n..(k + 1) * n]);
            }
        }
        Ok((out, n))
    }
}
