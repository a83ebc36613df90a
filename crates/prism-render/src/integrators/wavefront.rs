//! The wavefront path integrator: a tile's paths advance together, one stage at a time
//! (closest hits for every path, then emission, light sampling and BSDF sampling for every
//! path, then every shadow ray), instead of one path from camera to end after another. Each
//! path draws the same random numbers in the same order and adds the same terms in the same
//! order as the one-path-at-a-time integrator (`path`), so the two give identical images.

use prism_math::lanes::{F16, LANES};
use prism_math::{Ray, Rgb, Vec3};

use super::direct::light_term;
use super::{power, smooth16};
use crate::bsdf::lanes::SmoothKind;
use crate::camera::Perspective;
use crate::film::{camera_ray, PixelSum, RenderOptions};
use crate::interaction::Interaction;
use crate::lights::RenderLight;
use crate::profile::{Laps, Profile, Stage};
use crate::render_scene::RenderScene;
use crate::sampler::{lane_keys, lane_values, Sampler};

/// A path in flight: its pixel, random numbers and what it carries (the ray it traces next
/// is kept beside it, in the pass's list of rays).
pub(super) struct PathState {
    /// Index of the pixel in the tile's list.
    pixel: usize,
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
/// lanes ([`smooth16::Waiting`]).
#[derive(Default)]
pub(super) struct Shadows {
    rays: Vec<Ray>,
    dists: Vec<f32>,
    terms: Vec<Rgb>,
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

    fn clear(&mut self) {
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

/// The buffers of a sample pass, kept from pass to pass.
#[derive(Default)]
struct Buffers {
    paths: Vec<PathState>,
    /// Per path, the surface its ray found, then the surface it scatters from next (none
    /// if it ends).
    hits: Vec<Option<Interaction>>,
    /// The ray each path traces next, and the hierarchy's hits along them.
    rays: Vec<Ray>,
    bvh_hits: Vec<Option<prism_accel::Hit>>,
    /// Paths whose step runs sixteen at a time: at diffuse surfaces, then at conductors.
    fast: [Vec<usize>; 2],
    /// Their light samples, sixteen at a time (scratch).
    samples: Vec<smooth16::Candidate>,
    /// Their light samples waiting for shadow rays, and each group's estimate.
    waiting: Vec<smooth16::Waiting>,
    groups: Vec<smooth16::GroupTerms>,
    shadows: Shadows,
    lights: Vec<LightTerms>,
    pending: Vec<Option<Pending>>,
    alive: Vec<bool>,
    blocked: Vec<bool>,
}

/// The sums of the pixels `(x, y)` of one tile, in order, over sample indices `samples`.
pub(crate) fn tile(
    scene: &RenderScene,
    camera: &Perspective,
    opts: &RenderOptions,
    pixels: &[(u32, u32)],
    samples: &std::ops::Range<u32>,
    profile: Option<&Profile>,
) -> Vec<PixelSum> {
    let mut sums = vec![PixelSum::default(); pixels.len()];
    let mut active: Vec<usize> = (0..pixels.len()).collect();
    let mut radiance = vec![Rgb::BLACK; pixels.len()];
    let mut buffers = Buffers::default();
    let width = u64::from(opts.width);
    let keys: Vec<u64> = pixels
        .iter()
        .map(|&(x, y)| Sampler::pixel_key(opts.seed, u64::from(y) * width + u64::from(x)))
        .collect();
    // Light sampling at every bounce: the sixteen-lane step applies.
    let lanes = opts
        .only_bounce
        .is_none()
        .then_some(scene.lights.as_slice());
    let most = samples.len() as u32;
    let mut n = samples.start;
    let mut laps = Laps::start();
    active.retain(|&k| sums[k].wants_more(most));
    while !active.is_empty() {
        sample_pass(
            scene,
            camera,
            opts,
            (pixels, &keys),
            &active,
            n,
            &mut radiance,
            &mut buffers,
            lanes,
            &mut laps,
        );
        n += 1;
        active.retain(|&k| {
            sums[k].add(radiance[k], opts);
            sums[k].wants_more(most)
        });
        laps.lap(Stage::Gathering);
    }
    if let Some(p) = profile {
        p.add(&laps);
    }
    sums
}

/// Traces sample `n` of each pixel of `active` to its end, writing its radiance.
#[allow(clippy::too_many_arguments)]
fn sample_pass(
    scene: &RenderScene,
    camera: &Perspective,
    opts: &RenderOptions,
    pixels: (&[(u32, u32)], &[u64]),
    active: &[usize],
    n: u32,
    radiance: &mut [Rgb],
    b: &mut Buffers,
    lanes: Option<&[RenderLight]>,
    laps: &mut Laps,
) {
    b.paths.clear();
    b.rays.clear();
    start_paths(camera, pixels, active, n, (&mut b.paths, &mut b.rays));
    laps.lap(Stage::Camera);
    while !b.paths.is_empty() {
        scene.closest_hits(&b.rays, &mut b.bvh_hits);
        laps.lap(Stage::ClosestHits);
        scene.hit_records(&b.rays, &b.bvh_hits, &mut b.hits);
        laps.lap(Stage::HitRecords);
        b.shadows.clear();
        b.lights.clear();
        for ((p, ray), hit) in b.paths.iter_mut().zip(&b.rays).zip(b.hits.iter_mut()) {
            emit(scene, opts, p, ray.dir, hit);
        }
        laps.lap(Stage::Emission);
        let count = b.paths.len();
        b.pending.clear();
        b.pending.resize(count, None);
        b.alive.clear();
        b.alive.resize(count, false);
        b.fast.iter_mut().for_each(Vec::clear);
        b.waiting.clear();
        b.groups.clear();
        // The next bounce's light and BSDF samples: diffuse and rough conductor surfaces
        // sixteen at a time (one list per kind), the others one by one.
        for (i, surf) in b.hits.iter().enumerate() {
            let Some(hit) = surf else {
                continue;
            };
            if let (Some(_), Some(kind)) = (lanes, smooth16::smooth_kind(hit)) {
                b.fast[kind as usize].push(i);
                continue;
            }
            b.alive[i] = scatter(
                scene,
                opts,
                (&mut b.paths[i], &mut b.rays[i]),
                hit,
                (&mut b.shadows, &mut b.lights),
                &mut b.pending[i],
            )
            .is_some();
        }
        laps.lap(Stage::Scattering);
        if let Some(lights) = lanes {
            let mut out = smooth16::Outputs {
                samples: &mut b.samples,
                waiting: &mut b.waiting,
                groups: &mut b.groups,
                shadows: &mut b.shadows,
                alive: &mut b.alive,
            };
            for (fast, kind) in b
                .fast
                .iter()
                .zip([SmoothKind::Diffuse, SmoothKind::Conductor])
            {
                for group in fast.chunks(LANES) {
                    let paths = (&mut b.paths[..], &mut b.rays[..]);
                    smooth16::step_dispatch(kind, opts, lights, paths, &b.hits, group, &mut out);
                }
            }
        }
        laps.lap(Stage::SmoothLanes);
        b.blocked.clear();
        b.blocked.resize(b.shadows.len(), false);
        scene.occluded_batch(&b.shadows.rays, &b.shadows.dists, &mut b.blocked);
        laps.lap(Stage::ShadowRays);
        for (p, w) in b.paths.iter_mut().zip(&b.pending) {
            let Some(w) = w else {
                continue;
            };
            let mut total = Rgb::BLACK;
            for light in &b.lights[w.lights.0..w.lights.1] {
                let mut acc = Rgb::BLACK;
                for k in light.shadows.0..light.shadows.1 {
                    if !b.blocked[k] {
                        acc += b.shadows.terms[k];
                    }
                }
                total += acc * (1.0 / light.count as f32);
            }
            p.l += w.beta * total;
        }
        if let Some(lights) = lanes {
            for g in &b.groups {
                g.gather(opts, lights, &b.waiting, &b.blocked, &mut b.paths);
            }
        }
        let mut i = 0;
        let alive = &b.alive;
        b.paths.retain(|p| {
            let keep_going = alive[i];
            i += 1;
            if !keep_going {
                radiance[p.pixel] = p.l;
            }
            keep_going
        });
        let mut i = 0;
        b.rays.retain(|_| {
            i += 1;
            alive[i - 1]
        });
        laps.lap(Stage::Gathering);
    }
}

impl PathState {
    /// A path leaving the camera from pixel `pixel` of the tile's list.
    fn start(pixel: usize, sampler: Sampler) -> PathState {
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

/// Starts sample `n`'s path at each pixel of `active` (indices into `pixels`, whose
/// samplers' [`Sampler::pixel_key`]s are `keys`): its sampler and camera ray, those of
/// [`crate::film::camera_sample`]. A pinhole camera's rays are made sixteen at a time.
fn start_paths(
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
            let (x, y) = (x + ux, y + uy);
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

/// Adds the emission a path's ray (along `dir`) found, or what it sees escaping; leaves in
/// `hit` the surface the path scatters from next, or none if it ends there.
fn emit(
    scene: &RenderScene,
    opts: &RenderOptions,
    p: &mut PathState,
    dir: Vec3,
    hit: &mut Option<Interaction>,
) {
    if emitted(scene, opts, p, dir, hit.as_ref()).is_none() {
        *hit = None;
    }
}

/// [`emit`]'s work: `Some(())` if the path goes on from the surface.
fn emitted(
    scene: &RenderScene,
    opts: &RenderOptions,
    p: &mut PathState,
    dir: Vec3,
    hit: Option<&Interaction>,
) -> Option<()> {
    let keep = |bounces: u32| opts.only_bounce.is_none_or(|m| m == bounces);
    let nlights = opts.light_samples.max(1) as f32;
    // Emission along the ray.
    let hit = if p.bounce == 0 {
        match hit {
            None => {
                if keep(0) {
                    p.l = scene.escaped(dir, true);
                }
                return None;
            }
            Some(h) => {
                if keep(0) {
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
                    let (le, light_pdf) = scene.escaped_mis(dir);
                    if le.max_channel() > 0.0 {
                        let w = if p.mis {
                            power(1.0, p.pdf, nlights * light_pdf)
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
                        Some(li) if p.mis => {
                            power(1.0, p.pdf, nlights * scene.lights[li].pdf(dir, h.t, h.ng))
                        }
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

/// One path's step at `hit`, reached by `ray`: samples the lights (their shadow rays go to
/// `shadows`, the estimate's bookkeeping to `waiting`) and the BSDF. Returns `Some(())` if
/// the path goes on, with its next ray in `ray`.
fn scatter(
    scene: &RenderScene,
    opts: &RenderOptions,
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
        if hit.bsdf.is_smooth() {
            for light in &scene.lights {
                let count = light.sample_count(opts.light_samples);
                let first = shadows.len();
                for _ in 0..count {
                    let u = p.sampler.next_2d();
                    if let Some((ray, dist, term)) =
                        light_term(hit, light, u, (&frame, wo, wo_l), count, true)
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
    p.beta = p.beta * s.weight;
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
