//! Text on frames: the public-domain 8x8 bitmap font (font8x8's basic Latin), drawn at a
//! whole-number scale, for the help overlay and the status line.

use font8x8::UnicodeFonts;
use prism_image::Rgb8Image;

/// The side of a glyph cell, in pixels at scale 1.
pub const GLYPH: u32 = 8;

/// The width of `text` in pixels at `scale`.
#[must_use]
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * GLYPH * scale
}

/// Draws `text` with its top-left corner at `(x, y)`, each glyph pixel a `scale` x `scale`
/// square of `color`; characters outside basic Latin draw as `?`; what falls outside the
/// image is clipped.
pub fn draw_text(image: &mut Rgb8Image, x: i64, y: i64, text: &str, scale: u32, color: [u8; 3]) {
    let (w, h) = (i64::from(image.width()), i64::from(image.height()));
    let s = i64::from(scale.max(1));
    for (k, c) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS
            .get(c)
            .or_else(|| font8x8::BASIC_FONTS.get('?'))
            .unwrap_or([0; 8]);
        let x0 = x + k as i64 * 8 * s;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 0 {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        let (px, py) = (x0 + col * s + dx, y + row as i64 * s + dy);
                        if (0..w).contains(&px) && (0..h).contains(&py) {
                            image.set(px as u32, py as u32, color);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the font's own bitmap of `A` (rows 0x0C, 0x1E, 0x33, ... least significant
    /// bit leftmost), drawn at scale 1 and 2; clipping at the edges does not panic.
    #[test]
    fn glyphs_are_the_fonts_bitmaps() {
        let mut im = Rgb8Image::new(20, 20, [0, 0, 0]);
        draw_text(&mut im, 1, 1, "A", 1, [255, 255, 255]);
        let row = |y: u32| -> u8 {
            (0..8).fold(0, |acc, x| {
                acc | (u8::from(im.get(1 + x, 1 + y)[0] == 255) << x)
            })
        };
        assert_eq!([row(0), row(1), row(2), row(4)], [0x0C, 0x1E, 0x33, 0x3F]);
        let mut big = Rgb8Image::new(20, 20, [0, 0, 0]);
        draw_text(&mut big, 0, 0, "A", 2, [9, 9, 9]);
        assert_eq!(big.get(4, 0), [9, 9, 9]);
        assert_eq!(big.get(5, 1), [9, 9, 9]);
        assert_eq!(big.get(3, 0), [0, 0, 0]);
        draw_text(&mut big, -5, 15, "clipped\u{1F600}", 3, [1, 2, 3]);
        assert_eq!(text_width("abc", 2), 48);
    }
}
