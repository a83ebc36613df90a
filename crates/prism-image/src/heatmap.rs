//! Heat maps: per-pixel counts (such as adaptive sampling's samples per pixel) shown as
//! colours from blue (none) through cyan, green and yellow to red (the most).

use crate::{Image, Rgb8Image};

/// The heat map of a count image: blue for zero, red for the largest count in the image.
///
/// Each pixel's count is divided by the image's largest count (taken as 1 when every count
/// is zero, or the image is empty) and coloured by [`heat_colour`].
#[must_use]
pub fn heatmap(counts: &Image<u32>) -> Rgb8Image {
    let max = counts.pixels().iter().copied().max().unwrap_or(1).max(1);
    counts.map(|&n| heat_colour(n as f32 / max as f32))
}

/// The heat colour of `t` in `[0, 1]` as 8-bit RGB: blue (0), cyan (0.25), green (0.5),
/// yellow (0.75), red (1), linear in each quarter and truncated to 8 bits.
///
/// `t` outside `[0, 1]` is clamped.
#[must_use]
pub fn heat_colour(t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * 4.0;
    let (r, g, b) = match t {
        t if t < 1.0 => (0.0, t, 1.0),
        t if t < 2.0 => (0.0, 1.0, 2.0 - t),
        t if t < 3.0 => (t - 2.0, 1.0, 0.0),
        t => (1.0, 4.0 - t, 0.0),
    };
    [(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The five knots of the ramp, the clamp outside it, and one point inside a quarter.
    #[test]
    fn heat_colour_at_the_knots() {
        assert_eq!(heat_colour(0.0), [0, 0, 255]);
        assert_eq!(heat_colour(0.25), [0, 255, 255]);
        assert_eq!(heat_colour(0.5), [0, 255, 0]);
        assert_eq!(heat_colour(0.75), [255, 255, 0]);
        assert_eq!(heat_colour(1.0), [255, 0, 0]);
        assert_eq!(heat_colour(-1.0), [0, 0, 255]);
        assert_eq!(heat_colour(2.0), [255, 0, 0]);
        // t = 0.125 is halfway from blue to cyan: green 127.5, truncated.
        assert_eq!(heat_colour(0.125), [0, 127, 255]);
    }

    /// Along the ramp one channel moves at a time: green rises, then blue falls, then red
    /// rises, then green falls.
    #[test]
    fn heat_colour_moves_one_channel_at_a_time() {
        let mut prev = heat_colour(0.0);
        for k in 1..=400 {
            let c = heat_colour(k as f32 / 400.0);
            let changed = (0..3).filter(|&i| c[i] != prev[i]).count();
            assert!(changed <= 1, "{prev:?} -> {c:?}");
            prev = c;
        }
    }

    #[test]
    fn heatmap_scales_by_the_largest_count() {
        let counts = Image::from_fn(3, 1, |x, _| 2 * x);
        let heat = heatmap(&counts);
        assert_eq!(heat.get(0, 0), [0, 0, 255]);
        assert_eq!(heat.get(1, 0), [0, 255, 0]);
        assert_eq!(heat.get(2, 0), [255, 0, 0]);
        let none = heatmap(&Image::new(2, 2, 0u32));
        assert!(none.pixels().iter().all(|&c| c == [0, 0, 255]));
    }
}
