//! The Whitted film: [`RaytraceOptions`], the pixel loop over rows on rayon (one ray through
//! each pixel's lower-left corner, or jittered rays), a share of its tiles for split renders,
//! bloom, and the ray tree of one pixel for visual debugging.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use prism_image::{Bloom, Image, RgbImage};
use prism_math::{ExactSum, Ray, Rgb};
use rayon::prelude::*;

use super::camera::OrbitView;
use super::scene::{WhittedHit, WhittedScene};
use super::tracer::{
    shadow_ray, stratified, DebugRay, PixelSampler, RayCounts, RayKind, WhittedSettings,
    WhittedTracer, ONE_BELOW,
};
use crate::film::{tile_of, PixelSum, Share};

/// Whitted render settings.
#[derive(Clone, Copy, Debug)]
pub struct RaytraceOptions {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Features, light samples and depth.
    pub settings: WhittedSettings,
    /// Rays per pixel when `settings.features.multiple_rays_per_pixel` is on.
    pub spp: u32,
    /// Bloom threshold and passes (applied when `settings.features.bloom` is on).
    pub bloom: Bloom,
    /// Seed of the jitter.
    pub seed: u64,
}

/// A Whitted render.
pub struct Raytraced {
    /// Linear colour, row 0 at the top, bloom added if on.
    pub image: RgbImage,
    /// The bloom layer alone (black when bloom is off).
    pub bloom_layer: Option<RgbImage>,
    /// Rays cast, by kind.
    pub counts: RayCounts,
}

/// The sampler of ray `s` of the pixel at written position `(x, row)`.
fn pixel_sampler(opts: &RaytraceOptions, x: u32, row: u32, s: u32) -> PixelSampler {
    pixel_sampler_at(opts, x, row, u64::from(s))
}

/// The sampler of stream `index` of the pixel at written position `(x, row)`.
fn pixel_sampler_at(opts: &RaytraceOptions, x: u32, row: u32, index: u64) -> PixelSampler {
    PixelSampler::new(
        opts.seed,
        u64::from(row) * u64::from(opts.width) + u64::from(x),
        index,
    )
}

/// Camera rays per pixel actually cast: the most of `opts.spp` (with multiple rays per pixel
/// on), the lens samples (with depth of field on) and the shutter times (with motion blur
/// on); at least 1.
#[must_use]
pub fn rays_per_pixel(opts: &RaytraceOptions) -> u32 {
    let (f, e) = (opts.settings.features, opts.settings.extras);
    let mut n = 1;
    if f.multiple_rays_per_pixel {
        n = n.max(opts.spp);
    }
    if f.depth_of_field {
        n = n.max(e.dof_samples);
    }
    if f.motion_blur {
        n = n.max(e.motion_samples);
    }
    n
}

/// What every pixel of one render shares.
struct Frame<'a> {
    scene: &'a WhittedScene,
    view: OrbitView,
    opts: &'a RaytraceOptions,
    /// The distance of the plane in focus along the view axis.
    focus: f32,
    /// The camera rays' cone spread ([`OrbitView::cone_spread`]).
    spread: f32,
}

impl Frame<'_> {
    fn new<'a>(
        scene: &'a WhittedScene,
        camera: &prism_scene::OrbitCamera,
        opts: &'a RaytraceOptions,
    ) -> Frame<'a> {
        let view = OrbitView::new(camera, opts.width, opts.height);
        Frame {
            scene,
            view,
            opts,
            focus: (opts.settings.extras.dof_focal_distance).unwrap_or(camera.distance),
            spread: view.cone_spread(),
        }
    }
}

/// The order of a pixel's `n` shutter strata: a permutation of `0..n` drawn from the
/// pixel's own numbers (so that times and lens points are not paired stratum by stratum).
fn shutter_strata(opts: &RaytraceOptions, x: u32, row: u32, n: u32) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n).collect();
    let mut sampler = pixel_sampler_at(opts, x, row, u64::MAX);
    for i in (1..n as usize).rev() {
        let j = ((sampler.next_1d() * (i + 1) as f32) as usize).min(i);
        order.swap(i, j);
    }
    order
}

/// The sums of the pixel at written position `(x, row)` (row 0 at the top), with every ray
/// recorded into `record` if given. `first` is its one camera ray and that ray's closest
/// hit, when the row's rays were traced together (one ray per pixel, no lens, no shutter).
#[inline(always)]
fn pixel<S: Samples>(
    f: &Frame<'_>,
    x: u32,
    row: u32,
    first: Option<First<'_>>,
    counts: &mut RayCounts,
    record: Option<&mut Vec<DebugRay>>,
) -> S {
    let (scene, view, opts) = (f.scene, &f.view, f.opts);
    let (features, extras) = (opts.settings.features, opts.settings.extras);
    let y = opts.height - 1 - row;
    let n = rays_per_pixel(opts);
    let mut px = S::default();
    let mut rec: Option<Vec<DebugRay>> = record.as_ref().map(|_| Vec::new());
    let order = features
        .motion_blur
        .then(|| shutter_strata(opts, x, row, n));
    for s in 0..n {
        let mut sampler = pixel_sampler(opts, x, row, s);
        let (jx, jy) = if n > 1 && features.multiple_rays_per_pixel {
            (sampler.next_1d(), sampler.next_1d())
        } else {
            (0.0, 0.0)
        };
        // Stratified times over the shutter [0, 1).
        let time = order.as_ref().map_or(0.0, |o| {
            ((o[s as usize] as f32 + sampler.next_1d()) / n as f32).min(ONE_BELOW)
        });
        let (ray, kind) = if features.depth_of_field {
            let lens = prism_math::warp::concentric_disk(stratified(s, n, &mut sampler));
            let (sx, sy) = (x as f32 + jx, y as f32 + jy);
            (
                view.lens_ray(sx, sy, lens, extras.dof_aperture, f.focus),
                RayKind::Lens,
            )
        } else {
            match &first {
                Some(fr) if n == 1 => (fr.ray, RayKind::Camera),
                _ => (view.ray(x as f32 + jx, y as f32 + jy), RayKind::Camera),
            }
        };
        let mut tracer = WhittedTracer {
            scene,
            settings: &opts.settings,
            sampler,
            counts: &mut *counts,
            record: rec.take(),
            time,
            spread: f.spread,
            blocked: first.as_ref().map_or(&[], |fr| fr.blocked),
        };
        let color = match &first {
            Some(fr) if n == 1 => tracer.trace_hit(&fr.ray, 0, kind, 0.0, fr.hit),
            _ => tracer.trace(&ray, 0, kind, 0.0),
        };
        px.add(color);
        rec = tracer.record;
    }
    if let (Some(out), Some(r)) = (record, rec) {
        *out = r;
    }
    px
}

/// Renders `scene` through `camera`. `progress` is called with the number of rows done
/// after each row (from worker threads). The image is the same whatever the thread count.
#[must_use]
pub fn raytrace(
    scene: &WhittedScene,
    camera: &prism_scene::OrbitCamera,
    opts: &RaytraceOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Raytraced {
    raytrace_until(scene, camera, opts, None, progress)
}

/// [`raytrace`], ending early once `stop` is set (the rows not started are then black).
#[must_use]
pub fn raytrace_until(
    scene: &WhittedScene,
    camera: &prism_scene::OrbitCamera,
    opts: &RaytraceOptions,
    stop: Option<&AtomicBool>,
    progress: &(dyn Fn(u64) + Sync),
) -> Raytraced {
    let whole = Share::whole(rays_per_pixel(opts));
    let pass = Pass {
        share: &whole,
        stop,
        progress,
    };
    let (image, counts) = if rays_per_pixel(opts) == 1 {
        rows(scene, camera, opts, &pass, Rgb::BLACK, |p: One| p.mean())
    } else {
        rows(scene, camera, opts, &pass, Rgb::BLACK, |p: PixelSum| {
            p.mean()
        })
    };
    with_bloom(image, counts, opts)
}

/// Adds bloom to a Whitted image when `opts` turns it on.
#[must_use]
pub fn with_bloom(image: RgbImage, counts: RayCounts, opts: &RaytraceOptions) -> Raytraced {
    if !opts.settings.features.bloom {
        return Raytraced {
            image,
            bloom_layer: None,
            counts,
        };
    }
    let layer = opts.bloom.layer(&image);
    let mut sum = image;
    for (p, l) in sum.pixels_mut().iter_mut().zip(layer.pixels()) {
        *p += *l;
    }
    Raytraced {
        image: sum,
        bloom_layer: Some(layer),
        counts,
    }
}

/// The most bytes a `width x height` Whitted render's film holds at once: the pixel sums
/// (a split part's, filled row by row in place; a whole picture keeps colours) and three
/// colour images made from them (the picture, bloom's layer, the output). A caller checks
/// it against the memory budget before rendering.
#[must_use]
pub fn raytrace_bytes(width: u32, height: u32) -> u64 {
    let per_pixel = std::mem::size_of::<PixelSum>() + 3 * std::mem::size_of::<Rgb>();
    u64::from(width) * u64::from(height) * per_pixel as u64
}

/// Renders the pixels of `share`'s tiles (tiles counted on the written image, row 0 at the
/// top), before bloom: each pixel's sums over its rays, and the rays cast. The other pixels
/// hold no samples; the share's sample range is not used (every pixel takes all its rays).
#[must_use]
pub fn raytrace_share(
    scene: &WhittedScene,
    camera: &prism_scene::OrbitCamera,
    opts: &RaytraceOptions,
    share: &Share,
    progress: &(dyn Fn(u64) + Sync),
) -> (Image<PixelSum>, RayCounts) {
    let pass = Pass {
        share,
        stop: None,
        progress,
    };
    rows(
        scene,
        camera,
        opts,
        &pass,
        PixelSum::default(),
        |p: PixelSum| p,
    )
}

/// What one pass of [`rows`] covers: a share of the tiles, an optional flag that ends it
/// early, and the callback told of each row done.
struct Pass<'a> {
    share: &'a Share,
    stop: Option<&'a AtomicBool>,
    progress: &'a (dyn Fn(u64) + Sync),
}

/// What a pixel keeps of its samples.
trait Samples: Default {
    /// Takes one sample.
    fn add(&mut self, c: Rgb);
}

impl Samples for PixelSum {
    fn add(&mut self, c: Rgb) {
        self.accumulate(c);
    }
}

/// A pixel's only sample, for pictures of one ray per pixel: its [`One::mean`] is the
/// mean [`PixelSum`] gives of that one sample, bit for bit, without the sums' other work.
#[derive(Clone, Copy, Debug, Default)]
struct One(Rgb);

impl Samples for One {
    fn add(&mut self, c: Rgb) {
        self.0 = c;
    }
}

impl One {
    /// As [`PixelSum::mean`] after one [`PixelSum::accumulate`]: each channel in the exact
    /// sum's fixed point and back (a mean over one sample divides by 1, which is exact), or
    /// black if a channel is not representable there.
    fn mean(self) -> Rgb {
        let c = self.0;
        match (
            ExactSum::fixed(c.r),
            ExactSum::fixed(c.g),
            ExactSum::fixed(c.b),
        ) {
            (Some(r), Some(g), Some(b)) => Rgb::new(
                ExactSum(r).value() as f32,
                ExactSum(g).value() as f32,
                ExactSum(b).value() as f32,
            ),
            _ => Rgb::BLACK,
        }
    }
}

/// A worker's buffers for one row at a time: camera rays, their hits, and the shadow rays
/// from those hits towards point lights (whether each is blocked, by pixel and light).
#[derive(Default)]
struct RowScratch {
    rays: Vec<Ray>,
    hits: Vec<Option<WhittedHit>>,
    found: Vec<Option<prism_accel::Hit>>,
    shadow_rays: Vec<Ray>,
    shadow_ends: Vec<f32>,
    shadow_slots: Vec<usize>,
    shadow_blocked: Vec<bool>,
    known: Vec<Option<bool>>,
}

/// A pixel's one camera ray as its row traced it: the ray, its closest hit, and per light
/// whether the hit's shadow ray is blocked (where known).
struct First<'a> {
    ray: Ray,
    hit: Option<WhittedHit>,
    blocked: &'a [Option<bool>],
}

/// The pixel loop, row by row on rayon: each pixel of the pass's tiles stored as `store`
/// makes it of its sums, the others (and every pixel of a row begun after the pass's stop
/// flag is set) `empty`; and the rays cast. With one camera ray per
/// pixel and neither lens nor shutter, a row's camera rays (through the pixels' corners)
/// are traced together.
fn rows<T: Copy + Send + Sync, S: Samples>(
    scene: &WhittedScene,
    camera: &prism_scene::OrbitCamera,
    opts: &RaytraceOptions,
    pass: &Pass<'_>,
    empty: T,
    store: impl Fn(S) -> T + Sync,
) -> (Image<T>, RayCounts) {
    let (share, progress) = (pass.share, pass.progress);
    let frame = Frame::new(scene, camera, opts);
    let view = frame.view;
    let f = opts.settings.features;
    let batched = rays_per_pixel(opts) == 1 && !f.depth_of_field && !f.motion_blur;
    // Shadow rays from the camera hits are traced with their row's when the BVH is there
    // (brute force gains nothing from batches).
    let shadows = f.shading && f.hard_shadow && scene.bvh().is_some();
    let done = std::sync::atomic::AtomicU64::new(0);
    let totals = Mutex::new(RayCounts::default());
    // Each worker writes its rows into memory the image has not touched yet: no pass
    // filling it first, and its pages are first touched (and faulted in) by both threads.
    let n = opts.width as usize * opts.height as usize;
    let mut pixels: Vec<T> = Vec::with_capacity(n);
    pixels.spare_capacity_mut()[..n]
        .par_chunks_mut(opts.width as usize)
        .enumerate()
        .for_each_init(RowScratch::default, |scratch, (row, line)| {
            let row = row as u32;
            let mut counts = RayCounts::default();
            let whole = share.parts <= 1;
            let stopped = pass.stop.is_some_and(|s| s.load(Ordering::Relaxed));
            let mine = |x: u32| !stopped && (whole || share.has_tile(tile_of(x, row, opts.width)));
            let RowScratch {
                rays,
                hits,
                found,
                shadow_rays,
                shadow_ends,
                shadow_slots,
                shadow_blocked,
                known,
            } = scratch;
            rays.clear();
            known.clear();
            let lights = scene.lights.len();
            if batched && (0..opts.width).any(mine) {
                view.corner_rays(opts.height - 1 - row, rays);
                scene.intersect_batch(rays, f.normal_interp, hits, found);
                if shadows {
                    // The camera hits' shadow rays towards point lights, traced together.
                    shadow_rays.clear();
                    shadow_ends.clear();
                    shadow_slots.clear();
                    known.resize(rays.len() * lights, None);
                    for (x, hit) in hits.iter().enumerate() {
                        let Some(hit) = hit else { continue };
                        if !mine(x as u32) {
                            continue;
                        }
                        for (li, light) in scene.lights.iter().enumerate() {
                            if let prism_scene::Light::Point { position, .. } = light {
                                if let Some((ray, end)) = shadow_ray(hit, *position) {
                                    shadow_rays.push(ray);
                                    shadow_ends.push(end);
                                    shadow_slots.push(x * lights + li);
                                }
                            }
                        }
                    }
                    scene.occluded_batch(shadow_rays, shadow_ends, shadow_blocked);
                    for (&slot, &b) in shadow_slots.iter().zip(shadow_blocked.iter()) {
                        known[slot] = Some(b);
                    }
                }
            }
            for (x, p) in line.iter_mut().enumerate() {
                let x32 = x as u32;
                p.write(if mine(x32) {
                    let first = rays.get(x).map(|&ray| First {
                        ray,
                        hit: hits[x],
                        blocked: known.get(x * lights..(x + 1) * lights).unwrap_or(&[]),
                    });
                    store(pixel(&frame, x32, row, first, &mut counts, None))
                } else {
                    empty
                });
            }
            totals
                .lock()
                .expect("no panics under the lock")
                .add(&counts);
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(d);
        });
    // SAFETY: the loop above wrote every one of the first `n` elements (each row's every
    // pixel, of `n / width` rows), and `n` is within the capacity reserved.
    unsafe { pixels.set_len(n) };
    let counts = totals.into_inner().expect("no panics under the lock");
    (Image::from_vec(opts.width, opts.height, pixels), counts)
}

/// One pixel's ray tree, for visual debugging.
#[derive(Clone, Debug)]
pub struct PixelTrace {
    /// The pixel, `(x, row)` with row 0 at the top of the written image.
    pub pixel: (u32, u32),
    /// Its colour (before bloom).
    pub color: Rgb,
    /// Every ray cast for it, in the order cast.
    pub rays: Vec<DebugRay>,
}

/// Traces the pixel at `(x, row)` (row 0 at the top) exactly as [`raytrace`] does,
/// recording every ray.
///
/// # Panics
/// If the pixel is outside the image.
#[must_use]
pub fn trace_pixel(
    scene: &WhittedScene,
    camera: &prism_scene::OrbitCamera,
    opts: &RaytraceOptions,
    x: u32,
    row: u32,
) -> PixelTrace {
    assert!(
        x < opts.width && row < opts.height,
        "pixel outside the image"
    );
    let mut rays = Vec::new();
    let mut counts = RayCounts::default();
    let frame = Frame::new(scene, camera, opts);
    let color = pixel::<PixelSum>(&frame, x, row, None, &mut counts, Some(&mut rays)).mean();
    PixelTrace {
        pixel: (x, row),
        color,
        rays,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the pixel sums. One sample's mean by [`One`] is [`PixelSum`]'s, bit for bit,
    /// for ordinary, tiny, subnormal, huge, negative, infinite and NaN values.
    #[test]
    fn one_sample_mean_is_the_sums_mean() {
        let mut rng = prism_math::Pcg32::new(1, 2);
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            1e-30,
            1e-8,
            f32::MIN_POSITIVE,
            1e-45,
            3.0e16,
            3.7e16,
            f32::MAX,
            -2.5,
            f32::INFINITY,
            f32::NAN,
        ];
        values.extend((0..10_000).map(|_| {
            let e = (rng.next_f32() * 80.0 - 60.0) as i32;
            rng.next_f32() * 2f32.powi(e)
        }));
        for w in values.windows(3) {
            let c = Rgb::new(w[0], w[1], w[2]);
            let mut sums = PixelSum::default();
            sums.accumulate(c);
            let (a, b) = (One(c).mean(), sums.mean());
            assert_eq!(
                [a.r, a.g, a.b].map(f32::to_bits),
                [b.r, b.g, b.b].map(f32::to_bits),
                "{c:?}"
            );
        }
    }
}
