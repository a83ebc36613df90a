//! The path integrator: next-event estimation and BSDF sampling combined by multiple
//! importance sampling (power heuristic), with Russian roulette.

use prism_math::{Ray, Rgb, Vec3};

use super::direct::direct_lights;
use super::mis::power;
use super::settings::PathSettings;
use crate::interaction::Interaction;
use crate::render_scene::RenderScene;
use crate::sampler::Sampler;

/// Radiance along `ray`, whose first hit is `first`, by path tracing.
pub(super) fn path(
    scene: &RenderScene,
    first: Interaction,
    ray: &Ray,
    sampler: &mut Sampler,
    opts: &PathSettings,
) -> Rgb {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let mut l = if keep(0) && !opts.hide_emitters {
        first.emitted
    } else {
        Rgb::BLACK
    };
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
        let (frame, wo_l) = hit.shading_frame(wo);
        if keep(bounce) {
            l += beta * direct_lights(scene, &hit, (&frame, wo, wo_l), sampler, opts, true);
        }
        let u1 = sampler.next_1d();
        let u2 = sampler.next_2d();
        let Some(s) = hit.bsdf.sample(wo_l, u1, u2) else {
            break;
        };
        let wi = frame.to_world(s.wi);
        if !hit.consistent(wo, wi) {
            break;
        }
        beta = match hit.tilt {
            None => beta * s.weight,
            Some(_) => beta * s.weight * hit.tilt_factor(wi),
        };
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
        let next = hit.spawn(wi);
        let nlights = opts.light_samples.max(1) as f32;
        let pmf = opts.light_pmf(scene.lights.len());
        match scene.intersect(&next) {
            None => {
                if let (Some(i), true) = (scene.infinite, keep(bounce)) {
                    let le = scene.escaped(wi, false);
                    if le.max_channel() > 0.0 {
                        let w = if s.delta || !hit.bsdf.is_smooth() {
                            1.0
                        } else {
                            power(
                                1.0,
                                s.pdf,
                                nlights
                                    * (pmf * scene.lights[i].pdf(wi, f32::INFINITY, Vec3::ZERO)),
                            )
                        };
                        l += beta * le * w;
                    }
                }
                break;
            }
            Some(h) => {
                if keep(bounce) && h.emitted.max_channel() > 0.0 {
                    let w = match h.light {
                        Some(li) if !s.delta && hit.bsdf.is_smooth() => power(
                            1.0,
                            s.pdf,
                            nlights * (pmf * scene.lights[li].pdf(wi, h.t, h.ng)),
                        ),
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
