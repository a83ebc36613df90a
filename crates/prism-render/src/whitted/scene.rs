//! [`WhittedScene`], the scene as the Whitted ray tracer sees it: every triangle with its
//! vertex normals and uvs, spheres, Phong materials with their textures, lights, the meshes
//! that move over the shutter, the environment map, and the one BVH (or none, for brute
//! force); it answers closest-hit and shadow queries at a time of the shutter.

pub use prism_accel::Split;
use prism_accel::{
    intersect_sphere, intersect_triangle, BuildOptions, Bvh, BvhStats, RayPre, Sphere,
};
use prism_image::{PixelSampling, RgbImage, Texture, Wrap};
use prism_math::{Ray, Rgb, Vec2, Vec3};
use prism_scene::{Light, Material, Scene, Shading};

/// A Phong material ready to shade.
#[derive(Clone, Debug)]
pub struct PhongMaterial {
    /// Diffuse colour.
    pub kd: Rgb,
    /// Specular colour and mirror weight.
    pub ks: Rgb,
    /// Specular exponent.
    pub shininess: f32,
    /// The `map_Kd` texture (clamped to the edge, the file's top row at v = 1).
    pub texture: Option<Texture>,
    /// Opacity (1 opaque).
    pub transparency: f32,
    /// The material's name.
    pub name: String,
}

impl PhongMaterial {
    /// The Phong reading of a scene material: Phong as given; diffuse as `kd`; a mirror as
    /// `ks`; an emitter as `kd` of its radiance; glass and conductors as a white mirror.
    #[must_use]
    pub fn from_material(m: &Material, name: String) -> PhongMaterial {
        let plain = |kd: Rgb, ks: Rgb| PhongMaterial {
            kd,
            ks,
            shininess: 1.0,
            texture: None,
            transparency: 1.0,
            name: name.clone(),
        };
        match m {
            Material::Phong {
                kd,
                ks,
                shininess,
                kd_texture,
                transparency,
            } => PhongMaterial {
                kd: *kd,
                ks: *ks,
                shininess: *shininess,
                texture: kd_texture
                    .as_ref()
                    .map(|t| Texture::new((*t.image).clone()).with_wrap(Wrap::Clamp, Wrap::Clamp)),
                transparency: *transparency,
                name,
            },
            // A textured diffuse (the path tracer's) shows its texture's mean albedo.
            Material::Diffuse {
                reflectance,
                texture,
            } => {
                let mean = texture.as_ref().map_or(Rgb::WHITE, |t| {
                    let px = t.image.pixels();
                    px.iter().fold(Rgb::BLACK, |a, &c| a + c) * (1.0 / px.len().max(1) as f32)
                });
                plain(*reflectance * mean, Rgb::BLACK)
            }
            Material::Emission { radiance } => plain(*radiance, Rgb::BLACK),
            Material::AreaEmitter { radiance, .. } => plain(*radiance, Rgb::BLACK),
            Material::Mirror { reflectance } => plain(Rgb::BLACK, *reflectance),
            Material::ThinDielectric { reflectance, .. } => plain(Rgb::BLACK, *reflectance),
            Material::Plastic {
                diffuse, specular, ..
            }
            | Material::RoughPlastic {
                diffuse, specular, ..
            } => plain(*diffuse, *specular),
            Material::Glass { .. }
            | Material::Refraction { .. }
            | Material::Microfacet { .. }
            | Material::Conductor { .. }
            | Material::RoughDielectric { .. } => plain(Rgb::BLACK, Rgb::WHITE),
            Material::Principled { base_color, .. } => plain(*base_color, Rgb::BLACK),
            // Choices among other materials and tilts of their normals, which the path tracer
            // makes at each hit: grey.
            Material::Blend { .. }
            | Material::Mask { .. }
            | Material::NormalMap { .. }
            | Material::BumpMap { .. }
            | Material::Textured { .. } => plain(Rgb::splat(0.5), Rgb::BLACK),
        }
    }
}

/// One triangle's shading data.
#[derive(Clone, Copy, Debug)]
struct TriData {
    normals: [Vec3; 3],
    uvs: [Vec2; 3],
    material: u32,
}

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// Triangle `i`, counting the scene's meshes' triangles in order.
    Triangle(u32),
    /// Sphere `i` of the scene.
    Sphere(u32),
}

/// A ray's closest hit, with what shading needs.
#[derive(Clone, Copy, Debug)]
pub struct WhittedHit {
    /// Ray parameter.
    pub t: f32,
    /// Hit point.
    pub p: Vec3,
    /// Geometric unit normal, facing against the ray.
    pub n_g: Vec3,
    /// Shading unit normal (interpolated, if asked), flipped with `n_g`.
    pub n_s: Vec3,
    /// Interpolated texture coordinates ((0, 0) on spheres).
    pub uv: Vec2,
    /// Index into [`WhittedScene::materials`].
    pub material: u32,
    /// The primitive.
    pub surface: Surface,
}

/// A latitude-longitude environment map: what a ray that hits nothing sees.
#[derive(Clone, Debug)]
pub struct Environment {
    texture: Texture,
    strength: f32,
}

impl Environment {
    /// The map `image` (row 0 the top, looking up) scaled by `strength`.
    #[must_use]
    pub fn new(image: RgbImage, strength: f32) -> Environment {
        Environment {
            texture: Texture::new(image).with_wrap(Wrap::Repeat, Wrap::Clamp),
            strength,
        }
    }

    /// The radiance seen along unit direction `d`: the map at
    /// `u = 0.5 + atan2(d.x, -d.z) / 2 pi`, `v = acos(d.y) / pi` (v = 0 at the top row),
    /// bilinear, wrapping in u, times the strength.
    #[must_use]
    pub fn radiance(&self, d: Vec3) -> Rgb {
        let u = 0.5 + d.x.atan2(-d.z) / std::f32::consts::TAU;
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        self.texture
            .sample_level(Vec2::new(u, v), 0, PixelSampling::Bilinear)
            * self.strength
    }
}

/// How a scene is prepared: its BVH, its moving meshes, its environment.
#[derive(Clone, Debug, Default)]
pub struct SceneSetup {
    /// The BVH's split rule; `None` tests every ray against every primitive.
    pub bvh: Option<Split>,
    /// Meshes that move: index into the scene's meshes and the translation over the
    /// shutter interval [0, 1].
    pub motion: Vec<(usize, Vec3)>,
    /// What rays that miss see (with environment mapping on).
    pub environment: Option<Environment>,
}

/// A mesh that moves: its triangles (a run of the scene's), its translation over the
/// shutter, and a BVH of its own, traced with the ray moved back by the translation.
struct Mover {
    first: u32,
    count: u32,
    velocity: Vec3,
    bvh: Option<Bvh>,
}

/// The prepared scene.
pub struct WhittedScene {
    triangles: Vec<[Vec3; 3]>,
    tri_data: Vec<TriData>,
    spheres: Vec<(Sphere, u32)>,
    /// Materials, indexed by hits.
    pub materials: Vec<PhongMaterial>,
    /// Lights.
    pub lights: Vec<Light>,
    bvh: Option<Bvh>,
    /// The still triangles' numbers when some move (the BVH's triangle `i` is triangle
    /// `still[i]`); empty when none moves.
    still: Vec<u32>,
    movers: Vec<Mover>,
    environment: Option<Environment>,
    bounds_diagonal: f32,
}

impl WhittedScene {
    /// Prepares `scene` with nothing moving and no environment; `use_bvh` builds the BVH
    /// (binned SAH), else every ray tests every primitive.
    #[must_use]
    pub fn new(scene: &Scene, use_bvh: bool) -> WhittedScene {
        WhittedScene::prepare(
            scene,
            SceneSetup {
                bvh: use_bvh.then_some(Split::Sah),
                ..SceneSetup::default()
            },
        )
    }

    /// Prepares `scene` as `setup` says. Motion entries naming no mesh of the scene are
    /// left out.
    #[must_use]
    pub fn prepare(scene: &Scene, setup: SceneSetup) -> WhittedScene {
        let mut triangles = Vec::new();
        let mut tri_data = Vec::new();
        let mut mesh_start = Vec::with_capacity(scene.meshes.len());
        for m in &scene.meshes {
            mesh_start.push(triangles.len() as u32);
            for (ti, t) in m.triangles.iter().enumerate() {
                let pos = t.map(|i| m.positions[i as usize]);
                let geometric = (pos[1] - pos[0]).cross(pos[2] - pos[0]).normalize_or_zero();
                let normals = match &m.shading {
                    Shading::Smooth(n) => t.map(|i| n[i as usize]),
                    Shading::Corners(c) => c[ti],
                    Shading::Flat => [geometric; 3],
                };
                let uvs = m
                    .uvs
                    .as_ref()
                    .map_or([Vec2::ZERO; 3], |uv| t.map(|i| uv[i as usize]));
                triangles.push(pos);
                tri_data.push(TriData {
                    normals,
                    uvs,
                    material: m.material as u32,
                });
            }
        }
        let spheres: Vec<(Sphere, u32)> = scene
            .spheres
            .iter()
            .map(|s| {
                (
                    Sphere {
                        center: s.center,
                        radius: s.radius,
                    },
                    s.material as u32,
                )
            })
            .collect();
        let lights = scene.lights.clone();
        let opts = |split: Split| BuildOptions {
            split,
            ..BuildOptions::default()
        };
        let mut velocity: Vec<Option<Vec3>> = vec![None; scene.meshes.len()];
        for &(i, v) in &setup.motion {
            if let Some(slot) = velocity.get_mut(i) {
                *slot = Some(v);
            }
        }
        let mut movers = Vec::new();
        let mut moving = vec![false; triangles.len()];
        for (i, v) in velocity.iter().enumerate() {
            let Some(v) = *v else { continue };
            let first = mesh_start[i];
            let count = scene.meshes[i].triangles.len() as u32;
            moving[first as usize..(first + count) as usize].fill(true);
            movers.push(Mover {
                first,
                count,
                velocity: v,
                bvh: setup.bvh.map(|split| {
                    let own = &triangles[first as usize..(first + count) as usize];
                    Bvh::build(own, &[], &opts(split))
                }),
            });
        }
        let still: Vec<u32> = if movers.is_empty() {
            Vec::new()
        } else {
            (0..triangles.len() as u32)
                .filter(|&i| !moving[i as usize])
                .collect()
        };
        let bvh = setup.bvh.map(|split| {
            let s: Vec<Sphere> = spheres.iter().map(|s| s.0).collect();
            if movers.is_empty() {
                Bvh::build(&triangles, &s, &opts(split))
            } else {
                let t: Vec<[Vec3; 3]> = still.iter().map(|&i| triangles[i as usize]).collect();
                Bvh::build(&t, &s, &opts(split))
            }
        });
        let bounds_diagonal = scene.bounds().map_or(1.0, |(lo, hi)| (hi - lo).length());
        WhittedScene {
            triangles,
            tri_data,
            spheres,
            materials: scene
                .materials
                .iter()
                .enumerate()
                .map(|(i, m)| PhongMaterial::from_material(m, scene.material_name(i)))
                .collect(),
            lights,
            bvh,
            still,
            movers,
            environment: setup.environment,
            bounds_diagonal,
        }
    }

    /// The statistics of the BVH a split rule would build over this scene's primitives
    /// (all of them, standing still), for comparing rules.
    #[must_use]
    pub fn bvh_stats(&self, split: Split) -> BvhStats {
        let s: Vec<Sphere> = self.spheres.iter().map(|s| s.0).collect();
        let opts = BuildOptions {
            split,
            ..BuildOptions::default()
        };
        Bvh::build(&self.triangles, &s, &opts).stats()
    }

    /// The environment map, when the scene has one.
    #[must_use]
    pub fn environment(&self) -> Option<&Environment> {
        self.environment.as_ref()
    }

    /// True if some mesh moves over the shutter.
    #[must_use]
    pub fn has_motion(&self) -> bool {
        !self.movers.is_empty()
    }

    /// `sqrt(uv area / world area)` of triangle `i`: the texture's texel density along one
    /// side is this times the texture's `sqrt(width x height)`; 0 for a triangle without
    /// area.
    #[must_use]
    pub fn uv_density(&self, i: u32) -> f32 {
        let [v0, v1, v2] = self.triangles[i as usize];
        let [t0, t1, t2] = self.tri_data[i as usize].uvs;
        let world = (v1 - v0).cross(v2 - v0).length();
        let uv = (t1 - t0).perp_dot(t2 - t0).abs();
        if world > 0.0 {
            (uv / world).sqrt()
        } else {
            0.0
        }
    }

    /// The BVH, when built.
    #[must_use]
    pub fn bvh(&self) -> Option<&Bvh> {
        self.bvh.as_ref()
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Triangle `i`'s corners.
    #[must_use]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i]
    }

    /// The diagonal of the scene's bounds (1 for an empty scene), for drawing scales.
    #[must_use]
    pub fn size(&self) -> f32 {
        self.bounds_diagonal
    }

    /// The closest primitive hit with `0 < t < tmax` at shutter time `time`:
    /// `(t, primitive, b1, b2)`, primitives numbered triangles first, then spheres. The
    /// still primitives are searched first, then each moving mesh in turn (its ray moved
    /// back by its translation at `time`), a later one winning only when strictly closer;
    /// within each, the lowest number wins a tie.
    fn closest(&self, ray: &Ray, tmax: f32, time: f32) -> Option<(f32, u32, f32, f32)> {
        let nt = self.triangles.len() as u32;
        let mut best = if let Some(bvh) = &self.bvh {
            bvh.intersect(ray, 0.0, tmax).map(|h| {
                let prim = match self.still.get(h.prim as usize) {
                    Some(&i) => i,
                    // A sphere, numbered after the BVH's triangles.
                    None if h.prim >= self.still_count() => nt + h.prim - self.still_count(),
                    None => h.prim,
                };
                (h.t, prim, h.b1, h.b2)
            })
        } else {
            let mut best = if self.movers.is_empty() {
                self.brute_force(ray, 0..nt, tmax)
            } else {
                self.brute_force(ray, self.still.iter().copied(), tmax)
            };
            let mut tmax = best.map_or(tmax, |b| b.0);
            for (i, (s, _)) in self.spheres.iter().enumerate() {
                if let Some(t) = intersect_sphere(ray, s, 0.0, tmax) {
                    tmax = t;
                    best = Some((t, nt + i as u32, 0.0, 0.0));
                }
            }
            best
        };
        for m in &self.movers {
            let limit = best.map_or(tmax, |b| b.0);
            let moved = Ray::new(ray.origin - m.velocity * time, ray.dir);
            let hit = match &m.bvh {
                Some(bvh) => bvh
                    .intersect(&moved, 0.0, limit)
                    .map(|h| (h.t, m.first + h.prim, h.b1, h.b2)),
                None => self.brute_force(&moved, m.first..m.first + m.count, limit),
            };
            if hit.is_some() {
                best = hit;
            }
        }
        best
    }

    /// The closest of triangles `ids` (in that order, a later one winning only when strictly
    /// closer) hit with `0 < t < tmax`, tested one by one.
    fn brute_force(
        &self,
        ray: &Ray,
        ids: impl Iterator<Item = u32>,
        tmax: f32,
    ) -> Option<(f32, u32, f32, f32)> {
        let pre = RayPre::new(ray);
        let mut best = None;
        let mut tmax = tmax;
        for i in ids {
            let tri = &self.triangles[i as usize];
            if let Some((t, b1, b2)) = intersect_triangle(&pre, tri, 0.0, tmax) {
                tmax = t;
                best = Some((t, i, b1, b2));
            }
        }
        best
    }

    /// Triangles in the still BVH.
    fn still_count(&self) -> u32 {
        if self.movers.is_empty() {
            self.triangles.len() as u32
        } else {
            self.still.len() as u32
        }
    }

    /// True if something is hit with `0 < t < tmax` (nothing moving, or at time 0).
    #[must_use]
    pub fn occluded(&self, ray: &Ray, tmax: f32) -> bool {
        self.occluded_at(ray, tmax, 0.0)
    }

    /// True if something is hit with `0 < t < tmax` at shutter time `time`.
    #[must_use]
    pub fn occluded_at(&self, ray: &Ray, tmax: f32, time: f32) -> bool {
        if self.bvh.is_none() {
            return self.closest(ray, tmax, time).is_some();
        }
        let still = self
            .bvh
            .as_ref()
            .is_some_and(|b| b.occluded(ray, 0.0, tmax));
        still
            || self.movers.iter().any(|m| {
                let moved = Ray::new(ray.origin - m.velocity * time, ray.dir);
                m.bvh
                    .as_ref()
                    .is_some_and(|b| b.occluded(&moved, 0.0, tmax))
            })
    }

    /// The closest hit along `ray` (whose direction is a unit vector) with `0 < t < tmax`,
    /// nothing moving (or at time 0); `interpolate` picks interpolated over geometric
    /// shading normals. Both normals are turned to face against the ray when the geometric
    /// one faces along it.
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmax: f32, interpolate: bool) -> Option<WhittedHit> {
        self.intersect_at(ray, tmax, interpolate, 0.0)
    }

    /// [`WhittedScene::intersect`] at shutter time `time`: moving meshes are where their
    /// translation puts them then.
    #[must_use]
    pub fn intersect_at(
        &self,
        ray: &Ray,
        tmax: f32,
        interpolate: bool,
        time: f32,
    ) -> Option<WhittedHit> {
        let found = self.closest(ray, tmax, time)?;
        Some(self.hit(ray, found, interpolate))
    }

    /// [`WhittedScene::intersect`] for each ray of `rays` (unit directions, from the
    /// camera, nothing moving): `hits[i]` for `rays[i]`, the same hits, the BVH walking the
    /// rays together (`found` holds its answers on the way).
    pub fn intersect_batch(
        &self,
        rays: &[Ray],
        interpolate: bool,
        hits: &mut Vec<Option<WhittedHit>>,
        found: &mut Vec<Option<prism_accel::Hit>>,
    ) {
        hits.clear();
        match &self.bvh {
            Some(bvh) if self.movers.is_empty() => {
                found.clear();
                found.resize(rays.len(), None);
                bvh.intersect_batch(rays, 0.0, f32::INFINITY, found);
                hits.extend(rays.iter().zip(found.iter()).map(|(ray, h)| {
                    h.map(|h| self.hit(ray, (h.t, h.prim, h.b1, h.b2), interpolate))
                }));
            }
            _ => hits
                .extend((rays.iter()).map(|ray| self.intersect(ray, f32::INFINITY, interpolate))),
        }
    }

    /// [`WhittedScene::occluded`] for each ray of `rays` with its own end (`blocked[i]` for
    /// `rays[i]` and `tmax[i]`, nothing moving), the BVH walking the rays together.
    pub fn occluded_batch(&self, rays: &[Ray], tmax: &[f32], blocked: &mut Vec<bool>) {
        blocked.clear();
        blocked.resize(rays.len(), false);
        match &self.bvh {
            Some(bvh) if self.movers.is_empty() => bvh.occluded_batch(rays, 0.0, tmax, blocked),
            _ => {
                for ((ray, &t), b) in rays.iter().zip(tmax).zip(blocked.iter_mut()) {
                    *b = self.occluded(ray, t);
                }
            }
        }
    }

    /// What shading needs of the closest hit `(t, primitive, b1, b2)` along `ray`.
    fn hit(&self, ray: &Ray, found: (f32, u32, f32, f32), interpolate: bool) -> WhittedHit {
        let (t, prim, b1, b2) = found;
        let p = ray.origin + t * ray.dir;
        let nt = self.triangles.len() as u32;
        let (mut n_g, mut n_s, uv, material, surface) = if prim < nt {
            let [v0, v1, v2] = self.triangles[prim as usize];
            let d = &self.tri_data[prim as usize];
            let b0 = 1.0 - b1 - b2;
            let n_g = (v1 - v0).cross(v2 - v0).normalize_or_zero();
            let n_s = if interpolate {
                (b0 * d.normals[0] + b1 * d.normals[1] + b2 * d.normals[2]).normalize_or_zero()
            } else {
                n_g
            };
            let uv = b0 * d.uvs[0] + b1 * d.uvs[1] + b2 * d.uvs[2];
            (n_g, n_s, uv, d.material, Surface::Triangle(prim))
        } else {
            let (s, m) = self.spheres[(prim - nt) as usize];
            let n = (p - s.center) / s.radius;
            (n, n, Vec2::ZERO, m, Surface::Sphere(prim - nt))
        };
        if n_s == Vec3::ZERO {
            n_s = n_g;
        }
        if n_g.dot(ray.dir) > 0.0 {
            n_g = -n_g;
            n_s = -n_s;
        }
        WhittedHit {
            t,
            p,
            n_g,
            n_s,
            uv,
            material,
            surface,
        }
    }
}
