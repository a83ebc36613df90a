//! The rasterizer: a document is prepared into device-space primitives, then rendered in
//! horizontal bands (in parallel, one sample buffer per band) and each band is resolved
//! by a box filter over its samples.
//!
//! Sample `(i, j)` of pixel `(x, y)` at rate `r` (samples = r * r) sits at
//! `(x + (i + 0.5) / r, y + (j + 0.5) / r)`. Samples hold premultiplied RGBA in the
//! document's colour space (stored sRGB values, as SVG composites). Coverage rules:
//! paths and triangles use a top-left rule (a sample on a shared edge belongs to exactly
//! one side); the course's triangles ([`Item::Triangles`], and every triangle in
//! compat mode) count samples on an edge as inside. DDA lines and points are not
//! antialiased: they set every sample of the pixels they touch.

use std::sync::Arc;
use std::time::{Duration, Instant};

use prism_image::{LevelSampling, PixelSampling, Rgba8Image, Texture};
use prism_math::{DVec2, Rgb, Vec2};
use rayon::prelude::*;

use crate::document::{Document, FillRule, Gradient, GradientKind, Item, Mat3, Paint, Spread};
use crate::path::{stroke, Path, StrokeStyle};

/// Largest output width or height in pixels.
pub const MAX_DIMENSION: u32 = 16_384;
/// Largest sample count per pixel (a 16 x 16 grid).
pub const MAX_SAMPLES: u32 = 256;

/// Curve flattening tolerance in output pixels.
const TOLERANCE: f64 = 0.05;

/// How the document is placed in the output image.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum View {
    /// The document's viewport (after its `viewBox`) fills the output.
    #[default]
    Fit,
    /// The square region centred at `(cx, cy)` reaching `span` user units to each side,
    /// centred in the output with uniform scale `min(width, height) / (2 span)`.
    Region {
        /// Centre x in user units.
        cx: f64,
        /// Centre y in user units.
        cy: f64,
        /// Half the side of the visible square, in user units.
        span: f64,
    },
}

/// Settings for one render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Samples per pixel; a perfect square.
    pub samples: u32,
    /// Texel lookup for textured triangles.
    pub pixel_sampling: PixelSampling,
    /// Mip level selection for textured triangles.
    pub level_sampling: LevelSampling,
    /// Placement of the document.
    pub view: View,
    /// The course renderer's behaviour: opaque white background, all triangles with the
    /// inclusive edge rule, a one-pixel black canvas outline, truncating 8-bit conversion,
    /// and [`View::Fit`] meaning the course's view (centre of the canvas, 20% margin).
    pub compat: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1024,
            height: 1024,
            samples: 1,
            pixel_sampling: PixelSampling::Nearest,
            level_sampling: LevelSampling::Zero,
            view: View::Fit,
            compat: false,
        }
    }
}

/// Invalid render settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// Width or height outside `1..=MAX_DIMENSION`.
    #[error("output size {0}x{1} is outside 1..={MAX_DIMENSION} pixels per side")]
    BadSize(u32, u32),
    /// Sample count not a perfect square in `1..=MAX_SAMPLES`.
    #[error("samples per pixel must be a perfect square from 1 to {MAX_SAMPLES} (1, 4, 9, 16, ...), found {0}")]
    BadSamples(u32),
    /// The view region is not finite and positive.
    #[error("view span must be finite and positive, found centre ({0}, {1}) span {2}")]
    BadView(f64, f64, f64),
}

/// Wall-clock time spent in each stage of [`render`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Transforming, flattening and stroking items into device primitives.
    pub prepare: Duration,
    /// Rasterizing samples (band phase, apportioned by thread time).
    pub raster: Duration,
    /// Box-filtering samples into pixels (band phase, apportioned by thread time).
    pub resolve: Duration,
}

/// The sample rate `r` for `samples = r * r`, if it is a valid count.
#[must_use]
pub fn sample_rate(samples: u32) -> Option<u32> {
    let r = (f64::from(samples)).sqrt().round() as u32;
    ((1..=MAX_SAMPLES).contains(&samples) && r * r == samples).then_some(r)
}

/// The transform from document user space to output pixels for these options.
#[must_use]
pub fn view_transform(doc: &Document, opts: &RenderOptions) -> Mat3 {
    let region = match opts.view {
        View::Region { cx, cy, span } => Some((cx, cy, span)),
        View::Fit if opts.compat => {
            // The course's view: the canvas centre, 1.2 x the larger side across.
            let (w, h) = (doc.width as f32, doc.height as f32);
            let span = (1.2 * f64::from(w.max(h)) / 2.0) as f32;
            Some((f64::from(w / 2.0), f64::from(h / 2.0), f64::from(span)))
        }
        View::Fit => None,
    };
    match region {
        Some((cx, cy, span)) => {
            // Computed exactly as the course renderer does: NDC from a homogeneous
            // matrix with w = 2 span, then NDC to a centred square of the output.
            let (cx, cy, span) = (cx as f32, cy as f32, span as f32);
            let svg_to_ndc = Mat3([
                [1.0, 0.0, f64::from(span - cx)],
                [0.0, 1.0, f64::from(span - cy)],
                [0.0, 0.0, f64::from(2.0 * span)],
            ]);
            let (w, h) = (opts.width as f32, opts.height as f32);
            let s = w.min(h);
            let ndc_to_screen = Mat3([
                [f64::from(s), 0.0, f64::from((w - s) / 2.0)],
                [0.0, f64::from(s), f64::from((h - s) / 2.0)],
                [0.0, 0.0, 1.0],
            ]);
            let m = ndc_to_screen.mul(&svg_to_ndc);
            if opts.compat {
                m
            } else {
                m.mul(&doc.view_box_transform)
            }
        }
        None => Mat3::scale(
            f64::from(opts.width) / doc.width,
            f64::from(opts.height) / doc.height,
        )
        .mul(&doc.view_box_transform),
    }
}

/// A non-horizontal polygon edge in device space with `y0 < y1`.
#[derive(Clone, Copy, Debug)]
struct Edge {
    x0: f64,
    y0: f64,
    y1: f64,
    dxdy: f64,
    dir: i32,
}

fn edges_of(polys: impl IntoIterator<Item = Vec<DVec2>>, closed: bool, out: &mut Vec<Edge>) {
    for poly in polys {
        let n = poly.len();
        if n < 2 {
            continue;
        }
        let count = if closed { n } else { n - 1 };
        for i in 0..count {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            if a.y == b.y || !a.is_finite() || !b.is_finite() {
                continue;
            }
            let (p, q, dir) = if a.y < b.y { (a, b, 1) } else { (b, a, -1) };
            out.push(Edge {
                x0: p.x,
                y0: p.y,
                y1: q.y,
                dxdy: (q.x - p.x) / (q.y - p.y),
                dir,
            });
        }
    }
}

/// A paint resolved to device space.
#[derive(Clone, Debug)]
enum DevPaint {
    Solid([f32; 4]),
    Gradient {
        g: Arc<Gradient>,
        /// Device pixel to gradient space.
        inv: prism_math::DAffine2,
        /// Premultiplied colours for `t = i / (LUT_SIZE - 1)`.
        lut: Vec<[f32; 4]>,
    },
}

/// Entries in a gradient's colour table: `t` in [0, 1] is quantised to 1/1023.
const LUT_SIZE: usize = 1024;

/// Premultiplied colour of a gradient's stops at `t` in [0, 1], times `opacity`; colours
/// interpolate in stored (sRGB) values, as SVG specifies.
fn stop_color(g: &Gradient, t: f32, opacity: f32) -> [f32; 4] {
    let stops = &g.stops;
    let (c, a) = if t <= stops[0].offset {
        (stops[0].color, stops[0].opacity)
    } else if t >= stops[stops.len() - 1].offset {
        let s = stops[stops.len() - 1];
        (s.color, s.opacity)
    } else {
        let k = stops
            .windows(2)
            .position(|w| t >= w[0].offset && t <= w[1].offset)
            .unwrap_or(0);
        let (s0, s1) = (stops[k], stops[k + 1]);
        let span = s1.offset - s0.offset;
        let f = if span > 0.0 {
            (t - s0.offset) / span
        } else {
            1.0
        };
        (
            s0.color.lerp(s1.color, f),
            s0.opacity + (s1.opacity - s0.opacity) * f,
        )
    };
    let a = a * opacity;
    [c.r * a, c.g * a, c.b * a, a]
}

impl DevPaint {
    fn gradient(g: &Arc<Gradient>, inv: prism_math::DAffine2, opacity: f32) -> DevPaint {
        let lut = (0..LUT_SIZE)
            .map(|i| stop_color(g, i as f32 / (LUT_SIZE - 1) as f32, opacity))
            .collect();
        DevPaint::Gradient {
            g: g.clone(),
            inv,
            lut,
        }
    }

    fn at(&self, x: f64, y: f64) -> [f32; 4] {
        match self {
            DevPaint::Solid(c) => *c,
            DevPaint::Gradient { g, inv, lut } => {
                let p = inv.transform_point2(DVec2::new(x, y));
                let t = match g.kind {
                    GradientKind::Linear { start, end } => {
                        let d = end - start;
                        let l2 = d.length_squared();
                        if l2 == 0.0 {
                            1.0
                        } else {
                            (p - start).dot(d) / l2
                        }
                    }
                    GradientKind::Radial {
                        center,
                        radius,
                        focus,
                    } => radial_t(p, center, radius, focus),
                };
                let t = match g.spread {
                    Spread::Pad => t.clamp(0.0, 1.0),
                    Spread::Repeat => t.rem_euclid(1.0),
                    Spread::Reflect => {
                        let m = t.rem_euclid(2.0);
                        if m > 1.0 {
                            2.0 - m
                        } else {
                            m
                        }
                    }
                };
                let t = if t.is_nan() { 0.0 } else { t };
                lut[(t * (LUT_SIZE - 1) as f64 + 0.5) as usize]
            }
        }
    }
}

/// The gradient parameter of point `p` for a radial gradient with a focal point: the `t`
/// for which `p` lies on the circle interpolated from (focus, 0) to (center, radius).
fn radial_t(p: DVec2, center: DVec2, radius: f64, focus: DVec2) -> f64 {
    let cd = center - focus;
    let pd = p - focus;
    // Solve |pd - t cd| = t r for t >= 0.
    let a = cd.length_squared() - radius * radius;
    let b = pd.dot(cd);
    let c = pd.length_squared();
    if a.abs() < 1e-12 {
        if b.abs() < 1e-12 {
            return 0.0;
        }
        return c / (2.0 * b);
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return 0.0;
    }
    let s = disc.sqrt();
    let t1 = (b + s) / a;
    let t2 = (b - s) / a;
    // The reciprocal form: t is 1 / the larger root of the standard quadratic.
    let t = t1.min(t2);
    if t > 0.0 {
        1.0 / (1.0 / t).max(f64::MIN_POSITIVE)
    } else {
        t1.max(t2).max(0.0)
    }
}

#[derive(Clone, Debug)]
enum TriShade {
    Solid([f32; 4]),
    Color([Rgb; 3]),
    Tex {
        tex: Arc<Texture>,
        /// Alpha (red channel) for images with transparency; colours are then premultiplied.
        alpha_tex: Option<Arc<Texture>>,
        uvs: [Vec2; 3],
        lod: f32,
        psm: PixelSampling,
        lsm: LevelSampling,
        alpha: f32,
    },
}

#[derive(Clone, Debug)]
enum Prim {
    Tri {
        v: [DVec2; 3],
        inclusive: bool,
        shade: TriShade,
    },
    Poly {
        edges: Vec<Edge>,
        rule: FillRule,
        paint: DevPaint,
    },
    Pixels {
        px: Vec<(i32, i32)>,
        color: [f32; 4],
    },
    BeginLayer,
    EndLayer(f32),
}

/// A primitive with the pixel rows `[y0, y1)` and columns `[x0, x1)` it can touch.
#[derive(Clone, Debug)]
struct Placed {
    y0: i32,
    y1: i32,
    x0: i32,
    x1: i32,
    prim: Prim,
}

fn solid(c: Rgb, a: f32) -> [f32; 4] {
    [c.r * a, c.g * a, c.b * a, a]
}

/// Pixels within this distance outside the image still run the course's exact DDA; longer
/// lines are first clipped to the image grown by this margin.
const DDA_MARGIN: f64 = 4096.0;

/// Clips the segment to the rectangle `[lo, hi]` (Liang-Barsky); `None` if it misses.
fn clip_segment(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> Option<(DVec2, DVec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then(|| (a + d * t0, a + d * t1))
}

/// The course's DDA line (`rasterize_line`), in `f32` with accumulated steps, appending the
/// pixels `(floor x, floor y)` it visits inside a `width` x `height` image. A line reaching
/// more than [`DDA_MARGIN`] pixels outside the image is clipped to that margin first.
fn dda(a: DVec2, b: DVec2, width: i32, height: i32, out: &mut Vec<(i32, i32)>) {
    if !(a.is_finite() && b.is_finite()) {
        return;
    }
    let lo = DVec2::splat(-DDA_MARGIN);
    let hi = DVec2::new(f64::from(width), f64::from(height)) + DDA_MARGIN;
    let inside = |p: DVec2| p.x >= lo.x && p.y >= lo.y && p.x <= hi.x && p.y <= hi.y;
    let (a, b) = if inside(a) && inside(b) {
        (a, b)
    } else {
        match clip_segment(a, b, lo, hi) {
            Some(s) => s,
            None => return,
        }
    };
    let (mut x0, mut y0, mut x1, mut y1) = (a.x as f32, a.y as f32, b.x as f32, b.y as f32);
    if x0 > x1 {
        std::mem::swap(&mut x0, &mut x1);
        std::mem::swap(&mut y0, &mut y1);
    }
    let m = (y1 - y0) / (x1 - x0);
    let (mut dx, mut dy) = (1.0f32, m);
    if m.abs() > 1.0 {
        if x1 == x0 {
            dx = 0.0;
            dy = (y1 - y0) / (y1 - y0).abs();
        } else {
            dx = 1.0 / m.abs();
            dy = m / m.abs();
        }
    }
    let (mut x, mut y) = (x0, y0);
    while x.floor() <= x1.floor() && (y - y0).abs() <= (y1 - y0).abs() {
        let (px, py) = (x.floor() as i32, y.floor() as i32);
        if px >= 0 && py >= 0 && px < width && py < height {
            out.push((px, py));
        }
        let (nx, ny) = (x + dx, y + dy);
        if nx == x && ny == y {
            // The step vanished in f32 far from the origin: no further pixels.
            break;
        }
        x = nx;
        y = ny;
    }
}

fn to_f32(p: DVec2) -> (f32, f32) {
    (p.x as f32, p.y as f32)
}

/// Turns document items into device primitives.
fn prepare(doc: &Document, opts: &RenderOptions, view: &Mat3) -> Vec<Placed> {
    let h = opts.height as i32;
    let w = opts.width as f64;
    let hf = opts.height as f64;
    let rows = |lo: f64, hi: f64| -> Option<(i32, i32)> {
        if !(lo.is_finite() && hi.is_finite()) || hi < 0.0 || lo > hf {
            return None;
        }
        let y0 = (lo.floor() as i64).clamp(0, i64::from(h)) as i32;
        let y1 = (hi.floor() as i64).saturating_add(1).clamp(0, i64::from(h)) as i32;
        (y1 > y0).then_some((y0, y1))
    };
    let xs_visible = |lo: f64, hi: f64| hi >= -1.0 && lo <= w + 1.0;
    let cols = |lo: f64, hi: f64| -> (i32, i32) {
        let x0 = (lo.floor() as i64).clamp(0, w as i64) as i32;
        let x1 = (hi.floor() as i64).saturating_add(1).clamp(0, w as i64) as i32;
        (x0, x1)
    };
    let place_tri = |v: [DVec2; 3], inclusive: bool, shade: TriShade| -> Option<Placed> {
        let lo = v[0].min(v[1]).min(v[2]);
        let hi = v[0].max(v[1]).max(v[2]);
        if !xs_visible(lo.x, hi.x) {
            return None;
        }
        let (y0, y1) = rows(lo.y, hi.y)?;
        let (x0, x1) = cols(lo.x, hi.x);
        Some(Placed {
            y0,
            y1,
            x0,
            x1,
            prim: Prim::Tri {
                v,
                inclusive,
                shade,
            },
        })
    };
    let place_poly = |edges: Vec<Edge>, rule: FillRule, paint: DevPaint| -> Option<Placed> {
        if edges.is_empty() {
            return None;
        }
        let lo = edges.iter().map(|e| e.y0).fold(f64::INFINITY, f64::min);
        let hi = edges.iter().map(|e| e.y1).fold(f64::NEG_INFINITY, f64::max);
        let (y0, y1) = rows(lo, hi)?;
        let end_x = |e: &Edge| e.x0 + (e.y1 - e.y0) * e.dxdy;
        let xlo = edges
            .iter()
            .map(|e| e.x0.min(end_x(e)))
            .fold(f64::INFINITY, f64::min);
        let xhi = edges
            .iter()
            .map(|e| e.x0.max(end_x(e)))
            .fold(f64::NEG_INFINITY, f64::max);
        if !xs_visible(xlo, xhi) {
            return None;
        }
        let (x0, x1) = cols(xlo, xhi);
        Some(Placed {
            y0,
            y1,
            x0,
            x1,
            prim: Prim::Poly { edges, rule, paint },
        })
    };
    let dev_paint = |paint: &Paint, m: &Mat3, opacity: f32| -> Option<DevPaint> {
        match paint {
            Paint::Solid(c) => Some(DevPaint::Solid(solid(*c, opacity))),
            Paint::Gradient(g) => {
                let full = m.mul(&g.transform).to_affine();
                let det = full.matrix2.determinant();
                if det == 0.0 || !det.is_finite() {
                    return None;
                }
                Some(DevPaint::gradient(g, full.inverse(), opacity))
            }
        }
    };
    let tex_shade = |index: usize, dv: [DVec2; 3], uvs: [Vec2; 3], psm, lsm, alpha| {
        let tex = &doc.textures[index];
        let alpha_tex = doc.texture_alpha.get(index).cloned().flatten();
        // uv is an affine function of screen position: its derivatives are constant.
        let e1 = dv[1] - dv[0];
        let e2 = dv[2] - dv[0];
        let det = e1.x * e2.y - e1.y * e2.x;
        let (du1, du2) = (uvs[1] - uvs[0], uvs[2] - uvs[0]);
        let (duv_dx, duv_dy) = if det == 0.0 {
            (Vec2::ZERO, Vec2::ZERO)
        } else {
            let inv = 1.0 / det;
            let dx = (du1 * e2.y as f32 - du2 * e1.y as f32) * inv as f32;
            let dy = (du2 * e1.x as f32 - du1 * e2.x as f32) * inv as f32;
            (dx, dy)
        };
        TriShade::Tex {
            tex: tex.clone(),
            alpha_tex: alpha_tex.clone(),
            uvs,
            lod: tex.level_for(duv_dx, duv_dy),
            psm,
            lsm,
            alpha,
        }
    };
    // Device vertices as the course computes them: mapped in f64, passed on as f32.
    let dev = |m: &Mat3, p: DVec2| {
        let q = m.apply(p);
        if opts.compat {
            DVec2::new(f64::from(q.x as f32), f64::from(q.y as f32))
        } else {
            q
        }
    };
    let per_item = |item: &Item| -> Vec<Placed> {
        let mut out = Vec::new();
        match item {
            Item::Triangles {
                tris,
                transform,
                color,
            } => {
                let m = view.mul(transform);
                for t in tris {
                    let v = [dev(&m, t[0]), dev(&m, t[1]), dev(&m, t[2])];
                    out.extend(place_tri(v, true, TriShade::Solid(solid(*color, 1.0))));
                }
            }
            Item::Fill {
                path,
                transform,
                rule,
                paint,
                opacity,
            } => {
                let m = view.mul(transform);
                let Some(paint) = dev_paint(paint, &m, *opacity) else {
                    return out;
                };
                let dpath: Path = path.transformed(&m.to_affine());
                let lines = dpath.flatten(TOLERANCE);
                let mut edges = Vec::new();
                edges_of(lines.into_iter().map(|l| l.points), true, &mut edges);
                out.extend(place_poly(edges, *rule, paint));
            }
            Item::Stroke {
                path,
                transform,
                style,
                paint,
                opacity,
            } => {
                let m = view.mul(transform);
                let affine = m.to_affine();
                let scale = m.max_scale();
                if !(scale > 0.0 && scale.is_finite()) {
                    return out;
                }
                // Strokes thinner than a pixel are drawn one pixel wide with their opacity
                // scaled by their width (hairlines, as Skia and resvg draw them): a sample
                // grid cannot resolve sub-pixel widths without heavy noise.
                let device_width = style.width * scale;
                let thin = device_width < 1.0;
                let widened;
                let (style, opacity) = if thin {
                    widened = StrokeStyle {
                        width: 1.0 / scale,
                        ..style.clone()
                    };
                    (&widened, *opacity * device_width as f32)
                } else {
                    (style, *opacity)
                };
                let Some(paint) = dev_paint(paint, &m, opacity) else {
                    return out;
                };
                let tol = TOLERANCE / scale;
                let polys = stroke(&path.flatten(tol), style, tol);
                let mut edges = Vec::new();
                edges_of(
                    polys
                        .into_iter()
                        .map(|p| p.into_iter().map(|q| affine.transform_point2(q)).collect()),
                    true,
                    &mut edges,
                );
                out.extend(place_poly(edges, FillRule::NonZero, paint));
            }
            Item::Hairline {
                points,
                closed,
                transform,
                color,
                opacity,
            } => {
                let m = view.mul(transform);
                let n = points.len();
                let segs = if *closed { n } else { n.saturating_sub(1) };
                let mut px = Vec::new();
                for i in 0..segs {
                    let (a, b) = (points[i], points[(i + 1) % n]);
                    dda(m.apply(a), m.apply(b), opts.width as i32, h, &mut px);
                }
                if let (Some(lo), Some(hi)) =
                    (px.iter().map(|p| p.1).min(), px.iter().map(|p| p.1).max())
                {
                    let xl = px.iter().map(|p| p.0).min().unwrap_or(0);
                    let xh = px.iter().map(|p| p.0).max().unwrap_or(0);
                    out.push(Placed {
                        y0: lo,
                        y1: hi + 1,
                        x0: xl,
                        x1: xh + 1,
                        prim: Prim::Pixels {
                            px,
                            color: solid(*color, *opacity),
                        },
                    });
                }
            }
            Item::Point {
                at,
                transform,
                color,
            } => {
                let m = view.mul(transform);
                let (x, y) = to_f32(m.apply(*at));
                let (sx, sy) = (x.floor(), y.floor());
                if sx >= 0.0 && sy >= 0.0 && sx < opts.width as f32 && sy < opts.height as f32 {
                    let (sx, sy) = (sx as i32, sy as i32);
                    out.push(Placed {
                        y0: sy,
                        y1: sy + 1,
                        x0: sx,
                        x1: sx + 1,
                        prim: Prim::Pixels {
                            px: vec![(sx, sy)],
                            color: solid(*color, 1.0),
                        },
                    });
                }
            }
            Item::ColorTri {
                points,
                colors,
                transform,
            } => {
                let m = view.mul(transform);
                let v = [dev(&m, points[0]), dev(&m, points[1]), dev(&m, points[2])];
                out.extend(place_tri(v, opts.compat, TriShade::Color(*colors)));
            }
            Item::TexTri {
                points,
                uvs,
                texture,
                transform,
            } => {
                let m = view.mul(transform);
                let v = [dev(&m, points[0]), dev(&m, points[1]), dev(&m, points[2])];
                let shade = tex_shade(
                    *texture,
                    v,
                    *uvs,
                    opts.pixel_sampling,
                    opts.level_sampling,
                    1.0,
                );
                out.extend(place_tri(v, opts.compat, shade));
            }
            Item::Image {
                texture,
                rect,
                transform,
                opacity,
            } => {
                let m = view.mul(transform);
                let [x, y, w, h] = *rect;
                let c = [
                    DVec2::new(x, y),
                    DVec2::new(x + w, y),
                    DVec2::new(x, y + h),
                    DVec2::new(x + w, y + h),
                ];
                let d = c.map(|p| dev(&m, p));
                let uv = [
                    Vec2::new(0.0, 0.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.0, 1.0),
                    Vec2::new(1.0, 1.0),
                ];
                for (a, b, cc) in [(0, 1, 2), (2, 1, 3)] {
                    let v = [d[a], d[b], d[cc]];
                    let shade = tex_shade(
                        *texture,
                        v,
                        [uv[a], uv[b], uv[cc]],
                        PixelSampling::Bilinear,
                        LevelSampling::Linear,
                        *opacity,
                    );
                    out.extend(place_tri(v, opts.compat, shade));
                }
            }
            Item::BeginLayer => out.push(Placed {
                y0: 0,
                y1: 0,
                x0: 0,
                x1: 0,
                prim: Prim::BeginLayer,
            }),
            Item::EndLayer { opacity } => out.push(Placed {
                y0: 0,
                y1: 0,
                x0: 0,
                x1: 0,
                prim: Prim::EndLayer(*opacity),
            }),
        }
        out
    };
    let mut prims: Vec<Placed> = doc.items.par_iter().map(per_item).flatten_iter().collect();
    if opts.compat {
        // The course's canvas outline, corners pushed out by one pixel.
        let corner = |x: f64, y: f64, dx: f64, dy: f64| {
            let p = view.apply(DVec2::new(x, y));
            DVec2::new(p.x + dx, p.y + dy)
        };
        let a = corner(0.0, 0.0, -1.0, 1.0);
        let b = corner(doc.width, 0.0, 1.0, 1.0);
        let c = corner(0.0, doc.height, -1.0, -1.0);
        let d = corner(doc.width, doc.height, 1.0, -1.0);
        let mut px = Vec::new();
        for (p, q) in [(a, b), (a, c), (d, b), (d, c)] {
            dda(p, q, opts.width as i32, h, &mut px);
        }
        if !px.is_empty() {
            prims.push(Placed {
                y0: 0,
                y1: h,
                x0: 0,
                x1: opts.width as i32,
                prim: Prim::Pixels {
                    px,
                    color: [0.0, 0.0, 0.0, 1.0],
                },
            });
        }
    }
    bound_layers(&mut prims);
    prims
}

/// Gives every layer the bounding box of what it contains, so bands skip empty layers and
/// layer clearing and compositing touch only that box.
fn bound_layers(prims: &mut [Placed]) {
    let empty = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
    let mut stack: Vec<(usize, (i32, i32, i32, i32))> = Vec::new();
    let mut cur = empty;
    for i in 0..prims.len() {
        match prims[i].prim {
            Prim::BeginLayer => {
                stack.push((i, cur));
                cur = empty;
            }
            Prim::EndLayer(_) => {
                let Some((b, outer)) = stack.pop() else {
                    continue;
                };
                let inner = if cur.0 < cur.1 && cur.2 < cur.3 {
                    cur
                } else {
                    (0, 0, 0, 0)
                };
                for k in [b, i] {
                    prims[k].y0 = inner.0;
                    prims[k].y1 = inner.1;
                    prims[k].x0 = inner.2;
                    prims[k].x1 = inner.3;
                }
                cur = if inner.0 < inner.1 {
                    (
                        outer.0.min(inner.0),
                        outer.1.max(inner.1),
                        outer.2.min(inner.2),
                        outer.3.max(inner.3),
                    )
                } else {
                    outer
                };
            }
            _ => {
                let p = &prims[i];
                if p.y0 < p.y1 && p.x0 < p.x1 {
                    cur = (
                        cur.0.min(p.y0),
                        cur.1.max(p.y1),
                        cur.2.min(p.x0),
                        cur.3.max(p.x1),
                    );
                }
            }
        }
    }
}

#[inline]
fn blend(dst: &mut [f32; 4], src: [f32; 4]) {
    if src[3] >= 1.0 {
        *dst = src;
    } else if src[3] > 0.0 {
        let k = 1.0 - src[3];
        for c in 0..4 {
            dst[c] = src[c] + dst[c] * k;
        }
    }
}

/// The course renderer's translucent blend: both colours truncated to 8 bits, mixed as
/// `a * src + (1 - a) * dst` in `f32` on the 0..255 scale, truncated again. Opaque targets
/// only (the course's canvas is always opaque).
fn blend_8bit(dst: &mut [f32; 4], src: [f32; 4]) {
    let a = src[3];
    if a <= 0.0 {
        return;
    }
    for c in 0..3 {
        let s8 = ((src[c] / a) * 255.0) as u8 as f32;
        let d8 = (dst[c] * 255.0) as u8 as f32;
        dst[c] = f32::from((a * s8 + (1.0 - a) * d8) as u8) / 255.0;
    }
}

#[inline(always)]
fn add4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}

/// Where the samples of a pixel lie. Each pixel row is split into `sub_rows` sample rows;
/// sample row `j` holds `sub_cols` samples per pixel, the first at x offset `xoff[j]` and
/// the others `1 / sub_cols` apart. Sample `k` of sample row `j` (counted across the band)
/// sits at `x = k / sub_cols + xoff[j % sub_rows]`, `y = y0 + (j + 0.5) / sub_rows`.
#[derive(Clone, Debug)]
struct Pattern {
    sub_rows: usize,
    sub_cols: usize,
    xoff: Vec<f64>,
}

impl Pattern {
    /// The regular r x r grid at `((i + 0.5) / r, (j + 0.5) / r)`, as the course uses.
    fn grid(r: usize) -> Pattern {
        Pattern {
            sub_rows: r,
            sub_cols: r,
            xoff: vec![0.5 / r as f64; r],
        }
    }
}

/// One band's sample storage: `rows_px * sub_rows` sample rows of `cols` samples.
struct Band {
    /// Layer stack; the bottom is the band's canvas.
    layers: Vec<Vec<[f32; 4]>>,
    spare: Vec<Vec<[f32; 4]>>,
    cols: usize,
    /// First pixel row of the band.
    y0: i32,
    /// Pixel rows in the band.
    rows_px: i32,
    pat: Pattern,
    width: i32,
}

impl Band {
    fn top(&mut self) -> &mut Vec<[f32; 4]> {
        self.layers.last_mut().expect("band has a canvas")
    }

    fn sample_y(&self, j: usize) -> f64 {
        f64::from(self.y0) + (j as f64 + 0.5) / self.pat.sub_rows as f64
    }

    /// Sample-index ranges (rows, columns) of a placed box within this band.
    fn region(&self, pl: &Placed) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
        let ya = (pl.y0.max(self.y0) - self.y0).max(0) as usize * sr;
        let yb = (pl.y1.min(self.y0 + self.rows_px) - self.y0).max(0) as usize * sr;
        let xa = pl.x0.max(0) as usize * sc;
        let xb = (pl.x1.min(self.width).max(0) as usize * sc).max(xa);
        (ya..yb.max(ya), xa..xb)
    }

    fn draw(&mut self, pl: &Placed, compat: bool) {
        let p = &pl.prim;
        match p {
            Prim::BeginLayer => {
                let (rows, cols) = self.region(pl);
                let len = self.layers[0].len();
                let mut buf = self.spare.pop().unwrap_or_else(|| vec![[0.0; 4]; len]);
                for j in rows {
                    buf[j * self.cols + cols.start..j * self.cols + cols.end].fill([0.0; 4]);
                }
                self.layers.push(buf);
            }
            Prim::EndLayer(op) => {
                if self.layers.len() < 2 {
                    return;
                }
                let (rows, cols) = self.region(pl);
                let stride = self.cols;
                let src = self.layers.pop().expect("checked");
                let dst = self.top();
                for j in rows {
                    let range = j * stride + cols.start..j * stride + cols.end;
                    for (d, s) in dst[range.clone()].iter_mut().zip(&src[range]) {
                        blend(d, [s[0] * op, s[1] * op, s[2] * op, s[3] * op]);
                    }
                }
                self.spare.push(src);
            }
            Prim::Pixels { px, color } => {
                let (y0, y1, cols) = (self.y0, self.y0 + self.rows_px, self.cols);
                let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
                let buf = self.top();
                for &(x, y) in px {
                    if y < y0 || y >= y1 {
                        continue;
                    }
                    let base_row = (y - y0) as usize * sr;
                    for j in 0..sr {
                        let row = (base_row + j) * cols + x as usize * sc;
                        for s in &mut buf[row..row + sc] {
                            if compat && color[3] < 1.0 {
                                blend_8bit(s, *color);
                            } else {
                                blend(s, *color);
                            }
                        }
                    }
                }
            }
            Prim::Poly { edges, rule, paint } => self.poly(edges, *rule, paint),
            Prim::Tri {
                v,
                inclusive,
                shade,
            } => self.tri(v, *inclusive, shade, compat),
        }
    }

    fn poly(&mut self, edges: &[Edge], rule: FillRule, paint: &DevPaint) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols as f64);
        let band_lo = f64::from(self.y0);
        let band_hi = f64::from(self.y0 + self.rows_px);
        let local: Vec<Edge> = edges
            .iter()
            .filter(|e| e.y1 > band_lo && e.y0 < band_hi)
            .copied()
            .collect();
        if local.is_empty() {
            return;
        }
        let cols = self.cols;
        let mut xs: Vec<(f64, i32)> = Vec::with_capacity(16);
        // Gradients are evaluated once per pixel, at its centre, and the colour given to
        // every covered sample (as multisampling shades); alpha < 0 marks "not yet".
        let gradient = matches!(paint, DevPaint::Gradient { .. });
        let mut row_cache: Vec<[f32; 4]> = Vec::new();
        let mut cache_row = usize::MAX;
        for j in 0..self.rows_px as usize * sr {
            let y = self.sample_y(j);
            let xo = self.pat.xoff[j % sr];
            if gradient && j / sr != cache_row {
                cache_row = j / sr;
                row_cache.clear();
                row_cache.resize(self.width as usize, [0.0, 0.0, 0.0, -1.0]);
            }
            let y_centre = f64::from(self.y0) + (j / sr) as f64 + 0.5;
            xs.clear();
            for e in &local {
                // Half-open in y: an edge owns samples with y0 <= y < y1.
                if y >= e.y0 && y < e.y1 {
                    xs.push((e.x0 + (y - e.y0) * e.dxdy, e.dir));
                }
            }
            if xs.len() < 2 {
                continue;
            }
            xs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let row = &mut self.layers.last_mut().expect("canvas")[j * cols..(j + 1) * cols];
            let mut wind = 0;
            for k in 0..xs.len() - 1 {
                wind += xs[k].1;
                let inside = match rule {
                    FillRule::NonZero => wind != 0,
                    FillRule::EvenOdd => wind % 2 != 0,
                };
                if !inside {
                    continue;
                }
                // Samples with x in [xa, xb): left edges inclusive, right exclusive.
                let first = |x: f64| (((x - xo) * sc).ceil().clamp(0.0, cols as f64)) as usize;
                let (a, b) = (first(xs[k].0), first(xs[k + 1].0));
                match paint {
                    DevPaint::Solid(c) if c[3] >= 1.0 => row[a..b].fill(*c),
                    DevPaint::Solid(c) => {
                        for s in &mut row[a..b] {
                            blend(s, *c);
                        }
                    }
                    g => {
                        let sci = self.pat.sub_cols;
                        for (i, s) in row[a..b].iter_mut().enumerate() {
                            let px = (a + i) / sci;
                            let c = &mut row_cache[px];
                            if c[3] < 0.0 {
                                *c = g.at(px as f64 + 0.5, y_centre);
                            }
                            blend(s, *c);
                        }
                    }
                }
            }
        }
    }

    fn tri(&mut self, v: &[DVec2; 3], inclusive: bool, shade: &TriShade, compat: bool) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
        let (rf, cf) = (sr as f64, sc as f64);
        let lo = v[0].min(v[1]).min(v[2]);
        let hi = v[0].max(v[1]).max(v[2]);
        // Sample row range covering the bounding box, clipped to the band; columns per row.
        let j_lo = (((lo.y - f64::from(self.y0)) * rf - 0.5).ceil().max(0.0)) as usize;
        let j_hi = ((((hi.y - f64::from(self.y0)) * rf - 0.5).floor() + 1.0)
            .clamp(0.0, (self.rows_px as usize * sr) as f64)) as usize;
        let cols_of = |xo: f64| {
            let a = ((lo.x - xo) * cf).ceil().max(0.0) as usize;
            let b = (((hi.x - xo) * cf).floor() + 1.0).clamp(0.0, self.cols as f64) as usize;
            (a, b)
        };
        let i_lo = ((lo.x - 1.0) * cf).floor().max(0.0) as usize;
        let i_hi = (((hi.x + 1.0) * cf).ceil()).clamp(0.0, self.cols as f64) as usize;
        if j_lo >= j_hi || i_lo >= i_hi {
            return;
        }
        let area = (v[1] - v[0]).perp_dot(v[2] - v[0]);
        // Edge function of edge a->b at p; positive inside for counter-clockwise (area > 0).
        // In compat mode in f32, as the course's rasterizer computes it.
        let ef = |a: DVec2, b: DVec2, x: f64, y: f64| {
            if compat {
                let (ax, ay, bx, by) = (a.x as f32, a.y as f32, b.x as f32, b.y as f32);
                let (x, y) = (x as f32, y as f32);
                f64::from((bx - ax) * (y - ay) - (by - ay) * (x - ax))
            } else if (a.y, a.x) <= (b.y, b.x) {
                (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)
            } else {
                // Evaluate a shared edge in one canonical direction, so the two triangles
                // that share it get exactly opposite values: no sample is claimed twice or
                // dropped.
                -((a.x - b.x) * (y - b.y) - (a.y - b.y) * (x - b.x))
            }
        };
        let sign = if area < 0.0 { -1.0 } else { 1.0 };
        // Top-left rule: an edge owns its samples if it is a "top" or "left" edge.
        let owns = |a: DVec2, b: DVec2| {
            let (a, b) = if sign > 0.0 { (a, b) } else { (b, a) };
            let d = b - a;
            (d.y == 0.0 && d.x < 0.0) || d.y > 0.0
        };
        let edges = [(v[1], v[2]), (v[2], v[0]), (v[0], v[1])];
        let own = [
            owns(edges[0].0, edges[0].1),
            owns(edges[1].0, edges[1].1),
            owns(edges[2].0, edges[2].1),
        ];
        if !inclusive && area == 0.0 {
            return;
        }
        let cols = self.cols;
        let y0 = self.y0;
        let buf = self.layers.last_mut().expect("canvas");
        // Textures in standard mode are shaded once per pixel, at its centre, and the colour
        // is given to every covered sample (as multisampling does); the course shades every
        // sample.
        let per_pixel = !compat && matches!(shade, TriShade::Tex { .. });
        let fast_interior = !compat && (per_pixel || matches!(shade, TriShade::Solid(_)));
        // Colours of the current pixel row, by pixel column from i_lo / sc; alpha < 0 = unset.
        let px_lo = i_lo / sc;
        let mut row_cache: Vec<[f32; 4]> = if per_pixel {
            vec![[0.0, 0.0, 0.0, -1.0]; (i_hi - 1) / sc - px_lo + 1]
        } else {
            Vec::new()
        };
        let mut cache_row = usize::MAX;
        for j in j_lo..j_hi {
            if per_pixel && j / sr != cache_row {
                cache_row = j / sr;
                row_cache.fill([0.0, 0.0, 0.0, -1.0]);
            }
            let xo = self.pat.xoff[j % sr];
            let (row_lo, row_hi) = cols_of(xo);
            let y = f64::from(y0) + (j as f64 + 0.5) / rf;
            let yf = if compat { f64::from(y as f32) } else { y };
            // A superset of the covered samples on this row, from the three edge lines.
            let (mut xl, mut xr) = (f64::NEG_INFINITY, f64::INFINITY);
            if area != 0.0 {
                for (a, b) in edges {
                    let (c, dy) = ((b.x - a.x) * (yf - a.y) * sign, (b.y - a.y) * sign);
                    if dy > 0.0 {
                        xr = xr.min(a.x + c / dy);
                    } else if dy < 0.0 {
                        xl = xl.max(a.x + c / dy);
                    }
                }
            }
            let span_lo = (((xl - xo) * cf).floor() - 1.0).max(row_lo as f64);
            let span_hi = (((xr - xo) * cf).ceil() + 2.0).min(row_hi as f64);
            if span_lo.partial_cmp(&span_hi) != Some(std::cmp::Ordering::Less) {
                continue;
            }
            // Samples more than one sample spacing inside all three edge lines need no edge
            // test (standard mode, and only when the shading does not use barycentrics).
            let (in_lo, in_hi) = if fast_interior && xl.is_finite() && xr.is_finite() {
                (
                    ((xl - xo) * cf).ceil() + 1.0,
                    ((xr - xo) * cf).floor() - 1.0,
                )
            } else {
                (f64::INFINITY, f64::NEG_INFINITY)
            };
            for i in span_lo as usize..span_hi as usize {
                let x = i as f64 / cf + xo;
                let interior = (i as f64) >= in_lo && (i as f64) <= in_hi;
                let w = if interior {
                    [0.0; 3]
                } else {
                    [
                        ef(edges[0].0, edges[0].1, x, yf),
                        ef(edges[1].0, edges[1].1, x, yf),
                        ef(edges[2].0, edges[2].1, x, yf),
                    ]
                };
                let inside = if interior {
                    true
                } else if inclusive {
                    (w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0)
                        || (w[0] <= 0.0 && w[1] <= 0.0 && w[2] <= 0.0)
                } else {
                    (0..3).all(|k| {
                        let s = w[k] * sign;
                        s > 0.0 || (s == 0.0 && own[k])
                    })
                };
                if !inside {
                    continue;
                }
                let color = match shade {
                    TriShade::Solid(c) => *c,
                    TriShade::Color(c) => {
                        let (b0, b1) = if area == 0.0 {
                            (1.0, 0.0)
                        } else {
                            ((w[0] / area) as f32, (w[1] / area) as f32)
                        };
                        let b2 = 1.0 - b0 - b1;
                        let k = c[0] * b0 + c[1] * b1 + c[2] * b2;
                        [k.r, k.g, k.b, 1.0]
                    }
                    TriShade::Tex {
                        tex,
                        alpha_tex,
                        uvs,
                        lod,
                        psm,
                        lsm,
                        alpha,
                    } => {
                        let (b0, b1) = if area == 0.0 {
                            (1.0, 0.0)
                        } else if per_pixel {
                            let px = i / sc;
                            let hit = row_cache[px - px_lo];
                            if hit[3] >= 0.0 {
                                blend(&mut buf[j * cols + i], hit);
                                continue;
                            }
                            let (cx, cy) = (px as f64 + 0.5, f64::from(y0) + (j / sr) as f64 + 0.5);
                            let w0 = ef(edges[0].0, edges[0].1, cx, cy);
                            let w1 = ef(edges[1].0, edges[1].1, cx, cy);
                            ((w0 / area) as f32, (w1 / area) as f32)
                        } else {
                            ((w[0] / area) as f32, (w[1] / area) as f32)
                        };
                        let b2 = 1.0 - b0 - b1;
                        let uv = uvs[0] * b0 + uvs[1] * b1 + uvs[2] * b2;
                        let k = tex.sample_lod(uv, *lod, *psm, *lsm);
                        let cov = match alpha_tex {
                            Some(at) => at.sample_lod(uv, *lod, *psm, *lsm).r,
                            None => 1.0,
                        };
                        let c = [k.r * alpha, k.g * alpha, k.b * alpha, cov * alpha];
                        if per_pixel {
                            row_cache[i / sc - px_lo] = c;
                        }
                        c
                    }
                };
                blend(&mut buf[j * cols + i], color);
            }
        }
    }

    /// Box-filters the canvas layer into 8-bit straight-alpha pixels.
    fn resolve(&self, out: &mut [[u8; 4]], compat: bool) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
        let n = (sr * sc) as f32;
        let w = self.width as usize;
        let canvas = &self.layers[0];
        let mut acc = vec![[0f32; 4]; w];
        let stride = self.cols;
        for py in 0..self.rows_px as usize {
            // Sum the samples of every pixel in registers.
            let base = py * sr * stride;
            for (x, a) in acc.iter_mut().enumerate() {
                let mut sum = [0f32; 4];
                for j in 0..sr {
                    let start = base + j * stride + x * sc;
                    for s in &canvas[start..start + sc] {
                        sum = add4(sum, *s);
                    }
                }
                *a = sum;
            }
            let out_row = &mut out[py * w..(py + 1) * w];
            for (o, a) in out_row.iter_mut().zip(&acc) {
                if compat {
                    // The course's conversion: truncate channel * 255.
                    for c in 0..3 {
                        o[c] = ((a[c] / n) * 255.0).clamp(0.0, 255.0) as u8;
                    }
                    o[3] = 255;
                } else {
                    let alpha = a[3] / n;
                    if alpha <= 0.0 {
                        *o = [0, 0, 0, 0];
                        continue;
                    }
                    let k = 255.0 / (n * alpha);
                    // Round to nearest (`round()` is a libm call on baseline x86-64).
                    for c in 0..3 {
                        o[c] = ((a[c] * k).clamp(0.0, 255.0) + 0.5) as u8;
                    }
                    o[3] = (alpha.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                }
            }
        }
    }
}

/// Renders a document to straight-alpha RGBA8.
///
/// # Errors
/// [`RenderError`] for an output size, sample count or view outside the documented limits.
pub fn render(
    doc: &Document,
    opts: &RenderOptions,
) -> Result<(Rgba8Image, RenderStats), RenderError> {
    let (w, h) = (opts.width, opts.height);
    if w == 0 || h == 0 || w > MAX_DIMENSION || h > MAX_DIMENSION {
        return Err(RenderError::BadSize(w, h));
    }
    let r = sample_rate(opts.samples).ok_or(RenderError::BadSamples(opts.samples))? as usize;
    if let View::Region { cx, cy, span } = opts.view {
        if !(cx.is_finite() && cy.is_finite() && span.is_finite() && span > 0.0) {
            return Err(RenderError::BadView(cx, cy, span));
        }
    }
    let t0 = Instant::now();
    let view = view_transform(doc, opts);
    let prims = prepare(doc, opts, &view);
    let prepare_time = t0.elapsed();
    let t1 = Instant::now();
    // Regular r x r grid: it agreed better with analytic coverage (resvg) on the test suites
    // than n-rooks patterns did.
    let pat = Pattern::grid(r);
    let cols = w as usize * pat.sub_cols;
    // About 256 KiB of samples per band (and per layer of a band), to stay in L2.
    let band_rows = ((256usize << 10) / (cols * pat.sub_rows * 16)).clamp(1, 64);
    let mut pixels = vec![[0u8; 4]; w as usize * h as usize];
    let background = if opts.compat {
        [1.0, 1.0, 1.0, 1.0]
    } else {
        [0.0; 4]
    };
    let full = band_rows * pat.sub_rows * cols;
    let times: Vec<(Duration, Duration)> = pixels
        .par_chunks_mut(band_rows * w as usize)
        .enumerate()
        .map_init(
            // Sample buffers are reused from band to band on each thread.
            || Band {
                layers: Vec::new(),
                spare: Vec::new(),
                cols,
                y0: 0,
                rows_px: 0,
                pat: pat.clone(),
                width: w as i32,
            },
            |band, (bi, out)| {
                let ta = Instant::now();
                band.y0 = (bi * band_rows) as i32;
                band.rows_px = (out.len() / w as usize) as i32;
                let mut canvas = band.layers.pop().unwrap_or_else(|| vec![[0.0; 4]; full]);
                band.spare.append(&mut band.layers);
                canvas.fill(background);
                band.layers.push(canvas);
                let (y0, rows_px) = (band.y0, band.rows_px);
                for p in &prims {
                    if p.y1 > y0 && p.y0 < y0 + rows_px {
                        band.draw(p, opts.compat);
                    }
                }
                let tb = Instant::now();
                band.resolve(out, opts.compat);
                (tb - ta, tb.elapsed())
            },
        )
        .collect();
    let wall = t1.elapsed();
    let (rt, st): (Duration, Duration) = times
        .iter()
        .fold((Duration::ZERO, Duration::ZERO), |(a, b), (x, y)| {
            (a + *x, b + *y)
        });
    let total = (rt + st).as_secs_f64().max(1e-12);
    let stats = RenderStats {
        prepare: prepare_time,
        raster: wall.mul_f64(rt.as_secs_f64() / total),
        resolve: wall.mul_f64(st.as_secs_f64() / total),
    };
    Ok((Rgba8Image::from_vec(w, h, pixels), stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_rates() {
        assert_eq!(sample_rate(1), Some(1));
        assert_eq!(sample_rate(16), Some(4));
        assert_eq!(sample_rate(25), Some(5));
        assert_eq!(sample_rate(8), None);
        assert_eq!(sample_rate(0), None);
        assert_eq!(sample_rate(1024), None);
    }

    /// Course behaviour: a vertical line draws floor(|dy|) + 1 pixels; identical endpoints
    /// draw one pixel.
    #[test]
    fn dda_closed_forms() {
        let mut px = Vec::new();
        let d = DVec2::new;
        dda(d(3.5, 1.2), d(3.5, 6.7), 10, 10, &mut px);
        assert_eq!(px, (1..=6).map(|y| (3, y)).collect::<Vec<_>>());
        px.clear();
        dda(d(2.0, 2.0), d(2.0, 2.0), 10, 10, &mut px);
        assert_eq!(px, vec![(2, 2)]);
        px.clear();
        dda(d(0.0, 0.0), d(4.0, 2.0), 10, 10, &mut px);
        assert_eq!(px, vec![(0, 0), (1, 0), (2, 1), (3, 1), (4, 2)]);
        // Far outside: clipped, bounded work, only in-image pixels kept.
        px.clear();
        dda(d(-1e12, 5.0), d(1e12, 5.0), 10, 10, &mut px);
        assert_eq!(px, (0..10).map(|x| (x, 5)).collect::<Vec<_>>());
        px.clear();
        dda(d(-1e12, -1e12), d(-1e11, 3.0), 10, 10, &mut px);
        assert!(px.is_empty());
    }

    /// A deterministic pseudo-random stream for tests (SplitMix64).
    fn rng(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Property: a mesh of triangles tiling the image (jittered convex quads), with random
    /// diagonals and windings, covers every sample exactly once, both through the triangle rasterizer
    /// (top-left rule) and the path filler. Each triangle is drawn at 50% opacity in its
    /// own layer, so a doubly covered sample would show 75% and a crack 0%.
    #[test]
    fn shared_edges_are_watertight() {
        use crate::path::Path;
        for seed0 in 0..8u64 {
            let mut seed = seed0;
            let n = 7;
            let pts: Vec<Vec<DVec2>> = (0..=n)
                .map(|j| {
                    (0..=n)
                        .map(|i| {
                            let edge = |k: usize| k == 0 || k == n;
                            let jx = if edge(i) { 0.0 } else { rng(&mut seed) - 0.5 };
                            let jy = if edge(j) { 0.0 } else { rng(&mut seed) - 0.5 };
                            // Snapped to 1/8: samples then fall exactly on edges and
                            // vertices, so the tie-breaking rule is what is tested.
                            let snap = |v: f64| (v * 8.0).round() / 8.0;
                            DVec2::new(
                                snap(-4.0 + (i as f64 + jx * 0.4) * 48.0 / n as f64),
                                snap(-4.0 + (j as f64 + jy * 0.4) * 48.0 / n as f64),
                            )
                        })
                        .collect()
                })
                .collect();
            let mut tris = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (pts[j][i], pts[j][i + 1], pts[j + 1][i + 1], pts[j + 1][i]);
                    let pair = if rng(&mut seed) < 0.5 {
                        [[a, b, c], [a, c, d]]
                    } else {
                        [[a, b, d], [b, c, d]]
                    };
                    for mut t in pair {
                        if rng(&mut seed) < 0.5 {
                            t.swap(1, 2);
                        }
                        tris.push(t);
                    }
                }
            }
            for as_path in [false, true] {
                let mut doc = Document {
                    width: 40.0,
                    height: 40.0,
                    ..Document::default()
                };
                for t in &tris {
                    doc.items.push(Item::BeginLayer);
                    doc.items.push(if as_path {
                        Item::Fill {
                            path: Path::polygon(t, true),
                            transform: Mat3::IDENTITY,
                            rule: FillRule::NonZero,
                            paint: Paint::Solid(Rgb::new(1.0, 0.0, 0.0)),
                            opacity: 1.0,
                        }
                    } else {
                        Item::ColorTri {
                            points: *t,
                            colors: [Rgb::new(1.0, 0.0, 0.0); 3],
                            transform: Mat3::IDENTITY,
                        }
                    });
                    doc.items.push(Item::EndLayer { opacity: 0.5 });
                }
                for samples in [1, 16] {
                    let opts = RenderOptions {
                        width: 40,
                        height: 40,
                        samples,
                        ..RenderOptions::default()
                    };
                    let (img, _) = render(&doc, &opts).unwrap();
                    for (k, p) in img.pixels().iter().enumerate() {
                        assert_eq!(
                            p[3], 128,
                            "seed {seed0} path {as_path} spp {samples} pixel {k}: {p:?}"
                        );
                    }
                }
            }
        }
    }

    /// Regression (found by fuzzing): coordinates near the f64 range render without panics.
    #[test]
    fn huge_coordinates_do_not_panic() {
        use crate::{parse_svg, Dialect, Source};
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">
            <rect width="1e38" height="1e38" fill="red"/>
            <polygon points="0,0 1e38,5 5,1e38" fill="blue" stroke="green"/>
            <line x1="-1e38" y1="0" x2="1e38" y2="9" stroke="black"/>
            <colortri points="0 0 1e38 0 0 1e38" colors="1 0 0 1 0 1 0 1 0 0 1 1"/>
            <path d="M0 0 C1e38 0 0 1e38 5 5 Z" stroke="red" stroke-width="1e38"/></svg>"#;
        for dialect in [Dialect::Svg, Dialect::Cs184] {
            let doc = parse_svg(svg, dialect, &Source::default()).unwrap();
            let opts = RenderOptions {
                width: 16,
                height: 16,
                samples: 4,
                compat: dialect == Dialect::Cs184,
                ..RenderOptions::default()
            };
            render(&doc, &opts).unwrap();
        }
    }

    #[test]
    fn radial_t_is_distance_ratio_for_centred_focus() {
        let c = DVec2::new(5.0, 5.0);
        assert!((radial_t(DVec2::new(8.0, 5.0), c, 6.0, c) - 0.5).abs() < 1e-12);
        assert!((radial_t(c, c, 6.0, c)).abs() < 1e-12);
    }
}
