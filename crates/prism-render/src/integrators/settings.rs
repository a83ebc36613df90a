//! [`PathSettings`], what the path-space integrators are told: which estimator
//! ([`Integrator`]), how many light samples, how many bounces, which bounce to keep, and
//! when Russian roulette starts, whether light samples pick one light.

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

/// The integrators' settings (the film's are [`crate::film::FilmSettings`]).
#[derive(Clone, Copy, Debug)]
pub struct PathSettings {
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
    /// Russian roulette may end a path once it has this many bounces: after the BSDF sample
    /// at that surface, before its ray is traced (Mitsuba's `rr_depth`, default 5).
    pub rr_bounces: u32,
    /// Emitters seen straight from the camera (area lights, environments) show black
    /// (Mitsuba's `hide_emitters`); the light they shed is kept.
    pub hide_emitters: bool,
    /// Next-event estimation picks one light per sample, uniformly (Mitsuba's rule), instead
    /// of sampling every light at every shading point.
    pub one_light: bool,
}

impl PathSettings {
    /// The light that the light sample with first number `u` picks among `lights` when
    /// [`PathSettings::one_light`] is on, with `u` stretched back over `[0, 1)` for reuse,
    /// and the chance of picking it (Mitsuba's uniform emitter choice).
    #[must_use]
    pub fn pick_light(u: f32, lights: usize) -> (usize, f32, f32) {
        let n = lights as f32;
        let scaled = u * n;
        let i = (scaled as usize).min(lights - 1);
        (i, scaled - i as f32, 1.0 / n)
    }

    /// The chance that next-event estimation picks a given light of `lights`: `1 / lights`
    /// with [`PathSettings::one_light`], else 1 (every light is sampled).
    #[must_use]
    pub fn light_pmf(&self, lights: usize) -> f32 {
        if self.one_light && lights > 0 {
            1.0 / lights as f32
        } else {
            1.0
        }
    }
}

impl Default for PathSettings {
    fn default() -> PathSettings {
        PathSettings {
            light_samples: 1,
            max_bounces: 7,
            integrator: Integrator::Path,
            only_bounce: None,
            rr_bounces: 5,
            hide_emitters: false,
            one_light: false,
        }
    }
}
