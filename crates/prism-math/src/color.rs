//! [`Rgb`], a triple of `f32` colour channels, with its arithmetic.

use std::ops::{Add, AddAssign, Mul, MulAssign, Sub};

/// An RGB triple of `f32` channels; the colour space is whatever the owner states.
///
/// Images from 8-bit files hold their stored (sRGB-encoded) values divided by 255; renderers
/// that need linear light convert with `prism_image::srgb_to_linear`. Laid out as three
/// `f32` in order, so a slice of them is a slice of `3 * len` floats.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Rgb {
    /// Red channel.
    pub r: f32,
    /// Green channel.
    pub g: f32,
    /// Blue channel.
    pub b: f32,
}

impl Rgb {
    /// Black, `(0, 0, 0)`.
    pub const BLACK: Rgb = Rgb::new(0.0, 0.0, 0.0);
    /// White, `(1, 1, 1)`.
    pub const WHITE: Rgb = Rgb::new(1.0, 1.0, 1.0);

    /// Creates a colour from its three channels.
    #[must_use]
    pub const fn new(r: f32, g: f32, b: f32) -> Rgb {
        Rgb { r, g, b }
    }

    /// Creates a grey with all three channels equal to `v`.
    #[must_use]
    pub const fn splat(v: f32) -> Rgb {
        Rgb { r: v, g: v, b: v }
    }

    /// Creates a colour from 8-bit channels, each divided by 255.
    #[must_use]
    pub fn from_u8(c: [u8; 3]) -> Rgb {
        Rgb::new(
            f32::from(c[0]) / 255.0,
            f32::from(c[1]) / 255.0,
            f32::from(c[2]) / 255.0,
        )
    }

    /// Linear interpolation `self + (other - self) * t`.
    #[must_use]
    pub fn lerp(self, other: Rgb, t: f32) -> Rgb {
        self + (other - self) * t
    }

    /// Luminance of linear sRGB (Rec. 709 weights 0.2126, 0.7152, 0.0722).
    #[must_use]
    pub fn luminance(self) -> f32 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }

    /// The largest of the three channels.
    #[must_use]
    pub fn max_channel(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }

    /// True when every channel is finite.
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// The channels as an array `[r, g, b]`.
    #[must_use]
    pub fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul<f32> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f32) -> Rgb {
        Rgb::new(self.r * s, self.g * s, self.b * s)
    }
}

impl Mul<Rgb> for f32 {
    type Output = Rgb;
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}

impl Mul for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl MulAssign<f32> for Rgb {
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_u8_round_trips_through_255_scaling() {
        for v in 0..=255u8 {
            let c = Rgb::from_u8([v, v, v]);
            assert_eq!((c.r * 255.0).round() as u8, v);
        }
    }

    #[test]
    fn lerp_hits_endpoints() {
        let a = Rgb::new(0.1, 0.2, 0.3);
        let b = Rgb::new(0.9, 0.5, 0.0);
        assert_eq!(a.lerp(b, 0.0), a);
        let m = a.lerp(b, 1.0);
        assert!((m.r - b.r).abs() < 1e-7 && (m.g - b.g).abs() < 1e-7 && m.b.abs() < 1e-7);
    }
}
