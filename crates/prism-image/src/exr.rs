//! A minimal OpenEXR 2.0 writer: single-part scanline file, uncompressed, 32-bit float
//! B, G, R channels (alphabetical order, as the format requires), linear values.

use std::io::Write;
use std::path::Path;

use crate::{write_atomic, ImageError, RgbImage};

fn attr(out: &mut Vec<u8>, name: &str, ty: &str, value: &[u8]) {
    out.extend_from_slice(name.as_bytes());
    out.push(0);
    out.extend_from_slice(ty.as_bytes());
    out.push(0);
    out.extend_from_slice(&(value.len() as i32).to_le_bytes());
    out.extend_from_slice(value);
}

/// Encodes a linear RGB image as an uncompressed float OpenEXR file.
#[must_use]
pub fn encode_exr(image: &RgbImage) -> Vec<u8> {
    let (w, h) = (image.width() as i32, image.height() as i32);
    let mut out = Vec::new();
    out.extend_from_slice(&20_000_630i32.to_le_bytes());
    out.extend_from_slice(&2i32.to_le_bytes());
    let mut chlist = Vec::new();
    for ch in ["B", "G", "R"] {
        chlist.extend_from_slice(ch.as_bytes());
        chlist.push(0);
        chlist.extend_from_slice(&2i32.to_le_bytes()); // FLOAT
        chlist.extend_from_slice(&[0, 0, 0, 0]); // pLinear + reserved
        chlist.extend_from_slice(&1i32.to_le_bytes()); // xSampling
        chlist.extend_from_slice(&1i32.to_le_bytes()); // ySampling
    }
    chlist.push(0);
    attr(&mut out, "channels", "chlist", &chlist);
    attr(&mut out, "compression", "compression", &[0]);
    let mut bx = Vec::new();
    for v in [0, 0, w - 1, h - 1] {
        bx.extend_from_slice(&v.to_le_bytes());
    }
    attr(&mut out, "dataWindow", "box2i", &bx);
    attr(&mut out, "displayWindow", "box2i", &bx);
    attr(&mut out, "lineOrder", "lineOrder", &[0]);
    attr(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    let mut center = Vec::new();
    center.extend_from_slice(&0f32.to_le_bytes());
    center.extend_from_slice(&0f32.to_le_bytes());
    attr(&mut out, "screenWindowCenter", "v2f", &center);
    attr(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    let line_bytes = 4 * 3 * w as usize;
    let chunk = 8 + line_bytes;
    let table_start = out.len();
    let first = (table_start + 8 * h as usize) as u64;
    for y in 0..h as u64 {
        out.extend_from_slice(&(first + y * chunk as u64).to_le_bytes());
    }
    for y in 0..image.height() {
        out.extend_from_slice(&(y as i32).to_le_bytes());
        out.extend_from_slice(&(line_bytes as i32).to_le_bytes());
        let row = image.row(y);
        for c in [2usize, 1, 0] {
            for p in row {
                out.extend_from_slice(&p.to_array()[c].to_le_bytes());
            }
        }
    }
    out
}

/// Writes a linear RGB image as an OpenEXR file, atomically.
///
/// # Errors
/// [`ImageError::Io`] if the file cannot be written; the destination is then untouched.
pub fn write_exr(path: &Path, image: &RgbImage) -> Result<(), ImageError> {
    let bytes = encode_exr(image);
    write_atomic(path, |w| {
        w.write_all(&bytes).map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Image;
    use prism_math::Rgb;

    /// Property: the pixel data found through the offset table equals what was written, and
    /// the header is the OpenEXR magic, version 2, ending before the table.
    #[test]
    fn offsets_point_at_scanlines_holding_the_pixels() {
        let im = Image::from_fn(3, 2, |x, y| Rgb::new(x as f32, y as f32, 0.5));
        let b = encode_exr(&im);
        assert_eq!(&b[..4], &[0x76, 0x2f, 0x31, 0x01]);
        let text = String::from_utf8_lossy(&b);
        assert!(text.contains("channels\0chlist\0"));
        let table = b.len() - 2 * (8 + 36) - 16;
        for y in 0..2usize {
            let off = u64::from_le_bytes(b[table + 8 * y..table + 8 * y + 8].try_into().unwrap())
                as usize;
            assert_eq!(
                i32::from_le_bytes(b[off..off + 4].try_into().unwrap()),
                y as i32
            );
            let f = |i: usize| {
                f32::from_le_bytes(b[off + 8 + 4 * i..off + 12 + 4 * i].try_into().unwrap())
            };
            // B channel first, then G, then R.
            assert_eq!((f(0), f(3), f(6)), (0.5, y as f32, 0.0));
            assert_eq!(f(8), 2.0);
        }
    }
}
