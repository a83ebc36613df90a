//! The film: [`RenderOptions`], the pixel loop over tiles on rayon, each pixel's samples with
//! adaptive sampling, and the [`Rendered`] image with its sample counts.

use prism_image::Image;
use prism_math::{Ray, Rgb};
use rayon::prelude::*;

use crate::camera::Perspective;
use crate::integrators::{radiance, wavefront, Integrator};
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
}

const TILE: u32 = 32;

/// Renders the scene. `progress` is called with the number of samples taken so far after
/// each tile (from worker threads). The image is the same whatever the thread count.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    let (w, h) = (opts.width, opts.height);
    let camera = Perspective::new(&scene.camera, w, h);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let results: Vec<Vec<(Rgb, u32)>> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let pixels: Vec<(u32, u32)> = (y0..(y0 + TILE).min(h))
                .flat_map(|y| (x0..(x0 + TILE).min(w)).map(move |x| (x, y)))
                .collect();
            let out = if opts.integrator == Integrator::Path {
                wavefront::tile(scene, &camera, opts, &pixels)
            } else {
                pixels
                    .iter()
                    .map(|&(x, y)| pixel(scene, &camera, opts, x, y))
                    .collect()
            };
            let n: u64 = out.iter().map(|&(_, k)| u64::from(k)).sum();
            progress(done.fetch_add(n, std::sync::atomic::Ordering::Relaxed) + n);
            out
        })
        .collect();
    let mut image = Image::new(w, h, Rgb::BLACK);
    let mut samples = Image::new(w, h, 0u32);
    let mut total = 0u64;
    for (&(x0, y0), tile) in tiles.iter().zip(&results) {
        let mut k = 0;
        for y in y0..(y0 + TILE).min(h) {
            for x in x0..(x0 + TILE).min(w) {
                let (c, n) = tile[k];
                k += 1;
                image.set(x, y, c);
                samples.set(x, y, n);
                total += u64::from(n);
            }
        }
    }
    Rendered {
        image,
        samples,
        total_samples: total,
    }
}

/// A pixel's running sums: its radiance, and its illuminance's first two moments for
/// adaptive sampling.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PixelSum {
    sum: Rgb,
    s1: f64,
    s2: f64,
    /// Samples taken.
    pub(crate) n: u32,
    converged: bool,
}

impl PixelSum {
    /// Adds a sample (a non-finite one counts as black), then checks convergence every
    /// `batch` samples when sampling is adaptive.
    pub(crate) fn add(&mut self, l: Rgb, opts: &RenderOptions) {
        let l = if l.is_finite() { l } else { Rgb::BLACK };
        self.sum += l;
        let i = f64::from(l.luminance());
        self.s1 += i;
        self.s2 += i * i;
        self.n += 1;
        let n = self.n;
        if let Some(tol) = opts.adaptive {
            if n.is_multiple_of(opts.batch.max(1)) && n > 1 {
                let mean = self.s1 / f64::from(n);
                let var =
                    ((self.s2 - self.s1 * self.s1 / f64::from(n)) / f64::from(n - 1)).max(0.0);
                let interval = 1.96 * (var / f64::from(n)).sqrt();
                self.converged = interval <= f64::from(tol) * mean;
            }
        }
    }

    /// True while the pixel takes more samples.
    pub(crate) fn wants_more(&self, opts: &RenderOptions) -> bool {
        self.n < opts.spp && !self.converged
    }

    /// The mean radiance and the samples taken.
    pub(crate) fn result(&self) -> (Rgb, u32) {
        (self.sum * (1.0 / self.n as f32), self.n)
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
    let u = sampler.next_2d();
    // The lens takes dimensions only when there is one: pinhole images keep their bytes.
    let lens = if camera.has_lens() {
        sampler.next_2d()
    } else {
        prism_math::Vec2::ZERO
    };
    let ray = camera.ray(x as f32 + u.x, y as f32 + u.y, lens);
    (sampler, ray)
}

fn pixel(
    scene: &RenderScene,
    camera: &Perspective,
    opts: &RenderOptions,
    x: u32,
    y: u32,
) -> (Rgb, u32) {
    let mut px = PixelSum::default();
    while px.wants_more(opts) {
        let (mut sampler, ray) = camera_sample(camera, opts, (x, y), px.n);
        px.add(radiance(scene, &ray, &mut sampler, opts), opts);
    }
    px.result()
}
