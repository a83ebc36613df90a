//! The wavefront's camera stage: each pixel's sampler and camera ray for one sample, a
//! pinhole camera's sixteen at a time.

use prism_math::lanes::{F16, LANES};
use prism_math::{Ray, Vec3};

use super::queues::PathState;
use crate::camera::{camera_ray, Perspective};
use crate::sampler::{lane_keys, lane_values, Sampler};

/// Starts sample `n`'s path at each pixel of `active` (indices into `pixels`, whose
/// samplers' [`Sampler::pixel_key`]s are `keys`): its sampler and camera ray, those of
/// [`crate::film::camera_sample`]. A pinhole camera's rays are made sixteen at a time.
pub(super) fn start_paths(
    camera: &Perspective,
    (pixels, keys): (&[(u32, u32)], &[u64]),
    active: &[usize],
    n: u32,
    (paths, rays): (&mut Vec<PathState>, &mut Vec<Ray>),
) {
    let Some(eye) = camera.pinhole() else {
        for &k in active {
            let mut sampler = Sampler::from_pixel_key(keys[k], u64::from(n));
            rays.push(camera_ray(camera, pixels[k], &mut sampler));
            paths.push(PathState::start(k, sampler));
        }
        return;
    };
    let start = Pinhole {
        camera,
        eye,
        pixels,
        keys,
        n,
    };
    #[cfg(target_arch = "x86_64")]
    {
        if prism_math::Isa::avx512() {
            // SAFETY: the processor has AVX-512F and AVX-512DQ.
            return unsafe { start.paths_avx512(active, paths, rays) };
        }
        if prism_math::Isa::avx2() {
            // SAFETY: the processor has AVX2.
            return unsafe { start.paths_avx2(active, paths, rays) };
        }
    }
    start.paths(active, paths, rays);
}

/// What [`start_paths`] needs for a pinhole camera's paths.
struct Pinhole<'a> {
    camera: &'a Perspective,
    eye: Vec3,
    pixels: &'a [(u32, u32)],
    keys: &'a [u64],
    n: u32,
}

impl Pinhole<'_> {
    /// The paths of `active`, sixteen at a time: the samplers' keys, the two draws placing
    /// the sample in its pixel, and the ray directions on lanes (the last group padded with
    /// its first pixel).
    #[inline(always)]
    fn paths(&self, active: &[usize], paths: &mut Vec<PathState>, rays: &mut Vec<Ray>) {
        paths.reserve(active.len());
        rays.reserve(active.len());
        for group in active.chunks(LANES) {
            // Plain loops: `array::from_fn` is not always inlined.
            let (mut pixel_keys, mut x, mut y) = ([0; LANES], F16::default(), F16::default());
            for i in 0..LANES {
                let k = group[i.min(group.len() - 1)];
                pixel_keys[i] = self.keys[k];
                x.0[i] = self.pixels[k].0 as f32;
                y.0[i] = self.pixels[k].1 as f32;
            }
            let key = lane_keys(&pixel_keys, u64::from(self.n));
            let dim = [0; LANES];
            let ux = lane_values(&key, &dim, 0);
            let uy = lane_values(&key, &dim, 1);
            let (x, y) = if self.camera.box_filtered() {
                (x + ux, y + uy)
            } else {
                // A wider filter places each lane's sample as the scalar camera does.
                let (mut px, mut py) = (F16::default(), F16::default());
                for i in 0..LANES {
                    let k = group[i.min(group.len() - 1)];
                    let u = prism_math::Vec2::new(ux.0[i], uy.0[i]);
                    (px.0[i], py.0[i]) = self.camera.image_position(self.pixels[k], u);
                }
                (px, py)
            };
            let d = self.camera.pinhole_dirs(x, y);
            for (i, &pixel) in group.iter().enumerate() {
                paths.push(PathState::start(pixel, Sampler::from_state(key[i], 2)));
                let dir = Vec3::new(d.x.0[i], d.y.0[i], d.z.0[i]);
                rays.push(Ray::new(self.eye, dir));
            }
        }
    }

    /// [`Pinhole::paths`] compiled for AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F and AVX-512DQ.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    unsafe fn paths_avx512(
        &self,
        active: &[usize],
        paths: &mut Vec<PathState>,
        rays: &mut Vec<Ray>,
    ) {
        self.paths(active, paths, rays);
    }

    /// [`Pinhole::paths`] compiled for AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn paths_avx2(&self, active: &[usize], paths: &mut Vec<PathState>, rays: &mut Vec<Ray>) {
        self.paths(active, paths, rays);
    }
}
