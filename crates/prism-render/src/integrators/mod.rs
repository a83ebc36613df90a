//! The integrators: [`PathSettings`] (with [`Integrator`], which names the estimator),
//! [`radiance`], which dispatches a camera ray to it (`normals`, `direct`, `path`), and the
//! multiple-importance-sampling weight they share (`mis`);
//! `wavefront` runs a tile's paths together, stage by stage, to the same result as `path`.

mod direct;
mod mis;
mod normals;
mod path;
mod settings;
pub(crate) mod wavefront;

use prism_math::{Ray, Rgb};

pub use self::settings::{Integrator, PathSettings};

use crate::render_scene::RenderScene;
use crate::sampler::Sampler;

/// Radiance arriving along a camera ray.
pub fn radiance(scene: &RenderScene, ray: &Ray, sampler: &mut Sampler, opts: &PathSettings) -> Rgb {
    let first = if opts.hide_emitters {
        scene.past_emitters(ray)
    } else {
        scene.intersect(ray)
    };
    let Some(hit) = first else {
        return if opts.only_bounce.is_none_or(|m| m == 0) && !opts.hide_emitters {
            scene.escaped(ray.dir, true)
        } else {
            Rgb::BLACK
        };
    };
    match opts.integrator {
        Integrator::Normals => normals::normals(&hit),
        Integrator::Direct { hemisphere } => {
            direct::direct(scene, &hit, ray, sampler, opts, hemisphere)
        }
        Integrator::Path | Integrator::PathScalar => path::path(scene, hit, ray, sampler, opts),
    }
}
