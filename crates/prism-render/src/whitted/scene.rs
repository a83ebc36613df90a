//! [`WhittedScene`], the scene as the Whitted ray tracer sees it: every triangle with its
//! vertex normals and uvs, spheres, Phong materials with their textures, lights, and the
//! one BVH (or none, for brute force); it answers closest-hit and shadow queries.

use prism_accel::{intersect_sphere, intersect_triangle, BuildOptions, Bvh, RayPre, Sphere};
use prism_image::{Texture, Wrap};
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
    bounds_diagonal: f32,
}

impl WhittedScene {
    /// Prepares `scene`; `use_bvh` builds the BVH, else every ray tests every primitive.
    #[must_use]
    pub fn new(scene: &Scene, use_bvh: bool) -> WhittedScene {
        let mut triangles = Vec::new();
        let mut tri_data = Vec::new();
        for m in &scene.meshes {
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
        let bvh = use_bvh.then(|| {
            let s: Vec<Sphere> = spheres.iter().map(|s| s.0).collect();
            Bvh::build(&triangles, &s, &BuildOptions::default())
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
            bounds_diagonal,
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

    /// The closest primitive hit with `0 < t < tmax`: `(t, primitive, b1, b2)`, primitives
    /// numbered triangles first, then spheres.
    fn closest(&self, ray: &Ray, tmax: f32) -> Option<(f32, u32, f32, f32)> {
        if let Some(bvh) = &self.bvh {
            return bvh
                .intersect(ray, 0.0, tmax)
                .map(|h| (h.t, h.prim, h.b1, h.b2));
        }
        let pre = RayPre::new(ray);
        let mut best = None;
        let mut tmax = tmax;
        for (i, tri) in self.triangles.iter().enumerate() {
            if let Some((t, b1, b2)) = intersect_triangle(&pre, tri, 0.0, tmax) {
                tmax = t;
                best = Some((t, i as u32, b1, b2));
            }
        }
        let nt = self.triangles.len() as u32;
        for (i, (s, _)) in self.spheres.iter().enumerate() {
            if let Some(t) = intersect_sphere(ray, s, 0.0, tmax) {
                tmax = t;
                best = Some((t, nt + i as u32, 0.0, 0.0));
            }
        }
        best
    }

    /// True if something is hit with `0 < t < tmax`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray, tmax: f32) -> bool {
        if let Some(bvh) = &self.bvh {
            return bvh.occluded(ray, 0.0, tmax);
        }
        self.closest(ray, tmax).is_some()
    }

    /// The closest hit along `ray` (whose direction is a unit vector) with `0 < t < tmax`;
    /// `interpolate` picks interpolated over geometric shading normals. Both normals are
    /// turned to face against the ray when the geometric one faces along it.
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmax: f32, interpolate: bool) -> Option<WhittedHit> {
        let (t, prim, b1, b2) = self.closest(ray, tmax)?;
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
        Some(WhittedHit {
            t,
            p,
            n_g,
            n_s,
            uv,
            material,
            surface,
        })
    }
}
