//! Lights as the integrators see them: [`RenderLight`] (point, directional, area rectangle,
//! emissive mesh, hemisphere, constant and mapped environment) and the [`LightSample`] each
//! one draws, with the density of every sample (pbrt's `lights`); the environment map's data
//! in [`envmap`].

pub mod envmap;

use prism_math::warp::{
    cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere, uniform_sphere_pdf,
};
use prism_math::{Frame, Rgb, Vec2, Vec3};

use envmap::EnvMap;

use crate::materials::{look_up, Lookup};

/// A light source ready to sample: the renderer's form of a [`prism_scene::Light`].
#[derive(Clone, Debug)]
pub enum RenderLight {
    /// A point light.
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity.
        intensity: Rgb,
    },
    /// A spot light.
    Spot(Spot),
    /// A directional light.
    Directional {
        /// Direction towards the light (unit).
        to_light: Vec3,
        /// Irradiance.
        irradiance: Rgb,
    },
    /// A one-sided rectangle `corner + s e1 + t e2`, `s, t` in `[0, 1]`.
    Area {
        /// A corner.
        corner: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
        /// Unit normal of the emitting side.
        normal: Vec3,
        /// Area.
        area: f32,
        /// Radiance.
        radiance: Rgb,
    },
    /// An emissive mesh, sampled by area.
    Mesh(std::sync::Arc<MeshLight>),
    /// An emitting sphere, sampled by the cone it subtends.
    Sphere(SphereLight),
    /// Radiance from the upper hemisphere (world +Y), hidden from camera rays.
    Hemisphere {
        /// Radiance.
        radiance: Rgb,
    },
    /// Radiance from every direction, seen by every ray.
    Environment {
        /// Radiance.
        radiance: Rgb,
    },
    /// Radiance from every direction read from a map, seen by every ray.
    EnvironmentMap(std::sync::Arc<EnvMap>),
}

/// The triangles of an emissive mesh (both sides emit, as the course's emission BSDF
/// does, or only the front, where the winding's normal points, as a Mitsuba area emitter
/// does), with the cumulative areas that pick one in proportion to its area.
#[derive(Clone, Debug)]
pub struct MeshLight {
    triangles: Vec<[Vec3; 3]>,
    front_only: bool,
    /// `cumulative[i]`: the area of triangles `0..=i`.
    cumulative: Vec<f32>,
    area: f32,
    radiance: Rgb,
    /// A texture the radiance is multiplied by, and each triangle's surface coordinates
    /// (Mitsuba's) at its corners.
    map: Option<(Lookup, Vec<[Vec2; 3]>)>,
}

impl MeshLight {
    /// The light of triangles emitting `radiance`; `None` when they have no area.
    #[must_use]
    pub fn new(triangles: Vec<[Vec3; 3]>, radiance: Rgb) -> Option<MeshLight> {
        let mut sum = 0.0f64;
        let cumulative: Vec<f32> = triangles
            .iter()
            .map(|[a, b, c]| {
                sum += f64::from(0.5 * (*b - *a).cross(*c - *a).length());
                sum as f32
            })
            .collect();
        let area = sum as f32;
        (area > 0.0 && area.is_finite()).then_some(MeshLight {
            triangles,
            front_only: false,
            cumulative,
            area,
            radiance,
            map: None,
        })
    }

    /// The light with its radiance multiplied by the texel of `texture` at each point's
    /// surface coordinates, which are `uvs` at each triangle's corners (one entry per
    /// triangle, in order).
    #[must_use]
    pub(crate) fn textured(mut self, texture: Lookup, uvs: Vec<[Vec2; 3]>) -> MeshLight {
        debug_assert_eq!(uvs.len(), self.triangles.len());
        self.map = Some((texture, uvs));
        self
    }

    /// The radiance at barycentric coordinates `(b1, b2)` of triangle `i`.
    fn radiance_at(&self, i: usize, b1: f32, b2: f32) -> Rgb {
        match &self.map {
            None => self.radiance,
            Some((texture, uvs)) => {
                let [a, b, c] = uvs[i];
                let uv = a * (1.0 - b1 - b2) + b * b1 + c * b2;
                self.radiance * look_up(texture, uv)
            }
        }
    }

    /// The light emitting from its front side only (`true`) or from both sides.
    #[must_use]
    pub fn one_sided(mut self, front_only: bool) -> MeshLight {
        self.front_only = front_only;
        self
    }

    /// The emitting cosine toward a shading point in direction `wi` from it, at a point of
    /// normal `n`: `|wi.n|` for both sides, `-wi.n` for the front only.
    fn cos_toward(&self, wi: Vec3, n: Vec3) -> f32 {
        if self.front_only {
            -wi.dot(n)
        } else {
            wi.dot(n).abs()
        }
    }

    /// The total area.
    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// A point uniform over the mesh's area and its unit normal: a triangle chosen by area
    /// with `u.x`, which is then reused, stretched, inside it.
    fn sample_point(&self, u: Vec2) -> (Vec3, Vec3, Rgb) {
        let target = u.x * self.area;
        let i = self
            .cumulative
            .partition_point(|&c| c <= target)
            .min(self.triangles.len() - 1);
        let before = if i == 0 { 0.0 } else { self.cumulative[i - 1] };
        let width = self.cumulative[i] - before;
        let ux = if width > 0.0 {
            ((target - before) / width).clamp(0.0, 1.0 - f32::EPSILON)
        } else {
            0.5
        };
        let [a, b, c] = self.triangles[i];
        let r = ux.sqrt();
        let point = a * (1.0 - r) + b * (r * (1.0 - u.y)) + c * (r * u.y);
        let radiance = self.radiance_at(i, r * (1.0 - u.y), r * u.y);
        (point, (b - a).cross(c - a).normalize_or_zero(), radiance)
    }
}

/// A sphere emitting `radiance` from its outside (or, turned inwards, from its inside), as
/// Mitsuba's `area` emitter on a `sphere`: from a point outside it, directions are drawn
/// uniformly in the cone it subtends; from a point inside, points uniformly over its area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    /// Centre.
    pub center: Vec3,
    /// Radius (positive).
    pub radius: f32,
    /// Radiance from the emitting side.
    pub radiance: Rgb,
    /// True if the inside emits (Mitsuba's `flip_normals`).
    pub inward: bool,
}

impl SphereLight {
    /// The cosine of the half-angle of the cone the sphere subtends from a point at squared
    /// distance `dist2` from its centre (outside it).
    fn cos_max(&self, dist2: f32) -> f32 {
        (1.0 - self.radius * self.radius / dist2).max(0.0).sqrt()
    }

    /// Samples the sphere from `p` with `u`.
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let d = self.center - p;
        let dist2 = d.length_squared();
        if dist2 <= self.radius * self.radius {
            // Inside: a point uniform over the area, whose inside emits only when inward.
            if !self.inward {
                return None;
            }
            let n = uniform_sphere(u);
            let q = self.center + n * self.radius;
            let area = 4.0 * std::f32::consts::PI * self.radius * self.radius;
            return toward_surface(p, q, |wi| wi.dot(n), area, self.radiance);
        }
        if self.inward {
            return None;
        }
        let cos_max = self.cos_max(dist2);
        let cos = 1.0 - u.x * (1.0 - cos_max);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * u.y;
        let axis = d / dist2.sqrt();
        let wi =
            Frame::from_normal(axis).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos));
        // The nearer crossing of the sphere along `wi`.
        let b = wi.dot(d);
        let t = b
            - (self.radius * self.radius - (dist2 - b * b))
                .max(0.0)
                .sqrt();
        (t > 0.0 && cos_max < 1.0).then(|| LightSample {
            wi,
            dist: t,
            li: self.radiance,
            pdf: 1.0 / (2.0 * std::f32::consts::PI * (1.0 - cos_max)),
            delta: false,
        })
    }

    /// The density with which [`SphereLight::sample`] picks direction `wi`, which meets the
    /// sphere at distance `dist` where its normal (toward the emitting side) is `n`.
    fn pdf(&self, wi: Vec3, dist: f32, n: Vec3) -> f32 {
        let outward = if self.inward { -n } else { n };
        // From the shading point to the centre.
        let d = wi * dist - outward * self.radius;
        let dist2 = d.length_squared();
        if dist2 <= self.radius * self.radius {
            let cos = wi.dot(outward).abs();
            let area = 4.0 * std::f32::consts::PI * self.radius * self.radius;
            return if cos > 0.0 {
                dist * dist / (area * cos)
            } else {
                0.0
            };
        }
        let cos_max = self.cos_max(dist2);
        if cos_max < 1.0 {
            1.0 / (2.0 * std::f32::consts::PI * (1.0 - cos_max))
        } else {
            0.0
        }
    }
}

/// The light sample at `p` of point `q`, drawn uniformly over an emitter of `area` and
/// `radiance` whose emitting cosine toward a direction `wi` (from `p`) is `cos_at(wi)`: the
/// solid-angle density is `dist^2 / (area cos)`; `None` where the cosine is not positive.
fn toward_surface(
    p: Vec3,
    q: Vec3,
    cos_at: impl Fn(Vec3) -> f32,
    area: f32,
    radiance: Rgb,
) -> Option<LightSample> {
    let d = q - p;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    if dist <= 0.0 {
        return None;
    }
    let wi = d / dist;
    let cos_l = cos_at(wi);
    (cos_l > 0.0).then(|| LightSample {
        wi,
        dist,
        li: radiance,
        pdf: dist2 / (area * cos_l),
        delta: false,
    })
}

/// A sample of incident light at a point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Distance to the light (infinite for directional and hemisphere lights).
    pub dist: f32,
    /// Incident radiance (for delta lights, the irradiance-like factor that multiplies the
    /// BSDF and cosine directly).
    pub li: Rgb,
    /// Solid-angle density (1 for delta lights).
    pub pdf: f32,
    /// True for point and directional lights.
    pub delta: bool,
}

impl RenderLight {
    /// True for lights that need exactly one sample (point, directional).
    #[must_use]
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            RenderLight::Point { .. } | RenderLight::Directional { .. } | RenderLight::Spot(_)
        )
    }

    /// Samples taken of the light at a shading point when `light_samples` are asked for:
    /// one of a delta light (all would be the same), else `light_samples` (at least one).
    #[must_use]
    pub fn sample_count(&self, light_samples: u32) -> u32 {
        if self.is_delta() {
            1
        } else {
            light_samples.max(1)
        }
    }

    /// Samples incident light at `p` from `u`.
    #[must_use]
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            RenderLight::EnvironmentMap(ref map) => {
                map.sample(u).map(|(wi, li, pdf)| LightSample {
                    wi,
                    dist: f32::INFINITY,
                    li,
                    pdf,
                    delta: false,
                })
            }
            RenderLight::Point {
                position,
                intensity,
            } => {
                let d = position - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                (dist > 0.0).then(|| LightSample {
                    wi: d / dist,
                    dist,
                    li: intensity * (1.0 / dist2),
                    pdf: 1.0,
                    delta: true,
                })
            }
            RenderLight::Spot(ref spot) => spot.sample(p),
            RenderLight::Directional {
                to_light,
                irradiance,
            } => Some(LightSample {
                wi: to_light,
                dist: f32::INFINITY,
                li: irradiance,
                pdf: 1.0,
                delta: true,
            }),
            RenderLight::Area {
                corner,
                e1,
                e2,
                normal,
                area,
                radiance,
            } => {
                let q = corner + u.x * e1 + u.y * e2;
                // One-sided: only the normal's side emits.
                toward_surface(p, q, |wi| -wi.dot(normal), area, radiance)
            }
            RenderLight::Mesh(ref mesh) => {
                let (q, n, radiance) = mesh.sample_point(u);
                toward_surface(p, q, |wi| mesh.cos_toward(wi, n), mesh.area, radiance)
            }
            RenderLight::Sphere(ref sphere) => sphere.sample(p, u),
            RenderLight::Environment { radiance } => Some(LightSample {
                wi: uniform_sphere(u),
                dist: f32::INFINITY,
                li: radiance,
                pdf: uniform_sphere_pdf(),
                delta: false,
            }),
            RenderLight::Hemisphere { radiance } => {
                let frame = Frame::from_normal(Vec3::Y);
                let local = cosine_hemisphere(u);
                (local.z > 0.0).then(|| LightSample {
                    wi: frame.to_world(local),
                    dist: f32::INFINITY,
                    li: radiance,
                    pdf: cosine_hemisphere_pdf(local.z),
                    delta: false,
                })
            }
        }
    }

    /// The density with which [`RenderLight::sample`] picks direction `wi` that reaches the
    /// light at distance `dist` where its surface has geometric normal `ng` (area and mesh
    /// lights), or escapes (hemisphere and environment lights).
    #[must_use]
    pub fn pdf(&self, wi: Vec3, dist: f32, ng: Vec3) -> f32 {
        match *self {
            RenderLight::Mesh(ref mesh) => {
                let cos_l = mesh.cos_toward(wi, ng);
                if cos_l > 0.0 {
                    dist * dist / (mesh.area * cos_l)
                } else {
                    0.0
                }
            }
            RenderLight::Area { normal, area, .. } => {
                let cos_l = -wi.dot(normal);
                if cos_l > 0.0 {
                    dist * dist / (area * cos_l)
                } else {
                    0.0
                }
            }
            RenderLight::Sphere(ref sphere) => sphere.pdf(wi, dist, ng),
            RenderLight::Hemisphere { .. } => cosine_hemisphere_pdf(wi.y),
            RenderLight::Environment { .. } => uniform_sphere_pdf(),
            RenderLight::EnvironmentMap(ref map) => map.pdf(wi),
            _ => 0.0,
        }
    }
}

/// Mitsuba's spot light: a point light whose intensity is full within the beam width of
/// its axis and falls linearly in angle to 0 at the cutoff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    position: Vec3,
    to_local: prism_math::glam::Mat3,
    intensity: Rgb,
    cos_cutoff: f32,
    cos_beam: f32,
    cutoff: f32,
    inv_transition: f32,
}

impl Spot {
    /// The spot at `position` whose frame `to_local` takes world directions to (its axis
    /// is local +z), with `intensity` on the axis and half-angles `cutoff` and `beam_width`
    /// in degrees.
    #[must_use]
    pub fn new(
        position: Vec3,
        to_local: prism_math::glam::Mat3,
        intensity: Rgb,
        cutoff: f32,
        beam_width: f32,
    ) -> Spot {
        let (c, b) = (cutoff.to_radians(), beam_width.to_radians());
        Spot {
            position,
            to_local,
            intensity,
            cos_cutoff: c.cos(),
            cos_beam: b.cos(),
            cutoff: c,
            inv_transition: 1.0 / (c - b),
        }
    }

    /// The share of the axis intensity sent along world direction `d` (from the light).
    #[must_use]
    pub fn falloff(&self, d: Vec3) -> f32 {
        let cos = (self.to_local * d).normalize_or_zero().z;
        if cos <= self.cos_cutoff {
            0.0
        } else if cos >= self.cos_beam {
            1.0
        } else {
            (self.cutoff - prism_math::acos(cos)) * self.inv_transition
        }
    }

    /// The light at `p`.
    fn sample(&self, p: Vec3) -> Option<LightSample> {
        let d = self.position - p;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        let falloff = self.falloff(-d);
        (dist > 0.0 && falloff > 0.0).then(|| LightSample {
            wi: d / dist,
            dist,
            li: self.intensity * (falloff / dist2),
            pdf: 1.0,
            delta: true,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Pcg32;

    /// The solid angle of triangle `abc` seen from the origin (Van Oosterom and Strackee).
    fn solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f64 {
        let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * num.atan2(den)
    }

    /// Oracle: geometry. A square light in the plane z = 1 whose surface coordinates are
    /// its x and y, under a 2x2 nearest texture (a colour per quadrant): each sample's
    /// radiance is the light's radiance times the texel of the quadrant its direction from
    /// the point (0.3, 0.4, 0) meets the plane in.
    #[test]
    fn textured_mesh_light_emits_the_texel_where_it_samples() {
        let colours = [
            Rgb::new(1.0, 0.0, 0.0),
            Rgb::new(0.0, 1.0, 0.0),
            Rgb::new(0.0, 0.0, 1.0),
            Rgb::new(1.0, 1.0, 0.0),
        ];
        let image = prism_image::Image::from_fn(2, 2, |x, y| colours[(y * 2 + x) as usize]);
        let texture = std::sync::Arc::new(prism_image::Texture::new(image));
        let lookup: Lookup = (
            texture,
            prism_image::PixelSampling::Nearest,
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        );
        let quad = [
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)],
            [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        ];
        let tris = quad
            .iter()
            .map(|t| t.map(|(x, y)| Vec3::new(x, y, 1.0)))
            .collect();
        let uvs = quad
            .iter()
            .map(|t| t.map(|(x, y)| Vec2::new(x, y)))
            .collect();
        let light = MeshLight::new(tris, Rgb::splat(2.0))
            .unwrap()
            .textured(lookup, uvs);
        let light = RenderLight::Mesh(std::sync::Arc::new(light));
        let from = Vec3::new(0.3, 0.4, 0.0);
        let mut rng = Pcg32::new(1, 2);
        let mut seen = [0; 4];
        for _ in 0..4000 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let ls = light.sample(from, u).unwrap();
            let q = from + ls.wi * (1.0 / ls.wi.z);
            let (x, y) = ((q.x * 2.0) as usize, (q.y * 2.0) as usize);
            // Points within rounding of a texel's edge could go either way.
            if (q.x * 2.0 - x as f32).abs() < 1e-3 || (q.y * 2.0 - y as f32).abs() < 1e-3 {
                continue;
            }
            let k = y.min(1) * 2 + x.min(1);
            seen[k] += 1;
            assert_eq!(ls.li, colours[k] * 2.0, "at {q}");
        }
        assert!(seen.iter().all(|&n| n > 800), "{seen:?}");
    }

    /// Oracles for a sphere light: from outside, every sampled direction meets the sphere at
    /// the distance given, `pdf` recomputes each density, and the irradiance on a plate
    /// facing the centre is the closed form `pi L (r / D)^2`; from inside a sphere that
    /// emits inwards, the irradiance at the centre on a plate is `pi L`.
    #[test]
    fn sphere_light_samples_its_cone() {
        let mut rng = Pcg32::new(4, 4);
        let (center, radius, l) = (Vec3::new(0.2, 3.0, -0.5), 0.7, 2.0);
        let light = SphereLight {
            center,
            radius,
            radiance: Rgb::splat(l),
            inward: false,
        };
        let p = Vec3::new(0.2, 0.0, -0.5);
        let n = Vec3::Y;
        let (mut e, count) = (0.0f64, 200_000);
        for _ in 0..count {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let ls = light
                .sample(p, u)
                .expect("outside, every sample meets the sphere");
            let q = p + ls.wi * ls.dist;
            assert!(((q - center).length() - radius).abs() < 1e-4, "{q}");
            let normal = (q - center).normalize();
            let pdf = light.pdf(ls.wi, ls.dist, normal);
            assert!((pdf - ls.pdf).abs() <= 1e-4 * ls.pdf, "{pdf} vs {}", ls.pdf);
            e += f64::from(ls.li.g * ls.wi.dot(n).max(0.0) / ls.pdf);
        }
        let d = f64::from((center - p).length());
        let want = std::f64::consts::PI * f64::from(l) * (f64::from(radius) / d).powi(2);
        assert!(
            (e / f64::from(count) / want - 1.0).abs() < 2e-3,
            "{} vs {want}",
            e / f64::from(count)
        );
        // Inside a sphere that emits inwards, at its centre.
        let inside = SphereLight {
            inward: true,
            ..light
        };
        assert!(light.sample(center, Vec2::splat(0.3)).is_none());
        let mut e = 0.0f64;
        for _ in 0..count {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(ls) = inside.sample(center, u) {
                let q = center + ls.wi * ls.dist;
                let inward_normal = (center - q).normalize();
                let pdf = inside.pdf(ls.wi, ls.dist, inward_normal);
                assert!((pdf - ls.pdf).abs() <= 1e-3 * ls.pdf, "{pdf} vs {}", ls.pdf);
                e += f64::from(ls.li.g * ls.wi.dot(n).max(0.0) / ls.pdf);
            }
        }
        let want = std::f64::consts::PI * f64::from(l);
        assert!(
            (e / f64::from(count) / want - 1.0).abs() < 1e-2,
            "{} vs {want}",
            e / f64::from(count)
        );
    }

    /// Oracles for area sampling of an emissive mesh, from a point that sees both sides of
    /// it: the mean of `1 / pdf` is the solid angle the mesh subtends (closed form, per
    /// triangle); `pdf` recomputes every sample's density; triangles are chosen in
    /// proportion to their areas.
    #[test]
    fn mesh_light_samples_by_area() {
        let p = Vec3::new(0.1, -0.3, 0.2);
        let tris = vec![
            [
                Vec3::new(-0.5, 1.0, -0.4),
                Vec3::new(0.7, 1.1, -0.3),
                Vec3::new(0.2, 0.9, 0.6),
            ],
            [
                Vec3::new(1.5, 0.2, 0.0),
                Vec3::new(1.6, 0.9, 0.1),
                Vec3::new(1.4, 0.5, 0.9),
            ],
        ];
        let light = MeshLight::new(tris.clone(), Rgb::splat(2.0)).unwrap();
        let areas: Vec<f32> = tris
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
            .collect();
        assert!((light.area() - areas[0] - areas[1]).abs() < 1e-5);
        let omega: f64 = tris
            .iter()
            .map(|[a, b, c]| solid_angle(*a - p, *b - p, *c - p))
            .sum();
        let l = RenderLight::Mesh(std::sync::Arc::new(light));
        let mut rng = Pcg32::new(5, 1);
        let n = 400_000;
        let (mut sum, mut first) = (0.0f64, 0usize);
        for _ in 0..n {
            let s = l
                .sample(p, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            assert!(!s.delta && s.li == Rgb::splat(2.0));
            sum += 1.0 / f64::from(s.pdf);
            let q = p + s.wi * s.dist;
            let on_first = q.x < 1.0;
            first += usize::from(on_first);
            let [a, b, c] = tris[usize::from(!on_first)];
            let ng = (b - a).cross(c - a).normalize();
            let again = l.pdf(s.wi, s.dist, ng);
            assert!((again / s.pdf - 1.0).abs() < 1e-3, "{again} vs {}", s.pdf);
        }
        let estimate = sum / f64::from(n);
        assert!(
            (estimate / omega - 1.0).abs() < 0.01,
            "E[1/pdf] {estimate} vs solid angle {omega}"
        );
        let share = first as f64 / f64::from(n);
        let want = f64::from(areas[0] / (areas[0] + areas[1]));
        // Four binomial standard deviations.
        let sd = (want * (1.0 - want) / f64::from(n)).sqrt();
        assert!((share - want).abs() < 4.0 * sd, "{share} vs {want}");
        assert!(MeshLight::new(vec![[Vec3::ZERO; 3]], Rgb::WHITE).is_none());
    }
}

#[cfg(test)]
mod spot_tests {
    use super::*;

    /// Closed form of Mitsuba's spot profile: full within the beam width, linear in angle to
    /// 0 at the cutoff, nothing beyond; `1 / d^2` with distance.
    #[test]
    fn spot_falloff_is_mitsubas() {
        let spot = Spot::new(
            Vec3::ZERO,
            prism_math::glam::Mat3::IDENTITY,
            Rgb::splat(2.0),
            40.0,
            30.0,
        );
        let at = |deg: f32| {
            let a = deg.to_radians();
            spot.falloff(Vec3::new(a.sin(), 0.0, a.cos()))
        };
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(29.0), 1.0);
        assert!((at(35.0) - 0.5).abs() < 1e-4, "{}", at(35.0));
        assert_eq!(at(41.0), 0.0);
        // In front of the light on its axis, 2 away; behind it, nothing.
        let s = spot.sample(Vec3::new(0.0, 0.0, 2.0)).unwrap();
        assert!(s.delta && (s.li.r - 0.5).abs() < 1e-6, "{s:?}");
        assert!(spot.sample(Vec3::new(0.0, 0.0, -2.0)).is_none());
    }
}
