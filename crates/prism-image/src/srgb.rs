//! The exact sRGB transfer curves of IEC 61966-2-1.

/// Decodes an sRGB-encoded value in [0, 1] to linear light.
#[must_use]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Encodes a linear value in [0, 1] with the sRGB curve.
#[must_use]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Decodes an 8-bit sRGB value to linear light.
#[must_use]
pub fn srgb8_to_linear(v: u8) -> f32 {
    srgb_to_linear(f32::from(v) / 255.0)
}

/// Encodes a linear value to 8-bit sRGB, clamping to [0, 1] and rounding to nearest.
/// NaN encodes to 0.
#[must_use]
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_are_continuous_at_the_break_point() {
        // Closed form: both branches agree at the threshold to within f32 rounding.
        let lin = 0.040_45f32 / 12.92;
        let other = ((0.040_45f32 + 0.055) / 1.055).powf(2.4);
        assert!((lin - other).abs() < 1e-6);
    }

    #[test]
    fn eight_bit_round_trip_is_identity() {
        for v in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb8_to_linear(v)), v);
        }
    }

    #[test]
    fn known_values() {
        // Mid grey 0.5 linear is sRGB 188 (0.7354), a standard published value.
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
    }
}
