//! The Whitted tracer of the Delft ray tracer: Phong per light sample, hard shadows
//! from point lights, stratified samples of segment and parallelogram lights, recursive
//! mirror or glossy reflection, textures (mip-mapped by ray cones), transparency, the
//! environment map; every ray it casts can be recorded.

use prism_image::PixelSampling;
use prism_math::warp::cosine_power;
use prism_math::{Frame, Ray, Rgb, Vec2, Vec3};
use prism_scene::{Extras, Features, Light};

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
    /// The extras' settings (used where `features` turns them on).
    pub extras: Extras,
}

/// What kind of ray a debug record is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// From the camera.
    Camera,
    /// From a point of the lens (depth of field).
    Lens,
    /// A mirror reflection.
    Reflection,
    /// A reflection drawn from the Phong lobe (glossy reflection).
    Glossy,
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
    /// What a ray that hit nothing sees of the environment map: from the end of its
    /// record on, its colour the map's radiance.
    Environment,
}

impl RayKind {
    /// The name used in the debug JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Camera => "camera",
            RayKind::Lens => "lens",
            RayKind::Reflection => "reflection",
            RayKind::Glossy => "glossy",
            RayKind::Transmission => "transmission",
            RayKind::Shadow => "shadow",
            RayKind::AreaSample => "area-sample",
            RayKind::Normal => "normal",
            RayKind::InterpolatedNormal => "interpolated-normal",
            RayKind::Environment => "environment",
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
    /// The shutter time of its camera sample (with motion blur on).
    pub time: Option<f32>,
}

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub camera: u64,
    /// Reflection rays (mirror and glossy).
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
    /// Rays cast so far, added to as rays are cast.
    pub counts: &'a mut RayCounts,
    /// When set, every ray is recorded here.
    pub record: Option<Vec<DebugRay>>,
    /// The shutter time of this camera sample (0 without motion blur).
    pub time: f32,
    /// Growth of a ray cone's width per unit distance, `2 tan(alpha / 2)` for the camera's
    /// pixel spread angle alpha (used by mip-mapping).
    pub spread: f32,
    /// Per light, whether the camera hit's shadow ray towards it is blocked, where that was
    /// found beforehand (empty: nothing known).
    pub blocked: &'a [Option<bool>],
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

    /// The colour seen along `ray` (unit direction), `depth` bounces after the camera;
    /// `width` is its cone's width at its origin (0 from the camera).
    pub fn trace(&mut self, ray: &Ray, depth: u32, kind: RayKind, width: f32) -> Rgb {
        let f = self.settings.features;
        let hit = self
            .scene
            .intersect_at(ray, f32::INFINITY, f.normal_interp, self.time);
        self.trace_hit(ray, depth, kind, width, hit)
    }

    /// [`WhittedTracer::trace`] for a ray whose closest hit (at this tracer's time, with
    /// its normals as the features say) is known: `hit`.
    pub fn trace_hit(
        &mut self,
        ray: &Ray,
        depth: u32,
        kind: RayKind,
        width: f32,
        hit: Option<WhittedHit>,
    ) -> Rgb {
        match kind {
            RayKind::Camera | RayKind::Lens => self.counts.camera += 1,
            RayKind::Reflection | RayKind::Glossy => self.counts.reflection += 1,
            _ => self.counts.transmission += 1,
        }
        let time = self.time_tag();
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
            time,
        });
        let color = match hit {
            Some(hit) => self.shade(ray, &hit, depth, width + self.spread * hit.t),
            None => self.environment(ray, depth),
        };
        if let (Some(i), Some(rec)) = (slot, self.record.as_mut()) {
            rec[i].color = color;
        }
        color
    }

    /// The shutter time to record on rays, with motion blur on.
    fn time_tag(&self) -> Option<f32> {
        self.settings.features.motion_blur.then_some(self.time)
    }

    /// What a ray that hit nothing sees: the environment map with environment mapping on
    /// (recorded as an environment ray past the miss), else black.
    fn environment(&mut self, ray: &Ray, depth: u32) -> Rgb {
        let env = match self.scene.environment() {
            Some(e) if self.settings.features.environment_mapping => e,
            _ => return Rgb::BLACK,
        };
        let c = env.radiance(ray.dir);
        let time = self.time_tag();
        self.push(|_| DebugRay {
            kind: RayKind::Environment,
            depth,
            origin: ray.origin + MISS_LENGTH * ray.dir,
            end: ray.origin + 2.0 * MISS_LENGTH * ray.dir,
            color: c,
            blocked: None,
            blocked_at: None,
            hit: None,
            time,
        });
        c
    }

    /// The texel of `m`'s texture at `hit`: nearest or bilinear at level 0, or, with
    /// mip-mapping on, trilinear at the level of the ray cone's footprint (`width` at the
    /// hit, in world units).
    fn texel(&self, tex: &prism_image::Texture, hit: &WhittedHit, dir: Vec3, width: f32) -> Rgb {
        let f = self.settings.features;
        let uv = Vec2::new(hit.uv.x, 1.0 - hit.uv.y);
        if f.mipmap {
            if let Some(level) = self.texture_level(tex, hit, dir, width) {
                return tex.sample_at_level(uv, level, PixelSampling::Bilinear);
            }
        }
        let mode = if f.bilinear {
            PixelSampling::Bilinear
        } else {
            PixelSampling::Nearest
        };
        tex.sample_level(uv, 0, mode)
    }

    /// The mip level of `tex` for a ray cone `width` wide arriving along `dir` at `hit`:
    /// `max(0, log2(width / |n_s.dir| x texels per unit length))`, the texels per unit length
    /// being `sqrt(uv area x W x H / world area)` of the triangle hit; `None` on spheres.
    #[must_use]
    pub fn texture_level(
        &self,
        tex: &prism_image::Texture,
        hit: &WhittedHit,
        dir: Vec3,
        width: f32,
    ) -> Option<f32> {
        let super::scene::Surface::Triangle(i) = hit.surface else {
            return None;
        };
        let (w, h) = tex.size();
        let texels = self.scene.uv_density(i) * ((w as f32) * (h as f32)).sqrt();
        let footprint = width / hit.n_s.dot(dir).abs() * texels;
        Some(footprint.log2().max(0.0))
    }

    fn shade(&mut self, ray: &Ray, hit: &WhittedHit, depth: u32, width: f32) -> Rgb {
        let f = self.settings.features;
        let m: &PhongMaterial = &self.scene.materials[hit.material as usize];
        if self.record.is_some() {
            let len = 0.05 * self.scene.size();
            self.push(|t| DebugRay {
                kind: RayKind::Normal,
                depth,
                origin: hit.p,
                end: hit.p + len * hit.n_g,
                color: Rgb::WHITE,
                blocked: None,
                blocked_at: None,
                hit: None,
                time: t.time_tag(),
            });
            if f.normal_interp {
                self.push(|t| DebugRay {
                    kind: RayKind::InterpolatedNormal,
                    depth,
                    origin: hit.p,
                    end: hit.p + len * hit.n_s,
                    color: Rgb::new(0.0, 1.0, 1.0),
                    blocked: None,
                    blocked_at: None,
                    hit: None,
                    time: t.time_tag(),
                });
            }
        }
        let kd = match (&m.texture, f.texture_mapping) {
            (Some(tex), true) => self.texel(tex, hit, ray.dir, width),
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
            let reflected = if f.glossy_reflection {
                self.glossy(hit, r, shininess, depth, width)
            } else {
                self.trace(
                    &Ray::new(hit.p + RAY_EPSILON * r, r),
                    depth + 1,
                    RayKind::Reflection,
                    width,
                )
            };
            color += ks * reflected;
        }
        if f.transparency && transparency < 1.0 && depth < self.settings.max_depth {
            let behind = self.trace(
                &Ray::new(hit.p + RAY_EPSILON * ray.dir, ray.dir),
                depth + 1,
                RayKind::Transmission,
                width,
            );
            color = color * transparency + behind * (1.0 - transparency);
        }
        color
    }

    /// Glossy reflection at `hit`: the mean colour of `glossy_samples` rays about the
    /// mirror direction `r` drawn from the normalised Phong lobe `cos^shininess` (stratified
    /// on a square grid, the rest independent), those below the surface counting black.
    fn glossy(&mut self, hit: &WhittedHit, r: Vec3, shininess: f32, depth: u32, width: f32) -> Rgb {
        let n = self.settings.extras.glossy_samples.max(1);
        let frame = Frame::from_normal(r);
        let mut sum = Rgb::BLACK;
        for i in 0..n {
            let u = stratified(i, n, &mut self.sampler);
            let d = frame
                .to_world(cosine_power(u, shininess))
                .normalize_or_zero();
            if d.dot(hit.n_s) <= 0.0 {
                continue;
            }
            sum += self.trace(
                &Ray::new(hit.p + RAY_EPSILON * d, d),
                depth + 1,
                RayKind::Glossy,
                width,
            );
        }
        sum * (1.0 / n as f32)
    }

    /// One light's contribution at a shading point.
    fn light(&mut self, li: usize, at: &ShadePoint<'_>) -> Rgb {
        let f = self.settings.features;
        match self.scene.lights[li] {
            Light::Point {
                position,
                intensity,
            } => {
                // The camera hit's shadow rays may have been traced with its row's.
                let known = if at.depth == 0 {
                    self.blocked.get(li).copied().flatten()
                } else {
                    None
                };
                self.sample(
                    at,
                    position,
                    intensity,
                    f.hard_shadow,
                    RayKind::Shadow,
                    known,
                )
            }
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
                    sum += self.sample(at, q, c, true, RayKind::AreaSample, None);
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
                        sum += self.sample(at, q, c, true, RayKind::AreaSample, None);
                    }
                }
                sum * (1.0 / (k * k) as f32)
            }
            // Lights of the path tracer without a place in the template's model.
            _ => Rgb::BLACK,
        }
    }

    /// Phong for one light sample at `q` of colour `c`, shadow-tested if `shadowed`.
    /// `known`: whether the shadow ray is blocked, when that was found beforehand.
    fn sample(
        &mut self,
        at: &ShadePoint<'_>,
        q: Vec3,
        c: Rgb,
        shadowed: bool,
        kind: RayKind,
        known: Option<bool>,
    ) -> Rgb {
        let hit = at.hit;
        let Some((ray, tmax)) = shadow_ray(hit, q) else {
            return Rgb::BLACK;
        };
        let l = ray.dir;
        let mut blocked_at = None;
        if shadowed {
            match kind {
                RayKind::Shadow => self.counts.shadow += 1,
                _ => self.counts.area_sample += 1,
            }
            if let Some(b) = known {
                if b {
                    return Rgb::BLACK;
                }
            } else if self.record.is_some() {
                // The blocking point is drawn: find the closest blocker.
                blocked_at = (self.scene)
                    .intersect_at(&ray, tmax, false, self.time)
                    .map(|b| b.p);
            } else if self.scene.occluded_at(&ray, tmax, self.time) {
                return Rgb::BLACK;
            }
        }
        let blocked = blocked_at.is_some();
        let time = self.time_tag();
        self.push(|_| DebugRay {
            kind,
            depth: at.depth,
            origin: hit.p,
            end: q,
            color: if blocked { RED } else { c },
            blocked: Some(blocked),
            blocked_at,
            hit: None,
            time,
        });
        if blocked {
            return Rgb::BLACK;
        }
        phong(hit.n_s, l, at.v, at.kd, at.ks, at.shininess, c)
    }
}

/// The shadow ray from `hit` towards the light point `q` and its end: from
/// `p + 1e-4 l` along `l = normalize(q - p)`, ending `1e-4` short of `q`; none when `q` is
/// behind the shading normal or at the hit point itself.
#[must_use]
pub fn shadow_ray(hit: &WhittedHit, q: Vec3) -> Option<(Ray, f32)> {
    let to = q - hit.p;
    let dist = to.length();
    // normalize(q - p), as `Vec3::normalize` computes it.
    let l = to * dist.recip();
    // Also refuses a light at the hit point itself (NaN direction).
    let nl = hit.n_s.dot(l);
    if nl.is_nan() || nl <= 0.0 {
        return None;
    }
    Some((Ray::new(hit.p + RAY_EPSILON * l, l), dist - RAY_EPSILON))
}

/// Sample `i` of `n` on the unit square: with `k = floor(sqrt(n))`, the first `k^2` samples
/// are jittered in the cells of a `k x k` grid (row by row), the rest independent; every
/// sample is uniform over its cell, so the mean over all `n` is unbiased.
#[must_use]
pub fn stratified(i: u32, n: u32, sampler: &mut PixelSampler) -> Vec2 {
    let k = (n as f64).sqrt() as u32;
    let (a, b) = (sampler.next_1d(), sampler.next_1d());
    if i < k * k {
        let k_f = k as f32;
        Vec2::new(
            (((i % k) as f32 + a) / k_f).min(ONE_BELOW),
            (((i / k) as f32 + b) / k_f).min(ONE_BELOW),
        )
    } else {
        Vec2::new(a, b)
    }
}

/// The largest float below 1.
pub(crate) const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;
