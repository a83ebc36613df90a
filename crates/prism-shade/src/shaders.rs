//! [`Shader`], the course's shaders as Rust (normal, wireframe, diffuse, Blinn-Phong,
//! texture, bump, displacement, mirror), their [`Uniforms`], and the per-fragment formulas of
//! `FORMATS.md` §4.

use prism_image::{CubeMap, PixelSampling, Texture, Wrap};
use prism_math::{Rgb, Vec2, Vec3};

/// A shader with the images it reads.
#[derive(Clone, Debug)]
pub enum Shader {
    /// `(n + 1) / 2` of the interpolated (not renormalised) normal.
    Normal,
    /// The flat colour `u_color`.
    Wireframe,
    /// `I / r^2 max(n.l, 0)` (kd = 1).
    Diffuse,
    /// Blinn-Phong: `0.1 + 0.8 I/r^2 max(n.l, 0) + 0.5 I/r^2 max(n.h, 0)^32`.
    Phong,
    /// The texture's colour at the uv.
    Texture(Texture),
    /// Blinn-Phong with the normal bent by a height map's differences.
    Bump(Texture),
    /// Vertices moved along their normals by the height map, then bump shading.
    Displacement(Texture),
    /// The cube map along the mirror direction of the view.
    Mirror(CubeMap),
}

impl Shader {
    /// The name used on the command line.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Shader::Normal => "normal",
            Shader::Wireframe => "wireframe",
            Shader::Diffuse => "diffuse",
            Shader::Phong => "phong",
            Shader::Texture(_) => "texture",
            Shader::Bump(_) => "bump",
            Shader::Displacement(_) => "displacement",
            Shader::Mirror(_) => "mirror",
        }
    }
}

/// A 2D texture as the course app sets one up: RGB in `[0, 1]` (bytes / 255), bilinear on
/// level 0, wrap REPEAT, `v = 0` at the file's top row.
#[must_use]
pub fn course_texture(image: prism_image::RgbImage) -> Texture {
    Texture::new(image).with_wrap(Wrap::Repeat, Wrap::Repeat)
}

/// The values the app sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniforms {
    /// Light position (0.5, 2, 2).
    pub light_pos: Vec3,
    /// Light intensity (3, 3, 3).
    pub light_intensity: Rgb,
    /// `u_color`, white.
    pub color: Rgb,
    /// Normal scaling, 2.
    pub normal_scaling: f32,
    /// Height scaling, 0.1.
    pub height_scaling: f32,
    /// The camera position (set from the view).
    pub cam_pos: Vec3,
}

impl Default for Uniforms {
    fn default() -> Uniforms {
        Uniforms {
            light_pos: Vec3::new(0.5, 2.0, 2.0),
            light_intensity: Rgb::splat(3.0),
            color: Rgb::WHITE,
            normal_scaling: 2.0,
            height_scaling: 0.1,
            cam_pos: Vec3::ZERO,
        }
    }
}

/// The interpolated inputs of one fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Varyings {
    /// World position.
    pub position: Vec3,
    /// World normal (unit at the vertices, not renormalised).
    pub normal: Vec3,
    /// World tangent.
    pub tangent: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
}

impl Varyings {
    /// `a w0 + b w1 + c w2`.
    #[must_use]
    pub fn blend(a: &Varyings, b: &Varyings, c: &Varyings, w: [f32; 3]) -> Varyings {
        Varyings {
            position: a.position * w[0] + b.position * w[1] + c.position * w[2],
            normal: a.normal * w[0] + b.normal * w[1] + c.normal * w[2],
            tangent: a.tangent * w[0] + b.tangent * w[1] + c.tangent * w[2],
            uv: a.uv * w[0] + b.uv * w[1] + c.uv * w[2],
        }
    }

    /// `a + t (b - a)`.
    #[must_use]
    pub fn lerp(a: &Varyings, b: &Varyings, t: f32) -> Varyings {
        Varyings::blend(a, b, a, [1.0 - t, t, 0.0])
    }
}

/// The red channel of a height map at `uv`.
#[must_use]
pub fn height(map: &Texture, uv: Vec2) -> f32 {
    map.sample_level(uv, 0, PixelSampling::Bilinear).r
}

/// Blinn-Phong with ka 0.1 (ambient light 1), kd 0.8, ks 0.5, p 32:
/// `ka + kd I/r^2 max(n.l, 0) + ks I/r^2 max(n.h, 0)^p`, `h = normalize(l + v)`.
#[must_use]
pub fn blinn_phong(u: &Uniforms, p: Vec3, n: Vec3) -> Rgb {
    let to_light = u.light_pos - p;
    let r2 = to_light.dot(to_light);
    let l = to_light.normalize();
    let v = (u.cam_pos - p).normalize();
    let h = (l + v).normalize();
    let e = u.light_intensity * (1.0 / r2);
    // p = 32 by five squarings.
    let spec = n.dot(h).max(0.0).powi(32);
    Rgb::splat(0.1) + e * (0.8 * n.dot(l).max(0.0)) + e * (0.5 * spec)
}

/// The normal bent by the height map: `normalize(TBN (-dU, -dV, 1))`, `TBN = [t, n x t,
/// n]` with `n` and `t` normalised, `dU = (h(u + 1/w, v) - h(u, v)) k_h k_n`, `dV`
/// likewise along v.
#[must_use]
pub fn bumped_normal(u: &Uniforms, map: &Texture, f: &Varyings) -> Vec3 {
    let (w, h) = map.size();
    let h0 = height(map, f.uv);
    let k = u.height_scaling * u.normal_scaling;
    let du = (height(map, f.uv + Vec2::new(1.0 / w as f32, 0.0)) - h0) * k;
    let dv = (height(map, f.uv + Vec2::new(0.0, 1.0 / h as f32)) - h0) * k;
    let n = f.normal.normalize();
    let t = f.tangent.normalize();
    let b = n.cross(t);
    (t * -du + b * -dv + n).normalize()
}

/// The fragment's colour (before clamping).
#[must_use]
pub fn fragment(shader: &Shader, u: &Uniforms, f: &Varyings) -> Rgb {
    match shader {
        Shader::Normal => {
            let c = (f.normal + Vec3::ONE) * 0.5;
            Rgb::new(c.x, c.y, c.z)
        }
        Shader::Wireframe => u.color,
        Shader::Diffuse => {
            let n = f.normal.normalize();
            let to_light = u.light_pos - f.position;
            let r2 = to_light.dot(to_light);
            let l = to_light.normalize();
            u.light_intensity * (n.dot(l).max(0.0) / r2)
        }
        Shader::Phong => blinn_phong(u, f.position, f.normal.normalize()),
        Shader::Texture(t) => t.sample_level(f.uv, 0, PixelSampling::Bilinear),
        Shader::Bump(map) | Shader::Displacement(map) => {
            blinn_phong(u, f.position, bumped_normal(u, map, f))
        }
        Shader::Mirror(cube) => {
            let wo = u.cam_pos - f.position;
            let n = f.normal.normalize();
            let d = -wo;
            let wi = d - 2.0 * n.dot(d) * n;
            cube.sample(wi)
        }
    }
}
