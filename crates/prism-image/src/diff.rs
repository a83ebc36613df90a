//! Image-difference metrics: per-channel agreement between two 8-bit images.

use crate::Rgb8Image;

/// Per-channel agreement between two 8-bit images of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffStats {
    /// Fraction of pixels whose three channels are all equal.
    pub identical_fraction: f64,
    /// Largest absolute channel difference, 0..=255.
    pub max_error: u8,
    /// Mean absolute channel difference, in 0..=255 units.
    pub mean_abs_error: f64,
    /// Fraction of pixels with some channel off by more than 24.
    pub over_24_fraction: f64,
}

/// Compares two RGB8 images pixel by pixel; `None` if their sizes differ.
#[must_use]
pub fn compare_rgb8(a: &Rgb8Image, b: &Rgb8Image) -> Option<DiffStats> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return None;
    }
    let n = a.pixels().len().max(1) as f64;
    let (mut same, mut over, mut sum, mut max) = (0usize, 0usize, 0u64, 0u8);
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let mut pmax = 0u8;
        for c in 0..3 {
            let d = p[c].abs_diff(q[c]);
            sum += u64::from(d);
            pmax = pmax.max(d);
        }
        same += usize::from(pmax == 0);
        over += usize::from(pmax > 24);
        max = max.max(pmax);
    }
    Some(DiffStats {
        identical_fraction: same as f64 / n,
        max_error: max,
        mean_abs_error: sum as f64 / (3.0 * n),
        over_24_fraction: over as f64 / n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Image;

    #[test]
    fn counts_closed_form() {
        let a = Image::from_vec(2, 2, vec![[0, 0, 0]; 4]);
        let b = Image::from_vec(2, 2, vec![[0, 0, 0], [30, 0, 0], [0, 3, 0], [0, 0, 0]]);
        let d = compare_rgb8(&a, &b).unwrap();
        assert_eq!(d.identical_fraction, 0.5);
        assert_eq!(d.max_error, 30);
        assert_eq!(d.over_24_fraction, 0.25);
        assert!((d.mean_abs_error - 33.0 / 12.0).abs() < 1e-12);
        assert!(compare_rgb8(&a, &Image::new(1, 1, [0, 0, 0])).is_none());
    }
}
