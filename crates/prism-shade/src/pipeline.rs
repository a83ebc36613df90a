//! The software pipeline: the vertex stage through prism-math's `Transform` (OpenGL
//! `lookAt` and `perspective`), clipping against the near and far planes in homogeneous
//! coordinates, the viewport, rasterization at sample positions with a depth test (LESS),
//! perspective-correct varyings, the fragment shader, supersampling resolved by a box
//! filter, and an optional wireframe drawn on top with the depth test; bands of rows on
//! rayon, the same bytes whatever the thread count.

use prism_image::{Image, RgbImage};
use prism_math::{Rgb, Transform, Vec3};
use rayon::prelude::*;

use crate::error::ShadeError;
use crate::mesh::ShadeMesh;
use crate::shaders::{fragment, height, Shader, Uniforms, Varyings};

/// Near and far planes.
pub const NEAR: f32 = 0.01;
/// Far plane.
pub const FAR: f32 = 1000.0;
/// Rows per band of work.
const BAND: u32 = 16;

/// The camera and image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub eye: Vec3,
    /// The point looked at.
    pub target: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl View {
    /// `clip_from_world`: OpenGL `perspective(fov_y, W/H, 0.01, 1000) lookAt(eye, target,
    /// up)`.
    ///
    /// # Errors
    /// [`ShadeError::Camera`] when the eye is the target, up is along the view, or the field
    /// of view is outside (0, 180).
    pub fn clip_from_world(&self) -> Result<Transform, ShadeError> {
        let camera_from_world =
            Transform::look_at(self.eye, self.target, self.up).ok_or_else(|| {
                ShadeError::Camera("the eye is the target, or up lies along the view".into())
            })?;
        let aspect = self.width as f32 / self.height as f32;
        let clip_from_camera =
            Transform::perspective(self.fov_y, aspect, NEAR, FAR).ok_or_else(|| {
                ShadeError::Camera(format!(
                    "expected a field of view strictly between 0 and 180 degrees, found {}",
                    self.fov_y
                ))
            })?;
        Ok(clip_from_camera * camera_from_world)
    }
}

/// Render settings.
#[derive(Clone, Debug)]
pub struct ShadeOptions {
    /// Samples per pixel: a square number (1, 4, 9, 16, ...), on a regular grid.
    pub samples: u32,
    /// The colour where nothing is drawn.
    pub background: Rgb,
    /// Draw every triangle's edges on top, in this colour, depth-tested.
    pub wireframe: Option<Rgb>,
    /// Half the width of those edges, in pixels.
    pub wire_width: f32,
}

impl Default for ShadeOptions {
    fn default() -> ShadeOptions {
        ShadeOptions {
            samples: 1,
            background: Rgb::BLACK,
            wireframe: None,
            wire_width: 0.75,
        }
    }
}

/// A vertex after the vertex stage.
#[derive(Clone, Copy, Debug)]
struct ClipVertex {
    clip: [f32; 4],
    v: Varyings,
}

/// A vertex in window coordinates (x right, y down, z in [0, 1]) with `1/w`.
#[derive(Clone, Copy, Debug)]
struct ScreenVertex {
    x: f32,
    y: f32,
    z: f32,
    inv_w: f32,
    v: Varyings,
}

/// Clips a polygon against `plane(c) >= 0`, interpolating in clip space.
fn clip_polygon(poly: &[ClipVertex], plane: impl Fn(&[f32; 4]) -> f32) -> Vec<ClipVertex> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let a = &poly[i];
        let b = &poly[(i + 1) % poly.len()];
        let (da, db) = (plane(&a.clip), plane(&b.clip));
        if da >= 0.0 {
            out.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            let clip = std::array::from_fn(|k| a.clip[k] + t * (b.clip[k] - a.clip[k]));
            out.push(ClipVertex {
                clip,
                v: Varyings::lerp(&a.v, &b.v, t),
            });
        }
    }
    out
}

/// The screen-space triangles of the mesh: vertex stage, clipping, viewport.
fn screen_triangles(
    mesh: &ShadeMesh,
    view: &View,
    shader: &Shader,
    u: &Uniforms,
) -> Result<Vec<[ScreenVertex; 3]>, ShadeError> {
    let clip_from_world = view.clip_from_world()?.matrix();
    let displace = match shader {
        Shader::Displacement(map) => Some(map),
        _ => None,
    };
    let verts: Vec<ClipVertex> = (0..mesh.positions.len())
        .map(|i| {
            let n = mesh.normals[i];
            let mut p = mesh.positions[i];
            if let Some(map) = displace {
                p += n * (height(map, mesh.uvs[i]) * u.height_scaling);
            }
            let c = clip_from_world * p.extend(1.0);
            ClipVertex {
                clip: c.to_array(),
                v: Varyings {
                    position: p,
                    normal: n.normalize_or_zero(),
                    tangent: mesh
                        .tangents
                        .get(i)
                        .copied()
                        .unwrap_or(Vec3::X)
                        .normalize_or_zero(),
                    uv: mesh.uvs[i],
                },
            }
        })
        .collect();
    let (w, h) = (view.width as f32, view.height as f32);
    let mut out = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let tri = t.map(|i| verts[i as usize]);
        let inside = |c: &[f32; 4]| c[2] >= -c[3] && c[2] <= c[3];
        let poly = if tri.iter().all(|v| inside(&v.clip)) {
            tri.to_vec()
        } else {
            let near = clip_polygon(&tri, |c| c[2] + c[3]);
            clip_polygon(&near, |c| c[3] - c[2])
        };
        if poly.len() < 3 {
            continue;
        }
        let screen: Vec<ScreenVertex> = poly
            .iter()
            .map(|c| {
                let inv_w = 1.0 / c.clip[3];
                ScreenVertex {
                    x: (c.clip[0] * inv_w + 1.0) * 0.5 * w,
                    y: (1.0 - c.clip[1] * inv_w) * 0.5 * h,
                    z: (c.clip[2] * inv_w + 1.0) * 0.5,
                    inv_w,
                    v: c.v,
                }
            })
            .collect();
        for i in 1..screen.len() - 1 {
            out.push([screen[0], screen[i], screen[i + 1]]);
        }
    }
    Ok(out)
}

/// Twice the signed area of `(a, b, p)`.
#[inline]
fn edge(ax: f32, ay: f32, bx: f32, by: f32, px: f32, py: f32) -> f32 {
    (bx - ax) * (py - ay) - (by - ay) * (px - ax)
}

/// True if a sample exactly on edge `a -> b` belongs to the triangle (a top-left rule, so
/// that a shared edge is drawn once).
#[inline]
fn owns_edge(ax: f32, ay: f32, bx: f32, by: f32, area_sign: f32) -> bool {
    let (dx, dy) = ((bx - ax) * area_sign, (by - ay) * area_sign);
    dy < 0.0 || (dy == 0.0 && dx > 0.0)
}

/// Renders `mesh` seen by `view` with `shader`: linear colours, one per pixel (the
/// samples' mean), before clamping.
///
/// # Errors
/// [`ShadeError::Camera`] for an impossible camera; [`ShadeError::Samples`] for a sample
/// count that is not a square.
pub fn shade(
    mesh: &ShadeMesh,
    view: &View,
    shader: &Shader,
    uniforms: &Uniforms,
    opts: &ShadeOptions,
) -> Result<RgbImage, ShadeError> {
    render(mesh, view, shader, uniforms, opts, |c| c)
}

/// [`shade`] straight to the bytes [`to_bytes`] would make, without the floating-point
/// picture in between.
///
/// # Errors
/// As [`shade`].
pub fn shade_rgb8(
    mesh: &ShadeMesh,
    view: &View,
    shader: &Shader,
    uniforms: &Uniforms,
    opts: &ShadeOptions,
) -> Result<prism_image::Rgb8Image, ShadeError> {
    render(mesh, view, shader, uniforms, opts, |c| {
        [byte(c.r), byte(c.g), byte(c.b)]
    })
}

/// The pipeline, each pixel's clamped mean colour stored by `store`.
fn render<T: Copy + Default + Send>(
    mesh: &ShadeMesh,
    view: &View,
    shader: &Shader,
    uniforms: &Uniforms,
    opts: &ShadeOptions,
    store: impl Fn(Rgb) -> T + Sync,
) -> Result<Image<T>, ShadeError> {
    let k = (opts.samples as f64).sqrt().round() as u32;
    if k == 0 || k > 16 || k * k != opts.samples {
        return Err(ShadeError::Samples(opts.samples));
    }
    let mut u = *uniforms;
    u.cam_pos = view.eye;
    let needs = shader.needs();
    let tris = screen_triangles(mesh, view, shader, &u)?;
    let (w, h) = (view.width, view.height);
    // Triangles by band of rows, in mesh order.
    let bands = h.div_ceil(BAND) as usize;
    let mut by_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, t) in tris.iter().enumerate() {
        let (y0, y1) = t
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
                (a.min(v.y), b.max(v.y))
            });
        if !(y1 >= 0.0 && y0 <= h as f32) {
            continue;
        }
        let first = (y0.max(0.0) as u32 / BAND) as usize;
        let last = ((y1.min(h as f32 - 1.0).max(0.0) as u32) / BAND) as usize;
        for band in by_band.iter_mut().take(last.min(bands - 1) + 1).skip(first) {
            band.push(i as u32);
        }
    }
    let mut pixels = vec![T::default(); w as usize * h as usize];
    let rows_per_band = (BAND * w) as usize;
    pixels
        .par_chunks_mut(rows_per_band)
        .enumerate()
        .for_each(|(band, out)| {
            // Each worker keeps its band buffers from band to band and call to call (rayon
            // would make new ones for every piece of work it splits off).
            BAND_BUFFERS.with_borrow_mut(|buf| {
                let y_start = band as u32 * BAND;
                let rows = (out.len() / w as usize) as u32;
                let n = (k * k) as usize;
                // Every sample is cleared: the buffers are the worker's, reused band to band.
                buf.clear(out.len() * n);
                let target = Target {
                    k,
                    w,
                    y_start,
                    rows,
                };
                // Visibility first (depth LESS, the first of equals kept), then one fragment per
                // visible sample: the same colours as shading each fragment as it passes.
                for &i in &by_band[band] {
                    raster_triangle(&tris[i as usize], i, &target, buf, None);
                }
                for s in 0..buf.prim.len() {
                    let p = buf.prim[s];
                    if p == NONE {
                        buf.color[s] = opts.background;
                    } else {
                        let [a, b, c] = &tris[p as usize];
                        let l = buf.bary[s];
                        let pw = [l[0] * a.inv_w, l[1] * b.inv_w, l[2] * c.inv_w];
                        let inv = 1.0 / (pw[0] + pw[1] + pw[2]);
                        let v = Varyings::blend_only(
                            &a.v,
                            &b.v,
                            &c.v,
                            [pw[0] * inv, pw[1] * inv, pw[2] * inv],
                            needs,
                        );
                        buf.color[s] = fragment(shader, &u, &v);
                    }
                }
                if let Some(c) = opts.wireframe {
                    for &i in &by_band[band] {
                        raster_triangle(
                            &tris[i as usize],
                            i,
                            &target,
                            buf,
                            Some((c, opts.wire_width)),
                        );
                    }
                }
                for (p, samples) in out.iter_mut().zip(buf.color.chunks(n)) {
                    // Each sample is stored clamped, as in an 8-bit colour buffer.
                    let clamp = |c: Rgb| {
                        Rgb::new(
                            c.r.clamp(0.0, 1.0),
                            c.g.clamp(0.0, 1.0),
                            c.b.clamp(0.0, 1.0),
                        )
                    };
                    *p = if n == 1 {
                        store(clamp(samples[0]))
                    } else {
                        let sum = samples.iter().fold(Rgb::BLACK, |a, &c| a + clamp(c));
                        store(sum * (1.0 / n as f32))
                    };
                }
            });
        });
    Ok(Image::from_vec(w, h, pixels))
}

thread_local! {
    static BAND_BUFFERS: std::cell::RefCell<Band> = std::cell::RefCell::new(Band::default());
}

/// No triangle covers the sample.
const NONE: u32 = u32::MAX;

/// A worker's sample buffers for one band: depth, the triangle seen with its screen-space
/// barycentric weights, and the colour.
#[derive(Default)]
struct Band {
    depth: Vec<f32>,
    prim: Vec<u32>,
    bary: Vec<[f32; 3]>,
    color: Vec<Rgb>,
}

impl Band {
    /// Clears depth (to 1, the far plane: LESS passes below it) and the visible triangle;
    /// weights and colours are written before they are read.
    fn clear(&mut self, len: usize) {
        self.depth.clear();
        self.depth.resize(len, 1.0);
        self.prim.clear();
        self.prim.resize(len, NONE);
        if self.bary.len() != len {
            self.bary.resize(len, [0.0; 3]);
            self.color.resize(len, Rgb::BLACK);
        }
    }
}

/// Where a band's samples lie: `k x k` per pixel, `w` pixels a row, rows `y_start` on.
struct Target {
    k: u32,
    w: u32,
    y_start: u32,
    rows: u32,
}

/// Rasterizes triangle `id` into a band: the depth test and the visible triangle with its
/// weights; with `wire`, only samples within the half width of an edge, in that colour, the
/// depth test passing up to a small bias so that edges show on their own faces.
fn raster_triangle(
    t: &[ScreenVertex; 3],
    id: u32,
    to: &Target,
    buf: &mut Band,
    wire: Option<(Rgb, f32)>,
) {
    let Target {
        k,
        w,
        y_start,
        rows,
    } = *to;
    let [a, b, c] = t;
    let area = edge(a.x, a.y, b.x, b.y, c.x, c.y);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let sign = area.signum();
    let inv_area = 1.0 / (area * sign);
    let min_x = a.x.min(b.x).min(c.x).floor().max(0.0);
    let max_x = a.x.max(b.x).max(c.x).ceil().min(w as f32);
    let min_y = a.y.min(b.y).min(c.y).floor().max(y_start as f32);
    let max_y = a.y.max(b.y).max(c.y).ceil().min((y_start + rows) as f32);
    if !(min_x < max_x && min_y < max_y) {
        return;
    }
    let own = [
        owns_edge(b.x, b.y, c.x, c.y, sign),
        owns_edge(c.x, c.y, a.x, a.y, sign),
        owns_edge(a.x, a.y, b.x, b.y, sign),
    ];
    let edge_len = [
        ((c.x - b.x).powi(2) + (c.y - b.y).powi(2)).sqrt(),
        ((a.x - c.x).powi(2) + (a.y - c.y).powi(2)).sqrt(),
        ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt(),
    ];
    let n = (k * k) as usize;
    // Sample offsets inside a pixel (at most 16 x 16 samples).
    let mut offsets = [0.0f32; 16];
    for (i, o) in offsets.iter_mut().enumerate().take(k as usize) {
        *o = (i as f32 + 0.5) / k as f32;
    }
    for py in min_y as u32..max_y as u32 {
        for px in min_x as u32..max_x as u32 {
            for sy in 0..k {
                for sx in 0..k {
                    let x = px as f32 + offsets[sx as usize];
                    let y = py as f32 + offsets[sy as usize];
                    let e = [
                        edge(b.x, b.y, c.x, c.y, x, y) * sign,
                        edge(c.x, c.y, a.x, a.y, x, y) * sign,
                        edge(a.x, a.y, b.x, b.y, x, y) * sign,
                    ];
                    if e.iter().zip(own).any(|(&v, o)| v < 0.0 || (v == 0.0 && !o)) {
                        continue;
                    }
                    let l = [e[0] * inv_area, e[1] * inv_area, e[2] * inv_area];
                    let z = l[0] * a.z + l[1] * b.z + l[2] * c.z;
                    let s = ((py - y_start) * w + px) as usize * n + (sy * k + sx) as usize;
                    match wire {
                        None => {
                            // LESS: a NaN depth never passes.
                            if z.is_nan() || z >= buf.depth[s] {
                                continue;
                            }
                            buf.depth[s] = z;
                            buf.prim[s] = id;
                            buf.bary[s] = l;
                        }
                        Some((col, half_width)) => {
                            // Distance in pixels to the nearest edge.
                            let near_edge = (0..3).any(|i| e[i] / edge_len[i] <= half_width);
                            if !near_edge || z > buf.depth[s] + 1e-4 {
                                continue;
                            }
                            buf.depth[s] = z;
                            buf.color[s] = col;
                        }
                    }
                }
            }
        }
    }
}

/// A channel as OpenGL stores it: `round(clamp(v, 0, 1) 255)`, halves to even.
#[inline]
fn byte(v: f32) -> u8 {
    // Adding and taking away 2^23 rounds halves to even in the default rounding mode, for
    // the values 0..=255 here (`round_ties_even` would be a library call on plain x86-64).
    const SHIFT: f32 = 8_388_608.0;
    ((v.clamp(0.0, 1.0) * 255.0 + SHIFT) - SHIFT) as u8
}

/// Colours to bytes as OpenGL writes them: `round(clamp(c, 0, 1) 255)` with halves to even
/// (as the processor's conversion rounds; 0.3 is 76, not 77), no sRGB encoding.
#[must_use]
pub fn to_bytes(img: &RgbImage) -> prism_image::Rgb8Image {
    let bytes = img
        .pixels()
        .par_iter()
        .map(|p| [byte(p.r), byte(p.g), byte(p.b)])
        .collect();
    Image::from_vec(img.width(), img.height(), bytes)
}
