//! OpenEXR 2.0 written, the single-part scanline subset: uncompressed 32-bit float B, G, R
//! channels (alphabetical order, as the format requires) of linear values, whole or row by
//! row ([`ExrRowWriter`]), or any named float and uint channels with string attributes,
//! ZIP-compressed ([`ExrLayers`]); the header and ZIP transform the tiled writer shares.

use std::io::Write;
use std::path::Path;

use crate::exr::{ExrLayers, ExrSamples, TILED};
use crate::{write_atomic, ImageError, RgbImage};
use prism_math::Rgb;

fn attr(out: &mut Vec<u8>, name: &str, ty: &str, value: &[u8]) {
    out.extend_from_slice(name.as_bytes());
    out.push(0);
    out.extend_from_slice(ty.as_bytes());
    out.push(0);
    out.extend_from_slice(&(value.len() as i32).to_le_bytes());
    out.extend_from_slice(value);
}

/// The compression codes prism writes.
pub(crate) const UNCOMPRESSED: u8 = 0;
/// ZIP, sixteen lines a block in a scanline file, one tile a block in a tiled one.
pub(crate) const ZIP: u8 = 3;

/// The header of a single-part file of `width x height` pixels: magic, version (tiled with
/// square tiles of `tile` pixels, else scanline), the channels (`(name, pixel type)`, sorted
/// here), the standard attributes, the string attributes and the closing NUL.
pub(crate) fn header_bytes(
    (w, h): (usize, usize),
    channels: &[(&str, i32)],
    compression: u8,
    tile: Option<u32>,
    attributes: &[(String, String)],
) -> Vec<u8> {
    let mut channels = channels.to_vec();
    channels.sort();
    let mut out = Vec::new();
    out.extend_from_slice(&20_000_630i32.to_le_bytes());
    let version = if tile.is_some() { 2 | TILED } else { 2 };
    out.extend_from_slice(&version.to_le_bytes());
    let mut chlist = Vec::new();
    for (name, pixel_type) in &channels {
        chlist.extend_from_slice(name.as_bytes());
        chlist.push(0);
        chlist.extend_from_slice(&pixel_type.to_le_bytes());
        chlist.extend_from_slice(&[0, 0, 0, 0]); // pLinear + reserved
        chlist.extend_from_slice(&1i32.to_le_bytes()); // xSampling
        chlist.extend_from_slice(&1i32.to_le_bytes()); // ySampling
    }
    chlist.push(0);
    attr(&mut out, "channels", "chlist", &chlist);
    attr(&mut out, "compression", "compression", &[compression]);
    let mut bx = Vec::new();
    for v in [0, 0, w as i32 - 1, h as i32 - 1] {
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
    if let Some(t) = tile {
        // One level of `t x t` tiles, sizes rounded down.
        let mut desc = Vec::new();
        desc.extend_from_slice(&t.to_le_bytes());
        desc.extend_from_slice(&t.to_le_bytes());
        desc.push(0);
        attr(&mut out, "tiles", "tiledesc", &desc);
    }
    for (name, value) in attributes {
        attr(&mut out, name, "string", value.as_bytes());
    }
    out.push(0);
    out
}

/// OpenEXR's ZIP transform: interleave into even and odd bytes, the delta predictor, zlib.
pub(crate) fn zip(raw: &[u8]) -> Vec<u8> {
    let mut t: Vec<u8> = raw.iter().step_by(2).copied().collect();
    t.extend(raw.iter().skip(1).step_by(2));
    for i in (1..t.len()).rev() {
        t[i] = t[i].wrapping_sub(t[i - 1]).wrapping_add(128);
    }
    miniz_oxide::deflate::compress_to_vec_zlib(&t, 1)
}

/// The one encoder: channels sorted by name, then the standard attributes and the string
/// attributes; scanline blocks of one line uncompressed, or of sixteen lines ZIP-compressed
/// (a block that does not shrink is stored raw, as the format allows).
fn encode(layers: &ExrLayers, compress: bool) -> Vec<u8> {
    let (w, h) = (layers.width as usize, layers.height as usize);
    let mut channels: Vec<&(String, ExrSamples)> = layers.channels.iter().collect();
    channels.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, c) in &channels {
        assert_eq!(
            c.len(),
            w * h,
            "channel {name} holds the wrong number of samples"
        );
    }
    let types: Vec<(&str, i32)> = channels
        .iter()
        .map(|(n, c)| (n.as_str(), c.pixel_type()))
        .collect();
    let compression = if compress { ZIP } else { UNCOMPRESSED };
    let mut out = header_bytes((w, h), &types, compression, None, &layers.attributes);
    let lines = if compress { 16 } else { 1 };
    let blocks: Vec<Vec<u8>> = (0..h)
        .step_by(lines)
        .map(|first| {
            let mut raw = Vec::with_capacity(4 * channels.len() * w * lines);
            for y in first..(first + lines).min(h) {
                for (_, c) in &channels {
                    let row = y * w..(y + 1) * w;
                    match c {
                        ExrSamples::Float(v) => {
                            raw.extend(v[row].iter().flat_map(|s| s.to_le_bytes()));
                        }
                        ExrSamples::Uint(v) => {
                            raw.extend(v[row].iter().flat_map(|s| s.to_le_bytes()));
                        }
                    }
                }
            }
            if compress {
                let z = zip(&raw);
                if z.len() < raw.len() {
                    return z;
                }
            }
            raw
        })
        .collect();
    let mut at = (out.len() + 8 * blocks.len()) as u64;
    for b in &blocks {
        out.extend_from_slice(&at.to_le_bytes());
        at += 8 + b.len() as u64;
    }
    for (i, b) in blocks.iter().enumerate() {
        out.extend_from_slice(&((i * lines) as i32).to_le_bytes());
        out.extend_from_slice(&(b.len() as i32).to_le_bytes());
        out.extend_from_slice(b);
    }
    out
}

/// A linear RGB picture written as an uncompressed float OpenEXR file row by row, from the
/// top: the file's bytes are those of [`encode_exr`] on the whole picture, and only a row
/// is held at a time (every block's size is known, so the offset table comes first).
pub struct ExrRowWriter<W: Write> {
    out: W,
    width: usize,
    height: usize,
    rows: usize,
    line: Vec<u8>,
}

impl<W: Write> ExrRowWriter<W> {
    /// Writes the header and offset table of a `width x height` picture to `out`.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails.
    pub fn new(mut out: W, width: u32, height: u32) -> Result<Self, ImageError> {
        let (width, height) = (width as usize, height as usize);
        let channels = [("B", FLOAT), ("G", FLOAT), ("R", FLOAT)];
        let mut head = header_bytes((width, height), &channels, UNCOMPRESSED, None, &[]);
        let block = 8 + 12 * width as u64;
        let first = (head.len() + 8 * height) as u64;
        for y in 0..height as u64 {
            head.extend_from_slice(&(first + y * block).to_le_bytes());
        }
        out.write_all(&head).map_err(encode_io)?;
        Ok(ExrRowWriter {
            out,
            width,
            height,
            rows: 0,
            line: Vec::with_capacity(8 + 12 * width),
        })
    }

    /// Writes the next row.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails.
    ///
    /// # Panics
    /// If the row is not `width` pixels long or every row has been written.
    pub fn write_row(&mut self, row: &[Rgb]) -> Result<(), ImageError> {
        assert_eq!(row.len(), self.width, "a row of the picture's width");
        assert!(
            self.rows < self.height,
            "no more rows than the picture's height"
        );
        self.line.clear();
        self.line
            .extend_from_slice(&(self.rows as i32).to_le_bytes());
        self.line
            .extend_from_slice(&((12 * self.width) as i32).to_le_bytes());
        for c in [2, 1, 0] {
            for p in row {
                self.line.extend_from_slice(&p.to_array()[c].to_le_bytes());
            }
        }
        self.rows += 1;
        self.out.write_all(&self.line).map_err(encode_io)
    }

    /// Ends the file, handing back the writer.
    ///
    /// # Panics
    /// If a row is missing.
    pub fn finish(self) -> W {
        assert_eq!(self.rows, self.height, "every row written");
        self.out
    }
}

/// The pixel type of 32-bit floats.
const FLOAT: i32 = 2;

/// A writer's failure while encoding.
fn encode_io(e: std::io::Error) -> ImageError {
    ImageError::Encode {
        format: "OpenEXR",
        message: e.to_string(),
    }
}

/// Encodes a linear RGB image as an uncompressed float OpenEXR file.
#[must_use]
pub fn encode_exr(image: &RgbImage) -> Vec<u8> {
    let mut w = ExrRowWriter::new(Vec::new(), image.width(), image.height())
        .expect("a Vec takes any bytes");
    for row in image.pixels().chunks(image.width() as usize) {
        w.write_row(row).expect("a Vec takes any bytes");
    }
    w.finish()
}

/// Encodes any channels and string attributes as a ZIP-compressed OpenEXR file.
///
/// # Panics
/// If a channel does not hold `width * height` samples.
#[must_use]
pub fn encode_exr_layers(layers: &ExrLayers) -> Vec<u8> {
    encode(layers, true)
}

/// Writes any channels and string attributes as a ZIP-compressed OpenEXR file, atomically.
///
/// # Errors
/// [`ImageError::Io`] if the file cannot be written; the destination is then untouched.
pub fn write_exr_layers(path: &Path, layers: &ExrLayers) -> Result<(), ImageError> {
    write_bytes(path, &encode_exr_layers(layers))
}

/// Writes encoded bytes to `path` atomically.
fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    write_atomic(path, |w| {
        w.write_all(bytes).map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        })
    })
}

/// Writes a linear RGB image as an OpenEXR file, atomically.
///
/// # Errors
/// [`ImageError::Io`] if the file cannot be written; the destination is then untouched.
pub fn write_exr(path: &Path, image: &RgbImage) -> Result<(), ImageError> {
    write_atomic(path, |out| {
        let mut w = ExrRowWriter::new(out, image.width(), image.height())?;
        for row in image.pixels().chunks(image.width() as usize) {
            w.write_row(row)?;
        }
        w.finish();
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exr::{decode_exr, decode_exr_header, decode_exr_layers};
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

    /// Oracle: any channels and string attributes, ZIP-compressed over blocks of sixteen
    /// lines (and a last short block), read back exactly; the RGB reader sees the same R, G, B.
    #[test]
    fn layers_round_trip_through_zip() {
        let (w, h) = (7u32, 37u32);
        let n = (w * h) as usize;
        let layers = ExrLayers {
            width: w,
            height: h,
            channels: vec![
                (
                    "R".into(),
                    ExrSamples::Float((0..n).map(|i| i as f32 * 0.37).collect()),
                ),
                ("G".into(), ExrSamples::Float(vec![1.5; n])),
                (
                    "samples".into(),
                    ExrSamples::Uint((0..n as u32).map(|i| i * 977).collect()),
                ),
                (
                    "B".into(),
                    ExrSamples::Float((0..n).map(|i| -(i as f32)).collect()),
                ),
            ],
            attributes: vec![("prism.tile".into(), "2/7".into())],
        };
        let bytes = encode_exr_layers(&layers);
        let back = decode_exr_layers(&bytes, "mem").unwrap();
        let mut sorted = layers.clone();
        sorted.channels.sort_by(|a, b| a.0.cmp(&b.0));
        assert_eq!(back, sorted);
        assert_eq!(back.attribute("prism.tile"), Some("2/7"));
        let head = decode_exr_header(&bytes, "mem").unwrap();
        assert_eq!((head.width, head.height), (w, h));
        assert_eq!(head.attributes, back.attributes);
        let names: Vec<&str> = head.channels.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["B", "G", "R", "samples"]);
        assert!(matches!(head.channel("samples"), Some(ExrSamples::Uint(v)) if v.is_empty()));
        assert!(bytes.len() < 4 * 6 * n, "constant channels compress");
        let rgb = decode_exr(&bytes, "mem").unwrap();
        assert_eq!(rgb.get(3, 5), Rgb::new(38.0 * 0.37, 1.5, -38.0));
    }

    /// A file with no channels is refused (its data window alone could ask for any size),
    /// by the header reader too.
    #[test]
    fn files_without_channels_are_refused() {
        let empty = ExrLayers {
            width: 16384,
            height: 3,
            channels: Vec::new(),
            attributes: Vec::new(),
        };
        let bytes = encode_exr_layers(&empty);
        for e in [
            decode_exr(&bytes, "mem").unwrap_err(),
            decode_exr_header(&bytes, "mem").unwrap_err(),
        ] {
            assert_eq!(e.to_string(), "mem: expected at least one channel");
        }
    }

    /// A luminance-only file (channel `Y`, as OpenEXR's RGBA interface writes grey) reads
    /// as grey; a file with any of R, G, B reads its missing ones as 0.
    #[test]
    fn luminance_only_files_read_as_grey() {
        let n = 6;
        let y: Vec<f32> = (0..n).map(|i| i as f32 * 0.5 + 0.25).collect();
        let grey = ExrLayers {
            width: 3,
            height: 2,
            channels: vec![("Y".into(), ExrSamples::Float(y.clone()))],
            attributes: Vec::new(),
        };
        let im = decode_exr(&encode_exr_layers(&grey), "grey.exr").unwrap();
        for (i, p) in im.pixels().iter().enumerate() {
            assert_eq!(*p, Rgb::new(y[i], y[i], y[i]));
        }
        let mut red = grey.clone();
        red.channels
            .push(("R".into(), ExrSamples::Float(vec![2.0; n])));
        let im = decode_exr(&encode_exr_layers(&red), "red.exr").unwrap();
        assert!(im.pixels().iter().all(|p| *p == Rgb::new(2.0, 0.0, 0.0)));
    }

    /// Many channels over a modest window are refused by the image budget (every channel
    /// decodes to 4 bytes a sample), before their planes are allocated.
    #[test]
    fn channels_count_against_the_image_budget() {
        let channels = (0..2000)
            .map(|i| (format!("c{i:04}"), ExrSamples::Float(vec![0.0])))
            .collect();
        let wide = ExrLayers {
            width: 1,
            height: 1,
            channels,
            attributes: Vec::new(),
        };
        let mut bytes = encode_exr_layers(&wide);
        // Widen the data window in place to 256 x 512: 2000 channels need 1000 MiB.
        let at = bytes
            .windows(10)
            .position(|w| w == b"dataWindow")
            .expect("a data window")
            + 11
            + 6
            + 4;
        bytes[at + 8..at + 12].copy_from_slice(&255i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&511i32.to_le_bytes());
        let e = decode_exr_header(&bytes, "many.exr").unwrap_err();
        assert!(matches!(e, ImageError::OverBudget { .. }), "{e}");
    }

    /// Oracle: what the writer wrote reads back exactly.
    /// Brute force: the row writer's file is the general encoder's, uncompressed, for the
    /// same three channels.
    #[test]
    fn row_writer_bytes_equal_the_general_encoder() {
        let img = Image::from_fn(37, 5, |x, y| Rgb::new(x as f32, y as f32 * 0.25, -1.5));
        let channel =
            |c: usize| ExrSamples::Float(img.pixels().iter().map(|p| p.to_array()[c]).collect());
        let layers = ExrLayers {
            width: 37,
            height: 5,
            channels: vec![
                ("R".into(), channel(0)),
                ("G".into(), channel(1)),
                ("B".into(), channel(2)),
            ],
            attributes: Vec::new(),
        };
        assert_eq!(encode_exr(&img), encode(&layers, false));
    }

    #[test]
    fn uncompressed_float_round_trip() {
        let im = Image::from_fn(5, 3, |x, y| Rgb::new(x as f32 * 0.25, y as f32, -1.5));
        assert_eq!(decode_exr(&encode_exr(&im), "mem").unwrap(), im);
    }

    /// OpenEXR's ZIP transform applied by hand from the specification (split into even and
    /// odd bytes, delta predictor, zlib), with half-float channels: the reader undoes it.
    #[test]
    fn zip_half_float_blocks_read() {
        let (w, h) = (3usize, 18usize);
        let value = |x: usize, y: usize, c: usize| (x + 2 * y + 7 * c) as f32 * 0.5;
        // Halves of small multiples of 0.5 are exact: 1 sign, 5 exponent, 10 fraction bits.
        let half = |v: f32| -> u16 {
            if v == 0.0 {
                return 0;
            }
            let e = v.log2().floor() as i32;
            let frac = ((v / 2f32.powi(e) - 1.0) * 1024.0).round() as u16;
            (((e + 15) as u16) << 10) | frac
        };
        let mut head = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        let attr = |out: &mut Vec<u8>, name: &str, ty: &str, v: &[u8]| {
            for part in [name, ty] {
                out.extend_from_slice(part.as_bytes());
                out.push(0);
            }
            out.extend_from_slice(&(v.len() as i32).to_le_bytes());
            out.extend_from_slice(v);
        };
        let mut ch = Vec::new();
        for name in ["A", "B", "G", "R"] {
            ch.extend_from_slice(name.as_bytes());
            ch.extend_from_slice(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]);
        }
        ch.push(0);
        attr(&mut head, "channels", "chlist", &ch);
        attr(&mut head, "compression", "compression", &[3]);
        let bx: Vec<u8> = [0i32, 0, w as i32 - 1, h as i32 - 1]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        attr(&mut head, "dataWindow", "box2i", &bx);
        head.push(0);
        let mut blocks = Vec::new();
        for first in (0..h).step_by(16) {
            let mut raw = Vec::new();
            for y in first..(first + 16).min(h) {
                for c in [3usize, 2, 1, 0] {
                    for x in 0..w {
                        let v = if c == 3 { 1.0 } else { value(x, y, c) };
                        raw.extend_from_slice(&half(v).to_le_bytes());
                    }
                }
            }
            let mut t: Vec<u8> = raw.iter().step_by(2).copied().collect();
            t.extend(raw.iter().skip(1).step_by(2));
            for i in (1..t.len()).rev() {
                t[i] = t[i].wrapping_sub(t[i - 1]).wrapping_add(128);
            }
            blocks.push((first, miniz_oxide::deflate::compress_to_vec_zlib(&t, 6)));
        }
        let table_end = head.len() + 8 * blocks.len();
        let mut offset = table_end as u64;
        let mut file = head;
        for (_, z) in &blocks {
            file.extend_from_slice(&offset.to_le_bytes());
            offset += 8 + z.len() as u64;
        }
        for (first, z) in &blocks {
            file.extend_from_slice(&(*first as i32).to_le_bytes());
            file.extend_from_slice(&(z.len() as i32).to_le_bytes());
            file.extend_from_slice(z);
        }
        let im = decode_exr(&file, "zip.exr").unwrap();
        assert_eq!((im.width(), im.height()), (w as u32, h as u32));
        for y in 0..h {
            for x in 0..w {
                let p = im.get(x as u32, y as u32);
                assert_eq!(
                    (p.r, p.g, p.b),
                    (value(x, y, 0), value(x, y, 1), value(x, y, 2))
                );
            }
        }
        // Cut short anywhere: an error, never a panic.
        for cut in [0, 7, 30, file.len() / 2, file.len() - 1] {
            assert!(decode_exr(&file[..cut], "cut.exr").is_err());
        }
    }
}
