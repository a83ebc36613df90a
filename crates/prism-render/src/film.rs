//! The film: its [`FilmSettings`], its 32x32 tiles, each pixel's samples with adaptive
//! sampling into its [`PixelSum`], the [`Share`] of tiles and sample indices a split render
//! computes, and each sample's sampler and camera ray.

use std::ops::Range;

use prism_math::{ExactSum, Ray, Rgb};

use crate::camera::{camera_ray, Perspective};
use crate::sampler::Sampler;

/// The film's settings (the integrators' are [`crate::integrators::PathSettings`]).
#[derive(Clone, Copy, Debug)]
pub struct FilmSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (the most, with adaptive sampling).
    pub spp: u32,
    /// Adaptive sampling: stop a pixel once its 95% confidence interval is within this
    /// fraction of its mean illuminance, checked every `batch` samples.
    pub adaptive: Option<f32>,
    /// Samples between convergence checks.
    pub batch: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// The reconstruction filter: where a pixel's samples fall (a box: in the pixel).
    pub filter: prism_scene::Filter,
}

impl Default for FilmSettings {
    fn default() -> FilmSettings {
        FilmSettings {
            width: 512,
            height: 384,
            spp: 64,
            adaptive: None,
            batch: 32,
            seed: 0,
            filter: prism_scene::Filter::Box,
        }
    }
}

/// The side of a film tile in pixels: the unit of work of a thread and of a split render.
pub const TILE: u32 = 32;

/// The tiles of a `width x height` film, in row-major order: `(x0, y0)` of each.
#[must_use]
pub fn tiles(width: u32, height: u32) -> Vec<(u32, u32)> {
    (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect()
}

/// How many tiles a `width x height` film has.
#[must_use]
pub fn tile_count(width: u32, height: u32) -> usize {
    width.div_ceil(TILE) as usize * height.div_ceil(TILE) as usize
}

/// The row-major index of the tile holding pixel `(x, y)` of a film `width` pixels wide.
#[must_use]
pub fn tile_of(x: u32, y: u32, width: u32) -> usize {
    (y / TILE) as usize * width.div_ceil(TILE) as usize + (x / TILE) as usize
}

/// The share of a render one process computes: tiles dealt round-robin into `parts` shares
/// (tile `k`, counted row by row, goes to share `k mod parts`, so shares differ by at most
/// one tile and each holds tiles from all over the picture), and sample indices
/// `samples` of each of their pixels. A pixel's samples depend only on the seed, the pixel
/// and the sample index, so shares are independent.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Share {
    /// This share's index, from 0.
    pub part: u32,
    /// How many shares the tiles are dealt into.
    pub parts: u32,
    /// The sample indices taken in each pixel.
    pub samples: Range<u32>,
}

impl Share {
    /// Every tile, samples `0..spp`: the whole render.
    #[must_use]
    pub fn whole(spp: u32) -> Share {
        Share {
            part: 0,
            parts: 1,
            samples: 0..spp,
        }
    }

    /// True if tile `k` belongs to this share.
    #[must_use]
    pub fn has_tile(&self, k: usize) -> bool {
        k % self.parts.max(1) as usize == self.part as usize
    }
}

/// The most bytes a `width x height` path-traced picture's film holds at once: each pixel's
/// colour and sample count (the exact sums are kept per tile only while it renders), and
/// what encoding takes: three colours a pixel, for an EXR's float channels, its compressed
/// blocks and its file (an 8-bit PNG takes less). A caller checks it against the memory
/// budget before rendering. (Measured: an 8192 x 8192 render peaks at 1.3 GB to PNG and 3.4
/// GB to EXR, of the 3.5 GB this gives.)
#[must_use]
pub fn film_bytes(width: u32, height: u32) -> u64 {
    let per_pixel = std::mem::size_of::<(Rgb, u32)>() + 3 * std::mem::size_of::<Rgb>();
    u64::from(width) * u64::from(height) * per_pixel as u64
}

/// The most bytes a share of a `width x height` render (a part file's) holds at once when
/// written as it renders: the file's tile table, and per worker a few tiles' sums (rendered,
/// waiting for the tiles before them, and encoded).
#[must_use]
pub fn share_bytes(width: u32, height: u32) -> u64 {
    let tile = u64::from(TILE * TILE) * std::mem::size_of::<PixelSum>() as u64;
    let workers = rayon::current_num_threads() as u64;
    8 * tile_count(width, height) as u64 + 4 * workers * tile
}

/// A pixel's running sums: its radiance, exactly (so that samples split into ranges and
/// summed in any order give the same bits), and its illuminance's first two moments for
/// adaptive sampling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSum {
    /// The sums of the radiance samples' red, green and blue (a non-finite sample, or one of
    /// [`ExactSum::LIMIT`] or more, counts as black).
    pub sum: [ExactSum; 3],
    /// The sum of the samples' luminances.
    pub moment1: f64,
    /// The sum of the samples' squared luminances.
    pub moment2: f64,
    /// Samples taken.
    pub n: u32,
    pub(crate) converged: bool,
}

impl PixelSum {
    /// Adds a sample (a non-finite or too large one counts as black).
    pub(crate) fn accumulate(&mut self, l: Rgb) {
        let fixed = |c: f32| ExactSum::fixed(c);
        let (l, f) = match (fixed(l.r), fixed(l.g), fixed(l.b)) {
            (Some(r), Some(g), Some(b)) => (l, [r, g, b]),
            _ => (Rgb::BLACK, [0; 3]),
        };
        for (s, v) in self.sum.iter_mut().zip(f) {
            s.0 += v;
        }
        let i = f64::from(l.luminance());
        self.moment1 += i;
        self.moment2 += i * i;
        self.n += 1;
    }

    /// Adds a sample (as [`PixelSum::accumulate`]), then checks convergence every `batch`
    /// samples when sampling is adaptive.
    pub(crate) fn add(&mut self, l: Rgb, opts: &FilmSettings) {
        self.accumulate(l);
        let n = self.n;
        if let Some(tol) = opts.adaptive {
            if n.is_multiple_of(opts.batch.max(1)) && n > 1 {
                self.converged = self.within(tol);
            }
        }
    }

    /// The course's adaptive-sampling test: the 95% confidence interval of the pixel's
    /// illuminance, `1.96 sigma / sqrt(n)`, is at most `tol` times its mean (false with
    /// fewer than two samples).
    #[must_use]
    pub fn within(&self, tol: f32) -> bool {
        if self.n < 2 {
            return false;
        }
        let n = f64::from(self.n);
        let mean = self.moment1 / n;
        let var = ((self.moment2 - self.moment1 * self.moment1 / n) / (n - 1.0)).max(0.0);
        let interval = 1.96 * (var / n).sqrt();
        interval <= f64::from(tol) * mean
    }

    /// True while the pixel takes more of its `most` samples.
    pub(crate) fn wants_more(&self, most: u32) -> bool {
        self.n < most && !self.converged
    }

    /// Adds the sums of another share of this pixel's samples; false, leaving `self` as it
    /// was, if an exact sum or the sample count would overflow (no render reaches that: only
    /// crafted parts do).
    #[must_use]
    pub fn merge(&mut self, other: &PixelSum) -> bool {
        let mut sum = self.sum;
        for (s, o) in sum.iter_mut().zip(other.sum) {
            match s.0.checked_add(o.0) {
                Some(v) => s.0 = v,
                None => return false,
            }
        }
        let Some(n) = self.n.checked_add(other.n) else {
            return false;
        };
        self.sum = sum;
        self.n = n;
        self.moment1 += other.moment1;
        self.moment2 += other.moment2;
        true
    }

    /// The mean radiance (black without samples).
    #[must_use]
    pub fn mean(&self) -> Rgb {
        let [r, g, b] = self.sum.map(|s| s.mean(self.n));
        Rgb::new(r, g, b)
    }
}

/// Sample `n` of pixel `(x, y)`: its sampler, past the film and lens dimensions, and its
/// camera ray.
pub(crate) fn camera_sample(
    camera: &Perspective,
    opts: &FilmSettings,
    (x, y): (u32, u32),
    n: u32,
) -> (Sampler, Ray) {
    let index = u64::from(y) * u64::from(opts.width) + u64::from(x);
    let mut sampler = Sampler::new(opts.seed, index, u64::from(n));
    let ray = camera_ray(camera, (x, y), &mut sampler);
    (sampler, ray)
}
