//! OpenEXR 2.0 read, the single-part scanline subset: [`ExrLayers`], any named channels
//! with string attributes, and the reader, which takes 16- or 32-bit float and 32-bit uint
//! channels, uncompressed, ZIP-compressed (one or sixteen lines per block) or PIZ-compressed
//! (Mitsuba's default; `piz`), the forms most tools write. `exr_write` writes them.

use std::path::Path;

use crate::io::{check_size, decode_err, read_bytes, DEFLATE_MAX_RATIO};
use crate::{Image, ImageError, RgbImage};
use prism_math::Rgb;

/// The version field's flag of a single-part tiled file.
pub(crate) const TILED: i32 = 0x200;

/// One channel's samples, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub enum ExrSamples {
    /// 32-bit floats (half floats read as these too).
    Float(Vec<f32>),
    /// 32-bit unsigned integers.
    Uint(Vec<u32>),
}

impl ExrSamples {
    pub(crate) fn len(&self) -> usize {
        match self {
            ExrSamples::Float(v) => v.len(),
            ExrSamples::Uint(v) => v.len(),
        }
    }

    /// The OpenEXR pixel type: 0 uint, 2 float.
    pub(crate) fn pixel_type(&self) -> i32 {
        match self {
            ExrSamples::Float(_) => 2,
            ExrSamples::Uint(_) => 0,
        }
    }
}

/// An OpenEXR image with any named channels and string attributes, such as the part files of
/// a render split across machines.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrLayers {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Channels by name, each `width * height` samples; written in name order, as the format
    /// requires.
    pub channels: Vec<(String, ExrSamples)>,
    /// Attributes of type `string`, by name.
    pub attributes: Vec<(String, String)>,
}

impl ExrLayers {
    /// The channel called `name`.
    #[must_use]
    pub fn channel(&self, name: &str) -> Option<&ExrSamples> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c)
    }

    /// The string attribute called `name`.
    #[must_use]
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// A half-precision float's value.
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = (h >> 10) & 0x1f;
    let frac = f32::from(h & 0x3ff);
    match exp {
        0 => sign * frac * 2f32.powi(-24),
        31 if frac == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        e => sign * (1.0 + frac / 1024.0) * 2f32.powi(i32::from(e) - 15),
    }
}

/// A little-endian reader over a byte slice whose every read is checked.
struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
    what: &'a str,
}

impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], ImageError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.data.len());
        let end = end.ok_or_else(|| decode_err(self.what, "the file ends early"))?;
        let out = &self.data[self.at..end];
        self.at = end;
        Ok(out)
    }
    fn i32(&mut self) -> Result<i32, ImageError> {
        Ok(i32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, ImageError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    /// A NUL-terminated name of at most 255 bytes.
    fn name(&mut self) -> Result<&'a str, ImageError> {
        let rest = &self.data[self.at.min(self.data.len())..];
        let len = rest
            .iter()
            .take(256)
            .position(|&b| b == 0)
            .ok_or_else(|| decode_err(self.what, "expected a NUL-terminated name"))?;
        let name = std::str::from_utf8(&rest[..len])
            .map_err(|_| decode_err(self.what, "expected a UTF-8 name"))?;
        self.at += len + 1;
        Ok(name)
    }
}

/// Undoes OpenEXR's ZIP transform: inflate, then the byte predictor, then interleave the
/// two halves. The result must be exactly `expected` bytes.
pub(crate) fn unzip(block: &[u8], expected: usize, what: &str) -> Result<Vec<u8>, ImageError> {
    let t = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(block, expected)
        .map_err(|_| decode_err(what, "a ZIP block does not inflate to its scanlines"))?;
    if t.len() != expected {
        return Err(decode_err(what, "a ZIP block inflates to the wrong size"));
    }
    let mut t = t;
    let mut prev = 128u8;
    for v in &mut t {
        // The first byte is stored as is: 128 + v - 128.
        *v = prev.wrapping_add(*v).wrapping_sub(128);
        prev = *v;
    }
    let (even, odd) = t.split_at(t.len().div_ceil(2));
    let mut out = vec![0u8; t.len()];
    for ((pair, e), o) in out.chunks_exact_mut(2).zip(even).zip(odd) {
        pair[0] = *e;
        pair[1] = *o;
    }
    if even.len() > odd.len() {
        out[t.len() - 1] = even[even.len() - 1];
    }
    Ok(out)
}

/// Decodes an OpenEXR file's R, G and B channels (see the module's subset); a missing
/// channel reads as 0, and a file with none of the three but a luminance channel `Y` reads
/// as grey (R = G = B = Y), as OpenEXR's RGBA interface reads it. `what` names the source
/// in errors.
///
/// # Errors
/// [`ImageError::Decode`] for anything outside the subset or malformed (naming what), or
/// [`ImageError::OverBudget`] for an image over the image budget (all its channels, 4 bytes
/// a sample).
pub fn decode_exr(data: &[u8], what: &str) -> Result<RgbImage, ImageError> {
    let layers = decode_exr_layers(data, what)?;
    let (w, h) = (layers.width, layers.height);
    let grey = ["R", "G", "B"].iter().all(|c| layers.channel(c).is_none());
    let pick = |name: &'static str| match (grey, layers.channel(name)) {
        (true, _) => layers.channel("Y"),
        (false, c) => c,
    };
    let planes = [pick("R"), pick("G"), pick("B")];
    let value = |plane: Option<&ExrSamples>, i: usize| match plane {
        Some(ExrSamples::Float(v)) => v[i],
        Some(ExrSamples::Uint(v)) => v[i] as f32,
        None => 0.0,
    };
    Ok(Image::from_fn(w, h, |x, y| {
        let i = y as usize * w as usize + x as usize;
        Rgb::new(
            value(planes[0], i),
            value(planes[1], i),
            value(planes[2], i),
        )
    }))
}

/// Decodes every channel (half floats widened to floats) and every string attribute of an
/// OpenEXR file in the module's subset. `what` names the source in errors.
///
/// # Errors
/// As [`decode_exr`].
pub fn decode_exr_layers(data: &[u8], what: &str) -> Result<ExrLayers, ImageError> {
    decode(data, what, true)
}

/// Decodes an OpenEXR file's header only: its size, its channels' names and types (each
/// holding no samples) and its string attributes.
///
/// # Errors
/// As [`decode_exr`], for the header.
pub fn decode_exr_header(data: &[u8], what: &str) -> Result<ExrLayers, ImageError> {
    decode(data, what, false)
}

/// What a file's header says, for the reader.
pub(crate) struct Header {
    /// Channels as `(name, pixel type)`, in name order (the order of their samples).
    pub(crate) channels: Vec<(String, i32)>,
    /// The compression code.
    pub(crate) compression: u8,
    /// The data window's top row.
    pub(crate) y0: i32,
    /// Width and height.
    pub(crate) size: (u64, u64),
    /// The string attributes.
    pub(crate) attributes: Vec<(String, String)>,
    /// Tiled files: the tiles' width and height.
    pub(crate) tile: Option<(u32, u32)>,
    /// Where the header ends (the offset table begins).
    pub(crate) end: usize,
}

/// Reads a single-part file's header, scanline or (`tiled`) tiled with one level of tiles.
pub(crate) fn parse_header(data: &[u8], what: &str, tiled: bool) -> Result<Header, ImageError> {
    let mut b = Bytes { data, at: 0, what };
    if b.take(4)? != [0x76, 0x2f, 0x31, 0x01] {
        return Err(decode_err(what, "expected the OpenEXR signature"));
    }
    let version = b.i32()?;
    if tiled && (version & 0xff != 2 || version & 0x1e00 != TILED) {
        return Err(decode_err(
            what,
            "expected a single-part tiled OpenEXR 2 file",
        ));
    }
    if !tiled && (version & 0xff != 2 || version & 0x1e00 != 0) {
        return Err(decode_err(
            what,
            "expected a single-part scanline OpenEXR 2 file (tiled, deep and multi-part files are not read)",
        ));
    }
    let mut channels: Vec<(String, i32)> = Vec::new();
    let (mut compression, mut window, mut tile) = (None, None, None);
    let mut attributes = Vec::new();
    loop {
        let name = b.name()?;
        if name.is_empty() {
            break;
        }
        let ty = b.name()?;
        let size = usize::try_from(b.i32()?)
            .map_err(|_| decode_err(what, format!("attribute {name}: negative size")))?;
        let value = b.take(size)?;
        match (name, ty) {
            ("channels", "chlist") => {
                let mut c = Bytes {
                    data: value,
                    at: 0,
                    what,
                };
                loop {
                    let ch = c.name()?;
                    if ch.is_empty() {
                        break;
                    }
                    let pixel_type = c.i32()?;
                    c.take(4)?;
                    if (c.i32()?, c.i32()?) != (1, 1) {
                        return Err(decode_err(
                            what,
                            format!("channel {ch}: subsampled channels are not read"),
                        ));
                    }
                    channels.push((ch.to_string(), pixel_type));
                }
            }
            ("compression", "compression") => compression = value.first().copied(),
            (_, "string") => attributes.push((
                name.to_string(),
                String::from_utf8_lossy(value).into_owned(),
            )),
            ("tiles", "tiledesc") => {
                let mut c = Bytes {
                    data: value,
                    at: 0,
                    what,
                };
                let (x, y) = (c.i32()? as u32, c.i32()? as u32);
                let mode = c.take(1)?[0];
                if mode != 0 || x == 0 || y == 0 || x > 1 << 16 || y > 1 << 16 {
                    return Err(decode_err(
                        what,
                        "expected one level of tiles of 1 to 65536 pixels a side",
                    ));
                }
                tile = Some((x, y));
            }
            ("dataWindow", "box2i") => {
                let mut c = Bytes {
                    data: value,
                    at: 0,
                    what,
                };
                window = Some([c.i32()?, c.i32()?, c.i32()?, c.i32()?]);
            }
            _ => {}
        }
    }
    let [x0, y0, x1, y1] = window.ok_or_else(|| decode_err(what, "expected a dataWindow"))?;
    let (w, h) = (
        i64::from(x1) - i64::from(x0) + 1,
        i64::from(y1) - i64::from(y0) + 1,
    );
    if w <= 0 || h <= 0 {
        return Err(decode_err(what, format!("dataWindow is empty ({w}x{h})")));
    }
    let compression =
        compression.ok_or_else(|| decode_err(what, "expected a compression attribute"))?;
    if tiled && tile.is_none() {
        return Err(decode_err(what, "expected a tiles attribute"));
    }
    // A file without channels holds no pixels: its data window alone would let a few bytes
    // ask for an image of any size.
    if channels.is_empty() {
        return Err(decode_err(what, "expected at least one channel"));
    }
    channels.sort();
    Ok(Header {
        channels,
        compression,
        y0,
        size: (w as u64, h as u64),
        attributes,
        tile,
        end: b.at,
    })
}

/// The one decoder: the header, then the pixels if `pixels`.
fn decode(data: &[u8], what: &str, pixels: bool) -> Result<ExrLayers, ImageError> {
    let Header {
        channels,
        compression,
        y0,
        size: (w, h),
        attributes,
        end,
        ..
    } = parse_header(data, what, false)?;
    let mut b = Bytes {
        data,
        at: end,
        what,
    };
    let compression = Some(compression);
    let lines_per_block = match compression {
        Some(0) | Some(2) => 1,
        Some(3) => 16,
        Some(4) => crate::piz::PIZ_LINES,
        Some(c) => {
            let name = [
                "none", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB",
            ]
            .get(usize::from(c))
            .copied()
            .unwrap_or("unknown");
            return Err(decode_err(
                what,
                format!("{name} compression is not read (uncompressed, ZIPS, ZIP and PIZ are)"),
            ));
        }
        None => return Err(decode_err(what, "expected a compression attribute")),
    };
    // Channels are stored in name order; each has 2 (half) or 4 (uint, float) bytes a sample.
    let mut layout = Vec::new();
    let mut line_bytes = 0u64;
    for (name, ty) in &channels {
        let size = match ty {
            0 | 2 => 4,
            1 => 2,
            _ => {
                return Err(decode_err(
                    what,
                    format!("channel {name}: unknown pixel type {ty}"),
                ))
            }
        };
        layout.push((*ty, line_bytes as usize));
        line_bytes = line_bytes.saturating_add(size * w);
    }
    // Every channel decodes to 4 bytes a sample. Stored, the scanlines take at least their
    // size over zlib's greatest expansion: a file too small for its pixels is refused before
    // they are allocated (by this reader or by a caller that read only the header).
    let stored = h.saturating_mul(line_bytes);
    let needed = match compression {
        Some(0) => stored,
        _ => stored.div_ceil(DEFLATE_MAX_RATIO),
    };
    let samples = 4 * channels.len() as u64;
    check_size(what, (w, h), samples, needed, data.len())?;
    let (w, h, line_bytes) = (w as usize, h as usize, line_bytes as usize);
    if !pixels {
        return Ok(ExrLayers {
            width: w as u32,
            height: h as u32,
            channels: channels
                .into_iter()
                .map(|(n, ty)| {
                    let empty = match ty {
                        0 => ExrSamples::Uint(Vec::new()),
                        _ => ExrSamples::Float(Vec::new()),
                    };
                    (n, empty)
                })
                .collect(),
            attributes,
        });
    }
    // 16-bit words a sample, channel by channel (PIZ works on words).
    let words: Vec<usize> = channels
        .iter()
        .map(|(_, ty)| if *ty == 1 { 1 } else { 2 })
        .collect();
    let blocks = h.div_ceil(lines_per_block);
    // Each offset takes 8 bytes of the file: a short file cannot ask for a long table.
    let mut offsets = Vec::with_capacity(blocks.min(data.len() / 8));
    for _ in 0..blocks {
        offsets.push(b.u64()?);
    }
    let mut planes: Vec<ExrSamples> = channels
        .iter()
        .map(|(_, ty)| match ty {
            0 => ExrSamples::Uint(vec![0; w * h]),
            _ => ExrSamples::Float(vec![0.0; w * h]),
        })
        .collect();
    for offset in offsets {
        let mut c = Bytes {
            data,
            at: usize::try_from(offset).unwrap_or(usize::MAX),
            what,
        };
        let first = i64::from(c.i32()?) - i64::from(y0);
        let size = usize::try_from(c.i32()?)
            .map_err(|_| decode_err(what, "a block has a negative size"))?;
        let stored = c.take(size)?;
        if first < 0 || first as usize >= h || !(first as usize).is_multiple_of(lines_per_block) {
            return Err(decode_err(
                what,
                format!("a block starts at line {first}, outside the image"),
            ));
        }
        let first = first as usize;
        let lines = lines_per_block.min(h - first);
        let expected = lines * line_bytes;
        let raw = if size == expected {
            stored.to_vec()
        } else if compression == Some(0) {
            return Err(decode_err(what, "an uncompressed block has the wrong size"));
        } else if compression == Some(4) {
            crate::piz::unpiz(stored, &words, (w, lines), what)?
        } else {
            unzip(stored, expected, what)?
        };
        for l in 0..lines {
            let line = &raw[l * line_bytes..(l + 1) * line_bytes];
            let row = (first + l) * w;
            for (&(ty, start), plane) in layout.iter().zip(planes.iter_mut()) {
                let word = |x: usize| {
                    u32::from_le_bytes(
                        line[start + 4 * x..start + 4 * x + 4]
                            .try_into()
                            .expect("4 bytes"),
                    )
                };
                match plane {
                    ExrSamples::Uint(v) => {
                        for x in 0..w {
                            v[row + x] = word(x);
                        }
                    }
                    ExrSamples::Float(v) if ty == 1 => {
                        for x in 0..w {
                            v[row + x] = half_to_f32(u16::from_le_bytes([
                                line[start + 2 * x],
                                line[start + 2 * x + 1],
                            ]));
                        }
                    }
                    ExrSamples::Float(v) => {
                        for x in 0..w {
                            v[row + x] = f32::from_bits(word(x));
                        }
                    }
                }
            }
        }
    }
    Ok(ExrLayers {
        width: w as u32,
        height: h as u32,
        channels: channels.into_iter().map(|(n, _)| n).zip(planes).collect(),
        attributes,
    })
}

/// Reads an OpenEXR file (see [`decode_exr`]).
///
/// # Errors
/// [`ImageError::Io`] if it cannot be read, otherwise as [`decode_exr`].
pub fn read_exr(path: &Path) -> Result<RgbImage, ImageError> {
    let bytes = read_bytes(path)?;
    decode_exr(&bytes, &path.display().to_string())
}

/// Reads a file of linear radiance: OpenEXR (see [`decode_exr`]) or Radiance HDR (see
/// [`crate::decode_hdr`]), told apart by their first bytes.
///
/// # Errors
/// [`ImageError::Io`] if it cannot be read, otherwise as the decoder's.
pub fn read_radiance(path: &Path) -> Result<RgbImage, ImageError> {
    let bytes = read_bytes(path)?;
    let what = path.display().to_string();
    if crate::hdr::is_hdr(&bytes) {
        crate::hdr::decode_hdr(&bytes, &what)
    } else {
        decode_exr(&bytes, &what)
    }
}

/// Reads an OpenEXR file's every channel and string attribute (see [`decode_exr_layers`]).
///
/// # Errors
/// [`ImageError::Io`] if it cannot be read, otherwise as [`decode_exr`].
pub fn read_exr_layers(path: &Path) -> Result<ExrLayers, ImageError> {
    let bytes = read_bytes(path)?;
    decode_exr_layers(&bytes, &path.display().to_string())
}
