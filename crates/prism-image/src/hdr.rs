//! Radiance RGBE images (`.hdr`), read as Mitsuba reads them: the `#?` header, its `FORMAT`
//! line and the `-Y height +X width` resolution line, then flat or run-length-encoded
//! scanlines, each pixel `(r, g, b) * 2^(e - 136)` (0 where `e` is 0).

use crate::error::ImageError;
use crate::image::{Image, RgbImage};
use crate::io::check_size;
use prism_math::Rgb;

/// The longest header line read, and the most header lines.
const MAX_HEADER_LINE: usize = 4096;
const MAX_HEADER_LINES: usize = 1024;

/// True if `data` starts as a Radiance file does (`#?`).
#[must_use]
pub fn is_hdr(data: &[u8]) -> bool {
    data.starts_with(b"#?")
}

/// Decodes a Radiance RGBE file (`FORMAT=32-bit_rle_rgbe`, or no `FORMAT` line) whose
/// resolution line is `-Y height +X width` (rows top to bottom). `what` names the source in
/// errors.
///
/// # Errors
/// [`ImageError::Decode`] for a malformed file, an XYZE file or another orientation;
/// [`ImageError::OverBudget`] for an image over the image budget (12 bytes a pixel).
pub fn decode_hdr(data: &[u8], what: &str) -> Result<RgbImage, ImageError> {
    let err = |m: String| ImageError::Decode {
        what: what.to_string(),
        message: m,
    };
    if !is_hdr(data) {
        return Err(err("expected a Radiance header (#?)".into()));
    }
    let mut at = 0;
    let line = |at: &mut usize| -> Result<&str, ImageError> {
        let rest = &data[*at..];
        let end = rest
            .iter()
            .take(MAX_HEADER_LINE)
            .position(|&b| b == b'\n')
            .ok_or_else(|| err("the header ends before its resolution line".into()))?;
        *at += end + 1;
        std::str::from_utf8(&rest[..end])
            .map(str::trim)
            .map_err(|_| err("a header line is not text".into()))
    };
    line(&mut at)?;
    let mut size = None;
    for _ in 0..MAX_HEADER_LINES {
        let l = line(&mut at)?;
        if let Some(format) = l.strip_prefix("FORMAT=") {
            if format != "32-bit_rle_rgbe" {
                return Err(err(format!(
                    "FORMAT={format}: only 32-bit_rle_rgbe is read"
                )));
            }
            continue;
        }
        let tokens: Vec<&str> = l.split_whitespace().collect();
        if let [a, h, b, w] = tokens[..] {
            if ["-Y", "+Y", "-X", "+X"].contains(&a) {
                if (a, b) != ("-Y", "+X") {
                    return Err(err(format!(
                        "resolution {l:?}: only -Y height +X width (rows top to bottom) is read"
                    )));
                }
                let parse = |s: &str| {
                    s.parse::<u64>()
                        .map_err(|_| err(format!("resolution {l:?}: expected whole numbers")))
                };
                size = Some((parse(w)?, parse(h)?));
                break;
            }
        }
    }
    let (w, h) = size.ok_or_else(|| err("no resolution line in the first 1024 lines".into()))?;
    let pixels = &data[at..];
    let rle = (8..=0x7fff).contains(&w)
        && pixels.len() >= 4
        && pixels[0] == 2
        && pixels[1] == 2
        && pixels[2] & 0x80 == 0;
    // The fewest bytes such a file can hold: 4 a pixel flat; run-length encoded, 4 a
    // scanline and 2 for every 127 bytes of each channel.
    let needed = if rle {
        h.saturating_mul(4 + 8 * w.div_ceil(127))
    } else {
        w.saturating_mul(h).saturating_mul(4)
    };
    check_size(what, (w, h), 12, needed, pixels.len())?;
    let (w, h) = (w as usize, h as usize);
    let decode = |p: [u8; 4]| {
        if p[3] == 0 {
            return Rgb::BLACK;
        }
        let f = 2f64.powi(i32::from(p[3]) - 136);
        Rgb::new(
            (f64::from(p[0]) * f) as f32,
            (f64::from(p[1]) * f) as f32,
            (f64::from(p[2]) * f) as f32,
        )
    };
    let mut out = Vec::with_capacity(w * h);
    if !rle {
        out.extend(
            pixels[..w * h * 4]
                .chunks_exact(4)
                .map(|p| decode([p[0], p[1], p[2], p[3]])),
        );
        return Ok(Image::from_vec(w as u32, h as u32, out));
    }
    let mut line = vec![0u8; 4 * w];
    let mut at = 0;
    let truncated = || err("the pixels end early".into());
    for y in 0..h {
        let head = pixels.get(at..at + 4).ok_or_else(truncated)?;
        if head[0] != 2 || head[1] != 2 || (usize::from(head[2]) << 8 | usize::from(head[3])) != w {
            return Err(err(format!(
                "scanline {y}: expected a run-length header for {w} pixels"
            )));
        }
        at += 4;
        for channel in line.chunks_exact_mut(w) {
            let mut x = 0;
            while x < w {
                let pair = pixels.get(at..at + 2).ok_or_else(truncated)?;
                at += 2;
                let (count, value) = (usize::from(pair[0]), pair[1]);
                let (count, run) = if count > 128 {
                    (count - 128, true)
                } else {
                    (count, false)
                };
                if count == 0 || count > w - x {
                    return Err(err(format!("scanline {y}: a run past the scanline's end")));
                }
                if run {
                    channel[x..x + count].fill(value);
                } else {
                    channel[x] = value;
                    let rest = pixels.get(at..at + count - 1).ok_or_else(truncated)?;
                    channel[x + 1..x + count].copy_from_slice(rest);
                    at += count - 1;
                }
                x += count;
            }
        }
        out.extend(
            (0..w).map(|x| decode([line[x], line[w + x], line[2 * w + x], line[3 * w + x]])),
        );
    }
    Ok(Image::from_vec(w as u32, h as u32, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(w: u32, h: u32) -> Vec<u8> {
        format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y {h} +X {w}\n").into_bytes()
    }

    /// Closed form: flat pixels decode as `m * 2^(e - 136)`; e = 0 is black.
    #[test]
    fn flat_pixels_decode_as_mantissa_times_a_power_of_two() {
        let mut file = header(2, 1);
        file.extend([128, 64, 255, 129, 7, 7, 7, 0]);
        let im = decode_hdr(&file, "flat.hdr").unwrap();
        assert_eq!(im.get(0, 0), Rgb::new(1.0, 0.5, 255.0 / 128.0));
        assert_eq!(im.get(1, 0), Rgb::BLACK);
    }

    /// Oracle: a run-length-encoded scanline (runs and literals in each channel) decodes to
    /// the same pixels as the flat encoding of them.
    #[test]
    fn run_length_scanlines_equal_flat_ones() {
        let w = 10u32;
        let px: Vec<[u8; 4]> = (0..w as u8)
            .map(|i| [i * 20, 100, 255 - i, 130 + i % 2])
            .collect();
        let mut flat = header(w, 1);
        let mut w8 = header(w, 1);
        flat.extend(px.iter().flatten());
        w8.extend([2, 2, 0, w as u8]);
        // r: 10 literals; g: a run of 10; b: 5 literals then 5 literals; e: 10 literals.
        w8.push(10);
        w8.extend(px.iter().map(|p| p[0]));
        w8.extend([128 + 10, 100]);
        w8.push(5);
        w8.extend(px[..5].iter().map(|p| p[2]));
        w8.push(5);
        w8.extend(px[5..].iter().map(|p| p[2]));
        w8.push(10);
        w8.extend(px.iter().map(|p| p[3]));
        // A flat file of width 10 starts its pixels with a byte other than 2: flat.
        assert_eq!(
            decode_hdr(&w8, "rle.hdr").unwrap(),
            decode_hdr(&flat, "flat.hdr").unwrap()
        );
    }

    /// Hostile headers and pixels: located errors, nothing allocated for a size the file
    /// cannot hold or the budget refuses.
    #[test]
    fn malformed_files_are_refused() {
        let mut huge = header(30000, 30000);
        huge.extend([2, 2, 0x75, 0x30]);
        let e = decode_hdr(&huge, "huge.hdr").unwrap_err();
        assert!(matches!(e, ImageError::OverBudget { .. }), "{e}");
        let mut short = header(64, 64);
        short.extend([2, 2, 0, 64, 128 + 64, 1]);
        let e = decode_hdr(&short, "short.hdr").unwrap_err().to_string();
        assert!(e.contains("cannot fit"), "{e}");
        let mut overrun = header(8, 1);
        overrun.extend([2, 2, 0, 8, 128 + 9, 1, 0, 0, 0, 0, 0, 0, 0, 0]);
        let e = decode_hdr(&overrun, "overrun.hdr").unwrap_err().to_string();
        assert!(e.contains("a run past the scanline's end"), "{e}");
        let e = decode_hdr(b"#?RADIANCE\n\n+Y 4 +X 4\n", "up.hdr")
            .unwrap_err()
            .to_string();
        assert!(e.contains("only -Y height +X width"), "{e}");
        let e = decode_hdr(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n", "xyz.hdr")
            .unwrap_err()
            .to_string();
        assert!(e.contains("only 32-bit_rle_rgbe"), "{e}");
        let e = decode_hdr(b"#?RADIANCE\nno resolution", "cut.hdr")
            .unwrap_err()
            .to_string();
        assert!(e.contains("before its resolution line"), "{e}");
    }
}
