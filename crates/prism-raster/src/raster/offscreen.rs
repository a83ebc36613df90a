//! What is drawn offscreen before the bands run: pattern tiles (rendered once, then
//! sampled as a repeating paint) and filtered groups (rendered into their region, filtered,
//! then placed as pixels).

use std::sync::Arc;

use prism_math::{DAffine2, DVec2};

use super::options::RasterOptions;
use super::primitives::{DevPaint, Placed, Prim};
use super::render_premultiplied;
use crate::document::{Document, Mat3, Pattern};
use crate::filter::Filtered;

/// The most pixels a pattern tile is rendered with; larger tiles are drawn at a lower
/// resolution and magnified.
pub(super) const MAX_TILE_PIXELS: f64 = 4_194_304.0;

/// A rendered pattern tile: premultiplied pixels, repeated in both directions.
#[derive(Debug)]
pub(super) struct Tile {
    w: usize,
    h: usize,
    px: Vec<[f32; 4]>,
    /// Whether tile pixels map one to one onto device pixels (only shifted): then the
    /// nearest pixel is taken, as Skia does, and no blur is added.
    nearest: bool,
}

impl Tile {
    /// The bilinear sample at tile pixel coordinates `p` (pixel centres at half integers),
    /// wrapping around.
    pub(super) fn sample(&self, p: DVec2) -> [f32; 4] {
        let (u, v) = (p.x - 0.5, p.y - 0.5);
        if !(u.is_finite() && v.is_finite()) {
            return [0.0; 4];
        }
        if self.nearest {
            let x = (p.x.floor() as i64).rem_euclid(self.w as i64);
            let y = (p.y.floor() as i64).rem_euclid(self.h as i64);
            return self.px[y as usize * self.w + x as usize];
        }
        let (fu, fv) = (u.floor(), v.floor());
        let (tx, ty) = ((u - fu) as f32, (v - fv) as f32);
        let (w, h) = (self.w as i64, self.h as i64);
        let x0 = (fu as i64).rem_euclid(w);
        let y0 = (fv as i64).rem_euclid(h);
        let (x1, y1) = ((x0 + 1) % w, (y0 + 1) % h);
        let at = |x: i64, y: i64| self.px[(y * w + x) as usize];
        let (a, b, c, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * tx;
            let bottom = c[k] + (d[k] - c[k]) * tx;
            top + (bottom - top) * ty
        })
    }
}

/// The pattern as a device paint under `m` (the painted element's user space to device),
/// its tile rendered at the device scale; `None` when the tile has no area.
pub(super) fn pattern_paint(
    doc: &Document,
    p: &Pattern,
    m: &Mat3,
    opacity: f32,
    opts: &RasterOptions,
) -> Option<DevPaint> {
    let full = m.mul(&p.transform).to_affine();
    let (mut sx, mut sy) = (full.matrix2.x_axis.length(), full.matrix2.y_axis.length());
    let [rx, ry, rw, rh] = p.rect;
    if !(sx > 0.0 && sy > 0.0 && rw > 0.0 && rh > 0.0 && (sx * sy * rw * rh).is_finite()) {
        return None;
    }
    let area = rw * sx * rh * sy;
    if area > MAX_TILE_PIXELS {
        let k = (MAX_TILE_PIXELS / area).sqrt();
        sx *= k;
        sy *= k;
    }
    let (tw, th) = ((rw * sx).round().max(1.0), (rh * sy).round().max(1.0));
    let tile_opts = RasterOptions {
        width: tw as u32,
        height: th as u32,
        ..opts.clone()
    };
    let px = render_premultiplied(doc, &p.items, &tile_opts, &Mat3::scale(sx, sy));
    let to_device = full
        * DAffine2::from_translation(DVec2::new(rx, ry))
        * DAffine2::from_scale(DVec2::new(1.0 / sx, 1.0 / sy));
    let det = to_device.matrix2.determinant();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let m2 = to_device.matrix2;
    let nearest = (m2.x_axis - DVec2::X).length() < 1e-9 && (m2.y_axis - DVec2::Y).length() < 1e-9;
    Some(DevPaint::Pattern {
        tile: Arc::new(Tile {
            w: tw as usize,
            h: th as usize,
            px,
            nearest,
        }),
        inv: to_device.inverse(),
        opacity,
    })
}

/// A filtered group: its content rendered over its filter region (clipped to the image
/// grown by half its size on each side), filtered, and placed as pixels.
pub(super) fn filtered(
    doc: &Document,
    f: &Filtered,
    view: &Mat3,
    opts: &RasterOptions,
) -> Vec<Placed> {
    let m = view.mul(&f.transform).to_affine();
    let [x, y, w, h] = f.region;
    let pts = [(x, y), (x + w, y), (x, y + h), (x + w, y + h)]
        .map(|(a, b)| m.transform_point2(DVec2::new(a, b)));
    let lo = pts.iter().fold(pts[0], |a, b| a.min(*b));
    let hi = pts.iter().fold(pts[0], |a, b| a.max(*b));
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let (cw, ch) = (f64::from(opts.width), f64::from(opts.height));
    let x0 = lo.x.floor().max(-cw / 2.0);
    let y0 = lo.y.floor().max(-ch / 2.0);
    let x1 = hi.x.ceil().min(1.5 * cw);
    let y1 = hi.y.ceil().min(1.5 * ch);
    if x1 <= x0 || y1 <= y0 {
        return Vec::new();
    }
    let (rw, rh) = ((x1 - x0) as u32, (y1 - y0) as u32);
    let sub = RasterOptions {
        width: rw,
        height: rh,
        ..opts.clone()
    };
    let shift = Mat3::translate(-x0, -y0);
    let content = render_premultiplied(doc, &f.items, &sub, &shift.mul(view));
    let ts = shift.mul(view).mul(&f.transform).to_affine();
    let draw =
        |items: &[crate::document::Item], v: &Mat3| render_premultiplied(doc, items, &sub, v);
    let px = crate::filter::apply(f, content, rw as usize, rh as usize, &ts, &draw);
    let (ix, iy) = (x0 as i32, y0 as i32);
    let rows = (iy.max(0), (iy + rh as i32).min(opts.height as i32));
    let cols = (ix.max(0), (ix + rw as i32).min(opts.width as i32));
    if rows.1 <= rows.0 || cols.1 <= cols.0 {
        return Vec::new();
    }
    vec![Placed {
        y0: rows.0,
        y1: rows.1,
        x0: cols.0,
        x1: cols.1,
        prim: Prim::Raster {
            x0: ix,
            y0: iy,
            w: rw as usize,
            px: Arc::new(px),
        },
    }]
}
