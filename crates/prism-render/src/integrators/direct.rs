//! The direct-lighting integrator: emission plus one bounce of direct light, by uniform
//! hemisphere sampling or by light sampling; light sampling is also the path integrator's
//! next-event estimate.

use prism_math::{Frame, Ray, Rgb, Vec2, Vec3};

use super::mis::power;
use super::settings::PathSettings;
use crate::interaction::Interaction;
use crate::lights::RenderLight;
use crate::render_scene::RenderScene;
use crate::sampler::Sampler;

/// Radiance along `ray`, which hit `hit`: its emission and, if `max_bounces` allows, direct
/// light by the hemisphere estimator (`hemisphere`) or by light sampling.
pub(super) fn direct(
    scene: &RenderScene,
    hit: &Interaction,
    ray: &Ray,
    sampler: &mut Sampler,
    opts: &PathSettings,
    hemisphere: bool,
) -> Rgb {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let mut l = if keep(0) && !opts.hide_emitters {
        hit.emitted
    } else {
        Rgb::BLACK
    };
    if opts.max_bounces >= 1 && keep(1) {
        l += if hemisphere {
            direct_hemisphere(scene, hit, -ray.dir, sampler, opts)
        } else {
            let (frame, wo_l) = hit.shading_frame(-ray.dir);
            direct_lights(scene, hit, (&frame, -ray.dir, wo_l), sampler, opts, false)
        };
    }
    l
}

/// Light sampling at a hit: every light, `light_samples` samples each (one for delta
/// lights), or with [`PathSettings::one_light`] `light_samples` samples that each pick one
/// light; with `mis`, weighted against BSDF sampling by the power heuristic.
pub(super) fn direct_lights(
    scene: &RenderScene,
    hit: &Interaction,
    (frame, wo, wo_l): (&Frame, Vec3, Vec3),
    sampler: &mut Sampler,
    opts: &PathSettings,
    mis: bool,
) -> Rgb {
    if !hit.bsdf.is_smooth() {
        return Rgb::BLACK;
    }
    if opts.one_light {
        if scene.lights.is_empty() {
            return Rgb::BLACK;
        }
        let count = opts.light_samples.max(1);
        let mut acc = Rgb::BLACK;
        for _ in 0..count {
            let (light, u, pmf) = picked(&scene.lights, sampler.next_2d());
            let Some((shadow, dist, term)) =
                light_term(hit, light, u, (frame, wo, wo_l), (count, pmf), mis)
            else {
                continue;
            };
            if !scene.occluded(&shadow, dist) {
                acc += term;
            }
        }
        return acc * (1.0 / count as f32);
    }
    let mut total = Rgb::BLACK;
    for light in &scene.lights {
        let count = light.sample_count(opts.light_samples);
        let mut acc = Rgb::BLACK;
        for _ in 0..count {
            let u = sampler.next_2d();
            let Some((shadow, dist, term)) =
                light_term(hit, light, u, (frame, wo, wo_l), (count, 1.0), mis)
            else {
                continue;
            };
            if !scene.occluded(&shadow, dist) {
                acc += term;
            }
        }
        total += acc * (1.0 / count as f32);
    }
    total
}

/// The light a sample's numbers `u` pick among `lights` (not empty), the numbers left for
/// sampling it, and the chance it was picked ([`PathSettings::pick_light`]).
pub(super) fn picked(lights: &[RenderLight], u: Vec2) -> (&RenderLight, Vec2, f32) {
    let (i, ux, pmf) = PathSettings::pick_light(u.x, lights.len());
    (&lights[i], Vec2::new(ux, u.y), pmf)
}

/// One sample `u` of `light` at `hit`, one of `count`, the light picked with chance `pmf`:
/// its shadow ray, where that ray must reach unblocked, and the term it adds then
/// (weighted against BSDF sampling with `mis`); none if the sample cannot contribute.
pub(super) fn light_term(
    hit: &Interaction,
    light: &RenderLight,
    u: Vec2,
    (frame, wo, wo_l): (&Frame, Vec3, Vec3),
    (count, pmf): (u32, f32),
    mis: bool,
) -> Option<(Ray, f32, Rgb)> {
    let ls = light.sample(hit.p, u)?;
    if !hit.consistent(wo, ls.wi) {
        return None;
    }
    let wi_l = frame.to_local(ls.wi);
    let (f, bsdf_pdf) = hit.bsdf.eval_pdf(wo_l, wi_l);
    if f.max_channel() <= 0.0 {
        return None;
    }
    let f = match hit.tilt {
        None => f,
        Some(_) => match hit.tilt_factor(ls.wi) {
            0.0 => return None,
            g => f * g,
        },
    };
    // The shadow ray starts pushed off the surface and aims at the light's point itself
    // from there, stopping just short of it (a fraction of its length): aimed along `wi`
    // from the pushed origin, it would meet a light seen at a grazing angle before the
    // point sampled, and the light would block its own sample.
    let origin = hit.spawn(ls.wi).origin;
    let (shadow, dist) = if ls.dist.is_finite() {
        let to_light = hit.p + ls.wi * ls.dist - origin;
        let length = to_light.length();
        if length <= 0.0 {
            return None;
        }
        (Ray::new(origin, to_light / length), length * (1.0 - 1e-4))
    } else {
        (Ray::new(origin, ls.wi), f32::INFINITY)
    };
    // The density of the sample, its pick included (a delta light's is its pick alone).
    let pdf = pmf * ls.pdf;
    let w = if mis && !ls.delta {
        power(count as f32, pdf, bsdf_pdf)
    } else {
        1.0
    };
    Some((shadow, dist, f * ls.li * (w / pdf)))
}

/// The course's uniform hemisphere estimator of direct light.
fn direct_hemisphere(
    scene: &RenderScene,
    hit: &Interaction,
    wo: Vec3,
    sampler: &mut Sampler,
    opts: &PathSettings,
) -> Rgb {
    if !hit.bsdf.is_smooth() {
        return Rgb::BLACK;
    }
    let (frame, wo_l) = hit.shading_frame(wo);
    let count = (scene.lights.len() as u32 * opts.light_samples.max(1)).max(1);
    let mut acc = Rgb::BLACK;
    for _ in 0..count {
        let mut d = prism_math::warp::uniform_hemisphere(sampler.next_2d());
        if wo_l.z < 0.0 {
            d.z = -d.z;
        }
        let wi = frame.to_world(d);
        if !hit.consistent(wo, wi) {
            continue;
        }
        let f = hit.bsdf.eval(wo_l, d) * hit.tilt_factor(wi);
        let ray = hit.spawn(wi);
        let le = match scene.intersect(&ray) {
            Some(h) => h.emitted,
            None => scene.escaped(wi, false),
        };
        acc += f * le * (1.0 / prism_math::warp::uniform_hemisphere_pdf());
    }
    acc * (1.0 / count as f32)
}
