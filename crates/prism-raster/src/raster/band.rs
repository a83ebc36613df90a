//! Bands: a horizontal strip of the image as a stack of sample planes, the sample-level
//! drawing of every primitive kind, layers, and the box-filter resolve.

use prism_math::DVec2;

use super::edges::{Edge, Edges};
use super::plane::{Cover, Plane};
use super::primitives::{DevPaint, Placed, Prim, TriShade};
use super::resolve::Resolver;
use crate::blend::{composite, over as blend};
use crate::document::{BlendMode, FillRule, MaskKind};

/// The course renderer's translucent blend: both colours truncated to 8 bits, mixed as
/// `a * src + (1 - a) * dst` in `f32` on the 0..255 scale, truncated again. Opaque targets
/// only (the course's canvas is always opaque).
pub(super) fn blend_8bit(dst: &mut [f32; 4], src: [f32; 4]) {
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

/// Where the samples of a pixel lie. Each pixel row is split into `sub_rows` sample rows;
/// sample row `j` holds `sub_cols` samples per pixel, the first at x offset `xoff[j]` and
/// the others `1 / sub_cols` apart. Sample `k` of sample row `j` (counted across the band)
/// sits at `x = k / sub_cols + xoff[j % sub_rows]`, `y = y0 + (j + 0.5) / sub_rows`.
#[derive(Clone, Debug)]
pub(super) struct Pattern {
    pub(super) sub_rows: usize,
    pub(super) sub_cols: usize,
    pub(super) xoff: Vec<f64>,
}

impl Pattern {
    /// The regular r x r grid at `((i + 0.5) / r, (j + 0.5) / r)`, as the course uses.
    pub(super) fn grid(r: usize) -> Pattern {
        Pattern {
            sub_rows: r,
            sub_cols: r,
            xoff: vec![0.5 / r as f64; r],
        }
    }
}

/// One band: `rows_px` pixel rows of `width` pixels, each of `sub_rows * sub_cols` samples,
/// held as a stack of planes (the bottom one is the band's canvas).
pub(super) struct Band {
    layers: Vec<Plane>,
    spare: Vec<Plane>,
    cover: Cover,
    resolver: Resolver,
    /// Scratch for polygons: the active edges and a sample row's crossings.
    active: Vec<Edge>,
    crossings: Vec<(f64, i32)>,
    /// Pixels a plane holds (the most pixel rows a band has, times the width).
    capacity: usize,
    /// Sample columns across the band.
    cols: usize,
    /// First pixel row of the band.
    y0: i32,
    /// Pixel rows in the band.
    rows_px: i32,
    pat: Pattern,
    width: i32,
}

impl Band {
    /// An empty band of at most `max_rows` pixel rows of `width` pixels.
    pub(super) fn new(width: i32, max_rows: usize, pat: Pattern) -> Band {
        Band {
            layers: Vec::new(),
            spare: Vec::new(),
            cover: Cover::default(),
            resolver: Resolver::default(),
            active: Vec::new(),
            crossings: Vec::new(),
            capacity: max_rows * width as usize,
            cols: width as usize * pat.sub_cols,
            y0: 0,
            rows_px: 0,
            pat,
            width,
        }
    }

    /// Makes this band pixel rows `[y0, y0 + rows_px)`, every sample `background`.
    pub(super) fn start(&mut self, y0: i32, rows_px: i32, background: [f32; 4]) {
        self.y0 = y0;
        self.rows_px = rows_px;
        while self.layers.len() > 1 {
            let mut plane = self.layers.pop().expect("checked");
            plane.reset();
            self.spare.push(plane);
        }
        let n = self.pat.sub_rows * self.pat.sub_cols;
        let mut canvas = self
            .layers
            .pop()
            .unwrap_or_else(|| Plane::new(self.capacity, n));
        canvas.reset();
        canvas.fill(0..rows_px as usize * self.width as usize, background);
        self.layers.push(canvas);
    }

    fn top(&mut self) -> &mut Plane {
        self.layers.last_mut().expect("band has a canvas")
    }

    fn sample_y(&self, j: usize) -> f64 {
        f64::from(self.y0) + (j as f64 + 0.5) / self.pat.sub_rows as f64
    }

    /// Pixel ranges of a placed box within this band, one per pixel row.
    fn region(&self, pl: &Placed) -> impl Iterator<Item = std::ops::Range<usize>> {
        region(self.width, self.y0, self.rows_px, pl)
    }

    pub(super) fn draw(&mut self, pl: &Placed, compat: bool) {
        let p = &pl.prim;
        match p {
            Prim::BeginLayer => {
                let n = self.pat.sub_rows * self.pat.sub_cols;
                let capacity = self.capacity;
                let mut plane = self.spare.pop().unwrap_or_else(|| Plane::new(capacity, n));
                for range in self.region(pl) {
                    plane.fill(range, [0.0; 4]);
                }
                self.layers.push(plane);
            }
            Prim::EndLayer(op, mode) => {
                let op = *op;
                self.end_layer(pl, |d, s| {
                    let s = [s[0] * op, s[1] * op, s[2] * op, s[3] * op];
                    if *mode == BlendMode::Normal {
                        blend(d, s);
                    } else {
                        composite(d, s, *mode);
                    }
                });
            }
            Prim::ClipEnd => self.end_layer(pl, |d, s| {
                let k = s[3].min(1.0);
                *d = [d[0] * k, d[1] * k, d[2] * k, d[3] * k];
            }),
            Prim::MaskEnd(kind) => self.end_layer(pl, |d, s| {
                let k = match kind {
                    MaskKind::Alpha => s[3],
                    MaskKind::Luminance => 0.2125 * s[0] + 0.7154 * s[1] + 0.0721 * s[2],
                }
                .clamp(0.0, 1.0);
                *d = [d[0] * k, d[1] * k, d[2] * k, d[3] * k];
            }),
            Prim::Raster { x0, y0, w, px } => {
                let (by0, rows_px, width) = (self.y0, self.rows_px, self.width);
                let h = (px.len() / w.max(&1)) as i32;
                let ya = (*y0).max(by0);
                let yb = (y0 + h).min(by0 + rows_px);
                let xa = (*x0).max(0);
                let xb = (x0 + *w as i32).min(width);
                let plane = self.top();
                for y in ya..yb {
                    let src_row = (y - y0) as usize * w;
                    let row = (y - by0) as usize * width as usize;
                    for x in xa..xb {
                        plane.over(row + x as usize, px[src_row + (x - x0) as usize]);
                    }
                }
            }
            Prim::Pixels { px, color } => {
                let (y0, y1, w) = (self.y0, self.y0 + self.rows_px, self.width as usize);
                let plane = self.top();
                for &(x, y) in px {
                    if y < y0 || y >= y1 {
                        continue;
                    }
                    let p = (y - y0) as usize * w + x as usize;
                    if compat && color[3] < 1.0 {
                        plane.each(p, |s| blend_8bit(s, *color));
                    } else {
                        plane.over(p, *color);
                    }
                }
            }
            Prim::Poly { edges, rule, paint } => self.poly(edges, *rule, paint, compat),
            Prim::Tri {
                v,
                inclusive,
                shade,
            } => self.tri(v, *inclusive, shade, compat),
        }
    }

    /// Pops the top layer and combines each of its samples in the placed box into the
    /// layer below with `f(below, top)`.
    fn end_layer(&mut self, pl: &Placed, f: impl Fn(&mut [f32; 4], [f32; 4])) {
        if self.layers.len() < 2 {
            return;
        }
        let mut src = self.layers.pop().expect("checked");
        let (w, y0, rows_px) = (self.width, self.y0, self.rows_px);
        let dst = self.layers.last_mut().expect("band has a canvas");
        for range in region(w, y0, rows_px, pl) {
            dst.combine(&src, range, &f);
        }
        src.reset();
        self.spare.push(src);
    }

    /// Fills a polygon. A sample on an edge belongs to one side only: in compat mode the
    /// left and top edges own it (`y0 <= y < y1`); otherwise the right and bottom edges do
    /// (`y0 < y <= y1`), which is tiny-skia's rule, so that edges on the sample grid cover
    /// what resvg covers.
    fn poly(&mut self, edges: &Edges, rule: FillRule, paint: &DevPaint, compat: bool) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols as f64);
        let band_hi = f64::from(self.y0 + self.rows_px);
        // Edges sorted by their top; those reaching into the band become active at their
        // first sample row and leave after their last.
        let end = edges.starting_above(band_hi);
        let mut next = 0;
        let mut active = std::mem::take(&mut self.active);
        let mut xs = std::mem::take(&mut self.crossings);
        active.clear();
        let cols = self.cols;
        for py in 0..self.rows_px as usize {
            self.cover.clear();
            for j in py * sr..(py + 1) * sr {
                let y = self.sample_y(j);
                let xo = self.pat.xoff[j % sr];
                // An edge owns the sample rows with y0 <= y < y1 (compat) or y0 < y <= y1.
                let starts = |e: &Edge| if compat { e.y0 <= y } else { e.y0 < y };
                let ended = |e: &Edge| if compat { e.y1 <= y } else { e.y1 < y };
                while next < end {
                    let e = edges.get(next);
                    if !starts(&e) {
                        break;
                    }
                    if !ended(&e) {
                        active.push(e);
                    }
                    next += 1;
                }
                active.retain(|e| !ended(e));
                xs.clear();
                xs.extend(active.iter().map(|e| (e.x0 + (y - e.y0) * e.dxdy, e.dir)));
                if xs.len() >= 2 {
                    xs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                    let mut wind = 0;
                    for k in 0..xs.len() - 1 {
                        wind += xs[k].1;
                        let inside = match rule {
                            FillRule::NonZero => wind != 0,
                            FillRule::EvenOdd => wind % 2 != 0,
                        };
                        if inside {
                            self.cover.push(
                                first_sample(xs[k].0, xo, sc, cols, compat),
                                first_sample(xs[k + 1].0, xo, sc, cols, compat),
                            );
                        }
                    }
                }
                self.cover.end_row();
            }
            if self.cover.is_empty() {
                continue;
            }
            // Gradients and patterns are evaluated once per pixel, at its centre, and the
            // colour given to every covered sample (as multisampling shades).
            let y_centre = f64::from(self.y0) + py as f64 + 0.5;
            let plane = self.layers.last_mut().expect("canvas");
            let (w, sci) = (self.width as usize, self.pat.sub_cols);
            let uniform = match paint {
                DevPaint::Solid(c) => Some(*c),
                _ => None,
            };
            self.cover
                .paint(plane, py, w, sci, uniform, |x| match paint {
                    DevPaint::Solid(c) => *c,
                    g => g.at(x as f64 + 0.5, y_centre),
                });
        }
        self.active = active;
        self.crossings = xs;
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
        let (y0, width) = (self.y0, self.width as usize);
        // Solid triangles, and textures in standard mode (shaded once per pixel, at its
        // centre, the colour given to every covered sample, as multisampling does), paint
        // a cover; the course shades every sample.
        let per_pixel = !compat && matches!(shade, TriShade::Tex { .. });
        let by_pixel = per_pixel || matches!(shade, TriShade::Solid(_));
        let fast_interior = !compat && by_pixel;
        // The colour at barycentrics (b0, b1) (texture triangles).
        let shade_at = |b0: f32, b1: f32| -> [f32; 4] {
            let b2 = 1.0 - b0 - b1;
            match shade {
                TriShade::Solid(c) => *c,
                TriShade::Color(c) => {
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
                    let uv = uvs[0] * b0 + uvs[1] * b1 + uvs[2] * b2;
                    let k = tex.sample_lod(uv, *lod, *psm, *lsm);
                    let cov = match alpha_tex {
                        Some(at) => at.sample_lod(uv, *lod, *psm, *lsm).r,
                        None => 1.0,
                    };
                    [k.r * alpha, k.g * alpha, k.b * alpha, cov * alpha]
                }
            }
        };
        let bary = |w0: f64, w1: f64| {
            if area == 0.0 {
                (1.0, 0.0)
            } else {
                ((w0 / area) as f32, (w1 / area) as f32)
            }
        };
        let Band {
            layers, cover, pat, ..
        } = self;
        let plane = layers.last_mut().expect("canvas");
        for py in j_lo / sr..(j_hi - 1) / sr + 1 {
            cover.clear();
            for j in (py * sr).max(j_lo)..((py + 1) * sr).min(j_hi) {
                let s = j % sr;
                while cover.rows() < s {
                    cover.end_row();
                }
                let xo = pat.xoff[s];
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
                // Samples more than one sample spacing inside all three edge lines need no
                // edge test (standard mode, and only when the shading is per pixel).
                let (in_lo, in_hi) = if fast_interior && xl.is_finite() && xr.is_finite() {
                    (
                        ((xl - xo) * cf).ceil() + 1.0,
                        ((xr - xo) * cf).floor() - 1.0,
                    )
                } else {
                    (f64::INFINITY, f64::NEG_INFINITY)
                };
                let end = span_hi as usize;
                let mut i = span_lo as usize;
                while i < end {
                    if (i as f64) >= in_lo && (i as f64) <= in_hi {
                        let run_end = (in_hi as usize + 1).min(end);
                        cover.push(i, run_end);
                        i = run_end;
                        continue;
                    }
                    let x = i as f64 / cf + xo;
                    let w = [
                        ef(edges[0].0, edges[0].1, x, yf),
                        ef(edges[1].0, edges[1].1, x, yf),
                        ef(edges[2].0, edges[2].1, x, yf),
                    ];
                    let inside = if inclusive {
                        (w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0)
                            || (w[0] <= 0.0 && w[1] <= 0.0 && w[2] <= 0.0)
                    } else {
                        (0..3).all(|k| {
                            let s = w[k] * sign;
                            s > 0.0 || (s == 0.0 && own[k])
                        })
                    };
                    if inside {
                        if by_pixel {
                            cover.push(i, i + 1);
                        } else {
                            let (b0, b1) = bary(w[0], w[1]);
                            let p = py * width + i / sc;
                            let at = s * sc + i % sc;
                            blend(&mut plane.split(p)[at], shade_at(b0, b1));
                        }
                    }
                    i += 1;
                }
            }
            if !by_pixel {
                continue;
            }
            while cover.rows() < sr {
                cover.end_row();
            }
            let cy = f64::from(y0) + py as f64 + 0.5;
            let uniform = match shade {
                TriShade::Solid(c) => Some(*c),
                _ => None,
            };
            cover.paint(plane, py, width, sc, uniform, |x| match shade {
                TriShade::Solid(c) => *c,
                _ => {
                    let cx = x as f64 + 0.5;
                    let (b0, b1) = bary(
                        ef(edges[0].0, edges[0].1, cx, cy),
                        ef(edges[1].0, edges[1].1, cx, cy),
                    );
                    shade_at(b0, b1)
                }
            });
        }
    }

    /// Box-filters the canvas layer into premultiplied pixels.
    pub(super) fn resolve_premultiplied(&mut self, out: &mut [[f32; 4]]) {
        let n = self.pat.sub_rows * self.pat.sub_cols;
        let k = 1.0 / n as f32;
        let w = self.width as usize;
        for (row, out_row) in out.chunks_mut(w).enumerate() {
            self.resolver
                .row(&self.layers[0], row * w, out_row, |s| s.map(|v| v * k));
        }
    }

    /// Box-filters the canvas layer into 8-bit straight-alpha pixels.
    pub(super) fn resolve(&mut self, out: &mut [[u8; 4]], compat: bool) {
        let n = (self.pat.sub_rows * self.pat.sub_cols) as f32;
        let w = self.width as usize;
        for (row, out_row) in out.chunks_mut(w).enumerate() {
            self.resolver
                .row(&self.layers[0], row * w, out_row, |s| convert(s, n, compat));
        }
    }
}

/// The 8-bit straight-alpha pixel of the sum `a` of `n` premultiplied samples.
#[inline(always)]
fn convert(a: [f32; 4], n: f32, compat: bool) -> [u8; 4] {
    if compat {
        // The course's conversion: truncate channel * 255.
        let t = [a[0] / n * 255.0, a[1] / n * 255.0, a[2] / n * 255.0, 255.0];
        return t.map(|v| v.clamp(0.0, 255.0) as i32 as u8);
    }
    let alpha = a[3] / n;
    if alpha <= 0.0 {
        return [0, 0, 0, 0];
    }
    let k = 255.0 / (n * alpha);
    // Round to nearest (`round()` is a libm call on baseline x86-64). The alpha lane is
    // `alpha.clamp(0, 1) * 255`, as rounding is monotone.
    let t = [a[0] * k, a[1] * k, a[2] * k, alpha * 255.0];
    t.map(|v| (v.clamp(0.0, 255.0) + 0.5) as i32 as u8)
}

/// Pixel ranges of a placed box within the band of `rows_px` rows of `width` pixels from
/// row `y0`, one per pixel row.
fn region(
    width: i32,
    y0: i32,
    rows_px: i32,
    pl: &Placed,
) -> impl Iterator<Item = std::ops::Range<usize>> {
    let w = width as usize;
    let ya = (pl.y0.max(y0) - y0).max(0) as usize;
    let yb = (pl.y1.min(y0 + rows_px) - y0).max(0) as usize;
    let xa = pl.x0.clamp(0, width) as usize;
    let xb = (pl.x1.clamp(0, width) as usize).max(xa);
    (ya..yb.max(ya)).map(move |y| y * w + xa..y * w + xb)
}

/// The first sample column at or right of `x` (compat), or right of `x`, on a sample row
/// whose first sample sits at `xo`, clamped to `[0, cols]`.
#[inline]
fn first_sample(x: f64, xo: f64, sc: f64, cols: usize, compat: bool) -> usize {
    // (`floor` and `ceil` are libm calls on baseline x86-64: a truncating cast and a
    // correction do the same for the clamped range.)
    let k = ((x - xo) * sc).clamp(-1.0, cols as f64);
    let t = k as i64;
    let below = (t as f64) < k;
    let i = if compat {
        t + i64::from(below)
    } else {
        t + 1 - i64::from(k < t as f64)
    };
    i.clamp(0, cols as i64) as usize
}
