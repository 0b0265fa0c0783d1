//! 16-bit RGB PNG encoding (the `png` crate) for geometry images and normal maps.

use crate::error::{Error, Result};

/// Encodes `w × h` pixels of 16-bit RGB (row-major, top row first).
///
/// # Errors
/// `Internal` if the encoder fails (it writes to memory, so only on a bug).
pub fn write_rgb16(w: u32, h: u32, pixels: &[[u16; 3]]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Sixteen);
        let mut wr = enc.write_header().map_err(|e| Error::Internal(format!("png: {e}")))?;
        let mut data = Vec::with_capacity(pixels.len() * 6);
        for p in pixels {
            for c in p {
                data.extend_from_slice(&c.to_be_bytes());
            }
        }
        wr.write_image_data(&data).map_err(|e| Error::Internal(format!("png: {e}")))?;
    }
    Ok(out)
}

/// Decodes a 16-bit RGB PNG written by [`write_rgb16`].
///
/// # Errors
/// `InputError::Parse` for anything else.
pub fn read_rgb16(bytes: &[u8]) -> Result<(u32, u32, Vec<[u16; 3]>)> {
    let bad = |m: String| crate::InputError::Parse { format: "png", location: "image".into(), message: m };
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut r = dec.read_info().map_err(|e| bad(e.to_string()))?;
    let (w, h) = (r.info().width, r.info().height);
    if r.info().bit_depth != png::BitDepth::Sixteen || r.info().color_type != png::ColorType::Rgb {
        return Err(bad("not 16-bit RGB".into()).into());
    }
    let mut buf = vec![0; r.output_buffer_size().unwrap_or(0)];
    r.next_frame(&mut buf).map_err(|e| bad(e.to_string()))?;
    let px = buf.chunks_exact(6).map(|c| [0, 1, 2].map(|k| u16::from_be_bytes([c[2 * k], c[2 * k + 1]]))).collect();
    Ok((w, h, px))
}
