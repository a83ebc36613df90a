//! [`montage`]: pictures of one size set side by side in a grid, as one picture.

use crate::image::Image;

/// The panels in one picture, `cols` to a row, left to right then top to bottom; cells of
/// the last row that no panel fills are `fill`.
///
/// # Panics
/// If there are no panels, `cols` is 0, or the panels are not all the size of the first.
#[must_use]
pub fn montage<T: Copy>(panels: &[Image<T>], cols: usize, fill: T) -> Image<T> {
    assert!(cols > 0, "a montage needs at least one column");
    let first = panels.first().expect("a montage needs at least one panel");
    let (w, h) = (first.width(), first.height());
    assert!(
        panels.iter().all(|p| (p.width(), p.height()) == (w, h)),
        "montage panels must all be {w}x{h}"
    );
    let rows = panels.len().div_ceil(cols);
    Image::from_fn(w * cols as u32, h * rows as u32, |x, y| {
        let i = (y / h) as usize * cols + (x / w) as usize;
        panels.get(i).map_or(fill, |p| p.get(x % w, y % h))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: every pixel of the montage is its panel's pixel at the same offset, and the
    /// cells past the last panel are the fill.
    #[test]
    fn panels_land_in_their_cells() {
        let panels: Vec<Image<(u8, u32, u32)>> = (0..5u8)
            .map(|k| Image::from_fn(3, 2, |x, y| (k, x, y)))
            .collect();
        let m = montage(&panels, 2, (9, 0, 0));
        assert_eq!((m.width(), m.height()), (6, 6));
        for y in 0..6 {
            for x in 0..6 {
                let k = (y / 2) * 2 + x / 3;
                let expected = if k < 5 {
                    (k as u8, x % 3, y % 2)
                } else {
                    (9, 0, 0)
                };
                assert_eq!(m.get(x, y), expected, "({x}, {y})");
            }
        }
    }

    /// One row holds every panel when there are as many columns as panels.
    #[test]
    fn one_row() {
        let panels = [Image::new(1, 1, 1u8), Image::new(1, 1, 2u8)];
        let m = montage(&panels, 2, 0);
        assert_eq!(m.pixels(), &[1, 2]);
    }

    /// Panels of different sizes are refused.
    #[test]
    #[should_panic(expected = "must all be")]
    fn sizes_must_match() {
        let _ = montage(&[Image::new(1, 1, 0u8), Image::new(2, 1, 0u8)], 2, 0);
    }
}
