//! Integrators and the tiled render loop with adaptive sampling.

use prism_image::Image;
use prism_math::{Frame, Ray, Rgb, Vec3};
use rayon::prelude::*;

use crate::camera::Perspective;
use crate::render_scene::{spawn, Interaction, RenderScene};
use crate::sampler::Sampler;

/// Which estimator computes radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// The shading normal as a colour, `(n + 1) / 2`.
    Normals,
    /// Emission plus one bounce of direct light, by the course's two estimators: uniform
    /// hemisphere sampling, or light sampling (`-l` samples per area light).
    Direct {
        /// Uniform hemisphere sampling instead of light sampling.
        hemisphere: bool,
    },
    /// Path tracing: next-event estimation and BSDF sampling combined by multiple importance
    /// sampling (power heuristic), Russian roulette.
    Path,
}

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
            let mut out = Vec::with_capacity((TILE * TILE) as usize);
            for y in y0..(y0 + TILE).min(h) {
                for x in x0..(x0 + TILE).min(w) {
                    out.push(pixel(scene, &camera, opts, x, y));
                }
            }
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

/// Power heuristic with exponent 2 for `nf` samples of density `f` against one of `g`.
fn power(nf: f32, f: f32, g: f32) -> f32 {
    let a = nf * f;
    if a == 0.0 && g == 0.0 {
        return 0.0;
    }
    a * a / (a * a + g * g)
}

/// Radiance arriving along a camera ray.
pub fn radiance(
    scene: &RenderScene,
    ray: &Ray,
    sampler: &mut Sampler,
    opts: &RenderOptions,
) -> Rgb {
    let Some(hit) = scene.intersect(ray) else {
        return if opts.only_bounce.is_none_or(|m| m == 0) {
            scene.escaped(ray.dir, true)
        } else {
            Rgb::BLACK
        };
    };
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    match opts.integrator {
        Integrator::Normals => {
            let n = hit.ns;
            Rgb::new(n.x * 0.5 + 0.5, n.y * 0.5 + 0.5, n.z * 0.5 + 0.5)
        }
        Integrator::Direct { hemisphere } => {
            let mut l = if keep(0) { hit.emitted } else { Rgb::BLACK };
            if opts.max_bounces >= 1 && keep(1) {
                l += if hemisphere {
                    direct_hemisphere(scene, &hit, -ray.dir, sampler, opts)
                } else {
                    let (frame, wo_l) = local(&hit, -ray.dir);
                    direct_lights(scene, &hit, (&frame, -ray.dir, wo_l), sampler, opts, false)
                };
            }
            l
        }
        Integrator::Path => path(scene, hit, ray, sampler, opts),
    }
}

/// The shading frame at a hit, and `wo` in it.
fn local(hit: &Interaction, wo: Vec3) -> (Frame, Vec3) {
    let frame = Frame::from_normal(hit.ns);
    (frame, frame.to_local(wo))
}

/// True if `wi` leaves on a side the BSDF allows, judged by the geometric normal (no light
/// through an opaque surface because shading normals tilt).
fn consistent(hit: &Interaction, wo: Vec3, wi: Vec3) -> bool {
    !hit.bsdf.two_sided() || (wo.dot(hit.ng) > 0.0) == (wi.dot(hit.ng) > 0.0)
}

/// Light sampling at a hit: every light, `light_samples` samples each (one for delta
/// lights); with `mis`, weighted against BSDF sampling by the power heuristic.
fn direct_lights(
    scene: &RenderScene,
    hit: &Interaction,
    (frame, wo, wo_l): (&Frame, Vec3, Vec3),
    sampler: &mut Sampler,
    opts: &RenderOptions,
    mis: bool,
) -> Rgb {
    if !hit.bsdf.is_smooth() {
        return Rgb::BLACK;
    }
    let mut total = Rgb::BLACK;
    for light in &scene.lights {
        let count = if light.is_delta() {
            1
        } else {
            opts.light_samples.max(1)
        };
        let mut acc = Rgb::BLACK;
        for _ in 0..count {
            let u = sampler.next_2d();
            let Some(ls) = light.sample(hit.p, u) else {
                continue;
            };
            if !consistent(hit, wo, ls.wi) {
                continue;
            }
            let wi_l = frame.to_local(ls.wi);
            let f = hit.bsdf.eval(wo_l, wi_l);
            if f.max_channel() <= 0.0 {
                continue;
            }
            let shadow = spawn(hit.p, hit.ng, ls.wi);
            let dist = if ls.dist.is_finite() {
                ls.dist * (1.0 - 1e-4) - 1e-4
            } else {
                f32::INFINITY
            };
            if scene.occluded(&shadow, dist) {
                continue;
            }
            let w = if mis && !ls.delta {
                power(count as f32, ls.pdf, hit.bsdf.pdf(wo_l, wi_l))
            } else {
                1.0
            };
            acc += f * ls.li * (w / ls.pdf);
        }
        total += acc * (1.0 / count as f32);
    }
    total
}

/// The course's uniform hemisphere estimator of direct light.
fn direct_hemisphere(
    scene: &RenderScene,
    hit: &Interaction,
    wo: Vec3,
    sampler: &mut Sampler,
    opts: &RenderOptions,
) -> Rgb {
    if !hit.bsdf.is_smooth() {
        return Rgb::BLACK;
    }
    let (frame, wo_l) = local(hit, wo);
    let count = (scene.lights.len() as u32 * opts.light_samples.max(1)).max(1);
    let mut acc = Rgb::BLACK;
    for _ in 0..count {
        let mut d = prism_math::warp::uniform_hemisphere(sampler.next_2d());
        if wo_l.z < 0.0 {
            d.z = -d.z;
        }
        let wi = frame.to_world(d);
        if !consistent(hit, wo, wi) {
            continue;
        }
        let f = hit.bsdf.eval(wo_l, d);
        let ray = spawn(hit.p, hit.ng, wi);
        let le = match scene.intersect(&ray) {
            Some(h) => h.emitted,
            None => scene.escaped(wi, false),
        };
        acc += f * le * (1.0 / prism_math::warp::uniform_hemisphere_pdf());
    }
    acc * (1.0 / count as f32)
}

fn path(
    scene: &RenderScene,
    first: Interaction,
    ray: &Ray,
    sampler: &mut Sampler,
    opts: &RenderOptions,
) -> Rgb {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let mut l = if keep(0) { first.emitted } else { Rgb::BLACK };
    let mut hit = first;
    let mut wo = -ray.dir;
    let mut beta = Rgb::WHITE;
    let last = opts
        .only_bounce
        .map_or(opts.max_bounces, |m| m.min(opts.max_bounces));
    for bounce in 1..=last {
        if hit.bsdf == crate::bsdf::Bsdf::Black {
            break;
        }
        let (frame, wo_l) = local(&hit, wo);
        if keep(bounce) {
            l += beta * direct_lights(scene, &hit, (&frame, wo, wo_l), sampler, opts, true);
        }
        let u1 = sampler.next_1d();
        let u2 = sampler.next_2d();
        let Some(s) = hit.bsdf.sample(wo_l, u1, u2) else {
            break;
        };
        let wi = frame.to_world(s.wi);
        if !consistent(&hit, wo, wi) {
            break;
        }
        beta = beta * s.weight;
        if beta.max_channel() <= 0.0 {
            break;
        }
        // Russian roulette, decided before the ray is traced (Mitsuba's rule and depth).
        if bounce >= opts.rr_bounces {
            let q = beta.max_channel().min(0.95);
            if sampler.next_1d() >= q {
                break;
            }
            beta *= 1.0 / q;
        }
        let next = spawn(hit.p, hit.ng, wi);
        let nlights = opts.light_samples.max(1) as f32;
        match scene.intersect(&next) {
            None => {
                if let (Some(i), true) = (scene.infinite, keep(bounce)) {
                    let le = scene.escaped(wi, false);
                    if le.max_channel() > 0.0 {
                        let w = if s.delta || !hit.bsdf.is_smooth() {
                            1.0
                        } else {
                            power(1.0, s.pdf, nlights * scene.lights[i].pdf(wi, f32::INFINITY))
                        };
                        l += beta * le * w;
                    }
                }
                break;
            }
            Some(h) => {
                if keep(bounce) && h.emitted.max_channel() > 0.0 {
                    let w = match h.light {
                        Some(li) if !s.delta && hit.bsdf.is_smooth() => {
                            power(1.0, s.pdf, nlights * scene.lights[li].pdf(wi, h.t))
                        }
                        _ => 1.0,
                    };
                    l += beta * h.emitted * w;
                }
                hit = h;
                wo = -wi;
            }
        }
    }
    l
}
