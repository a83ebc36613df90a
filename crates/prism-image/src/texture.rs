//! The one texture sampler of prism: a full box-filtered mipmap chain, nearest and bilinear
//! texel lookups with clamp-to-edge, and level selection from screen-space uv derivatives.

use prism_math::{Rgb, Vec2};

use crate::{Image, RgbImage};

/// How texels are looked up within one mip level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelSampling {
    /// The texel whose square contains the sample point.
    #[default]
    Nearest,
    /// Bilinear interpolation between the four nearest texel centres.
    Bilinear,
    /// The Mitchell-Netravali cubic (B = C = 1/3) over the sixteen nearest texel centres,
    /// as Skia's and resvg's bicubic image filter; results are clamped to be non-negative.
    Bicubic,
}

/// How the mip level is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LevelSampling {
    /// Always level 0 (no mipmapping).
    #[default]
    Zero,
    /// The level nearest to the continuous level `D`.
    Nearest,
    /// Linear interpolation between levels `floor(D)` and `floor(D) + 1` (trilinear with
    /// bilinear pixel sampling).
    Linear,
}

/// A texture with its full mipmap chain.
///
/// Level 0 is the image as given; level `k + 1` has size `max(1, floor(w_k / 2))` by
/// `max(1, floor(h_k / 2))` and every texel is the area-weighted (box) average of the
/// level-`k` texels its footprint covers, so odd and non-power-of-two sizes are filtered
/// exactly. The chain ends with a 1x1 level. Values are stored as given: no colour-space
/// conversion happens here. uv `(0, 0)` is the top-left corner of the first row, `(1, 1)`
/// the bottom-right corner of the last row.
#[derive(Clone, Debug)]
pub struct Texture {
    levels: Vec<RgbImage>,
    uv: UvConvention,
    wrap: [Wrap; 2],
}

/// What a lookup outside `[0, 1]` reads, along one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The edge texel (clamp to edge).
    #[default]
    Clamp,
    /// The texture repeats: texel `i` of `w` is also texel `i + k w`.
    Repeat,
    /// The texture repeats mirrored: texel `-1 - i` is texel `i`, and the pattern repeats
    /// every `2 w` texels.
    Mirror,
}

/// Where uv coordinates fall on the texel grid of a level `w` texels wide.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum UvConvention {
    /// u = 0 and u = 1 are the outer edges of the first and last texels; texel `i` covers
    /// `[i / w, (i + 1) / w)` and its centre is at `(i + 0.5) / w` (OpenGL, pbrt).
    #[default]
    Standard,
    /// u = 0 and u = 1 are the centres of the first and last texels: the texel coordinate
    /// is `u * (w - 1)`, as in the CS184 course renderer.
    EdgeCenters,
}

/// Per-destination-index list of `(source index, weight)` for a box filter from `src` to
/// `dst` samples.
fn box_weights(src: u32, dst: u32) -> Vec<Vec<(u32, f32)>> {
    let scale = f64::from(src) / f64::from(dst);
    (0..dst)
        .map(|i| {
            let lo = f64::from(i) * scale;
            let hi = f64::from(i + 1) * scale;
            let mut taps = Vec::new();
            let mut s = lo.floor() as u32;
            while f64::from(s) < hi && s < src {
                let a = lo.max(f64::from(s));
                let b = hi.min(f64::from(s + 1));
                if b > a {
                    taps.push((s, ((b - a) / scale) as f32));
                }
                s += 1;
            }
            taps
        })
        .collect()
}

fn downsample(src: &RgbImage) -> RgbImage {
    let (w, h) = (src.width(), src.height());
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let wx = box_weights(w, nw);
    let wy = box_weights(h, nh);
    // Filter rows first, then columns.
    let tmp = Image::from_fn(nw, h, |x, y| {
        let row = src.row(y);
        wx[x as usize]
            .iter()
            .fold(Rgb::BLACK, |acc, &(s, wt)| acc + row[s as usize] * wt)
    });
    Image::from_fn(nw, nh, |x, y| {
        wy[y as usize]
            .iter()
            .fold(Rgb::BLACK, |acc, &(s, wt)| acc + tmp.get(x, s) * wt)
    })
}

impl Texture {
    /// Builds the full mipmap chain from a level-0 image.
    #[must_use]
    pub fn new(base: RgbImage) -> Texture {
        let mut levels = vec![base];
        loop {
            let last = levels.last().expect("chain starts non-empty");
            if last.width() == 1 && last.height() == 1 {
                break;
            }
            let next = downsample(last);
            levels.push(next);
        }
        Texture {
            levels,
            uv: UvConvention::Standard,
            wrap: [Wrap::Clamp; 2],
        }
    }

    /// Returns the texture with other wrap modes along u and v.
    #[must_use]
    pub fn with_wrap(mut self, u: Wrap, v: Wrap) -> Texture {
        self.wrap = [u, v];
        self
    }

    /// Returns the texture with a different uv convention.
    #[must_use]
    pub fn with_uv_convention(mut self, uv: UvConvention) -> Texture {
        self.uv = uv;
        self
    }

    /// The uv convention in use.
    #[must_use]
    pub fn uv_convention(&self) -> UvConvention {
        self.uv
    }

    /// The mip levels, finest first.
    #[must_use]
    pub fn levels(&self) -> &[RgbImage] {
        &self.levels
    }

    /// Width and height of level 0.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].width(), self.levels[0].height())
    }

    /// The continuous mip level `D = log2(L)` for screen-space uv derivatives, where `L` is
    /// the longer of the two derivative vectors measured in level-0 texels. Clamped to
    /// `[0, levels - 1]`; 0 for degenerate or non-finite input.
    #[must_use]
    pub fn level_for(&self, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
        let (w, h) = self.size();
        let scale = Vec2::new(w as f32, h as f32);
        let l = (duv_dx * scale).length().max((duv_dy * scale).length());
        let d = l.log2();
        if !d.is_finite() || d <= 0.0 {
            return 0.0;
        }
        d.min((self.levels.len() - 1) as f32)
    }

    /// Samples one mip level at `uv`, wrapping each axis as [`Texture::with_wrap`] set
    /// (clamping to the edge by default). Nearest picks the texel whose centre is closest;
    /// bilinear blends the four surrounding texel centres.
    ///
    /// # Panics
    /// If `level` is not below `levels().len()`.
    #[must_use]
    pub fn sample_level(&self, uv: Vec2, level: usize, mode: PixelSampling) -> Rgb {
        let im = &self.levels[level];
        let (w, h) = (im.width() as i64, im.height() as i64);
        // Continuous texel coordinates: integers are texel centres.
        let (gx, gy) = match self.uv {
            UvConvention::Standard => (
                f64::from(uv.x) * w as f64 - 0.5,
                f64::from(uv.y) * h as f64 - 0.5,
            ),
            UvConvention::EdgeCenters => (
                f64::from(uv.x) * (w - 1) as f64,
                f64::from(uv.y) * (h - 1) as f64,
            ),
        };
        match mode {
            PixelSampling::Nearest => {
                let (x, y) = (floor(gx + 0.5), floor(gy + 0.5));
                if !x.is_finite() || !y.is_finite() {
                    return im.get(0, 0);
                }
                im.get(self.fold(x as i64, w, 0), self.fold(y as i64, h, 1))
            }
            PixelSampling::Bilinear => {
                let Some(([f00, f10, f01, f11], tx, ty)) = self.corners(level, gx, gy) else {
                    return im.get(0, 0);
                };
                let top = f00.lerp(f10, tx);
                let bottom = f01.lerp(f11, tx);
                top.lerp(bottom, ty)
            }
            PixelSampling::Bicubic => {
                if !gx.is_finite() || !gy.is_finite() {
                    return im.get(0, 0);
                }
                let (fx, fy) = (floor(gx), floor(gy));
                let (wx, wy) = (mitchell((gx - fx) as f32), mitchell((gy - fy) as f32));
                let (x0, y0) = (fx as i64 - 1, fy as i64 - 1);
                if x0 >= 0 && y0 >= 0 && x0 <= w - 4 && y0 <= h - 4 {
                    // All sixteen texels inside: no wrapping, rows read as slices.
                    let px = im.pixels();
                    let mut sum = Rgb::BLACK;
                    for (j, wyj) in wy.iter().enumerate() {
                        let at = (y0 as usize + j) * w as usize + x0 as usize;
                        let mut row = Rgb::BLACK;
                        for (p, wxi) in px[at..at + 4].iter().zip(&wx) {
                            row += *p * *wxi;
                        }
                        sum += row * *wyj;
                    }
                    return Rgb::new(sum.r.max(0.0), sum.g.max(0.0), sum.b.max(0.0));
                }
                let xs: [u32; 4] = std::array::from_fn(|i| self.fold(x0 + i as i64, w, 0));
                let mut sum = Rgb::BLACK;
                for (j, wyj) in wy.iter().enumerate() {
                    let y = self.fold(y0 + j as i64, h, 1);
                    let mut row = Rgb::BLACK;
                    for (x, wxi) in xs.iter().zip(&wx) {
                        row += im.get(*x, y) * *wxi;
                    }
                    sum += row * *wyj;
                }
                Rgb::new(sum.r.max(0.0), sum.g.max(0.0), sum.b.max(0.0))
            }
        }
    }

    /// The derivatives of the bilinear lookup of level 0 at `uv` along the image's x and y,
    /// per texel: `[d/dx, d/dy]` (the standard uv convention).
    #[must_use]
    pub fn bilinear_gradient(&self, uv: Vec2) -> [Rgb; 2] {
        let (w, h) = self.size();
        let gx = f64::from(uv.x) * f64::from(w) - 0.5;
        let gy = f64::from(uv.y) * f64::from(h) - 0.5;
        let Some(([f00, f10, f01, f11], tx, ty)) = self.corners(0, gx, gy) else {
            return [Rgb::BLACK; 2];
        };
        [
            (f10 - f00) * (1.0 - ty) + (f11 - f01) * ty,
            (f01 - f00) * (1.0 - tx) + (f11 - f10) * tx,
        ]
    }

    /// Texel `i` of `n` along `axis` (0 for x), wrapped as the axis wraps.
    #[inline]
    fn fold(&self, i: i64, n: i64, axis: usize) -> u32 {
        match self.wrap[axis] {
            Wrap::Clamp => i.clamp(0, n - 1) as u32,
            // Inside the image, or one past its end (a bilinear lookup's second texel), no
            // division is needed.
            Wrap::Repeat if (0..n).contains(&i) => i as u32,
            Wrap::Repeat if i == n => 0,
            Wrap::Repeat => i.rem_euclid(n) as u32,
            Wrap::Mirror => {
                let j = i.rem_euclid(2 * n);
                (if j < n { j } else { 2 * n - 1 - j }) as u32
            }
        }
    }

    /// The four texels around continuous texel coordinates `(gx, gy)` of `level` (top left,
    /// top right, bottom left, bottom right) and the position between them; none for
    /// coordinates that are not finite.
    fn corners(&self, level: usize, gx: f64, gy: f64) -> Option<([Rgb; 4], f32, f32)> {
        if !gx.is_finite() || !gy.is_finite() {
            return None;
        }
        let im = &self.levels[level];
        let (w, h) = (i64::from(im.width()), i64::from(im.height()));
        let (x0, y0) = (floor(gx), floor(gy));
        let (tx, ty) = ((gx - x0) as f32, (gy - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        // (Coordinates far out saturate; the next texel must not overflow past them.)
        let (xa, xb) = (self.fold(x0, w, 0), self.fold(x0.saturating_add(1), w, 0));
        let (ya, yb) = (self.fold(y0, h, 1), self.fold(y0.saturating_add(1), h, 1));
        Some((
            [
                im.get(xa, ya),
                im.get(xb, ya),
                im.get(xa, yb),
                im.get(xb, yb),
            ],
            tx,
            ty,
        ))
    }

    /// Samples at `uv` with the given level and pixel modes, choosing the level from the
    /// screen-space derivatives `duv_dx`, `duv_dy` (uv change per pixel step in x and y).
    #[must_use]
    pub fn sample(
        &self,
        uv: Vec2,
        duv_dx: Vec2,
        duv_dy: Vec2,
        pixel: PixelSampling,
        level: LevelSampling,
    ) -> Rgb {
        let d = match level {
            LevelSampling::Zero => 0.0,
            _ => self.level_for(duv_dx, duv_dy),
        };
        self.sample_lod(uv, d, pixel, level)
    }

    /// Samples at `uv` given the continuous level `d` (from [`Texture::level_for`], which
    /// callers with constant derivatives compute once): level 0 for `Zero`, `round(d)` for
    /// `Nearest`, a blend of the two nearest levels for `Linear`.
    #[must_use]
    pub fn sample_lod(&self, uv: Vec2, d: f32, pixel: PixelSampling, level: LevelSampling) -> Rgb {
        match level {
            LevelSampling::Zero => self.sample_level(uv, 0, pixel),
            LevelSampling::Nearest => {
                let max = (self.levels.len() - 1) as f32;
                let k = if d.is_finite() {
                    d.round().clamp(0.0, max)
                } else {
                    0.0
                };
                self.sample_level(uv, k as usize, pixel)
            }
            LevelSampling::Linear => self.sample_at_level(uv, d, pixel),
        }
    }

    /// Samples at a continuous level `d`, blending levels `floor(d)` and `floor(d) + 1`
    /// linearly; `d` is clamped to the chain. Bicubic texels are for magnification: past
    /// level 0 the levels are already filtered, and their texels are blended bilinearly.
    #[must_use]
    pub fn sample_at_level(&self, uv: Vec2, d: f32, pixel: PixelSampling) -> Rgb {
        let max = (self.levels.len() - 1) as f32;
        let d = if d.is_finite() {
            d.clamp(0.0, max)
        } else {
            0.0
        };
        let pixel = if d > 0.0 && pixel == PixelSampling::Bicubic {
            PixelSampling::Bilinear
        } else {
            pixel
        };
        let lo = d.floor();
        let t = d - lo;
        let lo = lo as usize;
        let a = self.sample_level(uv, lo, pixel);
        if t == 0.0 || lo + 1 >= self.levels.len() {
            return a;
        }
        a.lerp(self.sample_level(uv, lo + 1, pixel), t)
    }
}

/// `x.floor()`, bit for bit (NaN gives NaN), without a call into the C library where the
/// processor's rounding instruction is not compiled in: truncation, moved down for negative
/// non-integers. From 2^52 up every float is an integer, its own floor.
#[inline]
fn floor(x: f64) -> f64 {
    const INTEGRAL: f64 = 4_503_599_627_370_496.0; // 2^52
    if x.is_nan() || x.abs() >= INTEGRAL {
        return x;
    }
    let t = x as i64 as f64;
    if t == x {
        // An integer, its sign of zero kept.
        x
    } else if t > x {
        t - 1.0
    } else {
        t
    }
}

/// The Mitchell-Netravali (B = C = 1/3) weights of the four texels at offsets -1, 0, 1, 2
/// from a point `t` in [0, 1) past the second: the kernel's two cubic pieces, for
/// `|x| < 1` `(7|x|^3 - 12|x|^2 + 16/3) / 6` and for `1 <= |x| < 2`
/// `(-7/3|x|^3 + 12|x|^2 - 20|x| + 32/3) / 6`.
#[inline]
fn mitchell(t: f32) -> [f32; 4] {
    // Both pieces at all four offsets, then one division of the four numerators (a single
    // vector division rather than four).
    let x = [1.0 + t, t, 1.0 - t, 2.0 - t];
    let near = x.map(|x| (7.0 * x - 12.0) * x * x + 16.0 / 3.0);
    let far = x.map(|x| ((-7.0 / 3.0 * x + 12.0) * x - 20.0) * x + 32.0 / 3.0);
    [far[0], near[1], near[2], far[3]].map(|v| v / 6.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: the Mitchell-Netravali kernel's weights sum to one and have no first
    /// moment, so bicubic sampling reproduces a linear ramp exactly away from the edges.
    #[test]
    fn bicubic_reproduces_linear_ramps() {
        let img = RgbImage::from_fn(16, 8, |x, y| {
            Rgb::new(
                x as f32 / 15.0,
                y as f32 / 7.0,
                0.25 + 0.5 * x as f32 / 15.0,
            )
        });
        let tex = Texture::new(img);
        for (u, v) in [(0.31f32, 0.43f32), (0.5, 0.5), (0.62, 0.37), (0.25, 0.6)] {
            let got = tex.sample_level(Vec2::new(u, v), 0, PixelSampling::Bicubic);
            let (gx, gy) = (u * 16.0 - 0.5, v * 8.0 - 0.5);
            let want = Rgb::new(gx / 15.0, gy / 7.0, 0.25 + 0.5 * gx / 15.0);
            for (a, b) in [(got.r, want.r), (got.g, want.g), (got.b, want.b)] {
                assert!(
                    (a - b).abs() < 1e-5,
                    "at ({u}, {v}): {got:?} against {want:?}"
                );
            }
        }
        let weights = mitchell(0.37);
        assert!((weights.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    /// Oracle: the standard library's `floor`, bit for bit, on edge cases (signed zeros,
    /// halves, the 2^52 boundary, huge values, infinities) and a million random floats.
    #[test]
    fn floor_equals_std_floor_bit_for_bit() {
        let same = |x: f64| {
            let (a, b) = (floor(x), x.floor());
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "{x:e}"
            );
        };
        let big = 4_503_599_627_370_496.0_f64;
        for x in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            0.999_999_999,
            -1e-300,
            1e-300,
            big,
            -big,
            big - 0.5,
            -big + 0.5,
            big + 1.0,
            1e19,
            -1e19,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            f64::MIN,
        ] {
            same(x);
        }
        let mut rng = prism_math::Pcg32::new(7, 1);
        for _ in 0..1_000_000 {
            let bits = (u64::from(rng.next_u32()) << 32) | u64::from(rng.next_u32());
            same(f64::from_bits(bits));
            same((f64::from(rng.next_f32()) - 0.5) * 4096.0);
        }
    }

    fn checker(n: u32) -> RgbImage {
        Image::from_fn(n, n, |x, y| {
            if (x + y) % 2 == 0 {
                Rgb::WHITE
            } else {
                Rgb::BLACK
            }
        })
    }

    fn close(a: Rgb, b: Rgb, eps: f32) -> bool {
        (a.r - b.r).abs() <= eps && (a.g - b.g).abs() <= eps && (a.b - b.b).abs() <= eps
    }

    #[test]
    fn chain_reaches_one_by_one_for_non_power_of_two() {
        let t = Texture::new(Image::new(2058, 1036, Rgb::WHITE));
        let sizes: Vec<_> = t.levels().iter().map(|l| (l.width(), l.height())).collect();
        assert_eq!(sizes[1], (1029, 518));
        assert_eq!(sizes[2], (514, 259));
        assert_eq!(*sizes.last().unwrap(), (1, 1));
        assert_eq!(sizes.len(), 12);
    }

    /// Closed form: a constant texture samples to the constant at every level and mode.
    #[test]
    fn constant_texture_is_constant_everywhere() {
        let c = Rgb::new(0.25, 0.5, 0.75);
        let t = Texture::new(Image::new(37, 23, c));
        for (k, l) in t.levels().iter().enumerate() {
            for p in l.pixels() {
                assert!(close(*p, c, 1e-6), "level {k}");
            }
            for uv in [
                Vec2::new(0.0, 0.0),
                Vec2::new(0.31, 0.77),
                Vec2::new(1.0, 1.0),
            ] {
                for m in [PixelSampling::Nearest, PixelSampling::Bilinear] {
                    assert!(close(t.sample_level(uv, k, m), c, 1e-6));
                }
            }
        }
        let s = t.sample_at_level(Vec2::splat(0.4), 1.3, PixelSampling::Bilinear);
        assert!(close(s, c, 1e-6));
    }

    /// Closed form: bilinear interpolation reproduces an affine ramp exactly between texel
    /// centres.
    #[test]
    fn bilinear_reproduces_linear_ramp() {
        let (w, h) = (16u32, 8u32);
        let ramp = |x: f32, y: f32| Rgb::new(0.01 * x, 0.02 * y, 0.005 * x + 0.01 * y);
        let t = Texture::new(Image::from_fn(w, h, |x, y| ramp(x as f32, y as f32)));
        for i in 0..50 {
            let tx = 0.5 + (w as f32 - 1.0) * (i as f32 / 49.0);
            let ty = 0.5 + (h as f32 - 1.0) * ((i * 7 % 50) as f32 / 49.0);
            let uv = Vec2::new(tx / w as f32, ty / h as f32);
            let got = t.sample_level(uv, 0, PixelSampling::Bilinear);
            assert!(close(got, ramp(tx - 0.5, ty - 0.5), 1e-5), "at {tx},{ty}");
        }
    }

    /// Closed form: level k of a checkerboard of 2^k-texel squares is their box average.
    #[test]
    fn checkerboard_levels_are_box_averages() {
        let n = 64;
        let t = Texture::new(checker(n));
        for p in t.levels()[1].pixels() {
            assert!(close(*p, Rgb::splat(0.5), 1e-6));
        }
        // A checkerboard of 4x4 squares: level 2 alternates pure colours, level 3 is grey.
        let big = Image::from_fn(n, n, |x, y| {
            if (x / 4 + y / 4) % 2 == 0 {
                Rgb::WHITE
            } else {
                Rgb::BLACK
            }
        });
        let t = Texture::new(big);
        let l2 = &t.levels()[2];
        assert_eq!(l2.get(0, 0), Rgb::WHITE);
        assert_eq!(l2.get(1, 0), Rgb::BLACK);
        for p in t.levels()[3].pixels() {
            assert!(close(*p, Rgb::splat(0.5), 1e-6));
        }
    }

    /// Property: the box filter preserves the mean of an odd-sized image exactly.
    #[test]
    fn odd_sizes_preserve_mean() {
        let im = Image::from_fn(7, 5, |x, y| {
            Rgb::splat(((x * 13 + y * 7) % 11) as f32 / 10.0)
        });
        let mean = |im: &RgbImage| {
            im.pixels().iter().map(|p| p.r as f64).sum::<f64>() / im.pixels().len() as f64
        };
        let t = Texture::new(im.clone());
        for l in t.levels() {
            assert!((mean(l) - mean(&im)).abs() < 1e-5);
        }
    }

    /// Closed form: trilinear at level 1.5 is the average of levels 1 and 2.
    #[test]
    fn trilinear_midpoint_is_average_of_levels() {
        let im = Image::from_fn(32, 32, |x, y| {
            Rgb::new(x as f32 / 31.0, y as f32 / 31.0, 0.3)
        });
        let t = Texture::new(im);
        let uv = Vec2::new(0.37, 0.61);
        let a = t.sample_level(uv, 1, PixelSampling::Bilinear);
        let b = t.sample_level(uv, 2, PixelSampling::Bilinear);
        let m = t.sample_at_level(uv, 1.5, PixelSampling::Bilinear);
        assert!(close(m, (a + b) * 0.5, 1e-6));
        // Derivatives of 2^1.5 texels per pixel select level 1.5.
        let d = 2f32.powf(1.5) / 32.0;
        let s = t.sample(
            uv,
            Vec2::new(d, 0.0),
            Vec2::new(0.0, d),
            PixelSampling::Bilinear,
            LevelSampling::Linear,
        );
        assert!(close(s, (a + b) * 0.5, 1e-5));
    }

    #[test]
    fn level_selection_closed_form() {
        let t = Texture::new(Image::new(64, 64, Rgb::WHITE));
        assert_eq!(t.level_for(Vec2::new(1.0 / 64.0, 0.0), Vec2::ZERO), 0.0);
        assert!(
            (t.level_for(Vec2::new(4.0 / 64.0, 0.0), Vec2::new(0.0, 1.0 / 64.0)) - 2.0).abs()
                < 1e-6
        );
        assert_eq!(t.level_for(Vec2::new(1e9, 0.0), Vec2::ZERO), 6.0);
        assert_eq!(t.level_for(Vec2::new(f32::NAN, 0.0), Vec2::ZERO), 0.0);
    }

    /// Closed form: with edge-centred uvs, u = k / (w - 1) lands exactly on texel k.
    #[test]
    fn edge_centres_convention() {
        let t = Texture::new(Image::from_fn(5, 1, |x, _| Rgb::splat(x as f32)))
            .with_uv_convention(UvConvention::EdgeCenters);
        for k in 0..5 {
            let uv = Vec2::new(k as f32 / 4.0, 0.5);
            assert_eq!(t.sample_level(uv, 0, PixelSampling::Nearest).r, k as f32);
            assert!((t.sample_level(uv, 0, PixelSampling::Bilinear).r - k as f32).abs() < 1e-6);
        }
        assert!(
            (t.sample_level(Vec2::new(0.125, 0.5), 0, PixelSampling::Bilinear)
                .r
                - 0.5)
                .abs()
                < 1e-6
        );
    }

    #[test]
    fn nearest_clamps_to_edge() {
        let t = Texture::new(Image::from_fn(4, 1, |x, _| Rgb::splat(x as f32)));
        assert_eq!(
            t.sample_level(Vec2::new(-3.0, 0.5), 0, PixelSampling::Nearest)
                .r,
            0.0
        );
        assert_eq!(
            t.sample_level(Vec2::new(0.3, 0.5), 0, PixelSampling::Nearest)
                .r,
            1.0
        );
        assert_eq!(
            t.sample_level(Vec2::new(9.0, 0.5), 0, PixelSampling::Nearest)
                .r,
            3.0
        );
        assert_eq!(
            t.sample_level(Vec2::new(1.0, 0.5), 0, PixelSampling::Bilinear)
                .r,
            3.0
        );
    }

    /// Repeat wraps: bilinear lookups across the seam blend the last and first columns, and
    /// u + 1 reads what u reads; v still clamps.
    #[test]
    fn repeat_wrap_crosses_the_seam() {
        let im = Image::from_fn(4, 2, |x, _| Rgb::splat(x as f32));
        let t = Texture::new(im).with_wrap(Wrap::Repeat, Wrap::Clamp);
        let at = |u: f32, v: f32| t.sample_level(Vec2::new(u, v), 0, PixelSampling::Bilinear);
        // u = 0 is the edge between texel 3 (value 3) and texel 0 (value 0).
        assert_eq!(at(0.0, 0.5), Rgb::splat(1.5));
        assert_eq!(at(1.25, 0.5), at(0.25, 0.5));
        assert_eq!(at(-0.75, 0.5), at(0.25, 0.5));
        assert_eq!(at(0.375, -3.0), at(0.375, 0.0));
    }

    /// Property: coordinates far out of range (even past i64 once scaled) or not finite
    /// sample some texel of the image, with either wrap, never a panic.
    #[test]
    fn far_and_non_finite_coordinates_sample_a_texel() {
        let img = crate::Image::from_fn(3, 2, |x, y| prism_math::Rgb::new(x as f32, y as f32, 0.5));
        for wrap in [Wrap::Clamp, Wrap::Repeat] {
            let t = Texture::new(img.clone()).with_wrap(wrap, wrap);
            for v in [1e30f32, -1e30, 3e38, f32::INFINITY, f32::NAN, 1e19] {
                for mode in [PixelSampling::Nearest, PixelSampling::Bilinear] {
                    let c = t.sample_level(Vec2::new(v, -v), 0, mode);
                    assert!(c.b == 0.5, "{v} {mode:?} {wrap:?}: {c:?}");
                }
            }
        }
    }

    /// Brute force: the bilinear gradient equals central differences of the bilinear lookup
    /// (away from texel centres' lines, where it is piecewise linear), across a repeating
    /// seam too.
    #[test]
    fn bilinear_gradient_equals_finite_differences() {
        let img = Image::from_fn(5, 3, |x, y| {
            Rgb::new(
                (x * x + 2 * y) as f32,
                (x * y) as f32,
                (7 * y + x) as f32 * 0.5,
            )
        });
        let tex = Texture::new(img).with_wrap(Wrap::Repeat, Wrap::Repeat);
        let (w, h) = (5.0, 3.0);
        for &(u, v) in &[(0.33, 0.41), (0.71, 0.93), (0.02, 0.07), (0.97, 0.5)] {
            let [dx, dy] = tex.bilinear_gradient(Vec2::new(u, v));
            let e = 1e-3;
            let at = |u: f32, v: f32| tex.sample_level(Vec2::new(u, v), 0, PixelSampling::Bilinear);
            let fx = (at(u + e / w, v) - at(u - e / w, v)) * (0.5 / e);
            let fy = (at(u, v + e / h) - at(u, v - e / h)) * (0.5 / e);
            for (a, b) in [(dx, fx), (dy, fy)] {
                let d = a - b;
                let worst = d.r.abs().max(d.g.abs()).max(d.b.abs());
                assert!(worst < 2e-2, "{u} {v}: {a:?} vs {b:?}");
            }
        }
    }
}
