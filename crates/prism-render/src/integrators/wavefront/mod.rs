//! The wavefront path integrator: a tile's paths advance together, one stage at a time
//! (closest hits for every path, then emission, light sampling and BSDF sampling for every
//! path, then every shadow ray), instead of one path from camera to end after another. Each
//! path draws the same random numbers in the same order and adds the same terms in the same
//! order as the one-path-at-a-time integrator (`path`), so the two give identical images.
//! The stages live beside this pass loop: `queues` (paths and waiting light samples),
//! `camera`, `emission`, `scatter` (one path at a time) and `lane_scatter` (sixteen paths at
//! once at smooth surfaces).

mod camera;
mod emission;
mod lane_scatter;
mod queues;
mod scatter;

use prism_math::lanes::LANES;
use prism_math::{Ray, Rgb};

use self::camera::start_paths;
use self::emission::emit;
use self::queues::{LightTerms, PathState, Pending, Shadows};
use self::scatter::scatter;
use super::settings::PathSettings;
use crate::bsdf::lanes::SmoothKind;
use crate::camera::Perspective;
use crate::film::{FilmSettings, PixelSum};
use crate::interaction::Interaction;
use crate::lights::RenderLight;
use crate::profile::{Laps, Profile, Stage};
use crate::render_scene::RenderScene;
use crate::sampler::Sampler;

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
    samples: Vec<lane_scatter::Candidate>,
    /// Their light samples waiting for shadow rays, and each group's estimate.
    waiting: Vec<lane_scatter::Waiting>,
    groups: Vec<lane_scatter::GroupTerms>,
    shadows: Shadows,
    lights: Vec<LightTerms>,
    pending: Vec<Option<Pending>>,
    /// The directions of the rays that leave the scene, and the map's radiance and density
    /// along each (a scene lit by a map).
    dirs: Vec<prism_math::Vec3>,
    escaped: Vec<(Rgb, f32)>,
    alive: Vec<bool>,
    blocked: Vec<bool>,
}

/// The sums of the pixels `(x, y)` of one tile, in order, over sample indices `samples`.
pub(crate) fn tile(
    scene: &RenderScene,
    camera: &Perspective,
    film: &FilmSettings,
    opts: &PathSettings,
    pixels: &[(u32, u32)],
    samples: &std::ops::Range<u32>,
    profile: Option<&Profile>,
) -> Vec<PixelSum> {
    let mut sums = vec![PixelSum::default(); pixels.len()];
    let mut active: Vec<usize> = (0..pixels.len()).collect();
    let mut radiance = vec![Rgb::BLACK; pixels.len()];
    let mut buffers = Buffers::default();
    let width = u64::from(film.width);
    let keys: Vec<u64> = pixels
        .iter()
        .map(|&(x, y)| Sampler::pixel_key(film.seed, u64::from(y) * width + u64::from(x)))
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
            sums[k].add(radiance[k], film);
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
    opts: &PathSettings,
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
        // Hidden emitters let camera rays through (`radiance` does the same).
        if opts.hide_emitters && b.paths.first().is_some_and(|p| p.bounce == 0) {
            for ((ray, hit), surf) in b.rays.iter().zip(&b.bvh_hits).zip(b.hits.iter_mut()) {
                if hit.is_some_and(|h| scene.is_emitter(h.prim)) {
                    *surf = scene.past_emitters(ray);
                }
            }
        }
        laps.lap(Stage::HitRecords);
        b.shadows.clear();
        b.lights.clear();
        // What the rays that leave the scene see of a map, looked up together.
        b.escaped.clear();
        if let Some(RenderLight::EnvironmentMap(map)) = scene.infinite.map(|i| &scene.lights[i]) {
            b.dirs.clear();
            let escaping = b.rays.iter().zip(&b.hits).filter(|(_, h)| h.is_none());
            b.dirs.extend(escaping.map(|(ray, _)| ray.dir));
            map.radiance_pdf_batch(&b.dirs, &mut b.escaped);
        }
        let mut escaped = b.escaped.iter();
        for ((p, ray), hit) in b.paths.iter_mut().zip(&b.rays).zip(b.hits.iter_mut()) {
            let seen = if hit.is_none() {
                escaped.next().copied()
            } else {
                None
            };
            emit(scene, opts, p, (ray.dir, seen), hit);
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
            if let (Some(_), Some(kind)) = (lanes, lane_scatter::smooth_kind(hit)) {
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
            let mut out = lane_scatter::Outputs {
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
                    lane_scatter::step_dispatch(
                        kind, opts, lights, paths, &b.hits, group, &mut out,
                    );
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
