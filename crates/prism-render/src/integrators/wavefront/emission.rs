//! The wavefront's emission stage: the light a path's ray found (emission at its hit, or
//! what it sees escaping), weighted against light sampling, and whether the path goes on.

use prism_math::{Rgb, Vec3};

use super::queues::PathState;
use crate::integrators::mis::power;
use crate::integrators::PathSettings;
use crate::interaction::Interaction;
use crate::render_scene::RenderScene;

/// Adds the emission a path's ray (along `dir`) found, or what it sees escaping (with
/// `seen`, the environment map's radiance and density along `dir`, if already looked up);
/// leaves in `hit` the surface the path scatters from next, or none if it ends there.
pub(super) fn emit(
    scene: &RenderScene,
    opts: &PathSettings,
    p: &mut PathState,
    (dir, seen): (Vec3, Option<(Rgb, f32)>),
    hit: &mut Option<Interaction>,
) {
    if emitted(scene, opts, p, (dir, seen), hit.as_ref()).is_none() {
        *hit = None;
    }
}

/// [`emit`]'s work: `Some(())` if the path goes on from the surface.
fn emitted(
    scene: &RenderScene,
    opts: &PathSettings,
    p: &mut PathState,
    (dir, seen): (Vec3, Option<(Rgb, f32)>),
    hit: Option<&Interaction>,
) -> Option<()> {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let nlights = opts.light_samples.max(1) as f32;
    let pmf = opts.light_pmf(scene.lights.len());
    // Emission along the ray.
    let hit = if p.bounce == 0 {
        match hit {
            None => {
                if keep(0) && !opts.hide_emitters {
                    p.l = seen.map_or_else(|| scene.escaped(dir, true), |(le, _)| le);
                }
                return None;
            }
            Some(h) => {
                if keep(0) && !opts.hide_emitters {
                    p.l = h.emitted;
                }
                h
            }
        }
    } else {
        let bounce = p.bounce;
        match hit {
            None => {
                if let (Some(_), true) = (scene.infinite, keep(bounce)) {
                    let (le, light_pdf) = seen.unwrap_or_else(|| scene.escaped_mis(dir));
                    if le.max_channel() > 0.0 {
                        let w = if p.mis {
                            power(1.0, p.pdf, nlights * (pmf * light_pdf))
                        } else {
                            1.0
                        };
                        p.l += p.beta * le * w;
                    }
                }
                return None;
            }
            Some(h) => {
                if keep(bounce) && h.emitted.max_channel() > 0.0 {
                    let w = match h.light {
                        Some(li) if p.mis => power(
                            1.0,
                            p.pdf,
                            nlights * (pmf * scene.lights[li].pdf(dir, h.t, h.ng)),
                        ),
                        _ => 1.0,
                    };
                    p.l += p.beta * h.emitted * w;
                }
                h
            }
        }
    };
    let bounce = p.bounce + 1;
    let last = opts
        .only_bounce
        .map_or(opts.max_bounces, |m| m.min(opts.max_bounces));
    if bounce > last || hit.bsdf == crate::bsdf::Bsdf::Black {
        return None;
    }
    Some(())
}
