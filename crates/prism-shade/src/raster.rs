//! Rasterization into a band's samples: [`ScreenVertex`], a corner in window coordinates;
//! [`Band`], a worker's sample buffers for a strip of rows; the edge functions with their
//! ownership rule; [`raster_fill`] (the depth test and the visible triangle with its
//! weights) and [`raster_wire`] (edges drawn on top), sixteen samples at a time.

use prism_math::lanes::{F16, LANES, M16};
use prism_math::Rgb;

use crate::shaders::Varyings;

/// A vertex in window coordinates (x right, y down) with `1/w` and its reversed depth
/// `rz = 1 - z`: 1 at the near plane, 0 at the far plane.
///
/// Window depth `z` crowds against 1 far from the eye (at 270 units, `1 - z` is 4e-5, and
/// a float near 1 resolves 6e-8 of it, half a unit of distance): a mesh of large
/// coordinates seen from afar lost its depth order to rounding. `1 - z` is the same
/// order reversed, and as a float it resolves those small values finely; it is computed
/// from `1/w` by the perspective's closed form, `n (f - w) / ((f - n) w) = n / (f - n) (f/w
/// - 1)`, not as a difference of nearly equal numbers (the same two operations as `z` took).
/// The test is OpenGL's LESS on `z`, that is GREATER on `rz`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScreenVertex {
    pub(crate) x: f32,
    pub(crate) y: f32,
    pub(crate) rz: f32,
    pub(crate) inv_w: f32,
    pub(crate) v: Varyings,
}

/// Twice the signed area of `(a, b, p)`.
#[inline]
pub(crate) fn edge(ax: f32, ay: f32, bx: f32, by: f32, px: f32, py: f32) -> f32 {
    (bx - ax) * (py - ay) - (by - ay) * (px - ax)
}

/// True if a sample exactly on edge `a -> b` belongs to the triangle (a top-left rule, so
/// that a shared edge is drawn once).
#[inline]
pub(crate) fn owns_edge(ax: f32, ay: f32, bx: f32, by: f32, area_sign: f32) -> bool {
    let (dx, dy) = ((bx - ax) * area_sign, (by - ay) * area_sign);
    dy < 0.0 || (dy == 0.0 && dx > 0.0)
}

/// No triangle covers the sample.
pub(crate) const NONE: u32 = u32::MAX;

/// A worker's sample buffers for one band, sample row after sample row (`k` per row of
/// pixels, `w k` samples each): depth, the triangle seen with its screen-space barycentric
/// weights (one buffer per corner), the colour, and each sample column's x. Every buffer
/// has [`LANES`] spare samples at the end, so that a group of lanes never runs out.
#[derive(Default)]
pub(crate) struct Band {
    pub(crate) depth: Vec<f32>,
    pub(crate) prim: Vec<u32>,
    pub(crate) bary: [Vec<f32>; 3],
    pub(crate) color: [Vec<f32>; 3],
    pub(crate) xs: Vec<f32>,
}

impl Band {
    /// Clears depth (to 0, the far plane in reversed depth: the test passes above it) and
    /// the visible triangle;
    /// weights and colours are written before they are read.
    pub(crate) fn clear(&mut self, len: usize, k: u32, row_len: usize) {
        let padded = len + LANES;
        self.depth.clear();
        self.depth.resize(padded, 0.0);
        self.prim.clear();
        self.prim.resize(padded, NONE);
        for b in &mut self.bary {
            b.resize(padded, 0.0);
        }
        for c in &mut self.color {
            c.resize(padded, 0.0);
        }
        self.xs.clear();
        self.xs.extend((0..row_len + LANES).map(|j| {
            let (px, sx) = (j as u32 / k, j as u32 % k);
            px as f32 + sample_offset(sx, k)
        }));
    }
}

/// Where sample `i` of `k` lies across a pixel: `(i + 1/2) / k`.
#[inline]
pub(crate) fn sample_offset(i: u32, k: u32) -> f32 {
    (i as f32 + 0.5) / k as f32
}

/// Where a band's samples lie: `k x k` per pixel, `w` pixels a row, rows `y_start` on.
pub(crate) struct Target {
    pub(crate) k: u32,
    pub(crate) w: u32,
    pub(crate) y_start: u32,
    pub(crate) rows: u32,
}

/// A triangle's set-up for rasterization: its sign and area, its pixel bounds clipped to
/// the band, and which of its edges own the samples exactly on them.
pub(crate) struct Setup {
    sign: f32,
    inv_area: f32,
    x: (u32, u32),
    y: (u32, u32),
    own: [bool; 3],
}

impl Setup {
    #[inline(always)]
    fn new(t: [&ScreenVertex; 3], to: &Target) -> Option<Setup> {
        let [a, b, c] = t;
        let area = edge(a.x, a.y, b.x, b.y, c.x, c.y);
        if area == 0.0 || !area.is_finite() {
            return None;
        }
        let sign = area.signum();
        let min_x = a.x.min(b.x).min(c.x).floor().max(0.0);
        let max_x = a.x.max(b.x).max(c.x).ceil().min(to.w as f32);
        let min_y = a.y.min(b.y).min(c.y).floor().max(to.y_start as f32);
        let max_y =
            a.y.max(b.y)
                .max(c.y)
                .ceil()
                .min((to.y_start + to.rows) as f32);
        if !(min_x < max_x && min_y < max_y) {
            return None;
        }
        Some(Setup {
            sign,
            inv_area: 1.0 / (area * sign),
            x: (min_x as u32, max_x as u32),
            y: (min_y as u32, max_y as u32),
            own: [
                owns_edge(b.x, b.y, c.x, c.y, sign),
                owns_edge(c.x, c.y, a.x, a.y, sign),
                owns_edge(a.x, a.y, b.x, b.y, sign),
            ],
        })
    }
}

/// A triangle's three edge functions (`b -> c`, `c -> a`, `a -> b`) over a band's sample
/// rows, sixteen samples at a time: each lane is [`edge`]'s operations in its order, times
/// the sign of the triangle's area, and [`Edges::inside`] applies the ownership rule.
struct Edges {
    /// Each edge's first corner.
    from: [(f32, f32); 3],
    /// Each edge's vector.
    along: [(f32, f32); 3],
    sign: F16,
    /// Lanes exactly on an edge the triangle does not own are outside.
    strict: [M16; 3],
}

impl Edges {
    #[inline(always)]
    fn new([a, b, c]: [&ScreenVertex; 3], set: &Setup) -> Edges {
        Edges {
            from: [(b.x, b.y), (c.x, c.y), (a.x, a.y)],
            along: [
                (c.x - b.x, c.y - b.y),
                (a.x - c.x, a.y - c.y),
                (b.x - a.x, b.y - a.y),
            ],
            sign: F16::splat(set.sign),
            strict: set.own.map(|o| M16::splat(!o)),
        }
    }

    /// The row's part of each function at sample row `y`: with `edge(p) = dx (y - fy) -
    /// dy (x - fx)`, the first product.
    #[inline(always)]
    fn across(&self, y: f32) -> [f32; 3] {
        let (along, from) = (&self.along, &self.from);
        [
            along[0].0 * (y - from[0].1),
            along[1].0 * (y - from[1].1),
            along[2].0 * (y - from[2].1),
        ]
    }

    /// The three functions at the samples `xs` of a row, times the area's sign.
    #[inline(always)]
    fn at(&self, across: &[f32; 3], xs: F16) -> [F16; 3] {
        // Written out, not a closure: a closure is compiled apart, without the caller's
        // vector instruction set.
        let (along, from, sign) = (&self.along, &self.from, self.sign);
        [
            (F16::splat(across[0]) - F16::splat(along[0].1) * (xs - from[0].0)) * sign,
            (F16::splat(across[1]) - F16::splat(along[1].1) * (xs - from[1].0)) * sign,
            (F16::splat(across[2]) - F16::splat(along[2].1) * (xs - from[2].0)) * sign,
        ]
    }

    /// The first `live` lanes that are inside: no function below zero, and none zero on an
    /// edge the triangle does not own.
    #[inline(always)]
    fn inside(&self, e: &[F16; 3], live: usize) -> M16 {
        let zero = F16::splat(0.0);
        let mut inside = M16::first(live);
        for (&e, &strict) in e.iter().zip(&self.strict) {
            inside = inside & !(e.lt(zero) | (e.eq(zero) & strict));
        }
        inside
    }
}

/// Rasterizes triangle `id` into a band: the depth test and the visible triangle with its
/// weights, sixteen samples of a sample row at a time. Each lane evaluates the edge
/// functions exactly as [`edge`] does.
#[inline(always)]
pub(crate) fn raster_fill(t: [&ScreenVertex; 3], id: u32, to: &Target, buf: &mut Band) {
    let Some(set) = Setup::new(t, to) else {
        return;
    };
    let [a, b, c] = t;
    let k = to.k;
    let row_len = (to.w * k) as usize;
    let (j0, j1) = ((set.x.0 * k) as usize, (set.x.1 * k) as usize);
    let edges = Edges::new(t, &set);
    for py in set.y.0..set.y.1 {
        for sy in 0..k {
            let y = py as f32 + sample_offset(sy, k);
            let row = ((py - to.y_start) * k + sy) as usize * row_len;
            let across = edges.across(y);
            // A triangle no wider than a group of lanes takes one group a row: narrowing
            // the row first would cost more than the lanes it saves.
            let (lo, hi) = if j1 - j0 <= LANES {
                (j0, j1)
            } else {
                match row_span(&across, &edges.along, &edges.from, set.sign, k, (j0, j1)) {
                    Some(span) => span,
                    None => continue,
                }
            };
            let mut j = lo;
            while j < hi {
                let e = edges.at(&across, F16::load(&buf.xs[j..]));
                let inside = edges.inside(&e, hi - j);
                if inside.any() {
                    let l = [
                        e[0] * set.inv_area,
                        e[1] * set.inv_area,
                        e[2] * set.inv_area,
                    ];
                    let rz = l[0] * a.rz + l[1] * b.rz + l[2] * c.rz;
                    let s = row + j;
                    let depth = F16::load(&buf.depth[s..]);
                    // LESS on z, GREATER on 1 - z: a NaN depth never passes.
                    let pass = inside & depth.lt(rz);
                    F16::select(pass, rz, depth).store(&mut buf.depth[s..]);
                    for (corner, weights) in l.iter().zip(&mut buf.bary) {
                        let old = F16::load(&weights[s..]);
                        F16::select(pass, *corner, old).store(&mut weights[s..]);
                    }
                    // A select per lane by its mask's bits (all ones or none), without
                    // branches.
                    let prim: &mut [u32; LANES] = (&mut buf.prim[s..s + LANES])
                        .try_into()
                        .expect("a group of lanes");
                    let mut seen = *prim;
                    for (p, &m) in seen.iter_mut().zip(&pass.0) {
                        *p = (id & m as u32) | (*p & !(m as u32));
                    }
                    *prim = seen;
                }
                j += LANES;
            }
        }
    }
}

/// The sample columns of a sample row, within `cols`, that can lie inside a triangle: a
/// range a little wider than where the three edge functions `(across - dy (x - fx)) sign`
/// are at least 0 (every sample in it is still tested exactly), or `None` when no sample
/// of the row can be inside.
#[inline(always)]
fn row_span(
    across: &[f32; 3],
    along: &[(f32, f32); 3],
    from: &[(f32, f32); 3],
    sign: f32,
    k: u32,
    cols: (usize, usize),
) -> Option<(usize, usize)> {
    let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::INFINITY);
    let mut scale = 0.0f32;
    for i in 0..3 {
        let (g, m) = (across[i] * sign, along[i].1 * sign);
        if m == 0.0 {
            // The edge function is `g` along the whole row.
            if g < 0.0 {
                return None;
            }
            continue;
        }
        let x = from[i].0 + g / m;
        scale = scale.max(x.abs()).max(from[i].0.abs());
        if m > 0.0 {
            hi = hi.min(x);
        } else {
            lo = lo.max(x);
        }
    }
    // A pixel and a relative margin cover rounding in the bound and in the exact test.
    let margin = 1.0 + scale * 1e-4;
    // (A NaN bound was dropped by `min`/`max`: only a looser range.)
    if !margin.is_finite() {
        return Some(cols);
    }
    let k = k as f32;
    let first = ((lo - margin) * k).floor();
    let last = ((hi + margin) * k).ceil();
    let first = if first > cols.0 as f32 {
        first as usize
    } else {
        cols.0
    };
    let last = if last < cols.1 as f32 {
        last.max(0.0) as usize
    } else {
        cols.1
    };
    (first < last).then_some((first, last))
}

/// Draws a triangle's edges into a band: samples within `half_width` pixels of an edge,
/// inside the triangle, take `color`, the depth test passing up to a small bias so that
/// edges show on their own faces. Sixteen samples of a sample row at a time, each lane the
/// scalar test's operations in its order.
#[inline(always)]
pub(crate) fn raster_wire(
    t: [&ScreenVertex; 3],
    to: &Target,
    buf: &mut Band,
    color: Rgb,
    half_width: f32,
) {
    let Some(set) = Setup::new(t, to) else {
        return;
    };
    let [a, b, c] = t;
    let k = to.k;
    let row_len = (to.w * k) as usize;
    let edge_len = [
        ((c.x - b.x).powi(2) + (c.y - b.y).powi(2)).sqrt(),
        ((a.x - c.x).powi(2) + (a.y - c.y).powi(2)).sqrt(),
        ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt(),
    ];
    let (j0, j1) = ((set.x.0 * k) as usize, (set.x.1 * k) as usize);
    let edges = Edges::new(t, &set);
    let width = F16::splat(half_width);
    // `e / len <= w` implies `e <= w len` up to a few roundings: a relative margin of
    // 1e-5 (and an absolute one for lengths near 0) covers them.
    let reach = edge_len.map(|len| F16::splat(half_width * len * (1.0 + 1e-5) + 1e-30));
    let colour = [color.r, color.g, color.b].map(F16::splat);
    for py in set.y.0..set.y.1 {
        for sy in 0..k {
            let y = py as f32 + sample_offset(sy, k);
            let row = ((py - to.y_start) * k + sy) as usize * row_len;
            let across = edges.across(y);
            let mut j = j0;
            while j < j1 {
                let e = edges.at(&across, F16::load(&buf.xs[j..]));
                let inside = edges.inside(&e, j1 - j);
                // Near an edge, by a test without division that takes a little more than
                // the exact one (decided below, only where this one passes).
                let roughly = e[0].le(reach[0]) | e[1].le(reach[1]) | e[2].le(reach[2]);
                if (inside & roughly).any() {
                    // Distance in pixels to the nearest edge.
                    let near = (e[0] / F16::splat(edge_len[0])).le(width)
                        | (e[1] / F16::splat(edge_len[1])).le(width)
                        | (e[2] / F16::splat(edge_len[2])).le(width);
                    let candidates = inside & near;
                    let l = [
                        e[0] * set.inv_area,
                        e[1] * set.inv_area,
                        e[2] * set.inv_area,
                    ];
                    let rz = l[0] * a.rz + l[1] * b.rz + l[2] * c.rz;
                    let s = row + j;
                    let depth = F16::load(&buf.depth[s..]);
                    // Behind what is drawn by more than the bias (1e-4 of window depth).
                    let pass = candidates & !rz.lt(depth - F16::splat(1e-4));
                    F16::select(pass, rz, depth).store(&mut buf.depth[s..]);
                    for (ch, value) in buf.color.iter_mut().zip(colour) {
                        let old = F16::load(&ch[s..]);
                        F16::select(pass, value, old).store(&mut ch[s..]);
                    }
                }
                j += LANES;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Vec3;

    /// The wireframe as first written, a sample at a time: the oracle for [`raster_wire`].
    fn raster_wire_scalar(
        t: [&ScreenVertex; 3],
        to: &Target,
        buf: &mut Band,
        color: Rgb,
        half_width: f32,
    ) {
        let Some(set) = Setup::new(t, to) else {
            return;
        };
        let [a, b, c] = t;
        let k = to.k;
        let row_len = (to.w * k) as usize;
        let edge_len = [
            ((c.x - b.x).powi(2) + (c.y - b.y).powi(2)).sqrt(),
            ((a.x - c.x).powi(2) + (a.y - c.y).powi(2)).sqrt(),
            ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt(),
        ];
        for py in set.y.0..set.y.1 {
            for sy in 0..k {
                let y = py as f32 + sample_offset(sy, k);
                let row = ((py - to.y_start) * k + sy) as usize * row_len;
                for j in (set.x.0 * k) as usize..(set.x.1 * k) as usize {
                    let x = buf.xs[j];
                    let e = [
                        edge(b.x, b.y, c.x, c.y, x, y) * set.sign,
                        edge(c.x, c.y, a.x, a.y, x, y) * set.sign,
                        edge(a.x, a.y, b.x, b.y, x, y) * set.sign,
                    ];
                    if e.iter()
                        .zip(set.own)
                        .any(|(&v, o)| v < 0.0 || (v == 0.0 && !o))
                    {
                        continue;
                    }
                    let l = e.map(|v| v * set.inv_area);
                    let rz = l[0] * a.rz + l[1] * b.rz + l[2] * c.rz;
                    let near_edge = (0..3).any(|i| e[i] / edge_len[i] <= half_width);
                    let s = row + j;
                    if !near_edge || rz < buf.depth[s] - 1e-4 {
                        continue;
                    }
                    buf.depth[s] = rz;
                    (buf.color[0][s], buf.color[1][s], buf.color[2][s]) =
                        (color.r, color.g, color.b);
                }
            }
        }
    }

    /// Brute force: the sixteen-lane wireframe writes exactly the samples, depths and
    /// colours the sample-at-a-time one does, over random triangles of every size (slivers
    /// and ones larger than the band included), 1 and 4 samples a pixel, on a band whose
    /// depth is already partly drawn.
    #[test]
    fn lane_wireframe_equals_the_sample_at_a_time_one() {
        let mut state = 7u32;
        let mut rand = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32
        };
        let v = |x: f32, y: f32, rz: f32| ScreenVertex {
            x,
            y,
            rz,
            inv_w: 1.0,
            v: Varyings {
                position: Vec3::ZERO,
                normal: Vec3::Z,
                tangent: Vec3::X,
                uv: prism_math::Vec2::ZERO,
            },
        };
        for k in [1u32, 2] {
            let to = Target {
                k,
                w: 61,
                y_start: 16,
                rows: 16,
            };
            let row_len = (to.w * k) as usize;
            let len = (to.rows * k) as usize * row_len;
            let mut lanes = Band::default();
            lanes.clear(len, k, row_len);
            for (i, d) in lanes.depth.iter_mut().enumerate() {
                *d = if i % 3 == 0 { 0.5 } else { 0.0 };
            }
            let mut scalar = Band::default();
            scalar.clear(len, k, row_len);
            scalar.depth.clone_from(&lanes.depth);
            for n in 0..400 {
                let size = [3.0, 12.0, 70.0][n % 3];
                let (cx, cy) = (rand() * 61.0, 16.0 + rand() * 16.0);
                let mut p = || {
                    v(
                        cx + (rand() - 0.5) * size,
                        cy + (rand() - 0.5) * size,
                        rand(),
                    )
                };
                let t = [p(), p(), p()];
                let colour = Rgb::new(rand(), rand(), rand());
                let hw = 0.3 + rand();
                raster_wire(t.each_ref(), &to, &mut lanes, colour, hw);
                raster_wire_scalar(t.each_ref(), &to, &mut scalar, colour, hw);
            }
            assert!(lanes.depth[..len] == scalar.depth[..len], "depth, k = {k}");
            for c in 0..3 {
                assert!(
                    lanes.color[c][..len] == scalar.color[c][..len],
                    "colour, k = {k}"
                );
            }
            assert!(
                lanes.depth[..len]
                    .iter()
                    .filter(|&&d| d != 0.0 && d != 0.5)
                    .count()
                    > 100
            );
        }
    }
}
