//! The wavefront's scatter stage, one path at a time: light samples with their shadow rays
//! queued, then the BSDF sample and Russian roulette that choose the path's next ray.

use prism_math::Ray;

use super::queues::{LightTerms, PathState, Pending, Shadows};
use crate::integrators::direct::{light_term, picked};
use crate::integrators::PathSettings;
use crate::interaction::Interaction;
use crate::render_scene::RenderScene;

/// One path's step at `hit`, reached by `ray`: samples the lights (their shadow rays go to
/// `shadows`, the estimate's bookkeeping to `waiting`) and the BSDF. Returns `Some(())` if
/// the path goes on, with its next ray in `ray`.
pub(super) fn scatter(
    scene: &RenderScene,
    opts: &PathSettings,
    (p, ray): (&mut PathState, &mut Ray),
    hit: &Interaction,
    (shadows, light_terms): (&mut Shadows, &mut Vec<LightTerms>),
    waiting: &mut Option<Pending>,
) -> Option<()> {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let dir = ray.dir;
    let bounce = p.bounce + 1;
    let wo = -dir;
    let (frame, wo_l) = hit.shading_frame(wo);
    if keep(bounce) {
        let first_light = light_terms.len();
        if hit.bsdf.is_smooth() && opts.one_light && !scene.lights.is_empty() {
            let count = opts.light_samples.max(1);
            let first = shadows.len();
            for _ in 0..count {
                let (light, u, pmf) = picked(&scene.lights, p.sampler.next_2d());
                if let Some((ray, dist, term)) =
                    light_term(hit, light, u, (&frame, wo, wo_l), (count, pmf), true)
                {
                    shadows.push(ray, dist, term);
                }
            }
            light_terms.push(LightTerms {
                shadows: (first, shadows.len()),
                count,
            });
        } else if hit.bsdf.is_smooth() && !opts.one_light {
            for light in &scene.lights {
                let count = light.sample_count(opts.light_samples);
                let first = shadows.len();
                for _ in 0..count {
                    let u = p.sampler.next_2d();
                    if let Some((ray, dist, term)) =
                        light_term(hit, light, u, (&frame, wo, wo_l), (count, 1.0), true)
                    {
                        shadows.push(ray, dist, term);
                    }
                }
                light_terms.push(LightTerms {
                    shadows: (first, shadows.len()),
                    count,
                });
            }
        }
        *waiting = Some(Pending {
            beta: p.beta,
            lights: (first_light, light_terms.len()),
        });
    }
    let u1 = p.sampler.next_1d();
    let u2 = p.sampler.next_2d();
    let s = hit.bsdf.sample(wo_l, u1, u2)?;
    let wi = frame.to_world(s.wi);
    if !hit.consistent(wo, wi) {
        return None;
    }
    p.beta = match hit.tilt {
        None => p.beta * s.weight,
        Some(_) => p.beta * s.weight * hit.tilt_factor(wi),
    };
    if p.beta.max_channel() <= 0.0 {
        return None;
    }
    // Russian roulette, decided before the ray is traced (Mitsuba's rule and depth).
    if bounce >= opts.rr_bounces {
        let q = p.beta.max_channel().min(0.95);
        if p.sampler.next_1d() >= q {
            return None;
        }
        p.beta *= 1.0 / q;
    }
    *ray = hit.spawn(wi);
    p.bounce = bounce;
    p.pdf = s.pdf;
    p.mis = !s.delta && hit.bsdf.is_smooth();
    Some(())
}
