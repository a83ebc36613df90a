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
use crate::raster::{raster_fill, raster_wire, Band, ScreenVertex, Target, NONE};
use crate::shaders::{fragment, fragment_lanes, height, Shader, Uniforms, Varyings};
use prism_math::lanes::{F16, LANES, M16, V16};

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

/// `1 - z` of window depth `z` for `1/w` (`w` the eye-space distance along the view) under
/// the [`NEAR`] and [`FAR`] perspective.
#[inline]
fn reversed_depth(inv_w: f32) -> f32 {
    const SCALE: f32 = NEAR / (FAR - NEAR);
    (FAR * inv_w - 1.0) * SCALE
}

/// A convex polygon of at most 9 corners: a triangle clipped by two planes.
#[derive(Clone, Copy)]
struct Polygon {
    corners: [ClipVertex; 9],
    len: usize,
}

impl Polygon {
    fn new(tri: [ClipVertex; 3]) -> Polygon {
        let mut corners = [tri[0]; 9];
        corners[..3].copy_from_slice(&tri);
        Polygon { corners, len: 3 }
    }

    fn corners(&self) -> &[ClipVertex] {
        &self.corners[..self.len]
    }

    fn push(&mut self, v: ClipVertex) {
        self.corners[self.len] = v;
        self.len += 1;
    }
}

/// Clips a polygon against `plane(c) >= 0`, interpolating in clip space.
fn clip_polygon(poly: &Polygon, plane: impl Fn(&[f32; 4]) -> f32) -> Polygon {
    let mut out = Polygon {
        corners: poly.corners,
        len: 0,
    };
    let corners = poly.corners();
    for i in 0..corners.len() {
        let a = &corners[i];
        let b = &corners[(i + 1) % corners.len()];
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

/// The mesh in window coordinates: vertices, and triangles over them in mesh order (the
/// mesh's own list when nothing needed clipping).
struct ScreenMesh<'a> {
    verts: Vec<ScreenVertex>,
    tris: std::borrow::Cow<'a, [[u32; 3]]>,
}

impl ScreenMesh<'_> {
    /// The corners of triangle `i`.
    #[inline(always)]
    fn tri(&self, i: u32) -> [&ScreenVertex; 3] {
        self.tris[i as usize].map(|v| &self.verts[v as usize])
    }
}

/// The screen-space triangles of the mesh: vertex stage (per vertex on rayon), clipping
/// against the near and far planes, viewport.
fn screen_triangles<'a>(
    mesh: &'a ShadeMesh,
    view: &View,
    shader: &Shader,
    u: &Uniforms,
) -> Result<ScreenMesh<'a>, ShadeError> {
    let clip_from_world = view.clip_from_world()?.matrix();
    let displace = match shader {
        Shader::Displacement(map) => Some(map),
        _ => None,
    };
    let clipped: Vec<ClipVertex> = (0..mesh.positions.len())
        .into_par_iter()
        .with_min_len(4096)
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
    let to_screen = |c: &ClipVertex| {
        let inv_w = 1.0 / c.clip[3];
        ScreenVertex {
            x: (c.clip[0] * inv_w + 1.0) * 0.5 * w,
            y: (1.0 - c.clip[1] * inv_w) * 0.5 * h,
            rz: reversed_depth(inv_w),
            inv_w,
            v: c.v,
        }
    };
    let inside = |c: &[f32; 4]| c[2] >= -c[3] && c[2] <= c[3];
    let mut verts: Vec<ScreenVertex> = clipped.par_iter().map(to_screen).collect();
    let all_inside = |t: &[u32; 3]| t.iter().all(|&i| inside(&clipped[i as usize].clip));
    if mesh.triangles.par_iter().all(all_inside) {
        return Ok(ScreenMesh {
            verts,
            tris: std::borrow::Cow::Borrowed(&mesh.triangles),
        });
    }
    // Some triangles cross the near or far plane: clip those and fan their polygons, in
    // mesh order, with the new corners appended.
    let mut tris = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        if all_inside(t) {
            tris.push(*t);
            continue;
        }
        let tri = Polygon::new(t.map(|i| clipped[i as usize]));
        let near = clip_polygon(&tri, |c| c[2] + c[3]);
        let poly = clip_polygon(&near, |c| c[3] - c[2]);
        let corners = poly.corners();
        if corners.len() < 3 {
            continue;
        }
        let first = verts.len() as u32;
        verts.extend(corners.iter().map(to_screen));
        for i in 1..corners.len() as u32 - 1 {
            tris.push([first, first + i, first + i + 1]);
        }
    }
    Ok(ScreenMesh {
        verts,
        tris: std::borrow::Cow::Owned(tris),
    })
}

/// The most bytes [`shade_rgb8`] holds for a `width x height` frame at `samples` samples a
/// pixel: the picture's bytes and, for each worker thread, one band's sample buffers
/// (depth, triangle, three weights and three colour channels a sample); [`shade`]'s linear
/// picture takes 12 bytes a pixel more. A caller checks it against the memory budget
/// before drawing.
#[must_use]
pub fn frame_bytes(width: u32, height: u32, samples: u32) -> u64 {
    let (w, h) = (u64::from(width), u64::from(height));
    let picture = w * h * 3;
    let band = u64::from(BAND) * w * u64::from(samples) * 32;
    picture + band * rayon::current_num_threads() as u64
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
    let tris = screen_triangles(mesh, view, shader, &u)?;
    let (w, h) = (view.width, view.height);
    // Triangles by band of rows, in mesh order.
    let bands = h.div_ceil(BAND) as usize;
    let mut by_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for i in 0..tris.tris.len() as u32 {
        let (y0, y1) = tris
            .tri(i)
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
            band.push(i);
        }
    }
    let frame = Frame {
        tris: &tris,
        by_band: &by_band,
        k,
        w,
        shader,
        u: &u,
        opts,
    };
    let mut pixels = vec![T::default(); w as usize * h as usize];
    let rows_per_band = (BAND * w) as usize;
    pixels
        .par_chunks_mut(rows_per_band)
        .enumerate()
        .for_each(|(band, out)| {
            // Each worker keeps its band buffers from band to band and call to call (rayon
            // would make new ones for every piece of work it splits off).
            BAND_BUFFERS.with_borrow_mut(|buf| frame.band(band as u32, out, buf, &store));
        });
    Ok(Image::from_vec(w, h, pixels))
}

/// What every band of one frame reads.
struct Frame<'a> {
    tris: &'a ScreenMesh<'a>,
    by_band: &'a [Vec<u32>],
    k: u32,
    w: u32,
    shader: &'a Shader,
    u: &'a Uniforms,
    opts: &'a ShadeOptions,
}

impl Frame<'_> {
    /// Draws band `band` into `out`, its rows of pixels.
    fn band<T>(&self, band: u32, out: &mut [T], buf: &mut Band, store: &impl Fn(Rgb) -> T) {
        #[cfg(target_arch = "x86_64")]
        {
            if prism_math::Isa::avx512() {
                // SAFETY: the processor has AVX-512F.
                return unsafe { self.band_avx512(band, out, buf, store) };
            }
            if prism_math::Isa::avx2() {
                // SAFETY: the processor has AVX2.
                return unsafe { self.band_avx2(band, out, buf, store) };
            }
        }
        self.band_with(band, out, buf, store);
    }

    /// [`Frame::band`] compiled for AVX-512 (a group of lanes is one vector).
    ///
    /// # Safety
    /// The processor must support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn band_avx512<T>(
        &self,
        band: u32,
        out: &mut [T],
        buf: &mut Band,
        store: &impl Fn(Rgb) -> T,
    ) {
        self.band_with(band, out, buf, store);
    }

    /// [`Frame::band`] compiled for AVX2 (a group of lanes is two vectors).
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn band_avx2<T>(
        &self,
        band: u32,
        out: &mut [T],
        buf: &mut Band,
        store: &impl Fn(Rgb) -> T,
    ) {
        self.band_with(band, out, buf, store);
    }

    #[inline(always)]
    fn band_with<T>(&self, band: u32, out: &mut [T], buf: &mut Band, store: &impl Fn(Rgb) -> T) {
        let (k, w) = (self.k, self.w);
        let y_start = band * BAND;
        let rows = (out.len() / w as usize) as u32;
        let n = (k * k) as usize;
        let row_len = (w * k) as usize;
        let len = rows as usize * k as usize * row_len;
        // Every sample is cleared: the buffers are the worker's, reused band to band.
        buf.clear(len, k, row_len);
        let target = Target {
            k,
            w,
            y_start,
            rows,
        };
        // Visibility first (depth LESS, the first of equals kept), then one fragment per
        // visible sample: the same colours as shading each fragment as it passes.
        for &i in &self.by_band[band as usize] {
            raster_fill(self.tris.tri(i), i, &target, buf);
        }
        self.shade_samples(buf, len);
        if let Some(c) = self.opts.wireframe {
            for &i in &self.by_band[band as usize] {
                raster_wire(self.tris.tri(i), &target, buf, c, self.opts.wire_width);
            }
        }
        // Each sample is stored clamped, as in an 8-bit colour buffer; a pixel is the mean
        // of its samples in row order.
        let clamp = |c: Rgb| {
            Rgb::new(
                c.r.clamp(0.0, 1.0),
                c.g.clamp(0.0, 1.0),
                c.b.clamp(0.0, 1.0),
            )
        };
        let color = |s: usize| Rgb::new(buf.color[0][s], buf.color[1][s], buf.color[2][s]);
        for (py, row) in out.chunks_mut(w as usize).enumerate() {
            let row_start = py * k as usize * row_len;
            if n == 1 {
                for (px, p) in row.iter_mut().enumerate() {
                    *p = store(clamp(color(row_start + px)));
                }
                continue;
            }
            for (px, p) in row.iter_mut().enumerate() {
                let first = row_start + px * k as usize;
                let mut sum = Rgb::BLACK;
                for sy in 0..k as usize {
                    for sx in 0..k as usize {
                        sum += clamp(color(first + sy * row_len + sx));
                    }
                }
                *p = store(sum * (1.0 / n as f32));
            }
        }
    }

    /// The colour of every sample: the background, or the fragment of the triangle seen,
    /// sixteen samples at a time where the shader has a lane form.
    #[inline(always)]
    fn shade_samples(&self, buf: &mut Band, len: usize) {
        let (u, shader, tris) = (self.u, self.shader, self.tris);
        let background = self.opts.background;
        let needs = shader.needs();
        let Band {
            prim, bary, color, ..
        } = buf;
        let mut s = 0;
        while s < len {
            let mut ids = [NONE; LANES];
            ids.copy_from_slice(&prim[s..s + LANES]);
            let live = (len - s).min(LANES);
            if ids[..live].iter().all(|&p| p == NONE) {
                color[0][s..s + live].fill(background.r);
                color[1][s..s + live].fill(background.g);
                color[2][s..s + live].fill(background.b);
                s += LANES;
                continue;
            }
            // Perspective-correct weights and the position and normal they blend, with
            // each lane's corners gathered (a lane that sees nothing borrows triangle 0).
            let mut inv_w = [F16::default(); 3];
            let mut normals = [V16::default(); 3];
            let mut positions = [V16::default(); 3];
            if ids.iter().all(|&p| p == ids[0]) {
                // One triangle under all the lanes: its corners, once.
                for (c, v) in tris.tri(ids[0]).iter().enumerate() {
                    inv_w[c] = F16::splat(v.inv_w);
                    normals[c] = V16::splat(v.v.normal);
                    positions[c] = V16::splat(v.v.position);
                }
            } else {
                for (l, &id) in ids.iter().enumerate() {
                    let t = tris.tri(if id == NONE { 0 } else { id });
                    for c in 0..3 {
                        inv_w[c].0[l] = t[c].inv_w;
                        let (n, p) = (t[c].v.normal, t[c].v.position);
                        (normals[c].x.0[l], normals[c].y.0[l], normals[c].z.0[l]) = (n.x, n.y, n.z);
                        (
                            positions[c].x.0[l],
                            positions[c].y.0[l],
                            positions[c].z.0[l],
                        ) = (p.x, p.y, p.z);
                    }
                }
            }
            let pw = [
                F16::load(&bary[0][s..]) * inv_w[0],
                F16::load(&bary[1][s..]) * inv_w[1],
                F16::load(&bary[2][s..]) * inv_w[2],
            ];
            let inv = F16::splat(1.0) / (pw[0] + pw[1] + pw[2]);
            let wt = [pw[0] * inv, pw[1] * inv, pw[2] * inv];
            // A function, not a closure: a closure would be compiled apart, without the
            // band's vector instruction set.
            #[inline(always)]
            fn blend(v: &[V16; 3], wt: &[F16; 3]) -> V16 {
                v[0] * wt[0] + v[1] * wt[1] + v[2] * wt[2]
            }
            let normal = blend(&normals, &wt);
            let lanes = if matches!(shader, Shader::Normal | Shader::Wireframe) {
                fragment_lanes(shader, u, V16::default(), normal)
            } else if matches!(shader, Shader::Diffuse | Shader::Phong) {
                fragment_lanes(shader, u, blend(&positions, &wt), normal)
            } else {
                None
            };
            if let Some(lanes) = lanes {
                let mut seen = [0i32; LANES];
                for (m, &p) in seen.iter_mut().zip(&ids) {
                    *m = -i32::from(p != NONE);
                }
                let back = [background.r, background.g, background.b];
                for ch in 0..3 {
                    F16::select(M16(seen), lanes[ch], F16::splat(back[ch]))
                        .store(&mut color[ch][s..]);
                }
            } else {
                for l in 0..live {
                    let c = if ids[l] == NONE {
                        background
                    } else {
                        let [a, b, c] = tris.tri(ids[l]);
                        let v = Varyings::blend_only(
                            &a.v,
                            &b.v,
                            &c.v,
                            [wt[0].0[l], wt[1].0[l], wt[2].0[l]],
                            needs,
                        );
                        fragment(shader, u, &v)
                    };
                    (color[0][s + l], color[1][s + l], color[2][s + l]) = (c.r, c.g, c.b);
                }
            }
            s += LANES;
        }
    }
}

thread_local! {
    static BAND_BUFFERS: std::cell::RefCell<Band> = std::cell::RefCell::new(Band::default());
}

/// A channel as OpenGL stores it: `round(clamp(v, 0, 1) 255)`, halves to even.
#[inline]
fn byte(v: f32) -> u8 {
    // Adding 2^23 rounds halves to even in the default rounding mode and leaves the integer
    // 0..=255 in the low bits of the sum (`round_ties_even` would be a library call on plain
    // x86-64, and a float-to-integer conversion costs more). NaN clamps to 0.
    const SHIFT: f32 = 8_388_608.0;
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    ((v * 255.0 + SHIFT).to_bits() & 0xff) as u8
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force against the library's rounding: every float from -0.01 to 1.01 in steps
    /// of a tenth of a byte (halves included), the neighbours of every half, and NaN and the
    /// infinities, round as `round_ties_even(clamp(v, 0, 1) 255)` does.
    #[test]
    fn bytes_round_halves_to_even_as_the_library_does() {
        let reference = |v: f32| {
            if v.is_nan() {
                0
            } else {
                (v.clamp(0.0, 1.0) * 255.0).round_ties_even() as u8
            }
        };
        let mut values: Vec<f32> = (-26..=2576).map(|i| i as f32 / 2550.0).collect();
        for k in 0..255 {
            let half = (k as f32 + 0.5) / 255.0;
            values.extend([half, half.next_up(), half.next_down()]);
        }
        values.extend([
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            1e30,
            -1e30,
        ]);
        for v in values {
            assert_eq!(byte(v), reference(v), "{v:e}");
        }
    }
}
