//! [`RenderScene`], the scene as the integrators see it: one BVH over every triangle, sphere
//! and area-light rectangle, the BSDFs and emission of its materials, and its lights
//! (emissive meshes among them); it answers closest-hit, shadow and escaped-ray queries.

use prism_accel::{BuildOptions, Bvh, BvhStats, Sphere};
use prism_math::{Ray, Rgb, Vec3};
use prism_scene::{Light, Scene, Shading};

use crate::bsdf::Bsdf;
use crate::interaction::Interaction;
use crate::lights::envmap::EnvMap;
use crate::lights::{MeshLight, RenderLight, SphereLight};
use crate::materials::Materials;

/// What a BVH primitive is.
#[derive(Clone, Copy, Debug)]
enum Prim {
    /// Triangle `tri` of mesh `mesh`, with its vertex indices (kept here so that a hit
    /// reads its vertices without first reading the mesh's triangle list).
    Mesh {
        mesh: u32,
        tri: u32,
        corners: [u32; 3],
        /// The unit geometric normal, `(b - a) x (c - a)` normalized, computed once here
        /// rather than at every hit.
        ng: Vec3,
        /// True if the three shading normals are one unit normal to within
        /// [`ONE_NORMAL_TOLERANCE`] (a flat face given its normal at each corner, as
        /// exported with rounding): a hit takes the first as it is instead of interpolating
        /// and normalizing, which gives it back to within the same tolerance.
        one_normal: bool,
    },
    /// Half of area light `light`.
    LightQuad { light: u32 },
    /// Sphere `index`.
    Sphere { index: u32 },
}

struct MeshRec {
    positions: Vec<Vec3>,
    shading: Shading,
    material: usize,
    /// The light it is, if it emits.
    light: Option<usize>,
    /// Texture coordinates per vertex, if it has them.
    uvs: Option<Vec<prism_math::Vec2>>,
}

/// A sphere as the renderer keeps it.
#[derive(Clone, Copy)]
struct SphereRec {
    sphere: Sphere,
    material: usize,
    /// True if its normals point inwards.
    inward: bool,
    /// The rotation from the world's axes to its own, where turned.
    to_local: Option<prism_math::glam::Mat3>,
    /// The light it is, if it emits.
    light: Option<usize>,
}

/// The prepared scene.
pub struct RenderScene {
    bvh: Bvh,
    prims: Vec<Prim>,
    meshes: Vec<MeshRec>,
    spheres: Vec<SphereRec>,
    materials: Materials,
    /// Lights.
    pub lights: Vec<RenderLight>,
    /// The scene's camera.
    pub camera: prism_scene::Camera,
    /// Index of the light that rays escaping the scene see (hemisphere or environment).
    pub infinite: Option<usize>,
}

impl RenderScene {
    /// Builds the BVH and light list. Segment lights and parallelogram lights without a
    /// facing side (the Whitted ray tracer's, given as colours, not radiance) are left out.
    #[must_use]
    pub fn new(scene: &Scene) -> RenderScene {
        let materials = Materials::new(scene);
        let mut tris = Vec::new();
        let mut prims = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            for (ti, t) in m.triangles.iter().enumerate() {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                tris.push([a, b, c]);
                prims.push(Prim::Mesh {
                    mesh: mi as u32,
                    tri: ti as u32,
                    corners: *t,
                    ng: (b - a).cross(c - a).normalize(),
                    one_normal: corner_normals(&m.shading, ti, *t).is_some_and(one_normal),
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
                Light::Spot {
                    position,
                    to_local,
                    intensity,
                    cutoff,
                    beam_width,
                } => lights.push(RenderLight::Spot(crate::lights::Spot::new(
                    position, to_local, intensity, cutoff, beam_width,
                ))),
                Light::Directional {
                    direction,
                    irradiance,
                } => lights.push(RenderLight::Directional {
                    to_light: -direction.normalize(),
                    irradiance,
                }),
                Light::Parallelogram {
                    corner,
                    edges: [dim_x, dim_y],
                    colors,
                    facing: Some(normal),
                } => {
                    // Radiance is uniform over the rectangle: the corners' mean if they
                    // differ.
                    let radiance = if colors.iter().all(|&c| c == colors[0]) {
                        colors[0]
                    } else {
                        (colors[0] + colors[1] + colors[2] + colors[3]) * 0.25
                    };
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
                // Lights of the Whitted ray tracer that shine both ways like point lights,
                // with colours rather than radiometric units: the path tracer has no use
                // for them.
                Light::Segment { .. } | Light::Parallelogram { facing: None, .. } => {}
                Light::EnvironmentMap {
                    ref radiance,
                    mapping,
                } => {
                    infinite = Some(lights.len());
                    lights.push(RenderLight::EnvironmentMap(std::sync::Arc::new(
                        EnvMap::with_mapping(radiance, mapping),
                    )));
                }
            }
        }
        // Every emitting mesh is also a light, sampled by area.
        let mut mesh_light = vec![None; scene.meshes.len()];
        for (mi, m) in scene.meshes.iter().enumerate() {
            let radiance = match scene.materials.get(m.material) {
                Some(
                    prism_scene::Material::Emission { radiance }
                    | prism_scene::Material::AreaEmitter { radiance, .. },
                ) => *radiance,
                _ => continue,
            };
            if radiance.max_channel() <= 0.0 {
                continue;
            }
            let tris: Vec<[Vec3; 3]> = m
                .triangles
                .iter()
                .map(|t| t.map(|i| m.positions[i as usize]))
                .collect();
            let one_sided = matches!(
                scene.materials.get(m.material),
                Some(prism_scene::Material::AreaEmitter { .. })
            );
            // A one-sided, untextured parallelogram (Mitsuba's rectangle) is sampled as one,
            // uniformly over its two edges (on the lanes, as Mitsuba samples a rectangle).
            let flat = one_sided && materials.emission_texture(m.material).is_none();
            if let Some(area) = flat.then(|| parallelogram(&tris, radiance)).flatten() {
                mesh_light[mi] = Some(lights.len());
                lights.push(area);
                continue;
            }
            let light = MeshLight::new(tris, radiance).map(|l| {
                let l = l.one_sided(one_sided);
                match materials.emission_texture(m.material) {
                    // Mitsuba's surface coordinates at the corners: the file's (v running
                    // down the image), else the barycentric coordinates.
                    Some(texture) => {
                        let uvs = m
                            .triangles
                            .iter()
                            .map(|t| match &m.uvs {
                                Some(uvs) => t.map(|i| {
                                    let uv = uvs[i as usize];
                                    prism_math::Vec2::new(uv.x, 1.0 - uv.y)
                                }),
                                None => [
                                    prism_math::Vec2::ZERO,
                                    prism_math::Vec2::X,
                                    prism_math::Vec2::Y,
                                ],
                            })
                            .collect();
                        l.textured(texture.clone(), uvs)
                    }
                    None => l,
                }
            });
            if let Some(light) = light {
                mesh_light[mi] = Some(lights.len());
                lights.push(RenderLight::Mesh(std::sync::Arc::new(light)));
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
        // A sphere under an untextured Mitsuba area emitter is a light too, sampled by the
        // cone it subtends (as Mitsuba samples it).
        let sphere_light: Vec<Option<usize>> = scene
            .spheres
            .iter()
            .map(|s| match scene.materials.get(s.material) {
                Some(prism_scene::Material::AreaEmitter {
                    radiance,
                    texture: None,
                    ..
                }) if radiance.max_channel() > 0.0 && s.radius > 0.0 => {
                    lights.push(RenderLight::Sphere(SphereLight {
                        center: s.center,
                        radius: s.radius,
                        radiance: *radiance,
                        inward: s.inward,
                    }));
                    Some(lights.len() - 1)
                }
                _ => None,
            })
            .collect();
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        RenderScene {
            bvh,
            prims,
            meshes: scene
                .meshes
                .iter()
                .zip(mesh_light)
                .map(|(m, light)| MeshRec {
                    positions: m.positions.clone(),
                    shading: m.shading.clone(),
                    material: m.material,
                    light,
                    uvs: m.uvs.clone(),
                })
                .collect(),
            spheres: spheres
                .into_iter()
                .zip(scene.spheres.iter().zip(sphere_light))
                .map(|(s, (sphere, light))| SphereRec {
                    sphere: s,
                    material: sphere.material,
                    inward: sphere.inward,
                    to_local: sphere.to_local,
                    light,
                })
                .collect(),
            materials,
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

    /// What a ray leaving the scene along `dir` after a bounce sees (as
    /// [`RenderScene::escaped`]), and the density with which light sampling picks `dir`
    /// from the scene's infinite light (0 without one), for MIS.
    #[must_use]
    pub fn escaped_mis(&self, dir: Vec3) -> (Rgb, f32) {
        match self.infinite.map(|i| &self.lights[i]) {
            Some(RenderLight::EnvironmentMap(map)) => map.radiance_pdf(dir),
            Some(light) => (
                self.escaped(dir, false),
                light.pdf(dir, f32::INFINITY, Vec3::ZERO),
            ),
            None => (Rgb::BLACK, 0.0),
        }
    }

    /// The BVH's build statistics.
    #[must_use]
    pub fn bvh_stats(&self) -> BvhStats {
        self.bvh.stats()
    }

    /// True if something blocks `ray` before distance `dist`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray, dist: f32) -> bool {
        self.bvh.occluded(ray, 0.0, dist)
    }

    /// True for each ray blocked before its distance (`blocked[i]` for `rays[i]` and
    /// `dist[i]`): [`RenderScene::occluded`] for a batch in one call.
    pub fn occluded_batch(&self, rays: &[Ray], dist: &[f32], blocked: &mut [bool]) {
        self.bvh.occluded_batch(rays, 0.0, dist, blocked);
    }

    /// The closest hit along each ray (`hits[i]` for `rays[i]`), the hierarchy traversed in
    /// one call; [`RenderScene::hit_records`] turns them into shading data.
    pub fn closest_hits(&self, rays: &[Ray], hits: &mut Vec<Option<prism_accel::Hit>>) {
        hits.clear();
        hits.resize(rays.len(), None);
        self.bvh.intersect_batch(rays, 0.0, f32::INFINITY, hits);
    }

    /// The shading data of each of [`RenderScene::closest_hits`]' hits (`out[i]` for
    /// `hits[i]` along `rays[i]`): with them, [`RenderScene::intersect`] for a batch.
    pub fn hit_records(
        &self,
        rays: &[Ray],
        hits: &[Option<prism_accel::Hit>],
        out: &mut Vec<Option<Interaction>>,
    ) {
        out.clear();
        // The hits land anywhere in the scene's tables: start loading a later hit's
        // primitive record while this one is computed, so that the cache misses overlap.
        // Its vertices and normals are not prefetched: that costs more than the misses it
        // hides.
        const RECORD_AHEAD: usize = 8;
        out.extend(
            rays.iter()
                .zip(hits.iter())
                .enumerate()
                .map(|(i, (ray, hit))| {
                    if let Some(Some(h)) = hits.get(i + RECORD_AHEAD) {
                        prism_math::prefetch(&self.prims[h.prim as usize]);
                    }
                    hit.map(|h| self.interaction(ray, h))
                }),
        );
    }

    /// The closest surface along the ray, with its shading data.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<Interaction> {
        let hit = self.bvh.intersect(ray, 0.0, f32::INFINITY)?;
        Some(self.interaction(ray, hit))
    }

    /// The first surface along a camera ray that is not an emitter's: Mitsuba's
    /// `hide_emitters` lets camera rays pass through area emitters (at most 64 of them).
    #[must_use]
    pub fn past_emitters(&self, ray: &Ray) -> Option<Interaction> {
        let mut r = *ray;
        for _ in 0..64 {
            let hit = self.bvh.intersect(&r, 0.0, f32::INFINITY)?;
            let here = self.interaction(&r, hit);
            if !self.is_emitter(hit.prim) {
                return Some(here);
            }
            r = here.spawn(ray.dir);
        }
        None
    }

    /// True if primitive `prim` belongs to an emitter (an area light, or a surface whose
    /// material emits).
    pub(crate) fn is_emitter(&self, prim: u32) -> bool {
        let material = match self.prims[prim as usize] {
            Prim::Mesh { mesh, .. } => self.meshes[mesh as usize].material,
            Prim::Sphere { index } => self.spheres[index as usize].material,
            Prim::LightQuad { .. } => return true,
        };
        self.materials.emission[material].is_some()
    }

    /// The shading data of `hit` along `ray`.
    #[inline(always)]
    fn interaction(&self, ray: &Ray, hit: prism_accel::Hit) -> Interaction {
        let b0 = 1.0 - hit.b1 - hit.b2;
        match self.prims[hit.prim as usize] {
            Prim::Mesh {
                mesh,
                tri,
                corners,
                ng,
                one_normal,
            } => {
                let m = &self.meshes[mesh as usize];
                let t = corners;
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                let p = b0 * a + hit.b1 * b + hit.b2 * c;
                let interp =
                    |n: [Vec3; 3]| (b0 * n[0] + hit.b1 * n[1] + hit.b2 * n[2]).try_normalize();
                let ns = match &m.shading {
                    Shading::Smooth(n) if one_normal => Some(n[t[0] as usize]),
                    Shading::Smooth(n) => interp(t.map(|i| n[i as usize])),
                    Shading::Corners(n) if one_normal => Some(n[tri as usize][0]),
                    Shading::Corners(n) => interp(n[tri as usize]),
                    Shading::Flat => None,
                }
                .unwrap_or(ng);
                let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
                let mats = &self.materials;
                // Texture coordinates as Mitsuba's (v running down the image), at the
                // corners and here; without any, the barycentric coordinates, as Mitsuba's.
                let corner_uvs = || {
                    m.uvs.as_ref().map(|uvs| {
                        t.map(|i| prism_math::Vec2::new(uvs[i as usize].x, 1.0 - uvs[i as usize].y))
                    })
                };
                let uv = || {
                    corner_uvs().map_or(prism_math::Vec2::new(hit.b1, hit.b2), |[ua, ub, uc]| {
                        b0 * ua + hit.b1 * ub + hit.b2 * uc
                    })
                };
                let (bsdf, chosen, tilt) = mats.scatterer(
                    m.material,
                    ray,
                    (ns, ng),
                    &uv,
                    || mesh_derivatives([a, b, c], corner_uvs(), ng),
                    m.uvs.is_some(),
                );
                Interaction {
                    p,
                    ng,
                    ns,
                    bsdf,
                    emitted: if mats.front_only[m.material] && ray.dir.dot(ng) >= 0.0 {
                        Rgb::BLACK
                    } else {
                        mats.emission_at(m.material, uv).unwrap_or(Rgb::BLACK)
                    },
                    light: m.light,
                    t: hit.t,
                    tangent: chosen
                        .is_some_and(|i| mats.anisotropic[i])
                        .then(|| mesh_derivatives([a, b, c], corner_uvs(), ng).0),
                    tilt,
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
                    tangent: None,
                    tilt: None,
                }
            }
            Prim::Sphere { index } => {
                let SphereRec {
                    sphere: s,
                    material,
                    inward,
                    to_local,
                    light,
                } = self.spheres[index as usize];
                let p = ray.at(hit.t);
                let outward = ((p - s.center) / s.radius).normalize();
                let n = if inward { -outward } else { outward };
                let mats = &self.materials;
                // Mitsuba's sphere coordinates: the azimuth over 2 pi, the polar angle from
                // +z over pi, about the sphere's own axes (the world's unless turned).
                let local = to_local.map_or(outward, |m| m * outward);
                let to_world = |v: Vec3| to_local.map_or(v, |m| m.transpose() * v);
                let uv = || {
                    let phi = local.y.atan2(local.x);
                    let phi = if phi < 0.0 {
                        phi + 2.0 * std::f32::consts::PI
                    } else {
                        phi
                    };
                    let theta = prism_math::acos(local.z.clamp(-1.0, 1.0));
                    prism_math::Vec2::new(
                        phi / (2.0 * std::f32::consts::PI),
                        theta / std::f32::consts::PI,
                    )
                };
                let (bsdf, chosen, tilt) = mats.scatterer(
                    material,
                    ray,
                    (n, n),
                    &uv,
                    || {
                        let (du, dv) = sphere_derivatives(local, s.radius);
                        (to_world(du), to_world(dv))
                    },
                    true,
                );
                Interaction {
                    p: s.center + outward * s.radius,
                    ng: n,
                    ns: n,
                    bsdf,
                    emitted: if mats.front_only[material] && ray.dir.dot(n) >= 0.0 {
                        Rgb::BLACK
                    } else {
                        mats.emission_at(material, uv).unwrap_or(Rgb::BLACK)
                    },
                    light,
                    t: hit.t,
                    // Along the parallels, as Mitsuba's sphere.
                    tangent: chosen
                        .is_some_and(|i| mats.anisotropic[i])
                        .then(|| to_world(Vec3::new(-local.y, local.x, 0.0))),
                    tilt,
                }
            }
        }
    }
}

/// The one-sided area light of two triangles that make a parallelogram (sharing a
/// diagonal, the other two corners opposite), emitting `radiance` from the side the first
/// triangle's winding faces; none for any other shape.
fn parallelogram(tris: &[[Vec3; 3]], radiance: Rgb) -> Option<RenderLight> {
    let [t0, t1] = tris else {
        return None;
    };
    // The corner of each triangle the other lacks; the two they share are the diagonal.
    let lone = |t: &[Vec3; 3], other: &[Vec3; 3]| {
        let alone: Vec<Vec3> = t.iter().copied().filter(|p| !other.contains(p)).collect();
        (alone.len() == 1).then(|| alone[0])
    };
    let (p, q) = (lone(t0, t1)?, lone(t1, t0)?);
    let shared: Vec<Vec3> = t0.iter().copied().filter(|v| t1.contains(v)).collect();
    let [s, t] = shared[..] else {
        return None;
    };
    let (e1, e2) = (s - p, t - p);
    let scale = e1.length().max(e2.length());
    if (p + e1 + e2 - q).length() > 1e-6 * scale {
        return None;
    }
    let [a, b, c] = *t0;
    let normal = (b - a).cross(c - a).try_normalize()?;
    let area = e1.cross(e2).length();
    (area > 0.0 && area.is_finite()).then_some(RenderLight::Area {
        corner: p,
        e1,
        e2,
        normal,
        area,
        radiance,
    })
}

/// A triangle's `dp/du` and `dp/dv` as Mitsuba's meshes have them: from texture coordinates
/// `uv` (Mitsuba's, `v` running down the image) where they are not degenerate, the frame
/// [`prism_math::Frame::from_normal`] puts around the geometric normal where they are, and
/// the edges from the first corner (barycentric coordinates) without any.
fn mesh_derivatives(p: [Vec3; 3], uv: Option<[prism_math::Vec2; 3]>, ng: Vec3) -> (Vec3, Vec3) {
    let (dp0, dp1) = (p[1] - p[0], p[2] - p[0]);
    let Some([a, b, c]) = uv else {
        return (dp0, dp1);
    };
    let (duv0, duv1) = (b - a, c - a);
    let det = duv0.x * duv1.y - duv0.y * duv1.x;
    if det == 0.0 {
        let f = prism_math::Frame::from_normal(ng);
        return (f.s, f.t);
    }
    let inv = 1.0 / det;
    (
        (dp0 * duv1.y - dp1 * duv0.y) * inv,
        (dp1 * duv0.x - dp0 * duv1.x) * inv,
    )
}

/// `dp/du` and `dp/dv` of a sphere of `radius` at the point of unit direction `local` from
/// its centre, in Mitsuba's coordinates (the azimuth over 2 pi and the polar angle from +z
/// over pi, the world's axes).
fn sphere_derivatives(local: Vec3, radius: f32) -> (Vec3, Vec3) {
    let tau = 2.0 * std::f32::consts::PI;
    let dpdu = Vec3::new(-local.y, local.x, 0.0) * (tau * radius);
    let rd = (local.x * local.x + local.y * local.y).sqrt();
    let dpdv = if rd == 0.0 {
        Vec3::X
    } else {
        Vec3::new(local.z * local.x / rd, local.z * local.y / rd, -rd)
    };
    (dpdu, dpdv * (std::f32::consts::PI * radius))
}

/// How far apart (per coordinate) the corner normals of a face shaded with one normal may be,
/// and how far from unit length: a few units in the last place of 1.
const ONE_NORMAL_TOLERANCE: f32 = 1e-6;

/// The shading normals at the corners of triangle `tri` (vertices `corners`), if the mesh
/// has any.
fn corner_normals(shading: &Shading, tri: usize, corners: [u32; 3]) -> Option<[Vec3; 3]> {
    match shading {
        Shading::Smooth(n) => Some(corners.map(|i| n[i as usize])),
        Shading::Corners(n) => Some(n[tri]),
        Shading::Flat => None,
    }
}

/// True if the three normals are one unit normal to within [`ONE_NORMAL_TOLERANCE`].
fn one_normal(n: [Vec3; 3]) -> bool {
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() <= ONE_NORMAL_TOLERANCE;
    n[0].is_finite()
        && close(n[0], n[1])
        && close(n[0], n[2])
        && (n[0].length_squared() - 1.0).abs() <= ONE_NORMAL_TOLERANCE
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Pcg32;

    /// Property, against the interpolation it replaces: for corner normals that pass
    /// `one_normal`, the normalized barycentric interpolation at any point of the face is
    /// the first normal to within 4e-6 per coordinate (a shading normal that moves by
    /// that changes a cosine by less than 1e-5).
    #[test]
    fn one_normal_is_the_interpolated_normal_to_within_its_tolerance() {
        let mut rng = Pcg32::new(3, 7);
        let mut u = || rng.next_f32();
        let mut tested = 0;
        for _ in 0..100_000 {
            let n = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize();
            let jitter = |u: &mut dyn FnMut() -> f32| {
                Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * (2.0 * ONE_NORMAL_TOLERANCE)
            };
            let corners = [n, n + jitter(&mut u), n + jitter(&mut u)];
            if !one_normal(corners) {
                continue;
            }
            tested += 1;
            let (b1, b2) = (u(), u());
            let (b1, b2) = if b1 + b2 > 1.0 {
                (1.0 - b1, 1.0 - b2)
            } else {
                (b1, b2)
            };
            let b0 = 1.0 - b1 - b2;
            let interp = (b0 * corners[0] + b1 * corners[1] + b2 * corners[2]).normalize();
            assert!(
                (interp - corners[0]).abs().max_element() <= 4e-6,
                "{corners:?} at {b1} {b2}: {interp}"
            );
        }
        assert!(tested > 10_000, "{tested}");
        // Normals further apart, or not of unit length, are interpolated.
        assert!(!one_normal([
            Vec3::Y,
            Vec3::Y,
            Vec3::new(0.0, 1.0, 1e-5).normalize()
        ]));
        assert!(!one_normal([Vec3::Y * 1.001; 3]));
        assert!(!one_normal([Vec3::new(f32::NAN, 1.0, 0.0); 3]));
        assert!(one_normal([Vec3::Y; 3]));
    }

    /// Oracle: the mesh light it stands for. Two triangles making a parallelogram (either
    /// diagonal, either winding) become an area light with the same area, emitting side and
    /// density toward any point; other pairs (a kite, a fold) stay meshes.
    #[test]
    fn parallelograms_become_area_lights_of_the_same_density() {
        let (a, b, c, d) = (
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.2),
            Vec3::new(1.5, 1.3, 1.2),
            Vec3::new(0.5, 1.3, 1.0),
        );
        let radiance = Rgb::splat(3.0);
        for tris in [
            [[a, b, c], [c, d, a]],
            [[b, c, d], [d, a, b]],
            [[a, d, c], [c, b, a]],
        ] {
            let area = parallelogram(&tris, radiance).expect("a parallelogram");
            let mesh = RenderLight::Mesh(std::sync::Arc::new(
                MeshLight::new(tris.to_vec(), radiance)
                    .unwrap()
                    .one_sided(true),
            ));
            let ng = (tris[0][1] - tris[0][0])
                .cross(tris[0][2] - tris[0][0])
                .normalize();
            for p in [Vec3::new(0.7, -1.0, 0.5), Vec3::new(0.2, 3.0, 0.4)] {
                let q = (a + c) * 0.5;
                let wi = (q - p).normalize();
                let dist = (q - p).length();
                let (x, y) = (area.pdf(wi, dist, ng), mesh.pdf(wi, dist, ng));
                assert!((x - y).abs() <= 1e-5 * y.max(1.0), "{x} vs {y}");
            }
        }
        let kite = [[a, b, c], [c, d + Vec3::X * 0.1, a]];
        assert!(parallelogram(&kite, radiance).is_none());
        let folded = [[a, b, c], [c, d + Vec3::Y * 0.3, a]];
        assert!(parallelogram(&folded, radiance).is_none());
        assert!(parallelogram(&[[a, b, c]], radiance).is_none());
    }
}
