//! The scene as the integrators see it: one BVH over every triangle, sphere and area-light
//! rectangle, BSDFs, and lights with their sampling routines.

use prism_accel::{BuildOptions, Bvh, BvhStats, Sphere};
use prism_math::warp::{
    cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere, uniform_sphere_pdf,
};
use prism_math::{Frame, Ray, Rgb, Vec2, Vec3};
use prism_scene::{Light, Scene, Shading};

use crate::bsdf::Bsdf;
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

/// What a BVH primitive is.
#[derive(Clone, Copy, Debug)]
enum Prim {
    /// Triangle `tri` of mesh `mesh`.
    Mesh { mesh: u32, tri: u32 },
    /// Half of area light `light`.
    LightQuad { light: u32 },
    /// Sphere `index`.
    Sphere { index: u32 },
}

struct MeshRec {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    shading: Shading,
    material: usize,
}

/// A surface point hit by a ray.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (unit).
    pub ng: Vec3,
    /// Shading normal (unit, on the same side as `ng`).
    pub ns: Vec3,
    /// The BSDF there.
    pub bsdf: Bsdf,
    /// Radiance emitted towards the ray's origin.
    pub emitted: Rgb,
    /// The area light hit, if it is one (for MIS).
    pub light: Option<usize>,
    /// Distance along the ray.
    pub t: f32,
}

/// The prepared scene.
pub struct RenderScene {
    bvh: Bvh,
    prims: Vec<Prim>,
    meshes: Vec<MeshRec>,
    spheres: Vec<(Sphere, usize)>,
    bsdfs: Vec<Bsdf>,
    emission: Vec<Option<Rgb>>,
    /// Lights.
    pub lights: Vec<RenderLight>,
    /// The scene's camera.
    pub camera: prism_scene::Camera,
    /// Index of the light that rays escaping the scene see (hemisphere or environment).
    pub infinite: Option<usize>,
}

impl RenderScene {
    /// Builds the BVH and light list.
    #[must_use]
    pub fn new(scene: &Scene) -> RenderScene {
        let mut tris = Vec::new();
        let mut prims = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            for (ti, t) in m.triangles.iter().enumerate() {
                tris.push(t.map(|i| m.positions[i as usize]));
                prims.push(Prim::Mesh {
                    mesh: mi as u32,
                    tri: ti as u32,
                });
            }
        }
        let mut lights = Vec::new();
        let mut infinite = None;
        for l in &scene.lights {
            match *l {
                Light::Point {
                    position,
                    intensity,
                } => lights.push(RenderLight::Point {
                    position,
                    intensity,
                }),
                Light::Directional {
                    direction,
                    irradiance,
                } => lights.push(RenderLight::Directional {
                    to_light: -direction.normalize(),
                    irradiance,
                }),
                Light::Area {
                    center,
                    dim_x,
                    dim_y,
                    normal,
                    radiance,
                } => {
                    let corner = center - 0.5 * dim_x - 0.5 * dim_y;
                    let index = lights.len() as u32;
                    let (a, b, c, d) = (
                        corner,
                        corner + dim_x,
                        corner + dim_x + dim_y,
                        corner + dim_y,
                    );
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                    prims.push(Prim::LightQuad { light: index });
                    prims.push(Prim::LightQuad { light: index });
                    lights.push(RenderLight::Area {
                        corner,
                        e1: dim_x,
                        e2: dim_y,
                        normal,
                        area: dim_x.cross(dim_y).length(),
                        radiance,
                    });
                }
                Light::Hemisphere { radiance } => {
                    infinite = Some(lights.len());
                    lights.push(RenderLight::Hemisphere { radiance });
                }
                Light::Environment { radiance } => {
                    infinite = Some(lights.len());
                    lights.push(RenderLight::Environment { radiance });
                }
                Light::EnvironmentMap { ref radiance } => {
                    infinite = Some(lights.len());
                    lights.push(RenderLight::EnvironmentMap(std::sync::Arc::new(
                        EnvMap::new(radiance),
                    )));
                }
            }
        }
        let spheres: Vec<Sphere> = scene
            .spheres
            .iter()
            .map(|s| Sphere {
                center: s.center,
                radius: s.radius,
            })
            .collect();
        for i in 0..spheres.len() {
            prims.push(Prim::Sphere { index: i as u32 });
        }
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        RenderScene {
            bvh,
            prims,
            meshes: scene
                .meshes
                .iter()
                .map(|m| MeshRec {
                    positions: m.positions.clone(),
                    triangles: m.triangles.clone(),
                    shading: m.shading.clone(),
                    material: m.material,
                })
                .collect(),
            spheres: spheres
                .into_iter()
                .zip(scene.spheres.iter().map(|s| s.material))
                .collect(),
            bsdfs: scene.materials.iter().map(Bsdf::from_material).collect(),
            emission: scene
                .materials
                .iter()
                .map(|m| match m {
                    prism_scene::Material::Emission { radiance } => Some(*radiance),
                    _ => None,
                })
                .collect(),
            lights,
            camera: scene.camera,
            infinite,
        }
    }

    /// Radiance arriving along `dir` from outside the scene; camera rays see only
    /// environment lights, not the course's hidden hemisphere light.
    #[must_use]
    pub fn escaped(&self, dir: Vec3, camera_ray: bool) -> Rgb {
        match self.infinite.map(|i| &self.lights[i]) {
            Some(RenderLight::Environment { radiance }) => *radiance,
            Some(RenderLight::EnvironmentMap(map)) => map.radiance(dir),
            Some(RenderLight::Hemisphere { radiance }) if !camera_ray && dir.y > 0.0 => *radiance,
            _ => Rgb::BLACK,
        }
    }

    /// The BVH's build statistics.
    #[must_use]
    pub fn bvh_stats(&self) -> BvhStats {
        self.bvh.stats()
    }

    /// True if something blocks the segment from `p` along `wi` up to `dist`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray, dist: f32) -> bool {
        self.bvh.occluded(ray, 0.0, dist)
    }

    /// The closest surface along the ray, with its shading data.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<Interaction> {
        let hit = self.bvh.intersect(ray, 0.0, f32::INFINITY)?;
        let b0 = 1.0 - hit.b1 - hit.b2;
        Some(match self.prims[hit.prim as usize] {
            Prim::Mesh { mesh, tri } => {
                let m = &self.meshes[mesh as usize];
                let t = m.triangles[tri as usize];
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                let p = b0 * a + hit.b1 * b + hit.b2 * c;
                let ng = (b - a).cross(c - a).normalize();
                let interp =
                    |n: [Vec3; 3]| (b0 * n[0] + hit.b1 * n[1] + hit.b2 * n[2]).try_normalize();
                let ns = match &m.shading {
                    Shading::Smooth(n) => interp(t.map(|i| n[i as usize])),
                    Shading::Corners(n) => interp(n[tri as usize]),
                    Shading::Flat => None,
                }
                .unwrap_or(ng);
                let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
                Interaction {
                    p,
                    ng,
                    ns,
                    bsdf: self.bsdfs[m.material],
                    emitted: self.emission[m.material].unwrap_or(Rgb::BLACK),
                    light: None,
                    t: hit.t,
                }
            }
            Prim::LightQuad { light } => {
                let RenderLight::Area {
                    normal, radiance, ..
                } = self.lights[light as usize]
                else {
                    unreachable!("light quads belong to area lights")
                };
                let front = ray.dir.dot(normal) < 0.0;
                Interaction {
                    p: ray.at(hit.t),
                    ng: normal,
                    ns: normal,
                    bsdf: Bsdf::Black,
                    emitted: if front { radiance } else { Rgb::BLACK },
                    light: Some(light as usize),
                    t: hit.t,
                }
            }
            Prim::Sphere { index } => {
                let (s, material) = self.spheres[index as usize];
                let p = ray.at(hit.t);
                let n = ((p - s.center) / s.radius).normalize();
                Interaction {
                    p: s.center + n * s.radius,
                    ng: n,
                    ns: n,
                    bsdf: self.bsdfs[material],
                    emitted: self.emission[material].unwrap_or(Rgb::BLACK),
                    light: None,
                    t: hit.t,
                }
            }
        })
    }
}

/// A ray leaving `p` along `dir`, its origin pushed off the surface (normal `ng`) to the
/// side `dir` points to, so that it does not hit the surface it starts on.
#[must_use]
pub fn spawn(p: Vec3, ng: Vec3, dir: Vec3) -> Ray {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    let side = if dir.dot(ng) >= 0.0 { ng } else { -ng };
    Ray::new(p + side * eps, dir)
}
