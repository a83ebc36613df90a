//! The Whitted tracer of the Delft ray tracer: Phong per light sample, hard shadows
//! from point lights, stratified samples of segment and parallelogram lights, recursive
//! mirror reflection, textures, transparency; every ray it casts can be recorded.

use prism_image::PixelSampling;
use prism_math::{Ray, Rgb, Vec2, Vec3};
use prism_scene::{Features, Light};

use super::scene::{PhongMaterial, Surface, WhittedHit, WhittedScene};
use super::shading::{parallelogram_color, parallelogram_grid, phong};
use crate::sampler::Sampler;

/// Offset of secondary-ray origins along their direction.
pub const RAY_EPSILON: f32 = 1e-4;
/// Length of a missed ray in the debug record: origin + this times the direction.
pub const MISS_LENGTH: f32 = 10.0;

/// Settings of one Whitted render.
#[derive(Clone, Copy, Debug)]
pub struct WhittedSettings {
    /// The template's feature switches.
    pub features: Features,
    /// Samples per segment light, and the target count for a parallelogram light (which
    /// takes a `k x k` grid, `k = ceil(sqrt(n))`).
    pub light_samples: u32,
    /// Most reflection (and transparency) bounces after the camera ray.
    pub max_depth: u32,
}

/// What kind of ray a debug record is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// From the camera.
    Camera,
    /// A mirror reflection.
    Reflection,
    /// Through a transparent surface.
    Transmission,
    /// Towards a point light.
    Shadow,
    /// Towards a sample of a segment or parallelogram light.
    AreaSample,
    /// The geometric normal at a hit.
    Normal,
    /// The interpolated normal at a hit.
    InterpolatedNormal,
}

impl RayKind {
    /// The name used in the debug JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Camera => "camera",
            RayKind::Reflection => "reflection",
            RayKind::Transmission => "transmission",
            RayKind::Shadow => "shadow",
            RayKind::AreaSample => "area-sample",
            RayKind::Normal => "normal",
            RayKind::InterpolatedNormal => "interpolated-normal",
        }
    }
}

/// One recorded ray (or normal) segment.
#[derive(Clone, Debug, PartialEq)]
pub struct DebugRay {
    /// Its kind.
    pub kind: RayKind,
    /// Bounces before it (0 for the camera ray and what starts at its hit).
    pub depth: u32,
    /// Start.
    pub origin: Vec3,
    /// The hit point, the light sample, or origin + [`MISS_LENGTH`] times the direction.
    pub end: Vec3,
    /// Camera and reflection rays: the colour they return; shadow rays and area samples:
    /// the light's colour when it is reached, red when blocked; normals: white.
    pub color: Rgb,
    /// Shadow rays and area samples: whether something blocks them.
    pub blocked: Option<bool>,
    /// Where a blocked shadow ray or area sample is blocked.
    pub blocked_at: Option<Vec3>,
    /// The surface it hit: material name and primitive.
    pub hit: Option<(String, Surface)>,
}

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub camera: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Transmission rays.
    pub transmission: u64,
    /// Shadow rays towards point lights.
    pub shadow: u64,
    /// Shadow rays towards area-light samples.
    pub area_sample: u64,
}

impl RayCounts {
    /// All rays.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.camera + self.reflection + self.transmission + self.shadow + self.area_sample
    }

    /// Adds another count.
    pub fn add(&mut self, o: &RayCounts) {
        self.camera += o.camera;
        self.reflection += o.reflection;
        self.transmission += o.transmission;
        self.shadow += o.shadow;
        self.area_sample += o.area_sample;
    }
}

/// A pixel's sampler, keyed on its first number: most pixels of a scene without area
/// lights or jitter never draw one, and keying costs a hash. Draws the same numbers as
/// [`Sampler::new`] with the same words.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    words: [u64; 3],
    inner: Option<Sampler>,
}

impl PixelSampler {
    /// The sampler of sample `index` of pixel `pixel` (as [`Sampler::new`]).
    #[must_use]
    pub fn new(seed: u64, pixel: u64, index: u64) -> PixelSampler {
        PixelSampler {
            words: [seed, pixel, index],
            inner: None,
        }
    }

    /// The next dimension's value in `[0, 1)`.
    pub fn next_1d(&mut self) -> f32 {
        let [a, b, c] = self.words;
        self.inner
            .get_or_insert_with(|| Sampler::new(a, b, c))
            .next_1d()
    }
}

/// One ray tree's state: the scene, settings, sampler, counters and optional record.
pub struct WhittedTracer<'a> {
    /// The scene.
    pub scene: &'a WhittedScene,
    /// The settings.
    pub settings: &'a WhittedSettings,
    /// Random numbers for light-sample jitter.
    pub sampler: PixelSampler,
    /// Rays cast so far.
    pub counts: RayCounts,
    /// When set, every ray is recorded here.
    pub record: Option<Vec<DebugRay>>,
}

const RED: Rgb = Rgb::new(1.0, 0.0, 0.0);

/// What every light sample at one hit needs: the hit, the direction to the viewer, the
/// material's (possibly textured) colours and exponent, and the bounce.
struct ShadePoint<'h> {
    hit: &'h WhittedHit,
    v: Vec3,
    kd: Rgb,
    ks: Rgb,
    shininess: f32,
    depth: u32,
}

impl WhittedTracer<'_> {
    /// Records a ray built by `make`, only when recording (building one costs a string).
    fn push(&mut self, make: impl FnOnce(&Self) -> DebugRay) -> Option<usize> {
        self.record.as_ref()?;
        let ray = make(self);
        let rec = self.record.as_mut()?;
        rec.push(ray);
        Some(rec.len() - 1)
    }

    /// The colour seen along `ray` (unit direction), `depth` bounces after the camera.
    pub fn trace(&mut self, ray: &Ray, depth: u32, kind: RayKind) -> Rgb {
        match kind {
            RayKind::Camera => self.counts.camera += 1,
            RayKind::Reflection => self.counts.reflection += 1,
            _ => self.counts.transmission += 1,
        }
        let f = self.settings.features;
        let hit = self.scene.intersect(ray, f32::INFINITY, f.normal_interp);
        let slot = self.push(|_| DebugRay {
            kind,
            depth,
            origin: ray.origin,
            end: hit.map_or(ray.origin + MISS_LENGTH * ray.dir, |h| h.p),
            color: Rgb::BLACK,
            blocked: None,
            blocked_at: None,
            hit: hit.map(|h| {
                (
                    self.scene.materials[h.material as usize].name.clone(),
                    h.surface,
                )
            }),
        });
        let Some(hit) = hit else { return Rgb::BLACK };
        let color = self.shade(ray, &hit, depth);
        if let (Some(i), Some(rec)) = (slot, self.record.as_mut()) {
            rec[i].color = color;
        }
        color
    }

    fn shade(&mut self, ray: &Ray, hit: &WhittedHit, depth: u32) -> Rgb {
        let f = self.settings.features;
        let m: &PhongMaterial = &self.scene.materials[hit.material as usize];
        if self.record.is_some() {
            let len = 0.05 * self.scene.size();
            self.push(|_| DebugRay {
                kind: RayKind::Normal,
                depth,
                origin: hit.p,
                end: hit.p + len * hit.n_g,
                color: Rgb::WHITE,
                blocked: None,
                blocked_at: None,
                hit: None,
            });
            if f.normal_interp {
                self.push(|_| DebugRay {
                    kind: RayKind::InterpolatedNormal,
                    depth,
                    origin: hit.p,
                    end: hit.p + len * hit.n_s,
                    color: Rgb::new(0.0, 1.0, 1.0),
                    blocked: None,
                    blocked_at: None,
                    hit: None,
                });
            }
        }
        let kd = match (&m.texture, f.texture_mapping) {
            (Some(tex), true) => {
                let mode = if f.bilinear {
                    PixelSampling::Bilinear
                } else {
                    PixelSampling::Nearest
                };
                tex.sample_level(Vec2::new(hit.uv.x, 1.0 - hit.uv.y), 0, mode)
            }
            _ => m.kd,
        };
        if !f.shading {
            return kd;
        }
        let (ks, shininess, transparency) = (m.ks, m.shininess, m.transparency);
        let at = ShadePoint {
            hit,
            v: -ray.dir,
            kd,
            ks,
            shininess,
            depth,
        };
        let mut local = Rgb::BLACK;
        for li in 0..self.scene.lights.len() {
            local += self.light(li, &at);
        }
        let mut color = local;
        if f.recursive && ks != Rgb::BLACK && depth < self.settings.max_depth {
            let n = hit.n_s;
            // The mirror direction of a unit ray about a unit normal is a unit vector; it
            // is used as computed, as the template does.
            let r = ray.dir - 2.0 * ray.dir.dot(n) * n;
            let reflected = self.trace(
                &Ray::new(hit.p + RAY_EPSILON * r, r),
                depth + 1,
                RayKind::Reflection,
            );
            color += ks * reflected;
        }
        if f.transparency && transparency < 1.0 && depth < self.settings.max_depth {
            let behind = self.trace(
                &Ray::new(hit.p + RAY_EPSILON * ray.dir, ray.dir),
                depth + 1,
                RayKind::Transmission,
            );
            color = color * transparency + behind * (1.0 - transparency);
        }
        color
    }

    /// One light's contribution at a shading point.
    fn light(&mut self, li: usize, at: &ShadePoint<'_>) -> Rgb {
        let f = self.settings.features;
        match self.scene.lights[li] {
            Light::Point {
                position,
                intensity,
            } => self.sample(at, position, intensity, f.hard_shadow, RayKind::Shadow),
            Light::Segment { endpoints, colors } => {
                if !f.soft_shadow {
                    return Rgb::BLACK;
                }
                let n = self.settings.light_samples.max(1);
                let mut sum = Rgb::BLACK;
                for i in 0..n {
                    let t = (i as f32 + self.sampler.next_1d()) / n as f32;
                    let q = endpoints[0] + t * (endpoints[1] - endpoints[0]);
                    let c = colors[0] * (1.0 - t) + colors[1] * t;
                    sum += self.sample(at, q, c, true, RayKind::AreaSample);
                }
                sum * (1.0 / n as f32)
            }
            Light::Parallelogram {
                corner,
                edges,
                colors,
                facing,
            } => {
                if !f.soft_shadow {
                    return Rgb::BLACK;
                }
                let k = parallelogram_grid(self.settings.light_samples);
                let mut sum = Rgb::BLACK;
                for j in 0..k {
                    for i in 0..k {
                        let a = (i as f32 + self.sampler.next_1d()) / k as f32;
                        let b = (j as f32 + self.sampler.next_1d()) / k as f32;
                        let q = corner + a * edges[0] + b * edges[1];
                        // A one-sided light gives nothing behind its plane.
                        if facing.is_some_and(|n| n.dot(at.hit.p - q) <= 0.0) {
                            continue;
                        }
                        let c = parallelogram_color(&colors, a, b);
                        sum += self.sample(at, q, c, true, RayKind::AreaSample);
                    }
                }
                sum * (1.0 / (k * k) as f32)
            }
            // Lights of the path tracer without a place in the template's model.
            _ => Rgb::BLACK,
        }
    }

    /// Phong for one light sample at `q` of colour `c`, shadow-tested if `shadowed`.
    fn sample(
        &mut self,
        at: &ShadePoint<'_>,
        q: Vec3,
        c: Rgb,
        shadowed: bool,
        kind: RayKind,
    ) -> Rgb {
        let hit = at.hit;
        let to = q - hit.p;
        let dist = to.length();
        // normalize(q - p), as `Vec3::normalize` computes it.
        let l = to * dist.recip();
        // Also refuses a light at the hit point itself (NaN direction).
        if hit.n_s.dot(l).is_nan() || hit.n_s.dot(l) <= 0.0 {
            return Rgb::BLACK;
        }
        let mut blocked_at = None;
        if shadowed {
            match kind {
                RayKind::Shadow => self.counts.shadow += 1,
                _ => self.counts.area_sample += 1,
            }
            let ray = Ray::new(hit.p + RAY_EPSILON * l, l);
            let tmax = dist - RAY_EPSILON;
            if self.record.is_some() {
                // The blocking point is drawn: find the closest blocker.
                blocked_at = self.scene.intersect(&ray, tmax, false).map(|b| b.p);
            } else if self.scene.occluded(&ray, tmax) {
                return Rgb::BLACK;
            }
        }
        let blocked = blocked_at.is_some();
        self.push(|_| DebugRay {
            kind,
            depth: at.depth,
            origin: hit.p,
            end: q,
            color: if blocked { RED } else { c },
            blocked: Some(blocked),
            blocked_at,
            hit: None,
        });
        if blocked {
            return Rgb::BLACK;
        }
        phong(hit.n_s, l, at.v, at.kd, at.ks, at.shininess, c)
    }
}
