//! Bands: sample storage for a horizontal strip of the image, the sample-level drawing of
//! every primitive kind, layers, and the box-filter resolve.

use prism_math::DVec2;

use super::primitives::{DevPaint, Edge, Placed, Prim, TriShade};
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

#[inline(always)]
pub(super) fn add4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
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

/// One band's sample storage: `rows_px * sub_rows` sample rows of `cols` samples.
pub(super) struct Band {
    /// Layer stack; the bottom is the band's canvas.
    pub(super) layers: Vec<Vec<[f32; 4]>>,
    pub(super) spare: Vec<Vec<[f32; 4]>>,
    pub(super) cols: usize,
    /// First pixel row of the band.
    pub(super) y0: i32,
    /// Pixel rows in the band.
    pub(super) rows_px: i32,
    pub(super) pat: Pattern,
    pub(super) width: i32,
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

    pub(super) fn draw(&mut self, pl: &Placed, compat: bool) {
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
                let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
                let (by0, rows_px, cols, width) = (self.y0, self.rows_px, self.cols, self.width);
                let h = (px.len() / w.max(&1)) as i32;
                let ya = (*y0).max(by0);
                let yb = (y0 + h).min(by0 + rows_px);
                let xa = (*x0).max(0);
                let xb = (x0 + *w as i32).min(width);
                let buf = self.top();
                for y in ya..yb {
                    let src_row = (y - y0) as usize * w;
                    for j in 0..sr {
                        let row = ((y - by0) as usize * sr + j) * cols;
                        for x in xa..xb {
                            let c = px[src_row + (x - x0) as usize];
                            if c[3] <= 0.0 {
                                continue;
                            }
                            let at = row + x as usize * sc;
                            for s in &mut buf[at..at + sc] {
                                blend(s, c);
                            }
                        }
                    }
                }
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
        let (rows, cols) = self.region(pl);
        let stride = self.cols;
        let src = self.layers.pop().expect("checked");
        let dst = self.top();
        for j in rows {
            let range = j * stride + cols.start..j * stride + cols.end;
            for (d, s) in dst[range.clone()].iter_mut().zip(&src[range]) {
                f(d, *s);
            }
        }
        self.spare.push(src);
    }

    /// Fills a polygon. A sample on an edge belongs to one side only: in compat mode the
    /// left and top edges own it (`y0 <= y < y1`); otherwise the right and bottom edges do
    /// (`y0 < y <= y1`), which is tiny-skia's rule, so that edges on the sample grid cover
    /// what resvg covers.
    fn poly(&mut self, edges: &[Edge], rule: FillRule, paint: &DevPaint, compat: bool) {
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
        let gradient = !matches!(paint, DevPaint::Solid(_));
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
                let owns = if compat {
                    y >= e.y0 && y < e.y1
                } else {
                    y > e.y0 && y <= e.y1
                };
                if owns {
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
                // The first sample at or right of x (compat), or right of x.
                // (`floor` and `ceil` are libm calls on baseline x86-64: a truncating cast
                // and a correction do the same for the clamped range.)
                let first = |x: f64| {
                    let k = ((x - xo) * sc).clamp(-1.0, cols as f64);
                    let t = k as i64;
                    let below = (t as f64) < k;
                    let i = if compat {
                        t + i64::from(below)
                    } else {
                        t + 1 - i64::from(k < t as f64)
                    };
                    i.clamp(0, cols as i64) as usize
                };
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
            let end = span_hi as usize;
            let mut i = span_lo as usize;
            while i < end {
                // Interior runs: solid colours and already-shaded pixels in one go.
                if (i as f64) >= in_lo && (i as f64) <= in_hi {
                    let run_end = (in_hi as usize + 1).min(end);
                    if let TriShade::Solid(c) = shade {
                        let run = &mut buf[j * cols + i..j * cols + run_end];
                        if c[3] >= 1.0 {
                            run.fill(*c);
                        } else {
                            run.iter_mut().for_each(|s| blend(s, *c));
                        }
                        i = run_end;
                        continue;
                    }
                    let px = i / sc;
                    if per_pixel && row_cache[px - px_lo][3] >= 0.0 {
                        let hit = row_cache[px - px_lo];
                        let stop = ((px + 1) * sc).min(run_end);
                        for s in &mut buf[j * cols + i..j * cols + stop] {
                            blend(s, hit);
                        }
                        i = stop;
                        continue;
                    }
                }
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
                    i += 1;
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
                                i += 1;
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
                i += 1;
            }
        }
    }

    /// Box-filters the canvas layer into premultiplied pixels.
    pub(super) fn resolve_premultiplied(&self, out: &mut [[f32; 4]]) {
        let (sr, sc) = (self.pat.sub_rows, self.pat.sub_cols);
        let k = 1.0 / (sr * sc) as f32;
        let w = self.width as usize;
        let stride = self.cols;
        for py in 0..self.rows_px as usize {
            let base = py * sr * stride;
            for (x, o) in out[py * w..(py + 1) * w].iter_mut().enumerate() {
                let mut sum = [0f32; 4];
                for j in 0..sr {
                    let start = base + j * stride + x * sc;
                    for s in &self.layers[0][start..start + sc] {
                        sum = add4(sum, *s);
                    }
                }
                *o = sum.map(|v| v * k);
            }
        }
    }

    /// Box-filters the canvas layer into 8-bit straight-alpha pixels.
    pub(super) fn resolve(&self, out: &mut [[u8; 4]], compat: bool) {
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
