//! [`Image`], the one image type: a row-major grid of pixels, with its 8-bit and float
//! aliases and conversions between them.

use prism_math::Rgb;

/// A rectangular grid of pixels stored row-major, top row first.
///
/// Invariant: `pixels.len() == width * height`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    width: u32,
    height: u32,
    pixels: Vec<T>,
}

/// An 8-bit RGB image (sRGB-encoded values as stored in files).
pub type Rgb8Image = Image<[u8; 3]>;
/// An 8-bit RGBA image, straight (not premultiplied) alpha.
pub type Rgba8Image = Image<[u8; 4]>;
/// A floating-point RGB image; the colour space is the owner's to state.
pub type RgbImage = Image<Rgb>;

impl<T: Copy> Image<T> {
    /// Creates a `width` x `height` image filled with `value`.
    #[must_use]
    pub fn new(width: u32, height: u32, value: T) -> Image<T> {
        Image {
            width,
            height,
            pixels: vec![value; width as usize * height as usize],
        }
    }

    /// Wraps a row-major pixel vector.
    ///
    /// # Panics
    /// If `pixels.len() != width * height`.
    #[must_use]
    pub fn from_vec(width: u32, height: u32, pixels: Vec<T>) -> Image<T> {
        assert_eq!(
            pixels.len(),
            width as usize * height as usize,
            "pixel count does not match {width}x{height}"
        );
        Image {
            width,
            height,
            pixels,
        }
    }

    /// Builds an image by calling `f(x, y)` for every pixel.
    #[must_use]
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> T) -> Image<T> {
        let mut pixels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Image {
            width,
            height,
            pixels,
        }
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> T {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Sets the pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    pub fn set(&mut self, x: u32, y: u32, value: T) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        self.pixels[y as usize * self.width as usize + x as usize] = value;
    }

    /// All pixels, row-major.
    #[must_use]
    pub fn pixels(&self) -> &[T] {
        &self.pixels
    }

    /// All pixels, row-major, mutable.
    #[must_use]
    pub fn pixels_mut(&mut self) -> &mut [T] {
        &mut self.pixels
    }

    /// Row `y`.
    #[must_use]
    pub fn row(&self, y: u32) -> &[T] {
        let w = self.width as usize;
        &self.pixels[y as usize * w..(y as usize + 1) * w]
    }

    /// Consumes the image and returns its pixel vector.
    #[must_use]
    pub fn into_vec(self) -> Vec<T> {
        self.pixels
    }

    /// Applies `f` to every pixel.
    #[must_use]
    pub fn map<U: Copy>(&self, f: impl FnMut(&T) -> U) -> Image<U> {
        Image {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        }
    }
}

impl Image<[u8; 4]> {
    /// Drops the alpha channel.
    #[must_use]
    pub fn to_rgb8(&self) -> Rgb8Image {
        self.map(|p| [p[0], p[1], p[2]])
    }

    /// Composites over an opaque background colour (straight alpha, in stored values).
    #[must_use]
    pub fn over_background(&self, bg: [u8; 3]) -> Rgb8Image {
        self.map(|&p| over_background8(p, bg))
    }
}

impl Image<[u8; 3]> {
    /// Converts to floating point, each channel divided by 255 (no colour-space change).
    #[must_use]
    pub fn to_rgb_f32(&self) -> RgbImage {
        self.map(|&p| Rgb::from_u8(p))
    }

    /// Decodes sRGB-encoded 8-bit values to linear light.
    #[must_use]
    pub fn srgb_to_linear(&self) -> RgbImage {
        self.map(|p| {
            Rgb::new(
                crate::srgb8_to_linear(p[0]),
                crate::srgb8_to_linear(p[1]),
                crate::srgb8_to_linear(p[2]),
            )
        })
    }
}

impl Image<Rgb> {
    /// Bytes with no colour-space change: each channel clamped to `[0, 1]` and
    /// `byte = trunc(255 v)` (the Delft ray tracer's bitmap output).
    #[must_use]
    pub fn to_rgb8_truncated(&self) -> Rgb8Image {
        self.map(|&p| truncated8(p))
    }

    /// Encodes linear values as 8-bit sRGB (clamped to [0, 1], rounded; NaN becomes 0).
    #[must_use]
    pub fn linear_to_srgb8(&self) -> Rgb8Image {
        self.map(|&p| srgb8(p))
    }
}

/// A straight-alpha 8-bit pixel composited over an opaque background colour, rounded to
/// nearest.
#[must_use]
pub fn over_background8(p: [u8; 4], bg: [u8; 3]) -> [u8; 3] {
    let a = u32::from(p[3]);
    let mix = |c: u8, b: u8| ((u32::from(c) * a + u32::from(b) * (255 - a) + 127) / 255) as u8;
    [mix(p[0], bg[0]), mix(p[1], bg[1]), mix(p[2], bg[2])]
}

/// A pixel as [`Image::to_rgb8_truncated`] writes it: each channel clamped to `[0, 1]`,
/// `byte = trunc(255 v)`.
#[must_use]
pub fn truncated8(p: Rgb) -> [u8; 3] {
    let b = |v: f32| (255.0 * v.clamp(0.0, 1.0)) as u8;
    [b(p.r), b(p.g), b(p.b)]
}

/// A pixel as [`Image::linear_to_srgb8`] writes it.
#[must_use]
pub fn srgb8(p: Rgb) -> [u8; 3] {
    [p.r, p.g, p.b].map(crate::linear_to_srgb8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_fn_is_row_major() {
        let im = Image::from_fn(3, 2, |x, y| x + 10 * y);
        assert_eq!(im.pixels(), &[0, 1, 2, 10, 11, 12]);
        assert_eq!(im.row(1), &[10, 11, 12]);
        assert_eq!(im.get(2, 1), 12);
    }

    /// Property: 8-bit sRGB -> linear -> 8-bit sRGB is the identity for every value.
    #[test]
    fn srgb_image_round_trip() {
        let im = Image::from_fn(256, 1, |x, _| [x as u8, 255 - x as u8, (x * 7 % 256) as u8]);
        assert_eq!(im.srgb_to_linear().linear_to_srgb8(), im);
    }

    #[test]
    fn over_background_closed_form() {
        let im = Image::from_vec(2, 1, vec![[255, 0, 0, 255], [255, 0, 0, 0]]);
        let rgb = im.over_background([0, 0, 255]);
        assert_eq!(rgb.pixels(), &[[255, 0, 0], [0, 0, 255]]);
    }
}
