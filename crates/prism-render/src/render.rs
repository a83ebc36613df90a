//! The tile loop: [`RenderOptions`] (the film's settings and the integrators'), the [`Job`]
//! one call computes (a share of the tiles, pixels left out, an optional profile), and
//! [`render_share`], which runs the film's tiles on rayon through the chosen integrator;
//! [`render`] is the whole picture as a [`Rendered`] image with its sample counts.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};

use prism_image::Image;
use prism_math::Rgb;
use rayon::prelude::*;

use crate::camera::Perspective;
use crate::film::{camera_sample, tiles, FilmSettings, PixelSum, Share, TILE};
use crate::integrators::{radiance, wavefront, Integrator, PathSettings};
use crate::profile::Profile;
use crate::render_scene::RenderScene;

/// Render settings: the film's and the integrators'.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderOptions {
    /// Image size, samples per pixel, adaptive sampling and seed.
    pub film: FilmSettings,
    /// The estimator and its light samples, bounces and Russian roulette.
    pub path: PathSettings,
}

impl RenderOptions {
    /// The options a Mitsuba scene file asks for, over `base`: its film's size, samples and
    /// filter, and its integrator's depth (`base`'s when unbounded), Russian roulette and
    /// hidden emitters. Under a box filter one light is picked per light sample, as Mitsuba
    /// samples lights; under a wider filter every light is sampled, which keeps the noise
    /// per pixel at Mitsuba's level (Mitsuba splats each sample over the filter's pixels,
    /// prism draws each sample's position from the filter), at one shadow ray per light.
    #[must_use]
    pub fn mitsuba(settings: &prism_scene::MitsubaSettings, base: RenderOptions) -> RenderOptions {
        RenderOptions {
            film: FilmSettings {
                width: settings.size.0,
                height: settings.size.1,
                spp: settings.spp,
                filter: settings.filter,
                ..base.film
            },
            path: PathSettings {
                max_bounces: settings.max_bounces.unwrap_or(base.path.max_bounces),
                rr_bounces: settings.rr_bounces,
                hide_emitters: settings.hide_emitters,
                one_light: settings.filter == prism_scene::Filter::Box,
                ..base.path
            },
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

/// What one call of [`render_share`] computes: a share of the tiles and sample indices,
/// without the pixels `skip` marks (row by row, one entry per pixel; a progressive renderer
/// uses it to stop converged pixels), adding the path integrator's time per stage to
/// `profile` if there is one. Once `stop` is set, tiles not yet started are left empty.
#[derive(Clone, Copy, Debug)]
pub struct Job<'a> {
    /// The tiles and sample indices computed.
    pub share: &'a Share,
    /// Pixels left out: they hold no samples.
    pub skip: Option<&'a [bool]>,
    /// Where the path integrator's time per stage is added.
    pub profile: Option<&'a Profile>,
    /// Set by another thread to end the job early (its result is then incomplete).
    pub stop: Option<&'a AtomicBool>,
    /// The camera to render through instead of the scene's (the same one without its crop
    /// window, say).
    pub camera: Option<&'a prism_scene::Camera>,
}

/// What a whole-picture render may be given besides its options.
#[derive(Clone, Copy, Debug, Default)]
pub struct Controls<'a> {
    /// Set by another thread to end the render early (the tiles not started then hold no
    /// samples).
    pub stop: Option<&'a AtomicBool>,
    /// The camera to render through instead of the scene's.
    pub camera: Option<&'a prism_scene::Camera>,
}

impl<'a> Job<'a> {
    /// The share `share`, every pixel of it, without a profile.
    #[must_use]
    pub fn share(share: &'a Share) -> Job<'a> {
        Job {
            share,
            skip: None,
            profile: None,
            stop: None,
            camera: None,
        }
    }
}

/// Renders the scene. `progress` is called with the number of samples taken so far after
/// each tile (from worker threads). The image is the same whatever the thread count.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    render_until(scene, opts, Controls::default(), progress)
}

/// [`render`] under `controls`: through another camera, or ending early once told to stop.
pub fn render_until(
    scene: &RenderScene,
    opts: &RenderOptions,
    controls: Controls<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    let profile = Profile::default();
    let share = Share::whole(opts.film.spp);
    let job = Job {
        share: &share,
        skip: None,
        profile: Some(&profile),
        stop: controls.stop,
        camera: controls.camera,
    };
    // Each tile's sums become colours and counts as soon as it is done, and go straight into
    // the picture: the film holds 16 bytes a pixel, not the sums' 80.
    let (w, h) = (opts.film.width, opts.film.height);
    let film = Mutex::new((
        Image::new(w, h, PixelSum::default().mean()),
        Image::new(w, h, 0u32),
        0u64,
    ));
    render_tiles(scene, opts, &job, progress, |origin, sums| {
        let mut f = film.lock().unwrap_or_else(PoisonError::into_inner);
        let (image, samples, total) = &mut *f;
        for ((x, y), p) in tile_pixels(origin, w, h).zip(sums) {
            image.set(x, y, p.mean());
            samples.set(x, y, p.n);
            *total += u64::from(p.n);
        }
    });
    let (image, samples, total_samples) = film.into_inner().unwrap_or_else(PoisonError::into_inner);
    Rendered {
        image,
        samples,
        total_samples,
        profile,
    }
}

/// Renders one job: the sums of its share's pixels; the other pixels, and those it skips,
/// hold no samples. Each pixel's sums equal those of the whole render when the share starts
/// at sample 0, whatever the thread count. `progress` is called as in [`render`].
///
/// # Panics
/// If the job's `skip` does not have one entry per pixel.
pub fn render_share(
    scene: &RenderScene,
    opts: &RenderOptions,
    job: &Job<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> Image<PixelSum> {
    let (w, h) = (opts.film.width, opts.film.height);
    let sums = Mutex::new(Image::new(w, h, PixelSum::default()));
    render_tiles(scene, opts, job, progress, |origin, tile| {
        let mut image = sums.lock().unwrap_or_else(PoisonError::into_inner);
        for ((x, y), s) in tile_pixels(origin, w, h).zip(tile) {
            image.set(x, y, *s);
        }
    });
    sums.into_inner().unwrap_or_else(PoisonError::into_inner)
}

/// The pixels of the tile at `(x0, y0)` of a `w x h` film, row by row.
fn tile_pixels((x0, y0): (u32, u32), w: u32, h: u32) -> impl Iterator<Item = (u32, u32)> {
    (y0..(y0 + TILE).min(h)).flat_map(move |y| (x0..(x0 + TILE).min(w)).map(move |x| (x, y)))
}

/// Renders the job's tiles on rayon, handing each to `done` as soon as it is rendered: its
/// origin and its pixels' sums row by row (a pixel the job skips has no samples). A tile
/// begun after `stop` is set is not rendered and not handed on. The workers take the tiles
/// in row-major order, one at a time, so they finish nearly in that order (a writer that
/// must store them in order holds few); each pixel's sums do not depend on the order.
///
/// # Panics
/// If the job's `skip` does not have one entry per pixel.
pub fn render_tiles(
    scene: &RenderScene,
    opts: &RenderOptions,
    job: &Job<'_>,
    progress: &(dyn Fn(u64) + Sync),
    done: impl Fn((u32, u32), &[PixelSum]) + Sync,
) {
    let (share, skip, profile) = (job.share, job.skip, job.profile);
    let stopped = || job.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let (w, h) = (opts.film.width, opts.film.height);
    if let Some(s) = skip {
        assert_eq!(s.len(), w as usize * h as usize, "one skip flag per pixel");
    }
    let skipped = |x: u32, y: u32| skip.is_some_and(|s| s[(y * w + x) as usize]);
    let camera = Perspective::new(job.camera.unwrap_or(&scene.camera), w, h)
        .with_filter(crate::pixel_filter::PixelFilter::new(&opts.film.filter));
    let tiles: Vec<(u32, u32)> = tiles(w, h)
        .into_iter()
        .enumerate()
        .filter(|&(k, _)| share.has_tile(k))
        .map(|(_, t)| t)
        .collect();
    let taken = std::sync::atomic::AtomicU64::new(0);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = rayon::current_num_threads().min(tiles.len());
    let each_tile = |origin: (u32, u32)| {
        let pixels: Vec<(u32, u32)> = tile_pixels(origin, w, h)
            .filter(|&(x, y)| !skipped(x, y))
            .collect();
        let out: Vec<PixelSum> = if opts.path.integrator == Integrator::Path {
            wavefront::tile(
                scene,
                &camera,
                &opts.film,
                &opts.path,
                &pixels,
                &share.samples,
                profile,
            )
        } else {
            pixels
                .iter()
                .map(|&(x, y)| pixel(scene, &camera, opts, x, y, &share.samples))
                .collect()
        };
        let n: u64 = out.iter().map(|p| u64::from(p.n)).sum();
        progress(taken.fetch_add(n, Ordering::Relaxed) + n);
        if skip.is_none() {
            done(origin, &out);
            return;
        }
        let mut sums = out.into_iter();
        let all: Vec<PixelSum> = tile_pixels(origin, w, h)
            .map(|(x, y)| {
                if skipped(x, y) {
                    PixelSum::default()
                } else {
                    sums.next().expect("one sum a pixel rendered")
                }
            })
            .collect();
        done(origin, &all);
    };
    (0..workers)
        .into_par_iter()
        .with_max_len(1)
        .for_each(|_| loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(&origin) = tiles.get(k) else {
                break;
            };
            if stopped() {
                break;
            }
            each_tile(origin);
        });
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
        let (mut sampler, ray) = camera_sample(camera, &opts.film, (x, y), samples.start + px.n);
        px.add(radiance(scene, &ray, &mut sampler, &opts.path), &opts.film);
    }
    px
}
