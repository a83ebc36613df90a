//! The film: [`RenderOptions`], the pixel loop over tiles on rayon, each pixel's samples with
//! adaptive sampling, and the [`Rendered`] image with its sample counts.

use prism_image::Image;
use prism_math::Rgb;
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

fn illuminance(c: Rgb) -> f32 {
    c.luminance()
}

fn pixel(
    scene: &RenderScene,
    camera: &Perspective,
    opts: &RenderOptions,
    x: u32,
    y: u32,
) -> (Rgb, u32) {
    let index = u64::from(y) * u64::from(opts.width) + u64::from(x);
    let mut sum = Rgb::BLACK;
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    let mut n = 0u32;
    while n < opts.spp {
        let mut sampler = Sampler::new(opts.seed, index, u64::from(n));
        let u = sampler.next_2d();
        // The lens takes dimensions only when there is one: pinhole images keep their bytes.
        let lens = if camera.has_lens() {
            sampler.next_2d()
        } else {
            prism_math::Vec2::ZERO
        };
        let ray = camera.ray(x as f32 + u.x, y as f32 + u.y, lens);
        let mut l = radiance(scene, &ray, &mut sampler, opts);
        if !l.is_finite() {
            l = Rgb::BLACK;
        }
        sum += l;
        let i = f64::from(illuminance(l));
        s1 += i;
        s2 += i * i;
        n += 1;
        if let Some(tol) = opts.adaptive {
            if n.is_multiple_of(opts.batch.max(1)) && n > 1 {
                let mean = s1 / f64::from(n);
                let var = ((s2 - s1 * s1 / f64::from(n)) / f64::from(n - 1)).max(0.0);
                let interval = 1.96 * (var / f64::from(n)).sqrt();
                if interval <= f64::from(tol) * mean {
                    break;
                }
            }
        }
    }
    (sum * (1.0 / n as f32), n)
}
