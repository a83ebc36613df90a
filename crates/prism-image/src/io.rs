//! Image files: PNG and JPEG reading (with size limits), PNG writing, and atomic file writes.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{ImageError, Rgb8Image, Rgba8Image};

pub(crate) fn decode_err(what: &str, message: impl ToString) -> ImageError {
    ImageError::Decode {
        what: what.to_string(),
        message: message.to_string(),
    }
}

/// Checks a header's size before anything is allocated for its pixels: both sides at least
/// 1, the decoded image (`bytes_per_pixel` bytes a pixel, all channels) within one image's
/// memory budget ([`prism_math::limits::image_budget`]), and `needed_bytes`, the fewest
/// bytes a file of that size must hold, within the `file_bytes` it has.
pub(crate) fn check_size(
    what: &str,
    (width, height): (u64, u64),
    bytes_per_pixel: u64,
    needed_bytes: u64,
    file_bytes: usize,
) -> Result<(), ImageError> {
    if width == 0 || height == 0 {
        return Err(ImageError::BadSize {
            what: what.to_string(),
            width,
            height,
        });
    }
    let bytes = width.saturating_mul(height).saturating_mul(bytes_per_pixel);
    prism_math::limits::check_image_memory(bytes).map_err(|source| ImageError::OverBudget {
        what: what.to_string(),
        width,
        height,
        source,
    })?;
    if needed_bytes > file_bytes as u64 {
        return Err(decode_err(
            what,
            format!("{width}x{height} pixels cannot fit in {file_bytes} bytes"),
        ));
    }
    Ok(())
}

/// The most bytes zlib's deflate can expand one compressed byte to: a length-258 copy coded
/// in two bits.
pub(crate) const DEFLATE_MAX_RATIO: u64 = 1032;

/// Decodes a PNG of any colour type and bit depth to straight-alpha RGBA8.
///
/// Palettes and grey are expanded, 16-bit channels keep their high byte, a missing alpha
/// channel becomes 255. `what` names the source in errors.
///
/// # Errors
/// [`ImageError::Decode`] for a malformed or truncated file, or one too short for the
/// pixels its header claims; [`ImageError::BadSize`] for an empty image;
/// [`ImageError::OverBudget`] for one over the image budget.
pub fn decode_png(bytes: &[u8], what: &str) -> Result<Rgba8Image, ImageError> {
    let budget = usize::try_from(prism_math::limits::image_budget()).unwrap_or(usize::MAX);
    let mut decoder = png::Decoder::new_with_limits(bytes, png::Limits { bytes: budget });
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    // The header alone is read first: its size is checked before the decoder allocates.
    let (w, h, stream) = {
        let info = decoder
            .read_header_info()
            .map_err(|e| decode_err(what, e))?;
        let row = (u64::from(info.width) * info.bits_per_pixel() as u64).div_ceil(8) + 1;
        (info.width, info.height, row * u64::from(info.height))
    };
    // The filtered scanlines inflate from at most the whole file.
    let needed = stream.div_ceil(DEFLATE_MAX_RATIO);
    check_size(what, (u64::from(w), u64::from(h)), 8, needed, bytes.len())?;
    let mut reader = decoder.read_info().map_err(|e| decode_err(what, e))?;
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| decode_err(what, e))?;
    let data = &buf[..frame.buffer_size()];
    let n = w as usize * h as usize;
    let stride = frame.line_size;
    let mut out = Vec::with_capacity(n);
    for y in 0..h as usize {
        let row = &data[y * stride..(y + 1) * stride];
        for x in 0..w as usize {
            let px = match frame.color_type {
                png::ColorType::Grayscale => [row[x], row[x], row[x], 255],
                png::ColorType::GrayscaleAlpha => {
                    let (g, a) = (row[2 * x], row[2 * x + 1]);
                    [g, g, g, a]
                }
                png::ColorType::Rgb => [row[3 * x], row[3 * x + 1], row[3 * x + 2], 255],
                png::ColorType::Rgba => {
                    [row[4 * x], row[4 * x + 1], row[4 * x + 2], row[4 * x + 3]]
                }
                png::ColorType::Indexed => {
                    return Err(decode_err(what, "palette was not expanded"));
                }
            };
            out.push(px);
        }
    }
    Ok(Rgba8Image::from_vec(w, h, out))
}

/// Decodes a baseline or progressive JPEG to RGBA8 (alpha 255).
///
/// # Errors
/// [`ImageError::Decode`] for malformed data, an unsupported pixel format, or a file too
/// short for the pixels its header claims; [`ImageError::BadSize`] for an empty image;
/// [`ImageError::OverBudget`] for one over the image budget.
pub fn decode_jpeg(bytes: &[u8], what: &str) -> Result<Rgba8Image, ImageError> {
    let mut decoder = jpeg_decoder::Decoder::new(bytes);
    decoder.read_info().map_err(|e| decode_err(what, e))?;
    let info = decoder
        .info()
        .ok_or_else(|| decode_err(what, "missing JPEG header"))?;
    let (w, h) = (u64::from(info.width), u64::from(info.height));
    // Every 8x8 block of the full-resolution component takes at least one bit (its DC
    // code), so a file of n bytes holds at most 8n blocks.
    let needed = (w.div_ceil(8) * h.div_ceil(8)).div_ceil(8);
    // The decoder's planes (up to 4 bytes a pixel), then the RGBA copy.
    check_size(what, (w, h), 8, needed, bytes.len())?;
    decoder.set_max_decoding_buffer_size(
        usize::try_from(prism_math::limits::image_budget()).unwrap_or(usize::MAX),
    );
    let data = decoder.decode().map_err(|e| decode_err(what, e))?;
    let n = usize::from(info.width) * usize::from(info.height);
    let pixels: Vec<[u8; 4]> = match info.pixel_format {
        jpeg_decoder::PixelFormat::L8 => data.iter().map(|&g| [g, g, g, 255]).collect(),
        jpeg_decoder::PixelFormat::RGB24 => data
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        jpeg_decoder::PixelFormat::CMYK32 => data
            .chunks_exact(4)
            .map(|c| {
                let k = u32::from(c[3]);
                let f = |v: u8| (u32::from(v) * k / 255) as u8;
                [f(c[0]), f(c[1]), f(c[2]), 255]
            })
            .collect(),
        jpeg_decoder::PixelFormat::L16 => data
            .chunks_exact(2)
            .map(|c| [c[0], c[0], c[0], 255])
            .collect(),
    };
    if pixels.len() != n {
        return Err(decode_err(
            what,
            "pixel data is shorter than the header says",
        ));
    }
    Ok(Rgba8Image::from_vec(
        u32::from(info.width),
        u32::from(info.height),
        pixels,
    ))
}

/// Decodes the first frame of a GIF to RGBA8, placed on its logical screen as resvg and
/// browsers show a still GIF.
///
/// # Errors
/// [`ImageError::Decode`] for malformed data; [`ImageError::BadSize`] for an empty image;
/// [`ImageError::OverBudget`] for a screen over the image budget.
pub fn decode_gif(bytes: &[u8], what: &str) -> Result<Rgba8Image, ImageError> {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = opts.read_info(bytes).map_err(|e| decode_err(what, e))?;
    let (w, h) = (u64::from(decoder.width()), u64::from(decoder.height()));
    check_size(what, (w, h), 8, 0, bytes.len())?;
    let frame = decoder
        .read_next_frame()
        .map_err(|e| decode_err(what, e))?
        .ok_or_else(|| decode_err(what, "no image frame"))?;
    let mut out = vec![[0u8; 4]; (w * h) as usize];
    let (fw, fh) = (usize::from(frame.width), usize::from(frame.height));
    let (fl, ft) = (usize::from(frame.left), usize::from(frame.top));
    for y in 0..fh {
        for x in 0..fw {
            let (sx, sy) = (fl + x, ft + y);
            if sx < w as usize && sy < h as usize {
                let i = (y * fw + x) * 4;
                if let Some(p) = frame.buffer.get(i..i + 4) {
                    out[sy * w as usize + sx] = [p[0], p[1], p[2], p[3]];
                }
            }
        }
    }
    Ok(Rgba8Image::from_vec(w as u32, h as u32, out))
}

/// Decodes a still WebP image (lossy or lossless; the first frame of an animation) to RGBA8.
///
/// # Errors
/// [`ImageError::Decode`] for malformed data; [`ImageError::BadSize`] for an empty image;
/// [`ImageError::OverBudget`] for one over the image budget, refused from its header.
pub fn decode_webp(bytes: &[u8], what: &str) -> Result<Rgba8Image, ImageError> {
    let mut decoder = image_webp::WebPDecoder::new(std::io::Cursor::new(bytes))
        .map_err(|e| decode_err(what, e))?;
    let (w, h) = decoder.dimensions();
    check_size(what, (u64::from(w), u64::from(h)), 8, 0, bytes.len())?;
    let alpha = decoder.has_alpha();
    let channels = if alpha { 4 } else { 3 };
    let mut buf = vec![0u8; w as usize * h as usize * channels];
    decoder
        .read_image(&mut buf)
        .map_err(|e| decode_err(what, e))?;
    let pixels = buf
        .chunks_exact(channels)
        .map(|c| [c[0], c[1], c[2], if alpha { c[3] } else { 255 }])
        .collect();
    Ok(Rgba8Image::from_vec(w, h, pixels))
}

/// The largest image file the readers open, in bytes (1 GiB).
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Reads an image file: a regular file of at most [`MAX_IMAGE_FILE_BYTES`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, ImageError> {
    prism_math::limits::read_input(path, MAX_IMAGE_FILE_BYTES).map_err(|source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a PNG file as RGBA8.
///
/// # Errors
/// [`ImageError::Io`] if the file cannot be read, or a decode error naming the file.
pub fn read_png(path: &Path) -> Result<Rgba8Image, ImageError> {
    decode_png(&read_bytes(path)?, &path.display().to_string())
}

/// Reads a PNG or JPEG file (recognised by its signature) as RGBA8.
///
/// # Errors
/// [`ImageError::Io`] if the file cannot be read; [`ImageError::Decode`] if it is neither a
/// PNG nor a JPEG, or is malformed.
pub fn read_image(path: &Path) -> Result<Rgba8Image, ImageError> {
    let bytes = read_bytes(path)?;
    let what = path.display().to_string();
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        decode_png(&bytes, &what)
    } else if bytes.starts_with(&[0xff, 0xd8]) {
        decode_jpeg(&bytes, &what)
    } else {
        Err(decode_err(&what, "expected a PNG or JPEG signature"))
    }
}

/// Encodes 8-bit pixels (3 or 4 channels per pixel, `CHANNELS`) as a PNG.
fn encode_png_channels(
    width: u32,
    height: u32,
    data: &[u8],
    color: png::ColorType,
    out: &mut impl Write,
) -> Result<(), ImageError> {
    let color = match color {
        png::ColorType::Rgba => crate::PngColor::Rgba,
        _ => crate::PngColor::Rgb,
    };
    let mut w = crate::PngRowWriter::new(out, width, height, color)?;
    for row in data.chunks_exact(data.len() / height as usize) {
        w.write_row(row)?;
    }
    w.finish().map(|_| ())
}

/// Encodes an RGB8 image as PNG bytes.
///
/// # Errors
/// [`ImageError::Encode`] if the encoder fails.
pub fn encode_png(image: &Rgb8Image) -> Result<Vec<u8>, ImageError> {
    let mut out = Vec::new();
    let flat = image.pixels().as_flattened();
    encode_png_channels(
        image.width(),
        image.height(),
        flat,
        png::ColorType::Rgb,
        &mut out,
    )?;
    Ok(out)
}

/// Encodes an RGBA8 (straight alpha) image as PNG bytes.
///
/// # Errors
/// [`ImageError::Encode`] if the encoder fails.
pub fn encode_png_rgba(image: &Rgba8Image) -> Result<Vec<u8>, ImageError> {
    let mut out = Vec::new();
    let flat = image.pixels().as_flattened();
    encode_png_channels(
        image.width(),
        image.height(),
        flat,
        png::ColorType::Rgba,
        &mut out,
    )?;
    Ok(out)
}

/// Quality of the JPEG files prism writes, from 1 to 100.
pub const JPEG_QUALITY: u8 = 95;

/// Encodes an RGB8 image as a baseline JPEG at [`JPEG_QUALITY`] (4:2:0 chroma, as most
/// encoders default to).
///
/// # Errors
/// [`ImageError::Encode`] for a side over 65535 pixels (JPEG's limit) or an encoder failure.
pub fn encode_jpeg(image: &Rgb8Image) -> Result<Vec<u8>, ImageError> {
    let err = |message: String| ImageError::Encode {
        format: "JPEG",
        message,
    };
    let (Ok(w), Ok(h)) = (u16::try_from(image.width()), u16::try_from(image.height())) else {
        return Err(err(format!(
            "{}x{} is over JPEG's 65535 pixels a side",
            image.width(),
            image.height()
        )));
    };
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, JPEG_QUALITY)
        .encode(
            image.pixels().as_flattened(),
            w,
            h,
            jpeg_encoder::ColorType::Rgb,
        )
        .map_err(|e| err(e.to_string()))?;
    Ok(out)
}

/// Writes an RGB8 image as a JPEG file (see [`encode_jpeg`]), atomically.
///
/// # Errors
/// [`ImageError::Io`] or [`ImageError::Encode`]; on error the destination is untouched.
pub fn write_jpeg(path: &Path, image: &Rgb8Image) -> Result<(), ImageError> {
    let bytes = encode_jpeg(image)?;
    write_atomic(path, |w| {
        w.write_all(&bytes).map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        })
    })
}

/// Encodes an RGB8 image as a 24-bit uncompressed Windows bitmap (BITMAPINFOHEADER, rows
/// stored bottom-up in BGR order, each padded to a multiple of 4 bytes).
///
/// # Errors
/// [`ImageError::Encode`] if the file would exceed 4 GiB.
pub fn encode_bmp(image: &Rgb8Image) -> Result<Vec<u8>, ImageError> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let row = (3 * w).div_ceil(4) * 4;
    let data = row * h;
    let size = u32::try_from(54 + data).map_err(|_| ImageError::Encode {
        format: "BMP",
        message: format!("{w} x {h} is over the format's 4 GiB"),
    })?;
    let mut out = Vec::with_capacity(54 + data);
    out.extend_from_slice(b"BM");
    out.extend_from_slice(&size.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&54u32.to_le_bytes());
    out.extend_from_slice(&40u32.to_le_bytes());
    out.extend_from_slice(&(w as i32).to_le_bytes());
    out.extend_from_slice(&(h as i32).to_le_bytes());
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&24u16.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(data as u32).to_le_bytes());
    out.extend_from_slice(&2835u32.to_le_bytes());
    out.extend_from_slice(&2835u32.to_le_bytes());
    out.extend_from_slice(&[0; 8]);
    for y in (0..image.height()).rev() {
        let start = out.len();
        for p in image.row(y) {
            out.extend_from_slice(&[p[2], p[1], p[0]]);
        }
        out.resize(start + row, 0);
    }
    Ok(out)
}

/// Writes an RGB8 image as a 24-bit BMP file (see [`encode_bmp`]), atomically.
///
/// # Errors
/// [`ImageError::Io`] or [`ImageError::Encode`]; on error the destination is untouched.
pub fn write_bmp(path: &Path, image: &Rgb8Image) -> Result<(), ImageError> {
    let bytes = encode_bmp(image)?;
    write_atomic(path, |w| {
        w.write_all(&bytes).map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        })
    })
}

/// Writes an RGB8 image as a PNG file, atomically (see [`write_atomic`]).
///
/// # Errors
/// [`ImageError::Io`] or [`ImageError::Encode`]; on error the destination is untouched.
pub fn write_png(path: &Path, image: &Rgb8Image) -> Result<(), ImageError> {
    let flat = image.pixels().as_flattened();
    write_atomic(path, |w| {
        encode_png_channels(image.width(), image.height(), flat, png::ColorType::Rgb, w)
    })
}

/// Writes an RGBA8 (straight alpha) image as a PNG file, atomically.
///
/// # Errors
/// [`ImageError::Io`] or [`ImageError::Encode`]; on error the destination is untouched.
pub fn write_png_rgba(path: &Path, image: &Rgba8Image) -> Result<(), ImageError> {
    let flat = image.pixels().as_flattened();
    write_atomic(path, |w| {
        encode_png_channels(image.width(), image.height(), flat, png::ColorType::Rgba, w)
    })
}

/// A file being written through a temporary file beside its path, renamed over the path
/// only by [`AtomicFile::commit`]: dropped uncommitted (an error, a panic), it leaves
/// nothing behind and the path untouched. The temporary file is removed as well by
/// [`remove_temporaries_before_exit`].
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path`.
    ///
    /// # Errors
    /// The operating system's error creating the temporary file.
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".to_string());
        static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{k}.tmp", std::process::id()));
        register_temporary(&tmp, true);
        match File::create(&tmp) {
            Ok(file) => Ok(AtomicFile {
                path: path.to_path_buf(),
                tmp,
                out: Some(BufWriter::new(file)),
            }),
            Err(e) => {
                register_temporary(&tmp, false);
                Err(e)
            }
        }
    }

    /// The path being written (not the temporary file's).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Where the bytes go.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.out
            .as_mut()
            .expect("an uncommitted file has its writer")
    }

    /// Flushes the file and renames it over the path, so readers see the old file or the
    /// whole new one. Like `cp` and other image tools, it does not wait for the disk.
    ///
    /// # Errors
    /// The operating system's error; the path is then untouched.
    pub fn commit(mut self) -> std::io::Result<()> {
        let out = self.out.take().expect("an uncommitted file has its writer");
        let file = out.into_inner().map_err(|e| e.into_error())?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path)?;
        register_temporary(&self.tmp, false);
        Ok(())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
            register_temporary(&self.tmp, false);
        }
    }
}

/// Writes a file by streaming into a temporary file beside `path`, then renaming it over
/// `path`, so that a failure never leaves a truncated file or clobbers an existing one
/// (an [`AtomicFile`]). The caller's error type carries file-system errors too: `io_error`
/// builds one from `path` (the caller's, not the temporary file's) and the OS error.
///
/// # Errors
/// `io_error(..)` for file-system errors, or whatever `write` returns.
pub fn write_atomic_with<E>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
    io_error: impl Fn(&Path, std::io::Error) -> E,
) -> Result<(), E> {
    // Errors name the user's path, never the temporary file's.
    let mut file = AtomicFile::create(path).map_err(|e| io_error(path, e))?;
    write(file.writer())?;
    file.commit().map_err(|e| io_error(path, e))
}

/// The temporary files being written now, by every thread.
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register_temporary(path: &Path, writing: bool) {
    let mut list = TEMPORARIES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if writing {
        list.push(path.to_path_buf());
    } else if let Some(i) = list.iter().position(|p| p == path) {
        list.swap_remove(i);
    }
}

/// Removes every temporary file being written (by [`write_atomic_with`]) and holds them
/// from being made again, for a process about to exit on a signal: no hidden `.NAME.tmp`
/// is left behind. Every later atomic write blocks.
pub fn remove_temporaries_before_exit() {
    let list = TEMPORARIES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    for p in list.iter() {
        let _ = std::fs::remove_file(p);
    }
    std::mem::forget(list);
}

/// [`write_atomic_with`] for image files: file-system errors are [`ImageError::Io`].
///
/// # Errors
/// [`ImageError::Io`] for file-system errors, or whatever `write` returns.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), ImageError>,
) -> Result<(), ImageError> {
    // An encoder's failure (a full disk, say) names the file being written.
    let named = |e: ImageError| match e {
        ImageError::Encode { format, message } => ImageError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(format!("encoding {format}: {message}")),
        },
        e => e,
    };
    write_atomic_with(
        path,
        |w| write(w).map_err(named),
        |p, source| ImageError::Io {
            path: p.to_path_buf(),
            source,
        },
    )
}

#[cfg(test)]
mod tests {

    /// Layout by hand: a 2 x 2 image is a 54-byte header and two rows of 6 bytes padded to
    /// 8, bottom row first, blue first.
    #[test]
    fn bmp_layout_by_hand() {
        let img = crate::Image::from_vec(2, 2, vec![[1, 2, 3], [4, 5, 6], [7, 8, 9], [10, 11, 12]]);
        let b = encode_bmp(&img).unwrap();
        assert_eq!(b.len(), 54 + 16);
        assert_eq!(&b[0..2], b"BM");
        assert_eq!(u32::from_le_bytes(b[2..6].try_into().unwrap()), 70);
        assert_eq!(u32::from_le_bytes(b[10..14].try_into().unwrap()), 54);
        assert_eq!(i32::from_le_bytes(b[18..22].try_into().unwrap()), 2);
        assert_eq!(i32::from_le_bytes(b[22..26].try_into().unwrap()), 2);
        assert_eq!(u16::from_le_bytes(b[28..30].try_into().unwrap()), 24);
        assert_eq!(&b[54..62], &[9, 8, 7, 12, 11, 10, 0, 0]);
        assert_eq!(&b[62..70], &[3, 2, 1, 6, 5, 4, 0, 0]);
    }

    use super::*;

    /// Property: a lossless WebP (made by the same crate's encoder) decodes to exactly the
    /// pixels it was made from, alpha included; malformed data is an error.
    #[test]
    fn webp_lossless_round_trip() {
        let (w, h) = (7u32, 5u32);
        let rgba: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                [
                    (i * 9) as u8,
                    (i * 31) as u8,
                    (255 - i) as u8,
                    (i * 50 % 256) as u8,
                ]
            })
            .collect();
        let mut bytes = Vec::new();
        image_webp::WebPEncoder::new(&mut bytes)
            .encode(&rgba, w, h, image_webp::ColorType::Rgba8)
            .unwrap();
        let img = decode_webp(&bytes, "test.webp").unwrap();
        assert_eq!((img.width(), img.height()), (w, h));
        let got: Vec<u8> = img.pixels().iter().flatten().copied().collect();
        assert_eq!(got, rgba);
        assert!(decode_webp(b"RIFF\0\0\0\0WEBPjunk", "junk.webp").is_err());
    }
    use crate::Image;

    #[test]
    fn png_round_trip_is_lossless() {
        let im = Image::from_fn(7, 5, |x, y| [(x * 30) as u8, (y * 50) as u8, 200]);
        let bytes = encode_png(&im).unwrap();
        let back = decode_png(&bytes, "mem").unwrap().to_rgb8();
        assert_eq!(back, im);
    }

    #[test]
    fn truncated_png_is_an_error_not_a_panic() {
        let im = Image::from_fn(16, 16, |x, y| [x as u8, y as u8, 0]);
        let bytes = encode_png(&im).unwrap();
        for cut in [0, 8, 20, 40, bytes.len() - 5] {
            assert!(decode_png(&bytes[..cut], "mem").is_err(), "cut at {cut}");
        }
    }

    #[test]
    fn write_atomic_leaves_old_file_on_failure() {
        let dir = std::env::temp_dir().join(format!("prism-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("keep.png");
        std::fs::write(&path, b"old").unwrap();
        let r = write_atomic(&path, |w| {
            w.write_all(b"partial").unwrap();
            Err(ImageError::Encode {
                format: "PNG",
                message: "boom".into(),
            })
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temp file left behind"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// 16-bit channels keep their high byte; grey expands to RGB.
    #[test]
    fn sixteen_bit_grey_png_decodes_to_high_bytes() {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, 2, 1);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Sixteen);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[0x12, 0x34, 0xfe, 0xdc]).unwrap();
        }
        let im = decode_png(&bytes, "mem").unwrap();
        assert_eq!(
            im.pixels(),
            &[[0x12, 0x12, 0x12, 255], [0xfe, 0xfe, 0xfe, 255]]
        );
    }

    /// Property: a smooth image survives JPEG at quality 95 within a few levels per channel
    /// (the decoder is the independent oracle), and the output starts with the SOI marker.
    #[test]
    fn jpeg_round_trip_is_close() {
        let im = Image::from_fn(64, 48, |x, y| [(x * 4) as u8, (y * 5) as u8, 128]);
        let bytes = encode_jpeg(&im).unwrap();
        assert_eq!(&bytes[..2], &[0xff, 0xd8]);
        let back = decode_jpeg(&bytes, "mem").unwrap().to_rgb8();
        let stats = crate::compare_rgb8(&im, &back).unwrap();
        assert!(stats.mean_abs_error < 2.0, "{stats:?}");
    }

    /// A PNG chunk with its CRC (ISO 3309, bit by bit: the independent oracle is the png
    /// crate, which checks it).
    fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
        let mut crc = !0u32;
        for &b in kind.iter().chain(data) {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xedb8_8320
                } else {
                    crc >> 1
                };
            }
        }
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        out.extend_from_slice(&(!crc).to_be_bytes());
        out
    }

    /// A PNG whose header claims `width` x `height` 8-bit RGB over `idat`.
    fn png_claiming(width: u32, height: u32, depth: u8, colour: u8, idat: &[u8]) -> Vec<u8> {
        let mut ihdr = width.to_be_bytes().to_vec();
        ihdr.extend_from_slice(&height.to_be_bytes());
        ihdr.extend_from_slice(&[depth, colour, 0, 0, 0]);
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.extend(chunk(b"IHDR", &ihdr));
        png.extend(chunk(b"IDAT", idat));
        png.extend(chunk(b"IEND", &[]));
        png
    }

    /// A short PNG claiming 4096 x 65535 pixels is refused by what its bytes can hold
    /// (deflate expands at most 1032 to 1), before any pixel is allocated.
    #[test]
    fn png_claiming_more_than_its_bytes_hold_is_refused() {
        let z = miniz_oxide::deflate::compress_to_vec_zlib(&[0; 64], 6);
        let png = png_claiming(4096, 65535 / 16, 8, 2, &z);
        let e = decode_png(&png, "small.png").unwrap_err().to_string();
        assert!(
            e.contains("small.png: 4096x4095 pixels cannot fit in"),
            "{e}"
        );
    }

    /// A 16384 x 16384 one-bit PNG is small on disk (its rows deflate well) but decodes to
    /// 1 GiB of RGBA: refused by the image budget, naming the file, the size and the budget.
    #[test]
    fn png_over_the_image_budget_is_refused() {
        let rows = vec![0u8; (1 + 16384 / 8) * 16384];
        let z = miniz_oxide::deflate::compress_to_vec_zlib(&rows, 1);
        assert!(z.len() < 1 << 20, "{} bytes", z.len());
        let png = png_claiming(16384, 16384, 1, 0, &z);
        let e = decode_png(&png, "big.png").unwrap_err();
        assert!(matches!(e, ImageError::OverBudget { .. }), "{e}");
        assert_eq!(
            e.to_string(),
            "big.png: a 16384x16384 image needs 2 GiB of memory, over the budget of 512 MiB \
             (--max-memory raises it)"
        );
    }

    /// A real JPEG with its frame header patched to claim 4096 x 65535 pixels (the sweep's
    /// 634-byte file): refused before decoding, by its size and by the budget.
    #[test]
    fn jpeg_claiming_a_huge_frame_is_refused() {
        let im = Image::from_fn(16, 16, |x, y| [(x * 9) as u8, (y * 9) as u8, 77]);
        let mut bytes = encode_jpeg(&im).unwrap();
        let sof = bytes
            .windows(2)
            .position(|w| w == [0xff, 0xc0])
            .expect("a baseline frame header");
        // Marker, length (2), precision (1), then height and width, big-endian.
        bytes[sof + 5..sof + 7].copy_from_slice(&65535u16.to_be_bytes());
        bytes[sof + 7..sof + 9].copy_from_slice(&4096u16.to_be_bytes());
        let e = decode_jpeg(&bytes, "huge.jpg").unwrap_err();
        assert!(matches!(e, ImageError::OverBudget { .. }), "{e}");
        // Within the budget but not within the file: 1024 x 1024 needs 16384 blocks, at
        // least 2048 bytes.
        bytes[sof + 5..sof + 7].copy_from_slice(&1024u16.to_be_bytes());
        bytes[sof + 7..sof + 9].copy_from_slice(&1024u16.to_be_bytes());
        let e = decode_jpeg(&bytes, "huge.jpg").unwrap_err().to_string();
        assert!(e.contains("1024x1024 pixels cannot fit in"), "{e}");
    }

    /// An encoder's failure while writing a file names the file (a full disk said only
    /// "encoding PNG: ..."), and the file is not made.
    #[test]
    fn encoding_failures_name_the_file() {
        let dir = std::env::temp_dir().join(format!("prism-encode-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.png");
        let e = write_atomic(&path, |_| {
            Err(ImageError::Encode {
                format: "PNG",
                message: "No space left on device (os error 28)".into(),
            })
        })
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: encoding PNG: No space left on device (os error 28)",
                path.display()
            )
        );
        assert!(!path.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
