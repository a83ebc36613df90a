//! The integrators: [`Integrator`] names the estimator, [`radiance`] dispatches a camera ray
//! to it (`normals`, `direct`, `path`), and the multiple-importance-sampling weight they share;
//! `wavefront` runs a tile's paths together, stage by stage, to the same result as `path`.

mod direct;
mod normals;
mod path;
pub(crate) mod wavefront;

use prism_math::{Ray, Rgb};

use crate::film::RenderOptions;
use crate::render_scene::RenderScene;
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
    /// sampling (power heuristic), Russian roulette; a tile's paths advance together, stage
    /// by stage (the wavefront integrator).
    Path,
    /// The same estimator one path at a time, camera to end: the reference that [`Path`]
    /// equals bit for bit.
    ///
    /// [`Path`]: Integrator::Path
    PathScalar,
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
    match opts.integrator {
        Integrator::Normals => normals::normals(&hit),
        Integrator::Direct { hemisphere } => {
            direct::direct(scene, &hit, ray, sampler, opts, hemisphere)
        }
        Integrator::Path | Integrator::PathScalar => path::path(scene, hit, ray, sampler, opts),
    }
}

/// Power heuristic with exponent 2 for `nf` samples of density `f` against one of `g`.
fn power(nf: f32, f: f32, g: f32) -> f32 {
    let a = nf * f;
    if a == 0.0 && g == 0.0 {
        return 0.0;
    }
    a * a / (a * a + g * g)
}
