//! The plain scene a renderer consumes: world-space triangle meshes and spheres with
//! materials, lights and a camera, all in a Y-up world. This module reads no file: the
//! readers (`collada`) build these types.

use std::sync::Arc;

use prism_image::RgbImage;
use prism_math::{Rgb, Transform, Vec2, Vec3};

/// A surface's scattering model, with the parameters the course's files give.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection.
    Diffuse {
        /// Albedo per channel (times the texture's texel where there is one).
        reflectance: Rgb,
        /// An image of albedos over the surface's texture coordinates (linear values; `v`
        /// up from the image's bottom row, as COLLADA and Blender lay images out).
        texture: Option<MaterialTexture>,
    },
    /// A black surface that emits `radiance` from both sides.
    Emission {
        /// Emitted radiance.
        radiance: Rgb,
    },
    /// A Mitsuba area emitter: `radiance` from the front (where the winding's normal
    /// points) of a surface that still scatters light as its own BSDF does (black without
    /// one).
    AreaEmitter {
        /// Emitted radiance.
        radiance: Rgb,
        /// An image the radiance is multiplied by, at the surface's coordinates (Mitsuba's
        /// textured `radiance`).
        texture: Option<MaterialTexture>,
        /// The surface's material, as an index into [`Scene::materials`], if it has one.
        surface: Option<usize>,
    },
    /// Mitsuba's smooth `plastic`: a diffuse base under a smooth dielectric coat of index
    /// `eta`, light scattering inside the coat (its linear model).
    Plastic {
        /// Albedo of the base.
        diffuse: Rgb,
        /// Scale of the coat's mirror reflection.
        specular: Rgb,
        /// Index of refraction of the coat over the outside.
        eta: f32,
        /// An image the base's albedo is multiplied by.
        texture: Option<MaterialTexture>,
        /// Mitsuba's `nonlinear`: light scattered inside the coat shifts the base's colour
        /// (`albedo / (1 - albedo Fdr)` rather than `albedo / (1 - Fdr)`).
        nonlinear: bool,
    },
    /// Mitsuba's `thindielectric`: a thin pane of index `ior` that reflects `2F / (1 + F)`
    /// of the light (its inner reflections summed) and lets the rest through undeviated.
    ThinDielectric {
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the transmitted part.
        transmittance: Rgb,
        /// Index of refraction of the pane over the outside.
        ior: f32,
    },
    /// A perfect mirror.
    Mirror {
        /// Reflectance per channel.
        reflectance: Rgb,
    },
    /// A smooth dielectric: Fresnel-weighted reflection and refraction.
    Glass {
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Given by the files and unused (the course's glass is smooth).
        roughness: f32,
        /// Index of refraction inside (outside is 1).
        ior: f32,
    },
    /// Refraction only, without Fresnel reflection (the course's `RefractionBSDF`).
    Refraction {
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Given by the files and unused.
        roughness: f32,
        /// Index of refraction inside.
        ior: f32,
    },
    /// A rough conductor with a Beckmann distribution of slope `alpha` and a complex index of
    /// refraction `eta + i k` per channel.
    Microfacet {
        /// Beckmann roughness.
        alpha: f32,
        /// Real part of the index of refraction.
        eta: Rgb,
        /// Imaginary part (absorption).
        k: Rgb,
    },
    /// Mitsuba's `conductor` (smooth, `roughness` none) and `roughconductor` (microfacets
    /// of `roughness`): the conductor Fresnel term of `eta + i k`, scaled by `specular`.
    Conductor {
        /// Distribution and slopes; none for a smooth surface.
        roughness: Option<Roughness>,
        /// Real part of the index of refraction.
        eta: Rgb,
        /// Imaginary part (absorption).
        k: Rgb,
        /// Scale of the reflection.
        specular: Rgb,
    },
    /// Mitsuba's `roughdielectric`: a rough boundary of relative index `ior` (inside over
    /// outside) that reflects and refracts through microfacets of `roughness`.
    RoughDielectric {
        /// Distribution and slopes.
        roughness: Roughness,
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Index of refraction inside over outside.
        ior: f32,
    },
    /// Mitsuba's `roughplastic`: a diffuse base under a rough dielectric coat of index
    /// `eta` and isotropic `roughness`.
    RoughPlastic {
        /// Distribution and slope (`alpha_u` equals `alpha_v`).
        roughness: Roughness,
        /// Albedo of the base.
        diffuse: Rgb,
        /// Scale of the coat's reflection.
        specular: Rgb,
        /// Index of refraction of the coat over the outside.
        eta: f32,
        /// An image the base's albedo is multiplied by.
        texture: Option<MaterialTexture>,
        /// Mitsuba's `nonlinear`: light scattered inside the coat shifts the base's colour
        /// (`albedo / (1 - albedo Fdr)` rather than `albedo / (1 - Fdr)`).
        nonlinear: bool,
    },
    /// Mitsuba's `blendbsdf`: at each hit, `materials[1]` with probability `weight` and
    /// `materials[0]` otherwise (the mixture `(1 - w) f0 + w f1` in expectation).
    Blend {
        /// The second material's share, clamped to [0, 1].
        weight: ScalarTexture,
        /// The two materials, as indices into [`Scene::materials`].
        materials: [usize; 2],
    },
    /// Mitsuba's `mask`: at each hit, `material` with probability `opacity`, and otherwise
    /// no surface at all: the ray passes on unchanged (a bounce, as Mitsuba counts it).
    /// Shadow rays stop at it, as Mitsuba's do.
    Mask {
        /// The probability that the surface is there, clamped to [0, 1].
        opacity: ScalarTexture,
        /// The material where it is, as an index into [`Scene::materials`].
        material: usize,
    },
    /// Mitsuba's `principled` (Disney's BSDF as Mitsuba 3 writes it).
    Principled {
        /// The base colour.
        base_color: Rgb,
        /// An image the base colour is multiplied by.
        texture: Option<MaterialTexture>,
        /// Perceptual roughness.
        roughness: f32,
        /// Anisotropy of the specular lobes.
        anisotropic: f32,
        /// Metalness.
        metallic: f32,
        /// Share of specular transmission.
        spec_trans: f32,
        /// True if the material transmits at all: `spec_trans` given as a number other than
        /// 0 or by a texture (Mitsuba's `has_spec_trans`).
        transmits: bool,
        /// Tint of the dielectric specular lobe towards the base colour.
        spec_tint: f32,
        /// Sheen's weight.
        sheen: f32,
        /// Tint of the sheen towards the base colour.
        sheen_tint: f32,
        /// Blend of the diffuse lobe towards a flat subsurface look.
        flatness: f32,
        /// Clearcoat's weight.
        clearcoat: f32,
        /// Clearcoat's glossiness.
        clearcoat_gloss: f32,
        /// Index of refraction inside over outside.
        eta: f32,
        /// Sampling rates of the main specular lobes, the clearcoat and the diffuse lobe.
        rates: [f32; 3],
        /// True inside Mitsuba's `twosided` (without transmission): the back scatters as the
        /// front.
        two_sided: bool,
    },
    /// `material` with some of its parameters read from textures at each hit (Mitsuba's
    /// textured `specular_reflectance`, `specular_transmittance`, `alpha`s and principled
    /// weights).
    Textured {
        /// The material, as an index into [`Scene::materials`].
        material: usize,
        /// Each parameter a texture gives, and the texture (its luminance for a number).
        textures: Vec<(TexturedParameter, MaterialTexture)>,
    },
    /// Mitsuba's `normalmap`: `material` under a shading normal read from an image, `2 rgb
    /// - 1` in the shading frame (x along `dp/du`).
    NormalMap {
        /// The normals.
        normals: MaterialTexture,
        /// The material under them, as an index into [`Scene::materials`].
        material: usize,
        /// How the tilted normal is used.
        tilt: TiltOptions,
    },
    /// Mitsuba's `bumpmap`: `material` under a shading normal tilted by the gradient of a
    /// height image's luminance (bilinear; flat where the image is looked up nearest).
    BumpMap {
        /// The heights.
        height: MaterialTexture,
        /// The heights' scale.
        scale: f32,
        /// The material under them, as an index into [`Scene::materials`].
        material: usize,
        /// How the tilted normal is used.
        tilt: TiltOptions,
    },
    /// The Phong model of Whitted ray tracers (the Delft project's): diffuse `kd` plus a
    /// specular lobe `ks * max(r.v, 0)^shininess` per light.
    Phong {
        /// Diffuse colour.
        kd: Rgb,
        /// Specular colour, also the weight of the mirror reflection.
        ks: Rgb,
        /// Specular exponent.
        shininess: f32,
        /// An image whose texel replaces `kd` where texture mapping is on.
        kd_texture: Option<MaterialTexture>,
        /// Opacity: 1 is opaque, 0 is fully transparent (the MTL's `d`).
        transparency: f32,
    },
}

/// The shape of a microfacet distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetKind {
    /// Beckmann's Gaussian distribution of slopes.
    Beckmann,
    /// GGX (Trowbridge-Reitz), with longer tails.
    Ggx,
}

/// A microfacet surface's roughness: the distribution and its slopes along the shading
/// frame's first and second tangent (equal for an isotropic surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    /// The distribution.
    pub kind: MicrofacetKind,
    /// Roughness along the first tangent.
    pub alpha_u: f32,
    /// Roughness along the second tangent.
    pub alpha_v: f32,
}

/// An image a material reads, with the file it came from and how it is looked up.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTexture {
    /// The file, for messages.
    pub path: String,
    /// Linear texel values; row 0 is the file's top row.
    pub image: Arc<RgbImage>,
    /// Nearest texel or bilinear between texel centres.
    pub sampling: prism_image::PixelSampling,
    /// What lies beyond the image, across and down.
    pub wrap: prism_image::Wrap,
    /// The affine map from the surface's coordinates to the image's (row-major 2x3, in
    /// coordinates whose `v` runs down the image from its top row, as Mitsuba's `to_uv`).
    pub to_uv: [f32; 6],
}

impl MaterialTexture {
    /// `image` from `path`, bilinear, repeating, with no `to_uv`.
    #[must_use]
    pub fn new(path: String, image: Arc<RgbImage>) -> MaterialTexture {
        MaterialTexture {
            path,
            image,
            sampling: prism_image::PixelSampling::Bilinear,
            wrap: prism_image::Wrap::Repeat,
            to_uv: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        }
    }
}

/// A material parameter a texture may give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexturedParameter {
    /// The scale of the specular reflection.
    SpecularReflectance,
    /// The scale of the specular transmission.
    SpecularTransmittance,
    /// The microfacet roughness along the first tangent.
    AlphaU,
    /// The microfacet roughness along the second tangent.
    AlphaV,
    /// One of a principled material's weights (its texture's luminance).
    Principled(PrincipledWeight),
}

/// A principled material's weights that a texture may give, as Mitsuba's principled BSDF
/// takes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrincipledWeight {
    /// `roughness`.
    Roughness,
    /// `anisotropic`.
    Anisotropic,
    /// `metallic`.
    Metallic,
    /// `spec_trans`.
    SpecTrans,
    /// `spec_tint`.
    SpecTint,
    /// `sheen`.
    Sheen,
    /// `sheen_tint`.
    SheenTint,
    /// `flatness`.
    Flatness,
    /// `clearcoat`.
    Clearcoat,
    /// `clearcoat_gloss`.
    ClearcoatGloss,
}

impl PrincipledWeight {
    /// The weight named `name` in Mitsuba's principled BSDF.
    #[must_use]
    pub fn named(name: &str) -> Option<PrincipledWeight> {
        Some(match name {
            "roughness" => PrincipledWeight::Roughness,
            "anisotropic" => PrincipledWeight::Anisotropic,
            "metallic" => PrincipledWeight::Metallic,
            "spec_trans" => PrincipledWeight::SpecTrans,
            "spec_tint" => PrincipledWeight::SpecTint,
            "sheen" => PrincipledWeight::Sheen,
            "sheen_tint" => PrincipledWeight::SheenTint,
            "flatness" => PrincipledWeight::Flatness,
            "clearcoat" => PrincipledWeight::Clearcoat,
            "clearcoat_gloss" => PrincipledWeight::ClearcoatGloss,
            _ => return None,
        })
    }

    /// True for the weights that may exceed 1 (`sheen`, `clearcoat`).
    #[must_use]
    pub fn unbounded(self) -> bool {
        matches!(self, PrincipledWeight::Sheen | PrincipledWeight::Clearcoat)
    }
}

/// How a bump or normal map's tilted normal is used, as Mitsuba's options say.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TiltOptions {
    /// Mirror the tilted normal's tangential part where the outgoing direction would fall
    /// below it (Mitsuba's `flip_invalid_normals`).
    pub flip_invalid_normals: bool,
    /// Darken grazing light by Estevez et al.'s microfacet shadowing term, which hides the
    /// shading-normal terminator (Mitsuba's `use_shadowing_function`).
    pub shadowing: bool,
}

/// A number over a surface: a constant, or the luminance of a texture's texel (Mitsuba's
/// `eval_1`: 0.212671 r + 0.715160 g + 0.072169 b).
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarTexture {
    /// The same everywhere.
    Constant(f32),
    /// The texel's luminance.
    Image(MaterialTexture),
}

/// How shading normals are chosen for meshes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalsMode {
    /// Area-weighted vertex normals computed from the positions (the course's).
    #[default]
    Area,
    /// The file's per-corner normals (falls back to `Area` for meshes without them).
    File,
    /// Geometric face normals.
    Flat,
}

/// Where the camera comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CameraMode {
    /// The course's rule: looking at the scene's bounding-box centre from 1.5 times its
    /// diagonal away, along the file camera's direction, with +Y up.
    #[default]
    Course,
    /// The file camera's own position and orientation.
    File,
}

/// Options for turning a document into a scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneOptions {
    /// Shading normals.
    pub normals: NormalsMode,
    /// Camera placement.
    pub camera: CameraMode,
}

/// Shading normals of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum Shading {
    /// One unit normal per vertex, interpolated.
    Smooth(Vec<Vec3>),
    /// Three unit normals per triangle, interpolated.
    Corners(Vec<[Vec3; 3]>),
    /// The geometric normal.
    Flat,
}

/// A world-space triangle mesh with one material.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    /// The node it came from, for messages.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Shading normals.
    pub shading: Shading,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Texture coordinates, one per vertex (`None` for meshes without them).
    pub uvs: Option<Vec<Vec2>>,
}

/// A world-space sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSphere {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// True if its normals point inwards (Mitsuba's `flip_normals`): its front, for a
    /// one-sided material or an emitter, is the inside.
    pub inward: bool,
    /// The rotation from the world's axes to the sphere's own, where its `to_world` turns
    /// it: Mitsuba's texture coordinates and `dp/du` follow the sphere's axes.
    pub to_local: Option<prism_math::glam::Mat3>,
}

/// A light source.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// An isotropic point light; irradiance falls off with the squared distance.
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity.
        intensity: Rgb,
    },
    /// A spot light (Mitsuba's `spot`): a point light whose intensity is full within
    /// `beam_width` degrees of its axis and falls linearly in angle to 0 at `cutoff`.
    Spot {
        /// Position.
        position: Vec3,
        /// World directions to the light's frame, whose +z is the axis (the inverse of the
        /// light's `to_world` without its translation).
        to_local: prism_math::glam::Mat3,
        /// Radiant intensity on the axis.
        intensity: Rgb,
        /// Half-angle of the cone beyond which nothing is emitted, in degrees.
        cutoff: f32,
        /// Half-angle of the full-intensity beam, in degrees.
        beam_width: f32,
    },
    /// Light arriving from infinitely far along one direction.
    Directional {
        /// The direction the light travels (unit).
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Rgb,
    },
    /// A light along the segment `endpoints[0]` to `endpoints[1]` whose colour goes linearly
    /// from `colors[0]` to `colors[1]`: at `p0 + t (p1 - p0)` it is `(1 - t) c0 + t c1`
    /// (the Delft ray tracer's segment light; it lights like a point light at each sample).
    Segment {
        /// The two ends.
        endpoints: [Vec3; 2],
        /// The colours at the two ends.
        colors: [Rgb; 2],
    },
    /// A light over the parallelogram `corner + a edges[0] + b edges[1]`, `a, b` in
    /// `[0, 1]`, whose colour is bilinear in the corners' colours:
    /// `(1 - a)((1 - b) c0 + b c2) + a((1 - b) c1 + b c3)`, where `c0` is at `corner`, `c1`
    /// at `corner + edges[0]`, `c2` at `corner + edges[1]` and `c3` at the far corner.
    ///
    /// This is both the course's area light (a rectangle of uniform radiance emitting
    /// towards `facing`; the path tracer reads the colours as radiance, and the mean of the
    /// four if they differ) and the Delft ray tracer's parallelogram light (`facing` `None`:
    /// it lights both sides, like a point light at each sample of colour `c`).
    Parallelogram {
        /// The corner where `colors[0]` is.
        corner: Vec3,
        /// The two edges from that corner.
        edges: [Vec3; 2],
        /// The colours at `corner`, `corner + e0`, `corner + e1` and `corner + e0 + e1`.
        colors: [Rgb; 4],
        /// The unit normal of the one emitting side, or `None` for light on both sides.
        facing: Option<Vec3>,
    },
    /// Radiance from every direction above the horizon (world y > 0), none from below; not
    /// seen by camera rays.
    Hemisphere {
        /// Radiance.
        radiance: Rgb,
    },
    /// The same radiance from every direction, seen by every ray (a furnace).
    Environment {
        /// Radiance.
        radiance: Rgb,
    },
    /// Radiance from every direction, seen by every ray, read from a latitude-longitude
    /// map laid over the sphere as `mapping` says.
    EnvironmentMap {
        /// Linear radiance, one texel per direction cell.
        radiance: std::sync::Arc<prism_image::RgbImage>,
        /// How directions find their place in the map.
        mapping: EnvMapping,
    },
}

/// How a latitude-longitude map covers the sphere of directions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum EnvMapping {
    /// The course's: direction `d` reads the map at `u = phi / 2 pi`, `v = theta / pi`
    /// (v = 0 the top row), where `theta = acos(d.y)` and `phi = atan2(-d.z, d.x) + pi`;
    /// texel centres at `(i + 0.5) / n` both ways.
    #[default]
    Course,
    /// Mitsuba's `envmap`: the direction taken to the map's frame by `to_local`, then
    /// `u = atan2(x, -z) / 2 pi` (wrapped to [0, 1)) with texel centres at `(i + 0.5) / w`,
    /// and `v = acos(y) / pi` with the first and last rows at the poles.
    Mitsuba {
        /// World directions to the map's frame (the inverse of its `to_world`).
        to_local: prism_math::glam::Mat3,
    },
}

impl Light {
    /// True if the light gives off any light (some radiance, intensity or irradiance above
    /// 0); the course's `*_unlit` files hold a hemisphere light of radiance 0.
    #[must_use]
    pub fn gives_off_light(&self) -> bool {
        let shines = |c: &Rgb| c.r > 0.0 || c.g > 0.0 || c.b > 0.0;
        match self {
            Light::Point { intensity, .. } => shines(intensity),
            Light::Directional { irradiance, .. } => shines(irradiance),
            Light::Spot { intensity, .. } => shines(intensity),
            Light::Hemisphere { radiance } | Light::Environment { radiance } => shines(radiance),
            Light::EnvironmentMap { radiance, .. } => radiance.pixels().iter().any(shines),
            Light::Segment { colors, .. } => colors.iter().any(shines),
            Light::Parallelogram { colors, .. } => colors.iter().any(shines),
        }
    }
}

/// A perspective camera: a pinhole, or a thin lens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// A point looked at.
    pub target: Vec3,
    /// Up direction (need not be orthogonal to the view).
    pub up: Vec3,
    /// Horizontal field of view in degrees.
    pub hfov: f32,
    /// Vertical field of view in degrees.
    pub vfov: f32,
    /// Near clip distance.
    pub near: f32,
    /// Far clip distance.
    pub far: f32,
    /// A thin lens, for depth of field; `None` is a pinhole.
    pub lens: Option<ThinLens>,
    /// An orthographic view instead of a perspective one: parallel rays along the view
    /// from the plane `near` ahead of the eye, over half extents `(x, y / aspect)` in world
    /// units (Mitsuba's `orthographic`: the film's width spans `2 x`).
    pub orthographic: Option<(f32, f32)>,
    /// The image is a window of a larger film (Mitsuba's `crop_*`); the view is the whole
    /// film's.
    pub crop: Option<Crop>,
}

/// A window of a larger film: the image's pixel `(x, y)` is the film's pixel
/// `(x + offset.0, y + offset.1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// The window's top-left pixel in the film.
    pub offset: (u32, u32),
    /// The whole film's width and height.
    pub full: (u32, u32),
}

/// A thin lens: rays leave a disk of `radius` around the eye, in the plane facing the view,
/// and meet on the plane of focus `focal_distance` along the view axis from the eye (the
/// course's thin-lens camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Radius of the lens, in world units.
    pub radius: f32,
    /// Distance from the eye to the plane in focus, along the view axis.
    pub focal_distance: f32,
}

impl Camera {
    /// The fields of view widened along the too-narrow axis to the image's aspect ratio
    /// `width / height`, as the course does: `(hfov, vfov)` in degrees.
    #[must_use]
    pub fn fov_for(&self, width: u32, height: u32) -> (f32, f32) {
        let aspect = width as f32 / height as f32;
        let th = (self.hfov.to_radians() / 2.0).tan();
        let tv = (self.vfov.to_radians() / 2.0).tan();
        if th / tv > aspect {
            (self.hfov, (2.0 * (th / aspect).atan()).to_degrees())
        } else {
            ((2.0 * (tv * aspect).atan()).to_degrees(), self.vfov)
        }
    }
}

/// The Delft ray tracer's camera: an orbit around `look_at`. With `R = Rz(rz) Ry(ry)
/// Rx(rx)` from `rotation` in degrees (x applied first), the eye is `look_at + R (0, 0,
/// -distance)`, the view direction `R (0, 0, 1)`, up `R (0, 1, 0)` and screen-right
/// `R (-1, 0, 0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    /// Distance from the eye to `look_at`.
    pub distance: f32,
    /// The point orbited.
    pub look_at: Vec3,
    /// Rotation about x, y and z in degrees.
    pub rotation: Vec3,
}

impl Default for OrbitCamera {
    /// The template's: 50 degrees, distance 3, looking at the origin, rotation (20, 20, 0).
    fn default() -> OrbitCamera {
        OrbitCamera {
            fov_y: 50.0,
            distance: 3.0,
            look_at: Vec3::ZERO,
            rotation: Vec3::new(20.0, 20.0, 0.0),
        }
    }
}

impl OrbitCamera {
    /// The rotation `R = Rz Ry Rx` (x applied first), from camera to world directions.
    #[must_use]
    pub fn rotation(&self) -> Transform {
        let axis = |a: Vec3, deg: f32| Transform::rotate(a, deg).expect("a unit axis");
        axis(Vec3::Z, self.rotation.z)
            * axis(Vec3::Y, self.rotation.y)
            * axis(Vec3::X, self.rotation.x)
    }

    /// World from camera: the rotation, then a move to the eye.
    #[must_use]
    pub fn world_from_camera(&self) -> Transform {
        Transform::translate(self.eye()) * self.rotation()
    }

    /// The eye position.
    #[must_use]
    pub fn eye(&self) -> Vec3 {
        self.look_at + self.rotation().vector(Vec3::new(0.0, 0.0, -self.distance))
    }

    /// The same view as a [`Camera`] for an image of aspect ratio `width / height`.
    #[must_use]
    pub fn to_camera(&self, aspect: f32) -> Camera {
        let r = self.rotation();
        let eye = self.eye();
        let hh = (self.fov_y.to_radians() / 2.0).tan();
        Camera {
            eye,
            target: eye + r.vector(Vec3::Z),
            up: r.vector(Vec3::Y),
            hfov: (2.0 * (hh * aspect).atan()).to_degrees(),
            vfov: self.fov_y,
            near: 1e-3,
            far: 1e4,
            lens: None,
            orthographic: None,
            crop: None,
        }
    }
}

/// A scene ready to render.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Triangle meshes.
    pub meshes: Vec<TriangleMesh>,
    /// Spheres.
    pub spheres: Vec<SceneSphere>,
    /// Materials, indexed by meshes and spheres.
    pub materials: Vec<Material>,
    /// The materials' names, where the file gives them (may be shorter than `materials`).
    pub material_names: Vec<String>,
    /// Per material, true if it scatters from its front only (where the winding's normal
    /// points) and is black from behind, as Mitsuba's opaque BSDFs outside a `twosided`
    /// are; may be shorter than `materials`, the rest scattering on both sides.
    pub one_sided: Vec<bool>,
    /// Lights.
    pub lights: Vec<Light>,
    /// The camera.
    pub camera: Camera,
    /// Things read past without being used, one message each.
    pub warnings: Vec<prism_math::Warning>,
}

impl Scene {
    /// A scene with nothing in it but the camera.
    #[must_use]
    pub fn new(camera: Camera) -> Scene {
        Scene {
            meshes: Vec::new(),
            spheres: Vec::new(),
            materials: Vec::new(),
            material_names: Vec::new(),
            one_sided: Vec::new(),
            lights: Vec::new(),
            camera,
            warnings: Vec::new(),
        }
    }

    /// A 64-bit fingerprint of everything that changes pixels: geometry, materials (with
    /// their texels), lights and camera, but not the warnings. Equal scenes give equal
    /// fingerprints on every machine; it is the FNV-1a hash of the fields' `Debug` forms,
    /// which print every float exactly.
    #[must_use]
    pub fn fingerprint(&self) -> u64 {
        struct Fnv(u64);
        impl std::fmt::Write for Fnv {
            fn write_str(&mut self, s: &str) -> std::fmt::Result {
                for &b in s.as_bytes() {
                    self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
                }
                Ok(())
            }
        }
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        // Writing to the hasher cannot fail.
        let _ = std::fmt::Write::write_fmt(
            &mut h,
            format_args!(
                "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
                self.meshes,
                self.spheres,
                self.materials,
                self.material_names,
                self.lights,
                self.camera
            ),
        );
        if !self.one_sided.is_empty() {
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("|{:?}", self.one_sided));
        }
        h.0
    }

    /// The name of material `i`: the file's, else `material i`.
    #[must_use]
    pub fn material_name(&self, i: usize) -> String {
        match self.material_names.get(i) {
            Some(n) => n.clone(),
            None => format!("material {i}"),
        }
    }

    /// True if some light or emitting material gives off light (of non-zero power).
    #[must_use]
    pub fn is_lit(&self) -> bool {
        self.has_emitting_material() || self.lights.iter().any(Light::gives_off_light)
    }

    /// True if some material emits light of non-zero power.
    fn has_emitting_material(&self) -> bool {
        self.materials.iter().any(|m| match m {
            Material::Emission { radiance } | Material::AreaEmitter { radiance, .. } => {
                radiance.r > 0.0 || radiance.g > 0.0 || radiance.b > 0.0
            }
            _ => false,
        })
    }

    /// True if the scene is lit only as a modelling tool's export lights a mesh, as every
    /// file of the course's MeshEdit is: no emitting material, and every light that gives
    /// off light is a point or directional light of colour exactly (1, 1, 1) (Blender's and
    /// Maya's default lamp). Such a file is a mesh to edit, not a scene to path-trace.
    #[must_use]
    pub fn lit_only_by_a_default_lamp(&self) -> bool {
        !self.has_emitting_material()
            && self
                .lights
                .iter()
                .filter(|l| l.gives_off_light())
                .all(|l| match l {
                    Light::Point { intensity: c, .. }
                    | Light::Directional { irradiance: c, .. } => *c == Rgb::WHITE,
                    _ => false,
                })
    }

    /// The bounding box of every mesh vertex and sphere: `(min, max)`, or `None` if the
    /// scene has no geometry.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for m in &self.meshes {
            for &p in &m.positions {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }
}

#[cfg(test)]
mod tests {
    /// Property: the fingerprint is the same for equal scenes, whatever their warnings, and
    /// changes when one coordinate moves by one ulp or a light's colour changes.
    #[test]
    fn fingerprint_tells_scenes_apart() {
        let a = crate::cornell_box();
        let mut b = a.clone();
        b.warnings
            .push(prism_math::Warning::new("read past something"));
        assert_eq!(a.fingerprint(), b.fingerprint());
        let mut c = a.clone();
        let p = &mut c.meshes[0].positions[0];
        p.x = f32::from_bits(p.x.to_bits() + 1);
        assert_ne!(a.fingerprint(), c.fingerprint());
        let mut d = a.clone();
        d.camera.eye.z += 1.0;
        assert_ne!(a.fingerprint(), d.fingerprint());
    }
}
