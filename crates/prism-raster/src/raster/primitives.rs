//! Device-space primitives (edges, triangles, pixel lists, layer markers), each with the
//! pixel box it can touch, and their preparation from document items.

use std::sync::Arc;

use prism_image::{LevelSampling, PixelSampling, Texture};
use prism_math::{DVec2, Rgb, Vec2};
use rayon::prelude::*;

use super::edges::{edges_of, Edge, Edges};
use super::offscreen::{filtered, pattern_tile, SubRender, Tile};
use super::options::{RasterOptions, TOLERANCE};
use crate::document::{
    BlendMode, Document, FillRule, Gradient, GradientKind, Item, MaskKind, Mat3, Paint, Spread,
};
use crate::path::{stroke, Path, StrokeStyle};

/// A paint resolved to device space.
#[derive(Clone, Debug)]
pub(super) enum DevPaint {
    Solid([f32; 4]),
    Gradient {
        g: Arc<Gradient>,
        /// Device pixel to gradient space.
        inv: prism_math::DAffine2,
        /// Premultiplied colours for `t = i / (LUT_SIZE - 1)`.
        lut: Vec<[f32; 4]>,
    },
    /// A repeated tile, sampled bilinearly.
    Pattern {
        tile: Arc<Tile>,
        /// Device pixel to tile pixel.
        inv: prism_math::DAffine2,
        opacity: f32,
    },
}

/// Entries in a gradient's colour table: `t` in [0, 1] is quantised to 1/1023.
pub(super) const LUT_SIZE: usize = 1024;

/// Premultiplied colour of a gradient's stops at `t` in [0, 1], times `opacity`; colours
/// interpolate in stored (sRGB) values, as SVG specifies.
pub(super) fn stop_color(g: &Gradient, t: f32, opacity: f32) -> [f32; 4] {
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

    pub(super) fn at(&self, x: f64, y: f64) -> [f32; 4] {
        match self {
            DevPaint::Solid(c) => *c,
            DevPaint::Pattern { tile, inv, opacity } => {
                let p = inv.transform_point2(DVec2::new(x, y));
                tile.sample(p).map(|v| v * opacity)
            }
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
                        focal_radius,
                    } => {
                        if focal_radius > 0.0 {
                            conical_t(p, center, radius, focus, focal_radius)
                        } else {
                            radial_t(p, center, radius, focus)
                        }
                    }
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
pub(super) fn radial_t(p: DVec2, center: DVec2, radius: f64, focus: DVec2) -> f64 {
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

/// The gradient parameter of `p` for the two-point conical gradient from the circle
/// (`focus`, `fr`) at 0 to (`center`, `radius`) at 1: the largest `t` whose circle, of
/// non-negative radius, passes through `p`.
pub(super) fn conical_t(p: DVec2, center: DVec2, radius: f64, focus: DVec2, fr: f64) -> f64 {
    let (cd, pd, dr) = (center - focus, p - focus, radius - fr);
    // |pd - t cd| = fr + t dr, squared: a t^2 - 2 b t + c = 0.
    let a = cd.length_squared() - dr * dr;
    let b = pd.dot(cd) + fr * dr;
    let c = pd.length_squared() - fr * fr;
    let ok = |t: f64| fr + t * dr >= 0.0;
    if a.abs() < 1e-12 {
        let t = if b.abs() < 1e-12 { 0.0 } else { c / (2.0 * b) };
        return if ok(t) { t } else { 0.0 };
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return 0.0;
    }
    let s = disc.sqrt();
    let (t1, t2) = ((b + s) / a, (b - s) / a);
    let (hi, lo) = (t1.max(t2), t1.min(t2));
    if ok(hi) {
        hi
    } else if ok(lo) {
        lo
    } else {
        0.0
    }
}

#[derive(Clone, Debug)]
pub(super) enum TriShade {
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
pub(super) enum Prim {
    Tri {
        v: [DVec2; 3],
        inclusive: bool,
        shade: TriShade,
    },
    Poly {
        /// Sorted by `y0`.
        edges: Edges,
        rule: FillRule,
        paint: DevPaint,
    },
    Pixels {
        px: Vec<(i32, i32)>,
        color: [f32; 4],
    },
    /// A premultiplied image aligned to the pixel grid: `w` pixels wide, its top-left pixel
    /// at `(x0, y0)`; every sample of a pixel takes the pixel's colour.
    Raster {
        x0: i32,
        y0: i32,
        w: usize,
        px: Arc<Vec<[f32; 4]>>,
    },
    BeginLayer,
    EndLayer(f32, BlendMode),
    ClipEnd,
    MaskEnd(MaskKind),
}

/// A primitive with the pixel rows `[y0, y1)` and columns `[x0, x1)` it can touch.
#[derive(Clone, Debug)]
pub(super) struct Placed {
    pub(super) y0: i32,
    pub(super) y1: i32,
    pub(super) x0: i32,
    pub(super) x1: i32,
    pub(super) prim: Prim,
}

pub(super) fn solid(c: Rgb, a: f32) -> [f32; 4] {
    [c.r * a, c.g * a, c.b * a, a]
}

/// Pixels within this distance outside the image still run the course's exact DDA; longer
/// lines are first clipped to the image grown by this margin.
pub(super) const DDA_MARGIN: f64 = 4096.0;

/// Clips the segment to the rectangle `[lo, hi]` (Liang-Barsky); `None` if it misses.
pub(super) fn clip_segment(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> Option<(DVec2, DVec2)> {
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
pub(super) fn dda(a: DVec2, b: DVec2, width: i32, height: i32, out: &mut Vec<(i32, i32)>) {
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

pub(super) fn to_f32(p: DVec2) -> (f32, f32) {
    (p.x as f32, p.y as f32)
}

/// Turns document items into device primitives.
pub(super) fn prepare(
    doc: &Document,
    items: &[Item],
    opts: &RasterOptions,
    view: &Mat3,
    render: SubRender,
) -> Vec<Placed> {
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
    let place_poly = |mut edges: Vec<Edge>, rule: FillRule, paint: DevPaint| -> Option<Placed> {
        if edges.is_empty() {
            return None;
        }
        // Top to bottom, so a band sweeps them in order.
        edges.sort_unstable_by(|a, b| a.y0.total_cmp(&b.y0));
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
            prim: Prim::Poly {
                edges: Edges::new(&edges),
                rule,
                paint,
            },
        })
    };
    let dev_paint = |paint: &Paint, m: &Mat3, opacity: f32| -> Option<DevPaint> {
        match paint {
            Paint::Pattern(p) => {
                let (tile, inv) = pattern_tile(doc, p, m, opts, render)?;
                Some(DevPaint::Pattern {
                    tile: Arc::new(tile),
                    inv,
                    opacity,
                })
            }
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
    // The device box whose pixels are drawn, with a margin for sub-pixel overhang.
    let visible = (
        DVec2::splat(-2.0),
        DVec2::new(opts.width as f64 + 2.0, opts.height as f64 + 2.0),
    );
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
                let lines = dpath.flatten_within(TOLERANCE, Some(visible));
                let edges = edges_of(lines.iter().map(|l| &l.points[..]));
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
                // The visible box in the path's own space, grown by how far a stroke
                // (with its joins) reaches.
                let inv = affine.inverse();
                let reach = style.width * style.miter_limit.max(1.0) + 1.0;
                let corners = [
                    visible.0,
                    DVec2::new(visible.1.x, visible.0.y),
                    DVec2::new(visible.0.x, visible.1.y),
                    visible.1,
                ]
                .map(|c| inv.transform_point2(c));
                let lo = corners.iter().fold(corners[0], |a, b| a.min(*b)) - reach;
                let hi = corners.iter().fold(corners[0], |a, b| a.max(*b)) + reach;
                let keep = (lo.is_finite() && hi.is_finite()).then_some((lo, hi));
                let mut polys = stroke(&path.flatten_within(tol, keep), style, tol);
                for q in polys.iter_mut().flatten() {
                    *q = affine.transform_point2(*q);
                }
                let edges = edges_of(polys.iter().map(|p| &p[..]));
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
                sampling,
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
                // An image whose texels land one to one on whole pixels is copied, not
                // filtered (as Skia drops filtering for an integer translation).
                let (tw, th) = doc.textures[*texture].size();
                let ex = (d[1] - d[0]) - DVec2::new(f64::from(tw), 0.0);
                let ey = (d[2] - d[0]) - DVec2::new(0.0, f64::from(th));
                let whole = |v: f64| (v - v.round()).abs() < 1e-6;
                let aligned =
                    ex.length() < 1e-6 && ey.length() < 1e-6 && whole(d[0].x) && whole(d[0].y);
                let sampling = if aligned {
                    PixelSampling::Nearest
                } else {
                    *sampling
                };
                for (a, b, cc) in [(0, 1, 2), (2, 1, 3)] {
                    let v = [d[a], d[b], d[cc]];
                    let shade = tex_shade(
                        *texture,
                        v,
                        [uv[a], uv[b], uv[cc]],
                        sampling,
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
            Item::EndLayer { opacity, blend } => out.push(Placed {
                y0: 0,
                y1: 0,
                x0: 0,
                x1: 0,
                prim: Prim::EndLayer(*opacity, *blend),
            }),
            Item::ClipEnd => out.push(Placed {
                y0: 0,
                y1: 0,
                x0: 0,
                x1: 0,
                prim: Prim::ClipEnd,
            }),
            Item::MaskEnd(kind) => out.push(Placed {
                y0: 0,
                y1: 0,
                x0: 0,
                x1: 0,
                prim: Prim::MaskEnd(*kind),
            }),
            Item::Filtered(f) => {
                let Some(r) = filtered(doc, f, view, opts, render) else {
                    return out;
                };
                let h = (r.px.len() / r.w.max(1)) as i32;
                let rows = (r.y0.max(0), (r.y0 + h).min(opts.height as i32));
                let cols = (r.x0.max(0), (r.x0 + r.w as i32).min(opts.width as i32));
                if rows.1 > rows.0 && cols.1 > cols.0 {
                    out.push(Placed {
                        y0: rows.0,
                        y1: rows.1,
                        x0: cols.0,
                        x1: cols.1,
                        prim: Prim::Raster {
                            x0: r.x0,
                            y0: r.y0,
                            w: r.w,
                            px: Arc::new(r.px),
                        },
                    });
                }
            }
        }
        out
    };
    let mut prims: Vec<Placed> = items.par_iter().map(per_item).flatten_iter().collect();
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

/// Gives every layer the bounding box of what it contains (a clip or mask layer: the box
/// of what it clips), so bands skip empty layers and layer clearing and compositing touch
/// only that box; then limits every primitive to the box of each layer around it, so that
/// a band that skips a layer skips all of its content.
pub(super) fn bound_layers(prims: &mut [Placed]) {
    box_layers(prims);
    let mut stack: Vec<(i32, i32, i32, i32)> = Vec::new();
    for p in prims.iter_mut() {
        let opens = matches!(p.prim, Prim::BeginLayer);
        let closes = matches!(
            p.prim,
            Prim::EndLayer(..) | Prim::ClipEnd | Prim::MaskEnd(_)
        );
        if closes {
            stack.pop();
        }
        if let Some(&(y0, y1, x0, x1)) = stack.last() {
            p.y0 = p.y0.max(y0);
            p.y1 = p.y1.min(y1);
            p.x0 = p.x0.max(x0);
            p.x1 = p.x1.min(x1);
            if p.y1 <= p.y0 || p.x1 <= p.x0 {
                (p.y0, p.y1, p.x0, p.x1) = (0, 0, 0, 0);
            }
        }
        if opens {
            stack.push((p.y0, p.y1, p.x0, p.x1));
        }
    }
}

/// Gives the primitives at `at` the box `(y0, y1, x0, x1)`, or the empty box when it has
/// no area; returns the box given.
fn set_box(prims: &mut [Placed], at: [usize; 2], b: (i32, i32, i32, i32)) -> (i32, i32, i32, i32) {
    let b = if b.0 < b.1 && b.2 < b.3 {
        b
    } else {
        (0, 0, 0, 0)
    };
    for k in at {
        (prims[k].y0, prims[k].y1, prims[k].x0, prims[k].x1) = b;
    }
    b
}

fn box_layers(prims: &mut [Placed]) {
    let empty = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
    let mut stack: Vec<(usize, (i32, i32, i32, i32))> = Vec::new();
    let mut cur = empty;
    for i in 0..prims.len() {
        match prims[i].prim {
            Prim::BeginLayer => {
                stack.push((i, cur));
                cur = empty;
            }
            Prim::ClipEnd | Prim::MaskEnd(_) => {
                // A clip or mask layer covers the whole box of what it clips (outside its
                // own shapes it removes everything), and the box does not grow.
                let Some((b, outer)) = stack.pop() else {
                    continue;
                };
                set_box(prims, [b, i], outer);
                cur = outer;
            }
            Prim::EndLayer(..) => {
                let Some((b, outer)) = stack.pop() else {
                    continue;
                };
                let inner = set_box(prims, [b, i], cur);
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
