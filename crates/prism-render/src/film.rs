//! The film: [`RenderOptions`], the pixel loop over 32x32 tiles on rayon, each pixel's samples
//! with adaptive sampling into its [`PixelSum`], the [`Share`] of tiles and sample indices a
//! split render computes, and the [`Rendered`] image with its sample counts.

use std::ops::Range;

use prism_image::Image;
use prism_math::{ExactSum, Ray, Rgb};
use rayon::prelude::*;

use crate::camera::Perspective;
use crate::integrators::{radiance, wavefront, Integrator};
use crate::profile::Profile;
use crate::render_scene::RenderScene;
use crate::sampler::Sampler;

/// Render settings.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (the most, with adaptive sampling).
    pub spp: u32,
    /// Samples per area or hemisphere light per shading point.
    pub light_samples: u32,
    /// Most bounces a path may take (the course's `-m`): 0 shows emitters only, 1 adds
    /// direct light.
    pub max_bounces: u32,
    /// The estimator.
    pub integrator: Integrator,
    /// Keep only light that took exactly this many bounces (the course's "only the m-th
    /// bounce" mode).
    pub only_bounce: Option<u32>,
    /// Adaptive sampling: stop a pixel once its 95% confidence interval is within this
    /// fraction of its mean illuminance, checked every `batch` samples.
    pub adaptive: Option<f32>,
    /// Samples between convergence checks.
    pub batch: u32,
    /// Russian roulette may end a path once it has this many bounces: after the BSDF sample
    /// at that surface, before its ray is traced (Mitsuba's `rr_depth`, default 5).
    pub rr_bounces: u32,
    /// Seed of every random number.
    pub seed: u64,
}

impl Default for RenderOptions {
    fn default() -> RenderOptions {
        RenderOptions {
            width: 512,
            height: 384,
            spp: 64,
            light_samples: 1,
            max_bounces: 7,
            integrator: Integrator::Path,
            only_bounce: None,
            adaptive: None,
            batch: 32,
            rr_bounces: 5,
            seed: 0,
        }
    }
}

/// A rendered picture.
pub struct Rendered {
    /// Linear radiance per pixel.
    pub image: Image<Rgb>,
    /// Samples taken per pixel.
    pub samples: Image<u32>,
    /// All samples taken.
    pub total_samples: u64,
    /// Where the path integrator's time went (empty for the other integrators).
    pub profile: Profile,
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

/// The most bytes a `width x height` path-traced render's film holds at once: the pixel
/// sums twice (the tiles' results and the image they are gathered into), each pixel's
/// place in its tile, and three colour images made from the sums. A caller checks it
/// against the memory budget before rendering. (Measured: a 2048 x 2048 render peaks at
/// 680 MB of the 856 MB this gives.)
#[must_use]
pub fn film_bytes(width: u32, height: u32) -> u64 {
    let per_pixel = 2 * std::mem::size_of::<PixelSum>()
        + std::mem::size_of::<(u32, u32)>()
        + 3 * std::mem::size_of::<Rgb>();
    u64::from(width) * u64::from(height) * per_pixel as u64
}

/// Renders the scene. `progress` is called with the number of samples taken so far after
/// each tile (from worker threads). The image is the same whatever the thread count.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    let profile = Profile::default();
    let sums = render_tiles(
        scene,
        opts,
        &Share::whole(opts.spp),
        None,
        progress,
        Some(&profile),
    );
    Rendered {
        image: sums.map(|p| p.mean()),
        samples: sums.map(|p| p.n),
        total_samples: sums.pixels().iter().map(|p| u64::from(p.n)).sum(),
        profile,
    }
}

/// Renders one share of the scene: the sums of the share's pixels; the other pixels hold no
/// samples. Each pixel's sums equal those of the whole render when the share starts at sample
/// 0, whatever the thread count. `progress` is called as in [`render`].
pub fn render_share(
    scene: &RenderScene,
    opts: &RenderOptions,
    share: &Share,
    progress: &(dyn Fn(u64) + Sync),
) -> Image<PixelSum> {
    render_share_except(scene, opts, share, None, progress)
}

/// [`render_share`], adding the path integrator's time per stage to `profile`.
pub fn render_share_profiled(
    scene: &RenderScene,
    opts: &RenderOptions,
    share: &Share,
    progress: &(dyn Fn(u64) + Sync),
    profile: &Profile,
) -> Image<PixelSum> {
    render_tiles(scene, opts, share, None, progress, Some(profile))
}

/// [`render_share`] leaving out the pixels `skip` marks (row by row, `width x height`
/// entries): they hold no samples. A progressive renderer uses it to stop converged pixels.
///
/// # Panics
/// If `skip` does not have one entry per pixel.
pub fn render_share_except(
    scene: &RenderScene,
    opts: &RenderOptions,
    share: &Share,
    skip: Option<&[bool]>,
    progress: &(dyn Fn(u64) + Sync),
) -> Image<PixelSum> {
    render_tiles(scene, opts, share, skip, progress, None)
}

/// [`render_share_except`], adding the path integrator's time per stage to `profile`.
fn render_tiles(
    scene: &RenderScene,
    opts: &RenderOptions,
    share: &Share,
    skip: Option<&[bool]>,
    progress: &(dyn Fn(u64) + Sync),
    profile: Option<&Profile>,
) -> Image<PixelSum> {
    let (w, h) = (opts.width, opts.height);
    if let Some(s) = skip {
        assert_eq!(s.len(), w as usize * h as usize, "one skip flag per pixel");
    }
    let skipped = |x: u32, y: u32| skip.is_some_and(|s| s[(y * w + x) as usize]);
    let camera = Perspective::new(&scene.camera, w, h);
    let tiles: Vec<(u32, u32)> = tiles(w, h)
        .into_iter()
        .enumerate()
        .filter(|&(k, _)| share.has_tile(k))
        .map(|(_, t)| t)
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    // Each tile's pixels rendered and their sums.
    type Rendered = (Vec<(u32, u32)>, Vec<PixelSum>);
    let results: Vec<Rendered> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let pixels: Vec<(u32, u32)> = (y0..(y0 + TILE).min(h))
                .flat_map(|y| (x0..(x0 + TILE).min(w)).map(move |x| (x, y)))
                .filter(|&(x, y)| !skipped(x, y))
                .collect();
            let out = if opts.integrator == Integrator::Path {
                wavefront::tile(scene, &camera, opts, &pixels, &share.samples, profile)
            } else {
                pixels
                    .iter()
                    .map(|&(x, y)| pixel(scene, &camera, opts, x, y, &share.samples))
                    .collect()
            };
            let n: u64 = out.iter().map(|p| u64::from(p.n)).sum();
            progress(done.fetch_add(n, std::sync::atomic::Ordering::Relaxed) + n);
            (pixels, out)
        })
        .collect();
    let mut sums = Image::new(w, h, PixelSum::default());
    for (pixels, out) in &results {
        for (&(x, y), s) in pixels.iter().zip(out) {
            sums.set(x, y, *s);
        }
    }
    sums
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
    pub(crate) fn add(&mut self, l: Rgb, opts: &RenderOptions) {
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
    opts: &RenderOptions,
    (x, y): (u32, u32),
    n: u32,
) -> (Sampler, Ray) {
    let index = u64::from(y) * u64::from(opts.width) + u64::from(x);
    let mut sampler = Sampler::new(opts.seed, index, u64::from(n));
    let ray = camera_ray(camera, (x, y), &mut sampler);
    (sampler, ray)
}

/// The camera ray through pixel `(x, y)` that a sample's first dimensions choose (the
/// position in the pixel, then the lens point if there is a lens).
pub(crate) fn camera_ray(camera: &Perspective, (x, y): (u32, u32), sampler: &mut Sampler) -> Ray {
    let u = sampler.next_2d();
    // The lens takes dimensions only when there is one: pinhole images keep their bytes.
    let lens = if camera.has_lens() {
        sampler.next_2d()
    } else {
        prism_math::Vec2::ZERO
    };
    camera.ray(x as f32 + u.x, y as f32 + u.y, lens)
}

fn pixel(
    scene: &RenderScene,
    camera: &Perspective,
    opts: &RenderOptions,
    x: u32,
    y: u32,
    samples: &Range<u32>,
) -> PixelSum {
    let mut px = PixelSum::default();
    let most = samples.len() as u32;
    while px.wants_more(most) {
        let (mut sampler, ray) = camera_sample(camera, opts, (x, y), samples.start + px.n);
        px.add(radiance(scene, &ray, &mut sampler, opts), opts);
    }
    px
}
