//! [`PngRowWriter`]: an 8-bit RGB or RGBA PNG written a row at a time, the one PNG encoder
//! prism writes with (every row Paeth-filtered, fdeflate's fast compression, the stream cut
//! into IDAT chunks of at most 1 MiB), so a picture written whole and one streamed row by
//! row are the same bytes.

use std::io::Write;

use crate::ImageError;

/// The most bytes of compressed data an IDAT chunk holds.
const IDAT_BYTES: usize = 1 << 20;

/// The Paeth filter's type byte.
const PAETH: u8 = 4;

/// Pixel layouts a [`PngRowWriter`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngColor {
    /// Three bytes a pixel.
    Rgb,
    /// Four bytes a pixel, straight alpha.
    Rgba,
}

impl PngColor {
    fn bytes(self) -> usize {
        match self {
            PngColor::Rgb => 3,
            PngColor::Rgba => 4,
        }
    }
}

/// Writes one PNG chunk: length, type, data, CRC of type and data.
fn chunk(out: &mut impl Write, kind: &[u8; 4], data: &[u8]) -> std::io::Result<()> {
    let mut crc = crc32fast::Hasher::new();
    crc.update(kind);
    crc.update(data);
    out.write_all(&(data.len() as u32).to_be_bytes())?;
    out.write_all(kind)?;
    out.write_all(data)?;
    out.write_all(&crc.finalize().to_be_bytes())
}

/// The compressed stream, cut into IDAT chunks as it grows.
struct Idat<W: Write> {
    out: W,
    pending: Vec<u8>,
}

impl<W: Write> Write for Idat<W> {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        self.pending.extend_from_slice(data);
        while self.pending.len() >= IDAT_BYTES {
            chunk(&mut self.out, b"IDAT", &self.pending[..IDAT_BYTES])?;
            self.pending.drain(..IDAT_BYTES);
        }
        Ok(data.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// An 8-bit PNG being written row by row from the top.
pub struct PngRowWriter<W: Write> {
    deflate: fdeflate::Compressor<Idat<W>>,
    bpp: usize,
    row_bytes: usize,
    rows_left: u32,
    previous: Vec<u8>,
    filtered: Vec<u8>,
}

impl<W: Write> PngRowWriter<W> {
    /// Writes the signature and header of a `width x height` picture to `out`.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails or the size is 0 or over PNG's limit.
    pub fn new(mut out: W, width: u32, height: u32, color: PngColor) -> Result<Self, ImageError> {
        if width == 0 || height == 0 || width > i32::MAX as u32 || height > i32::MAX as u32 {
            return Err(ImageError::Encode {
                format: "PNG",
                message: format!("a {width}x{height} picture cannot be a PNG"),
            });
        }
        let mut head = Vec::with_capacity(13);
        head.extend_from_slice(&width.to_be_bytes());
        head.extend_from_slice(&height.to_be_bytes());
        let kind = match color {
            PngColor::Rgb => 2,
            PngColor::Rgba => 6,
        };
        head.extend_from_slice(&[8, kind, 0, 0, 0]);
        out.write_all(b"\x89PNG\r\n\x1a\n").map_err(encode)?;
        chunk(&mut out, b"IHDR", &head).map_err(encode)?;
        let idat = Idat {
            out,
            pending: Vec::new(),
        };
        let row_bytes = width as usize * color.bytes();
        Ok(PngRowWriter {
            deflate: fdeflate::Compressor::new(idat).map_err(encode)?,
            bpp: color.bytes(),
            row_bytes,
            rows_left: height,
            previous: vec![0; row_bytes],
            filtered: vec![0; row_bytes + 1],
        })
    }

    /// Writes the next row, `width` pixels of the picture's layout.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if the destination fails.
    ///
    /// # Panics
    /// If the row is the wrong length or every row has been written.
    pub fn write_row(&mut self, row: &[u8]) -> Result<(), ImageError> {
        assert_eq!(row.len(), self.row_bytes, "a row of the picture's width");
        assert!(self.rows_left > 0, "no more rows than the picture's height");
        self.rows_left -= 1;
        filter_paeth(row, &self.previous, self.bpp, &mut self.filtered[1..]);
        self.filtered[0] = PAETH;
        self.previous.copy_from_slice(row);
        self.deflate.write_data(&self.filtered).map_err(encode)
    }

    /// Ends the stream and the file, handing back the writer.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if the destination fails.
    ///
    /// # Panics
    /// If a row is missing.
    pub fn finish(self) -> Result<W, ImageError> {
        assert_eq!(self.rows_left, 0, "every row written");
        let mut idat = self.deflate.finish().map_err(encode)?;
        if !idat.pending.is_empty() {
            chunk(&mut idat.out, b"IDAT", &idat.pending).map_err(encode)?;
        }
        chunk(&mut idat.out, b"IEND", &[]).map_err(encode)?;
        Ok(idat.out)
    }
}

/// Paeth-filters `row` (above it `up`, `bpp` bytes a pixel) into `out`. Every byte reads
/// only unfiltered bytes, so the loop has no dependence from byte to byte and runs in the
/// processor's vectors.
fn filter_paeth(row: &[u8], up: &[u8], bpp: usize, out: &mut [u8]) {
    let n = row.len();
    let head = bpp.min(n);
    // The first pixel has nothing to its left: Paeth predicts from above.
    for i in 0..head {
        out[i] = row[i].wrapping_sub(paeth(0, up[i], 0));
    }
    let (x, a) = (&row[head..], &row[..n - head]);
    let (b, c) = (&up[head..], &up[..n - head]);
    let out = &mut out[head..n];
    for i in 0..out.len() {
        out[i] = x[i].wrapping_sub(paeth(a[i], b[i], c[i]));
    }
}

/// PNG's Paeth predictor of a byte from the bytes left (`a`), up (`b`) and up-left (`c`),
/// without branches.
#[inline(always)]
fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let (ia, ib, ic) = (i16::from(a), i16::from(b), i16::from(c));
    // p = a + b - c; its distances to a, b and c.
    let pa = (ib - ic).abs();
    let pb = (ia - ic).abs();
    let pc = (ia + ib - 2 * ic).abs();
    let b_or_c = if pb <= pc { b } else { c };
    if pa <= pb && pa <= pc {
        a
    } else {
        b_or_c
    }
}

fn encode(e: std::io::Error) -> ImageError {
    ImageError::Encode {
        format: "PNG",
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the filter equals the predictor written as the PNG specification
    /// writes it (with branches), on every triple of bytes in steps that hit the ties.
    #[test]
    fn branchless_paeth_is_the_specification() {
        let spec = |a: u8, b: u8, c: u8| {
            let p = i16::from(a) + i16::from(b) - i16::from(c);
            let (pa, pb, pc) = (
                (p - i16::from(a)).abs(),
                (p - i16::from(b)).abs(),
                (p - i16::from(c)).abs(),
            );
            if pa <= pb && pa <= pc {
                a
            } else if pb <= pc {
                b
            } else {
                c
            }
        };
        for a in (0..=255u8).step_by(3) {
            for b in (0..=255u8).step_by(5) {
                for c in 0..=255u8 {
                    assert_eq!(paeth(a, b, c), spec(a, b, c), "{a} {b} {c}");
                }
            }
        }
    }

    /// Oracle (the png crate's decoder): a picture with smooth areas, noise and edges, in
    /// both layouts and over several IDAT chunks, decodes to the rows written.
    #[test]
    fn decodes_to_the_rows_written() {
        for (color, w, h) in [
            (PngColor::Rgb, 300, 7),
            (PngColor::Rgba, 5, 3),
            (PngColor::Rgb, 700, 600),
        ] {
            let n = w * h * color.bytes();
            let mut state = 12345u32;
            let data: Vec<u8> = (0..n)
                .map(|i| {
                    state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
                    if (i / 97) % 3 == 0 {
                        (state >> 16) as u8
                    } else {
                        (i % 251) as u8
                    }
                })
                .collect();
            let mut wr = PngRowWriter::new(Vec::new(), w as u32, h as u32, color).unwrap();
            for row in data.chunks(w * color.bytes()) {
                wr.write_row(row).unwrap();
            }
            let bytes = wr.finish().unwrap();
            let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes))
                .read_info()
                .unwrap();
            let mut buf = vec![0; reader.output_buffer_size()];
            let info = reader.next_frame(&mut buf).unwrap();
            assert_eq!((info.width, info.height), (w as u32, h as u32));
            assert_eq!(&buf[..info.buffer_size()], &data[..]);
        }
    }
}
