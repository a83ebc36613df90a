//! OpenEXR 2.0, the single-part scanline subset: the writer makes uncompressed 32-bit float
//! B, G, R channels (alphabetical order, as the format requires) of linear values, or any
//! named float and uint channels with string attributes, ZIP-compressed ([`ExrLayers`]); the
//! reader takes 16- or 32-bit float and 32-bit uint channels, uncompressed, ZIP-compressed
//! (one or sixteen lines per block) or PIZ-compressed (Mitsuba's default; `piz`), the forms
//! most tools write.

use std::io::Write;
use std::path::Path;

use crate::io::{check_size, decode_err, read_bytes, DEFLATE_MAX_RATIO};
use crate::{write_atomic, Image, ImageError, RgbImage};
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
