//! [`Shader`], the course's shaders as Rust (normal, wireframe, diffuse, Blinn-Phong,
//! texture, bump, displacement, mirror), their [`Uniforms`], and the per-fragment formulas of
//! `FORMATS.md` §4.

use prism_image::{CubeMap, PixelSampling, Texture, Wrap};
use prism_math::{Rgb, Vec2, Vec3};

use prism_math::lanes::{F16, V16};

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

/// Which varyings a shader reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// The world position.
    pub position: bool,
    /// The tangent.
    pub tangent: bool,
    /// The texture coordinates.
    pub uv: bool,
}

impl Shader {
    /// The varyings the shader reads (the normal is always interpolated).
    #[must_use]
    pub fn needs(&self) -> Needs {
        match self {
            Shader::Normal | Shader::Wireframe => Needs {
                position: false,
                tangent: false,
                uv: false,
            },
            Shader::Diffuse | Shader::Phong | Shader::Mirror(_) => Needs {
                position: true,
                tangent: false,
                uv: false,
            },
            Shader::Texture(_) => Needs {
                position: false,
                tangent: false,
                uv: true,
            },
            Shader::Bump(_) | Shader::Displacement(_) => Needs {
                position: true,
                tangent: true,
                uv: true,
            },
        }
    }

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

impl Uniforms {
    /// The course's uniforms with the light for a mesh bounded by `lo`..`hi`: `light` and
    /// `intensity` where given; else the course's light (0.5, 2, 2) for a mesh within a unit
    /// of the origin (the course's meshes are), or that point scaled by the mesh's half
    /// diagonal `r` and moved with the centre of its bounds, with the course's intensity
    /// scaled by `r^2` (unless the light's position is given), so that any mesh is lit as
    /// the course's are (the same directions, the same `I / d^2`).
    #[must_use]
    pub fn lit_for(lo: Vec3, hi: Vec3, light: Option<Vec3>, intensity: Option<Rgb>) -> Uniforms {
        let course = Uniforms::default();
        let (centre, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
        let (placed, scale) = if lo.abs().max_element() <= 1.0 && hi.abs().max_element() <= 1.0 {
            (course.light_pos, 1.0)
        } else {
            (centre + course.light_pos * radius, radius * radius)
        };
        Uniforms {
            light_pos: light.unwrap_or(placed),
            light_intensity: intensity.unwrap_or(if light.is_some() {
                course.light_intensity
            } else {
                course.light_intensity * scale
            }),
            ..course
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

    /// [`Varyings::blend`] of the varyings in `needs` and the normal; the rest are zero.
    #[must_use]
    pub fn blend_only(
        a: &Varyings,
        b: &Varyings,
        c: &Varyings,
        w: [f32; 3],
        needs: Needs,
    ) -> Varyings {
        let zero = Varyings {
            position: Vec3::ZERO,
            normal: a.normal * w[0] + b.normal * w[1] + c.normal * w[2],
            tangent: Vec3::ZERO,
            uv: Vec2::ZERO,
        };
        Varyings {
            position: if needs.position {
                a.position * w[0] + b.position * w[1] + c.position * w[2]
            } else {
                zero.position
            },
            tangent: if needs.tangent {
                a.tangent * w[0] + b.tangent * w[1] + c.tangent * w[2]
            } else {
                zero.tangent
            },
            uv: if needs.uv {
                a.uv * w[0] + b.uv * w[1] + c.uv * w[2]
            } else {
                zero.uv
            },
            ..zero
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

/// [`fragment`] for sixteen fragments at once, from their world positions and interpolated
/// normals, for the shaders that read nothing else (normal, wireframe, diffuse, Blinn-Phong):
/// each lane is bit for bit the scalar formula. `None` for the other shaders.
#[inline(always)]
pub(crate) fn fragment_lanes(
    shader: &Shader,
    u: &Uniforms,
    position: V16,
    normal: V16,
) -> Option<[F16; 3]> {
    let one = F16::splat(1.0);
    match shader {
        Shader::Normal => Some([
            (normal.x + 1.0) * 0.5,
            (normal.y + 1.0) * 0.5,
            (normal.z + 1.0) * 0.5,
        ]),
        Shader::Wireframe => Some([
            F16::splat(u.color.r),
            F16::splat(u.color.g),
            F16::splat(u.color.b),
        ]),
        Shader::Diffuse => {
            let n = normal.normalize();
            let to_light = V16::splat(u.light_pos) - position;
            let r2 = to_light.dot(to_light);
            let l = to_light.normalize();
            let s = n.dot(l).max0() / r2;
            let i = u.light_intensity;
            Some([
                F16::splat(i.r) * s,
                F16::splat(i.g) * s,
                F16::splat(i.b) * s,
            ])
        }
        Shader::Phong => {
            let n = normal.normalize();
            let to_light = V16::splat(u.light_pos) - position;
            let r2 = to_light.dot(to_light);
            let l = to_light.normalize();
            let v = (V16::splat(u.cam_pos) - position).normalize();
            let h = (l + v).normalize();
            let inv_r2 = one / r2;
            let s = n.dot(h).max0();
            let s2 = s * s;
            let s4 = s2 * s2;
            let s8 = s4 * s4;
            let s16 = s8 * s8;
            let spec = (s16 * s16) * 0.5;
            let diffuse = F16::splat(0.8) * n.dot(l).max0();
            let i = u.light_intensity;
            // A function, not a closure: a closure would be compiled apart, without the
            // caller's vector instruction set.
            #[inline(always)]
            fn channel(i: f32, inv_r2: F16, diffuse: F16, spec: F16) -> F16 {
                let e = F16::splat(i) * inv_r2;
                (F16::splat(0.1) + e * diffuse) + e * spec
            }
            Some([
                channel(i.r, inv_r2, diffuse, spec),
                channel(i.g, inv_r2, diffuse, spec),
                channel(i.b, inv_r2, diffuse, spec),
            ])
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: every shader gives the same colour from the varyings it says it needs as
    /// from all of them.
    #[test]
    fn needs_cover_what_fragments_read() {
        let tex = course_texture(prism_image::Image::from_fn(4, 4, |x, y| {
            Rgb::new(x as f32 / 4.0, y as f32 / 4.0, 0.5)
        }));
        let faces: [prism_image::RgbImage; 6] = std::array::from_fn(|i| {
            prism_image::Image::from_fn(2, 2, |x, y| Rgb::new(i as f32 / 6.0, x as f32, y as f32))
        });
        let cube = CubeMap::new(faces).unwrap();
        let shaders = [
            Shader::Normal,
            Shader::Wireframe,
            Shader::Diffuse,
            Shader::Phong,
            Shader::Texture(tex.clone()),
            Shader::Bump(tex.clone()),
            Shader::Displacement(tex),
            Shader::Mirror(cube),
        ];
        let v = |k: f32| Varyings {
            position: Vec3::new(0.1 * k, 0.3, -0.2 * k),
            normal: Vec3::new(0.2, 1.0, 0.3 * k).normalize(),
            tangent: Vec3::new(1.0, 0.1 * k, 0.0).normalize(),
            uv: Vec2::new(0.3 * k, 0.7),
        };
        let (a, b, c) = (v(1.0), v(2.0), v(3.0));
        let w = [0.2, 0.3, 0.5];
        let u = Uniforms {
            cam_pos: Vec3::new(0.0, 1.0, 3.0),
            ..Uniforms::default()
        };
        for s in &shaders {
            let full = fragment(s, &u, &Varyings::blend(&a, &b, &c, w));
            let only = fragment(s, &u, &Varyings::blend_only(&a, &b, &c, w, s.needs()));
            assert_eq!(full, only, "{}", s.name());
        }
    }

    /// Property: the lane forms of normal, wireframe, diffuse and Blinn-Phong equal the
    /// scalar fragment shader bit for bit, lane by lane.
    #[test]
    fn lane_shaders_equal_scalar_fragments() {
        use prism_math::lanes::LANES;
        let u = Uniforms {
            cam_pos: Vec3::new(0.3, 1.1, 2.9),
            ..Uniforms::default()
        };
        for round in 0..50 {
            let f = |l: usize, k: f32| ((l * 7 + round * 13) as f32 * k).sin();
            let p: Vec<Vec3> = (0..LANES)
                .map(|l| Vec3::new(f(l, 0.7), f(l, 1.3) * 0.5, f(l, 2.1)))
                .collect();
            let n: Vec<Vec3> = (0..LANES)
                .map(|l| Vec3::new(f(l, 0.3), 1.0 + f(l, 0.9), f(l, 1.7)) * 0.9)
                .collect();
            let lanes = |v: &[Vec3]| V16 {
                x: F16(std::array::from_fn(|l| v[l].x)),
                y: F16(std::array::from_fn(|l| v[l].y)),
                z: F16(std::array::from_fn(|l| v[l].z)),
            };
            for shader in [
                Shader::Normal,
                Shader::Wireframe,
                Shader::Diffuse,
                Shader::Phong,
            ] {
                let [r, g, b] = fragment_lanes(&shader, &u, lanes(&p), lanes(&n)).unwrap();
                for l in 0..LANES {
                    let v = Varyings {
                        position: p[l],
                        normal: n[l],
                        tangent: Vec3::X,
                        uv: Vec2::ZERO,
                    };
                    let c = fragment(&shader, &u, &v);
                    assert_eq!(
                        [r.0[l], g.0[l], b.0[l]],
                        [c.r, c.g, c.b],
                        "{} lane {l}",
                        shader.name()
                    );
                }
            }
        }
    }
}
