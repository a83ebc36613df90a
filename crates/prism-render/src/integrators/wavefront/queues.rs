//! The wavefront's queues: the paths in flight, the light samples waiting for their shadow
//! rays, and the next-event estimates those samples add to.

use prism_math::{Ray, Rgb};

use crate::sampler::Sampler;

/// A path in flight: its pixel, random numbers and what it carries (the ray it traces next
/// is kept beside it, in the pass's list of rays).
pub(super) struct PathState {
    /// Index of the pixel in the tile's list.
    pub(super) pixel: usize,
    pub(super) sampler: Sampler,
    /// Radiance gathered so far.
    pub(super) l: Rgb,
    /// Throughput.
    pub(super) beta: Rgb,
    /// Bounces taken by its ray (0 for the camera ray).
    pub(super) bounce: u32,
    /// The density of the BSDF sample that chose its ray.
    pub(super) pdf: f32,
    /// True if emission found by its ray is weighted against light sampling (the sample was
    /// not a delta lobe, and the BSDF is smooth).
    pub(super) mis: bool,
}

/// Light samples waiting for their shadow rays: the rays and where each ends (arrays side by
/// side, as the batched query takes them), and the term each sample of a one-by-one step
/// adds if unblocked. Those samples come first; the sixteen-lane step's keep their terms on
/// lanes ([`super::lane_scatter::Waiting`]).
#[derive(Default)]
pub(super) struct Shadows {
    pub(super) rays: Vec<Ray>,
    pub(super) dists: Vec<f32>,
    pub(super) terms: Vec<Rgb>,
}

impl Shadows {
    /// Adds a sample.
    #[inline]
    pub(super) fn push(&mut self, ray: Ray, dist: f32, term: Rgb) {
        debug_assert_eq!(
            self.terms.len(),
            self.rays.len(),
            "samples with terms come first"
        );
        self.rays.push(ray);
        self.dists.push(dist);
        self.terms.push(term);
    }

    /// Adds a sample whose term is kept elsewhere (after every sample with a term).
    #[inline]
    pub(super) fn push_ray(&mut self, ray: Ray, dist: f32) {
        self.rays.push(ray);
        self.dists.push(dist);
    }

    /// Samples held.
    pub(super) fn len(&self) -> usize {
        self.rays.len()
    }

    /// Drops every sample.
    pub(super) fn clear(&mut self) {
        self.rays.clear();
        self.dists.clear();
        self.terms.clear();
    }
}

/// Next-event estimation of one path at one surface, waiting for its shadow rays: the
/// throughput it is scaled by, and its lights (a range of `LightTerms`).
#[derive(Clone, Copy)]
pub(super) struct Pending {
    pub(super) beta: Rgb,
    pub(super) lights: (usize, usize),
}

/// One light's samples at one surface: a range of `Shadows`, and the samples taken.
#[derive(Clone, Copy)]
pub(super) struct LightTerms {
    pub(super) shadows: (usize, usize),
    pub(super) count: u32,
}

impl PathState {
    /// A path leaving the camera from pixel `pixel` of the tile's list.
    pub(super) fn start(pixel: usize, sampler: Sampler) -> PathState {
        PathState {
            pixel,
            sampler,
            l: Rgb::BLACK,
            beta: Rgb::WHITE,
            bounce: 0,
            pdf: 0.0,
            mis: false,
        }
    }
}
