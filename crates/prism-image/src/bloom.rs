//! [`Bloom`]: glow around bright pixels, as the course's ray tracer makes it (a bright
//! layer weighted by luminance, blurred by a separable 21-tap Gaussian, added back).

use prism_math::Rgb;

use crate::RgbImage;

/// Taps on each side of the centre.
const RADIUS: usize = 10;
/// Taps of the kernel: offsets `-RADIUS..=RADIUS`.
const TAPS: usize = 2 * RADIUS + 1;

/// The 21 weights of the bloom blur, for offsets -10 to 10: `exp(-x^2 / (2 sigma^2))` with
/// `sigma = 10 / 3`, normalised to sum 1 (computed in `f64`, rounded to `f32`).
#[must_use]
pub fn bloom_weights() -> [f32; 21] {
    let sigma = RADIUS as f64 / 3.0;
    let raw: [f64; TAPS] = std::array::from_fn(|i| {
        let x = i as f64 - RADIUS as f64;
        (-x * x / (2.0 * sigma * sigma)).exp()
    });
    let sum: f64 = raw.iter().sum();
    raw.map(|w| (w / sum) as f32)
}

/// Bloom settings. The layer is the image's bright pixels, each times its luminance,
/// blurred `passes` times; [`Bloom::apply`] adds it to the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bloom {
    /// Pixels whose luminance is at most this (or at most 0) are left out of the bright
    /// layer.
    pub threshold: f32,
    /// Blur passes, each horizontal then vertical; 0 leaves the bright layer unblurred.
    pub passes: u32,
}

impl Default for Bloom {
    /// Threshold 0 (every pixel of positive luminance counts), one pass.
    fn default() -> Bloom {
        Bloom {
            threshold: 0.0,
            passes: 1,
        }
    }
}

impl Bloom {
    /// The blurred bright layer alone.
    ///
    /// The bright layer holds `p * L` where the luminance
    /// `L = 0.2126 R + 0.7152 G + 0.0722 B` exceeds both the threshold and 0 (a NaN `L`
    /// does not), else black. Each pass convolves every row, then every column, with
    /// [`bloom_weights`]; a tap outside the image takes the value of the pixel being
    /// computed. Sequential, so the result does not depend on the thread count.
    #[must_use]
    pub fn layer(&self, img: &RgbImage) -> RgbImage {
        let threshold = self.threshold;
        let mut layer = img.map(|&p| {
            let l = p.luminance();
            if l > threshold && l > 0.0 {
                p * l
            } else {
                Rgb::BLACK
            }
        });
        let w = bloom_weights();
        for _ in 0..self.passes {
            layer = blur_pass(&layer, &w);
        }
        layer
    }

    /// The image plus [`Bloom::layer`], pixel by pixel.
    #[must_use]
    pub fn apply(&self, img: &RgbImage) -> RgbImage {
        let layer = self.layer(img);
        let pixels = img
            .pixels()
            .iter()
            .zip(layer.pixels())
            .map(|(&p, &q)| p + q)
            .collect();
        RgbImage::from_vec(img.width(), img.height(), pixels)
    }
}

/// The index tap `k` of the pixel at `centre` reads along a line of `len` pixels: the
/// centre itself when the tap falls outside.
#[inline]
fn tap_index(centre: usize, k: usize, len: usize) -> usize {
    (centre + k)
        .checked_sub(RADIUS)
        .filter(|&i| i < len)
        .unwrap_or(centre)
}

/// One blur pass: every row, then every column, convolved with `w`. Each output pixel
/// sums its taps in order from offset -10 to 10.
fn blur_pass(src: &RgbImage, w: &[f32; TAPS]) -> RgbImage {
    let (width, height) = (src.width() as usize, src.height() as usize);
    let mut rows = Vec::with_capacity(width * height);
    for y in 0..height {
        let row = src.row(y as u32);
        for x in 0..width {
            let mut acc = Rgb::BLACK;
            for (k, &wk) in w.iter().enumerate() {
                acc += row[tap_index(x, k, width)] * wk;
            }
            rows.push(acc);
        }
    }
    // Whether a vertical tap is outside depends on the row alone, so a whole row of sums
    // advances one tap at a time (the same order per pixel, read along rows).
    let mut out = vec![Rgb::BLACK; width * height];
    for (y, out_row) in out.chunks_exact_mut(width.max(1)).enumerate() {
        for (k, &wk) in w.iter().enumerate() {
            let ys = tap_index(y, k, height);
            let src_row = &rows[ys * width..(ys + 1) * width];
            for (o, &s) in out_row.iter_mut().zip(src_row) {
                *o += s * wk;
            }
        }
    }
    RgbImage::from_vec(src.width(), src.height(), out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Pcg32;

    fn bright_value(p: Rgb) -> Rgb {
        p * p.luminance()
    }

    /// Brute force: one pass computed pixel by pixel with signed offsets, the horizontal
    /// sum from the source image and the vertical one from the horizontal result.
    fn reference_pass(src: &RgbImage) -> RgbImage {
        let w = bloom_weights();
        let (wd, ht) = (src.width() as i64, src.height() as i64);
        let read = |img: &RgbImage, x: i64, y: i64, cx: i64, cy: i64| {
            if x < 0 || x >= wd || y < 0 || y >= ht {
                img.get(cx as u32, cy as u32)
            } else {
                img.get(x as u32, y as u32)
            }
        };
        let h = RgbImage::from_fn(src.width(), src.height(), |x, y| {
            let (x, y) = (i64::from(x), i64::from(y));
            let mut acc = Rgb::BLACK;
            for d in -10..=10i64 {
                acc += read(src, x + d, y, x, y) * w[(d + 10) as usize];
            }
            acc
        });
        RgbImage::from_fn(src.width(), src.height(), |x, y| {
            let (x, y) = (i64::from(x), i64::from(y));
            let mut acc = Rgb::BLACK;
            for d in -10..=10i64 {
                acc += read(&h, x, y + d, x, y) * w[(d + 10) as usize];
            }
            acc
        })
    }

    fn random_image(width: u32, height: u32, seed: u64) -> RgbImage {
        let mut rng = Pcg32::new(seed, 1);
        RgbImage::from_fn(width, height, |_, _| {
            // Mostly dim, a few bright, some negative channels.
            let s = if rng.next_f32() < 0.1 { 8.0 } else { 1.0 };
            Rgb::new(
                s * (rng.next_f32() - 0.1),
                s * rng.next_f32(),
                s * (rng.next_f32() - 0.2),
            )
        })
    }

    /// Closed form: each weight is `exp(-9 x^2 / 200) / S` (sigma^2 = 100/9), `S` the sum
    /// of the unnormalised terms; the weights sum to 1 and are symmetric about the centre.
    #[test]
    fn weights_match_closed_form_sum_to_one_and_are_symmetric() {
        let w = bloom_weights();
        let term = |x: f64| (-9.0 * x * x / 200.0).exp();
        let s: f64 = (-10..=10).map(|x| term(f64::from(x))).sum();
        for (i, &wi) in w.iter().enumerate() {
            let expected = term(i as f64 - 10.0) / s;
            assert!(
                (f64::from(wi) - expected).abs() <= 1e-7 * expected,
                "w[{i}] = {wi}, closed form {expected}"
            );
            assert_eq!(wi, w[20 - i], "asymmetric at {i}");
        }
        let sum: f64 = w.iter().map(|&x| f64::from(x)).sum();
        assert!((sum - 1.0).abs() < 1e-6, "sum {sum}");
        // Gaussian shape: the end taps are exp(-4.5) of the centre.
        assert!((f64::from(w[0]) / f64::from(w[10]) - (-4.5f64).exp()).abs() < 1e-6);
    }

    /// Separability: one pass over a lone bright pixel far from the edges gives exactly
    /// `v * w[10 + dx] * w[10 + dy]` within ten pixels of it (`v` its bright value) and 0
    /// elsewhere.
    #[test]
    fn lone_pixel_spreads_into_outer_product_of_weights() {
        let (n, c) = (61u32, 30u32);
        let p = Rgb::new(2.0, 1.0, 0.5);
        let mut img = RgbImage::new(n, n, Rgb::BLACK);
        img.set(c, c, p);
        let v = bright_value(p);
        let w = bloom_weights();
        let layer = Bloom::default().layer(&img);
        for y in 0..n {
            for x in 0..n {
                let (dx, dy) = (i64::from(x) - 30, i64::from(y) - 30);
                let expected = if dx.abs() <= 10 && dy.abs() <= 10 {
                    v * w[(dx + 10) as usize] * w[(dy + 10) as usize]
                } else {
                    Rgb::BLACK
                };
                assert_eq!(layer.get(x, y), expected, "at ({x}, {y})");
            }
        }
    }

    /// Property: outside taps take the centre value, so every pixel of a constant image
    /// sums the same terms in the same order: the layer is exactly constant (corners
    /// included), and equals the bright value up to rounding since the weights sum to 1.
    #[test]
    fn constant_image_stays_constant_to_the_corners() {
        let p = Rgb::new(0.9, 0.6, 0.3);
        let v = bright_value(p);
        for (wd, ht) in [(5, 4), (40, 30), (1, 1), (23, 1)] {
            for passes in [1, 3] {
                let layer = Bloom {
                    threshold: 0.0,
                    passes,
                }
                .layer(&RgbImage::new(wd, ht, p));
                let corner = layer.get(0, 0);
                for q in [
                    layer.get(wd - 1, 0),
                    layer.get(0, ht - 1),
                    layer.get(wd - 1, ht - 1),
                ] {
                    assert_eq!(q, corner, "{wd}x{ht}");
                }
                assert!(layer.pixels().iter().all(|&q| q == corner), "{wd}x{ht}");
                for (a, b) in corner.to_array().into_iter().zip(v.to_array()) {
                    assert!((a - b).abs() <= 1e-5 * b, "{a} vs {b}");
                }
            }
        }
    }

    /// Closed form at the edge: in a one-row image with only its first pixel bright
    /// (value `v`), pixel 0 gets `v` times the weights of offsets -10..=0 (its outside taps
    /// read itself), pixel `x` in 1..=10 gets `v * w[10 - x]` (its outside taps read its own
    /// black value, where edge clamping would read `v`), and the rest 0. The vertical pass
    /// of a one-row image multiplies by the sum of the weights, 1 up to rounding.
    #[test]
    fn outside_taps_read_the_centre_pixel_closed_form() {
        let p = Rgb::new(1.5, 0.5, 2.0);
        let v = bright_value(p);
        let mut img = RgbImage::new(30, 1, Rgb::BLACK);
        img.set(0, 0, p);
        let layer = Bloom::default().layer(&img);
        let w = bloom_weights();
        let close = |a: Rgb, b: Rgb| {
            a.to_array()
                .into_iter()
                .zip(b.to_array())
                .all(|(a, b)| (a - b).abs() <= 1e-6 * b.abs().max(1e-30))
        };
        let first: f32 = w[..=10].iter().sum();
        assert!(close(layer.get(0, 0), v * first), "{:?}", layer.get(0, 0));
        for x in 1..30u32 {
            let expected = if x <= 10 {
                v * w[10 - x as usize]
            } else {
                Rgb::BLACK
            };
            assert!(close(layer.get(x, 0), expected), "x = {x}");
        }
    }

    /// Closed form of the bright layer (0 passes): `p * L` where `L` exceeds the threshold
    /// and 0, black where `L` equals the threshold, is below it, or is negative.
    #[test]
    fn threshold_excludes_dim_pixels() {
        let dim = Rgb::splat(0.1);
        let at = Rgb::splat(0.5);
        let bright = Rgb::new(1.0, 0.8, 0.2);
        let img = RgbImage::from_vec(4, 1, vec![dim, at, bright, Rgb::BLACK]);
        let bloom = Bloom {
            threshold: at.luminance(),
            passes: 0,
        };
        let layer = bloom.layer(&img);
        assert_eq!(
            layer.pixels(),
            &[Rgb::BLACK, Rgb::BLACK, bright_value(bright), Rgb::BLACK]
        );
        // Threshold 0 takes every positive luminance; negative luminance never counts,
        // whatever the threshold.
        let neg = Rgb::new(-1.0, 0.1, 0.0);
        let img = RgbImage::from_vec(3, 1, vec![dim, neg, Rgb::BLACK]);
        let zero = Bloom {
            threshold: 0.0,
            passes: 0,
        };
        assert_eq!(
            zero.layer(&img).pixels(),
            &[bright_value(dim), Rgb::BLACK, Rgb::BLACK]
        );
        let below = Bloom {
            threshold: -10.0,
            passes: 0,
        };
        assert_eq!(below.layer(&img), zero.layer(&img));
        // With every pixel at or under the threshold, the blurred layer is black.
        let dim_only = RgbImage::new(30, 20, dim);
        let high = Bloom {
            threshold: 0.2,
            passes: 2,
        };
        assert!(high
            .layer(&dim_only)
            .pixels()
            .iter()
            .all(|&q| q == Rgb::BLACK));
    }

    /// Brute force: one pass equals the pixel-by-pixel reference on a random image smaller
    /// than and larger than the kernel, and two passes equal the reference applied twice
    /// to the bright layer.
    #[test]
    fn passes_match_brute_force_reference_applied_repeatedly() {
        for (wd, ht, seed) in [(37, 23, 7), (6, 9, 8), (25, 2, 9)] {
            let img = random_image(wd, ht, seed);
            let bright = Bloom {
                threshold: 0.3,
                passes: 0,
            }
            .layer(&img);
            let one = reference_pass(&bright);
            let layer = |passes| {
                Bloom {
                    threshold: 0.3,
                    passes,
                }
                .layer(&img)
            };
            assert_eq!(layer(1), one, "{wd}x{ht}");
            assert_eq!(layer(2), reference_pass(&one), "{wd}x{ht}");
        }
    }

    /// Closed form: `apply` is the image plus the layer; with no pass, `p + p * L`.
    #[test]
    fn apply_adds_the_layer_to_the_image() {
        let img = random_image(19, 13, 3);
        let bloom = Bloom::default();
        let layer = bloom.layer(&img);
        let out = bloom.apply(&img);
        for ((&o, &p), &q) in out.pixels().iter().zip(img.pixels()).zip(layer.pixels()) {
            assert_eq!(o, p + q);
        }
        let unblurred = Bloom {
            threshold: 0.0,
            passes: 0,
        };
        let p = Rgb::new(0.5, 2.0, 0.25);
        let one = RgbImage::new(1, 1, p);
        assert_eq!(unblurred.apply(&one).get(0, 0), p + bright_value(p));
        // An empty image stays empty.
        let empty = RgbImage::new(0, 0, Rgb::BLACK);
        assert_eq!(bloom.apply(&empty), empty);
    }
}
