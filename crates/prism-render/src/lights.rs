//! Lights as the integrators see them: [`RenderLight`] (point, directional, area rectangle,
//! hemisphere, constant and mapped environment) and the [`LightSample`] each one draws, with
//! the density of every sample (pbrt's `lights`).

use prism_math::warp::{
    cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere, uniform_sphere_pdf,
};
use prism_math::{Frame, Rgb, Vec2, Vec3};

use crate::envmap::EnvMap;

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
            RenderLight::Point { .. } | RenderLight::Directional { .. }
        )
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
                let d = q - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                if dist <= 0.0 {
                    return None;
                }
                let wi = d / dist;
                let cos_l = -wi.dot(normal);
                (cos_l > 0.0).then(|| LightSample {
                    wi,
                    dist,
                    li: radiance,
                    pdf: dist2 / (area * cos_l),
                    delta: false,
                })
            }
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

    /// The density with which [`RenderLight::sample`] picks direction `wi` that reaches the light
    /// at distance `dist` (area lights) or escapes (hemisphere and environment lights).
    #[must_use]
    pub fn pdf(&self, wi: Vec3, dist: f32) -> f32 {
        match *self {
            RenderLight::Area { normal, area, .. } => {
                let cos_l = -wi.dot(normal);
                if cos_l > 0.0 {
                    dist * dist / (area * cos_l)
                } else {
                    0.0
                }
            }
            RenderLight::Hemisphere { .. } => cosine_hemisphere_pdf(wi.y),
            RenderLight::Environment { .. } => uniform_sphere_pdf(),
            RenderLight::EnvironmentMap(ref map) => map.pdf(wi),
            _ => 0.0,
        }
    }
}
