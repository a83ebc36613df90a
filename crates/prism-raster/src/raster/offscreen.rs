//! What is drawn offscreen before the bands run: pattern tiles (rendered once, then
//! sampled as a repeating paint) and filtered groups (rendered into their region, filtered,
//! then placed as pixels).

use prism_math::{DAffine2, DVec2};

use super::options::RasterOptions;
use crate::document::{Document, Item, Mat3, Pattern};
use crate::filter::Filtered;

/// Renders items of a document through a view into premultiplied pixels of
/// `opts.width` x `opts.height` (the rasterizer's own offscreen entry, handed in so that
/// this file needs nothing above it).
pub(super) type SubRender = fn(&Document, &[Item], &RasterOptions, &Mat3) -> Vec<[f32; 4]>;

/// A filtered group's pixels: `w` wide, the top-left one at device pixel `(x0, y0)`.
pub(super) struct Raster {
    pub(super) x0: i32,
    pub(super) y0: i32,
    pub(super) w: usize,
    pub(super) px: Vec<[f32; 4]>,
}

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

/// The pattern's tile rendered at the device scale of `m` (the painted element's user
/// space to device), and the map from device pixels to tile pixels; `None` when the tile
/// has no area.
pub(super) fn pattern_tile(
    doc: &Document,
    p: &Pattern,
    m: &Mat3,
    opts: &RasterOptions,
    render: SubRender,
) -> Option<(Tile, DAffine2)> {
    let full = m.mul(&p.transform).to_affine();
    let (mut sx, mut sy) = crate::filter::scale_of(&full);
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
    let px = render(doc, &p.items, &tile_opts, &Mat3::scale(sx, sy));
    let to_device = full
        * DAffine2::from_translation(DVec2::new(rx, ry))
        * DAffine2::from_scale(DVec2::new(1.0 / sx, 1.0 / sy));
    let det = to_device.matrix2.determinant();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let m2 = to_device.matrix2;
    let nearest = (m2.x_axis - DVec2::X).length() < 1e-9 && (m2.y_axis - DVec2::Y).length() < 1e-9;
    let tile = Tile {
        w: tw as usize,
        h: th as usize,
        px,
        nearest,
    };
    Some((tile, to_device.inverse()))
}

/// A filtered group: its content rendered over its filter region (clipped to the image
/// grown by half its size on each side) and filtered; `None` when that region is empty.
pub(super) fn filtered(
    doc: &Document,
    f: &Filtered,
    view: &Mat3,
    opts: &RasterOptions,
    render: SubRender,
) -> Option<Raster> {
    let m = view.mul(&f.transform).to_affine();
    let [x, y, w, h] = f.region;
    let pts = [(x, y), (x + w, y), (x, y + h), (x + w, y + h)]
        .map(|(a, b)| m.transform_point2(DVec2::new(a, b)));
    let lo = pts.iter().fold(pts[0], |a, b| a.min(*b));
    let hi = pts.iter().fold(pts[0], |a, b| a.max(*b));
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let (cw, ch) = (f64::from(opts.width), f64::from(opts.height));
    let x0 = lo.x.floor().max(-cw / 2.0);
    let y0 = lo.y.floor().max(-ch / 2.0);
    let x1 = hi.x.ceil().min(1.5 * cw);
    let y1 = hi.y.ceil().min(1.5 * ch);
    if x1 <= x0 || y1 <= y0 {
        return None;
    }
    let (rw, rh) = ((x1 - x0) as u32, (y1 - y0) as u32);
    let sub = RasterOptions {
        width: rw,
        height: rh,
        ..opts.clone()
    };
    let shift = Mat3::translate(-x0, -y0);
    let content = render(doc, &f.items, &sub, &shift.mul(view));
    let ts = shift.mul(view).mul(&f.transform).to_affine();
    let draw = |items: &[Item], v: &Mat3| render(doc, items, &sub, v);
    let px = crate::filter::apply(f, content, rw as usize, rh as usize, &ts, &draw);
    Some(Raster {
        x0: x0 as i32,
        y0: y0 as i32,
        w: rw as usize,
        px,
    })
}
