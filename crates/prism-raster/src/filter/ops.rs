//! Per-pixel and neighbourhood filter primitives on premultiplied images: blend,
//! composite, offset, tile, colour matrix, component transfer, convolution, morphology and
//! displacement.

use std::collections::VecDeque;
use std::sync::Arc;

use usvg::filter::{
    ColorChannel, ColorMatrixKind, ComponentTransfer, CompositeOperator, ConvolveMatrix,
    DisplacementMap, EdgeMode, MorphologyOperator, TransferFunction,
};

use super::{IRect, Img};
use crate::document::BlendMode;

/// A transparent image of `a`'s size, region and colour space.
fn like(a: &Img) -> Img {
    Img {
        px: Arc::new(vec![[0.0; 4]; a.px.len()]),
        ..a.clone()
    }
}

/// `feBlend`: `a` (in) blended onto `b` (in2).
pub(crate) fn blend(a: &Img, b: &Img, mode: BlendMode) -> Img {
    let mut out = b.clone();
    for (d, s) in Arc::make_mut(&mut out.px).iter_mut().zip(a.px.iter()) {
        crate::blend::composite(d, *s, mode);
    }
    out
}

/// `feComposite`: `a` (in) with `b` (in2) by Porter-Duff or arithmetic.
pub(crate) fn composite(a: &Img, b: &Img, op: CompositeOperator) -> Img {
    let mut out = like(a);
    let px = Arc::make_mut(&mut out.px);
    for ((o, s), d) in px.iter_mut().zip(a.px.iter()).zip(b.px.iter()) {
        let (sa, da) = (s[3], d[3]);
        *o = match op {
            CompositeOperator::Over => std::array::from_fn(|c| s[c] + d[c] * (1.0 - sa)),
            CompositeOperator::In => s.map(|v| v * da),
            CompositeOperator::Out => s.map(|v| v * (1.0 - da)),
            CompositeOperator::Atop => std::array::from_fn(|c| s[c] * da + d[c] * (1.0 - sa)),
            CompositeOperator::Xor => {
                std::array::from_fn(|c| s[c] * (1.0 - da) + d[c] * (1.0 - sa))
            }
            CompositeOperator::Lighter => std::array::from_fn(|c| (s[c] + d[c]).min(1.0)),
            CompositeOperator::Arithmetic { k1, k2, k3, k4 } => {
                let v: [f32; 4] =
                    std::array::from_fn(|c| k1 * s[c] * d[c] + k2 * s[c] + k3 * d[c] + k4);
                let a = v[3].clamp(0.0, 1.0);
                [
                    v[0].clamp(0.0, a),
                    v[1].clamp(0.0, a),
                    v[2].clamp(0.0, a),
                    a,
                ]
            }
        };
    }
    out
}

/// `feOffset`: the image moved by whole pixels.
pub(crate) fn offset(a: &Img, dx: i32, dy: i32) -> Img {
    let mut out = like(a);
    let px = Arc::make_mut(&mut out.px);
    let (w, h) = (a.w as i64, a.h as i64);
    for y in 0..h {
        let sy = y - i64::from(dy);
        if sy < 0 || sy >= h {
            continue;
        }
        for x in 0..w {
            let sx = x - i64::from(dx);
            if sx >= 0 && sx < w {
                px[(y * w + x) as usize] = a.px[(sy * w + sx) as usize];
            }
        }
    }
    out
}

/// `feTile`: the input's region repeated over `region`.
pub(crate) fn tile(a: &Img, region: IRect) -> Img {
    let t = a.region.intersect(IRect {
        x0: 0,
        y0: 0,
        x1: a.w as i32,
        y1: a.h as i32,
    });
    let mut out = like(a);
    if t.is_empty() {
        return out;
    }
    let (tw, th) = (t.x1 - t.x0, t.y1 - t.y0);
    let px = Arc::make_mut(&mut out.px);
    for y in region.y0.max(0)..region.y1.min(a.h as i32) {
        let sy = t.y0 + (y - t.y0).rem_euclid(th);
        for x in region.x0.max(0)..region.x1.min(a.w as i32) {
            let sx = t.x0 + (x - t.x0).rem_euclid(tw);
            px[y as usize * a.w + x as usize] = a.px[sy as usize * a.w + sx as usize];
        }
    }
    out
}

/// Applies `f` to each pixel's straight (unpremultiplied) colour and alpha.
fn straight(img: &mut Img, f: impl Fn([f32; 4]) -> [f32; 4]) {
    for p in Arc::make_mut(&mut img.px).iter_mut() {
        let a = p[3];
        let s = if a > 0.0 {
            [p[0] / a, p[1] / a, p[2] / a, a]
        } else {
            [0.0; 4]
        };
        let r = f(s).map(|v| v.clamp(0.0, 1.0));
        *p = [r[0] * r[3], r[1] * r[3], r[2] * r[3], r[3]];
    }
}

/// `feColorMatrix` on straight colours.
pub(crate) fn color_matrix(img: &mut Img, kind: &ColorMatrixKind) {
    let m: [f32; 20] = match kind {
        ColorMatrixKind::Matrix(v) => std::array::from_fn(|i| v.get(i).copied().unwrap_or(0.0)),
        ColorMatrixKind::Saturate(s) => {
            let s = s.get();
            [
                0.213 + 0.787 * s,
                0.715 - 0.715 * s,
                0.072 - 0.072 * s,
                0.0,
                0.0,
                0.213 - 0.213 * s,
                0.715 + 0.285 * s,
                0.072 - 0.072 * s,
                0.0,
                0.0,
                0.213 - 0.213 * s,
                0.715 - 0.715 * s,
                0.072 + 0.928 * s,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
            ]
        }
        ColorMatrixKind::HueRotate(deg) => {
            let (s, c) = deg.to_radians().sin_cos();
            [
                0.213 + c * 0.787 - s * 0.213,
                0.715 - c * 0.715 - s * 0.715,
                0.072 - c * 0.072 + s * 0.928,
                0.0,
                0.0,
                0.213 - c * 0.213 + s * 0.143,
                0.715 + c * 0.285 + s * 0.140,
                0.072 - c * 0.072 - s * 0.283,
                0.0,
                0.0,
                0.213 - c * 0.213 - s * 0.787,
                0.715 - c * 0.715 + s * 0.715,
                0.072 + c * 0.928 + s * 0.072,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
            ]
        }
        ColorMatrixKind::LuminanceToAlpha => [
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2125,
            0.7154, 0.0721, 0.0, 0.0,
        ],
    };
    straight(img, |p| {
        std::array::from_fn(|r| {
            let row = &m[r * 5..r * 5 + 5];
            row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + row[3] * p[3] + row[4]
        })
    });
}

fn transfer(f: &TransferFunction, c: f32) -> f32 {
    match f {
        TransferFunction::Identity => c,
        TransferFunction::Table(v) if !v.is_empty() => {
            let n = v.len() - 1;
            let k = ((c * n as f32).floor() as usize).min(n);
            if k == n {
                v[n]
            } else {
                v[k] + (c - k as f32 / n as f32) * n as f32 * (v[k + 1] - v[k])
            }
        }
        TransferFunction::Discrete(v) if !v.is_empty() => {
            let n = v.len();
            v[((c * n as f32).floor() as usize).min(n - 1)]
        }
        TransferFunction::Table(_) | TransferFunction::Discrete(_) => c,
        TransferFunction::Linear { slope, intercept } => slope * c + intercept,
        TransferFunction::Gamma {
            amplitude,
            exponent,
            offset,
        } => amplitude * c.powf(*exponent) + offset,
    }
}

/// `feComponentTransfer` on straight colours.
pub(crate) fn component_transfer(img: &mut Img, fe: &ComponentTransfer) {
    straight(img, |p| {
        [
            transfer(fe.func_r(), p[0]),
            transfer(fe.func_g(), p[1]),
            transfer(fe.func_b(), p[2]),
            transfer(fe.func_a(), p[3]),
        ]
    });
}

/// `feConvolveMatrix` (on premultiplied colours, or straight ones with `preserveAlpha`).
pub(crate) fn convolve(a: &Img, fe: &ConvolveMatrix) -> Img {
    let m = fe.matrix();
    let (cols, rows) = (m.columns() as i64, m.rows() as i64);
    let (tx, ty) = (i64::from(m.target_x()), i64::from(m.target_y()));
    let (w, h) = (a.w as i64, a.h as i64);
    let div = fe.divisor().get();
    let bias = fe.bias();
    let keep = fe.preserve_alpha();
    let mut out = like(a);
    let px = Arc::make_mut(&mut out.px);
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0f32; 4];
            for oy in 0..rows {
                for ox in 0..cols {
                    let (mut sx, mut sy) = (x - tx + ox, y - ty + oy);
                    match fe.edge_mode() {
                        EdgeMode::None => {
                            if sx < 0 || sy < 0 || sx >= w || sy >= h {
                                continue;
                            }
                        }
                        EdgeMode::Duplicate => {
                            sx = sx.clamp(0, w - 1);
                            sy = sy.clamp(0, h - 1);
                        }
                        EdgeMode::Wrap => {
                            sx = sx.rem_euclid(w);
                            sy = sy.rem_euclid(h);
                        }
                    }
                    let k = m.get((cols - ox - 1) as u32, (rows - oy - 1) as u32);
                    let mut p = a.px[(sy * w + sx) as usize];
                    if keep && p[3] > 0.0 {
                        p = [p[0] / p[3], p[1] / p[3], p[2] / p[3], p[3]];
                    }
                    for c in 0..4 {
                        acc[c] += p[c] * k;
                    }
                }
            }
            let own = a.px[(y * w + x) as usize][3];
            let alpha = if keep {
                own
            } else {
                (acc[3] / div + bias).clamp(0.0, 1.0)
            };
            let f = |v: f32| {
                let v = v / div + bias * alpha;
                if keep {
                    v.clamp(0.0, 1.0) * alpha
                } else {
                    v.clamp(0.0, alpha)
                }
            };
            px[(y * w + x) as usize] = [f(acc[0]), f(acc[1]), f(acc[2]), alpha];
        }
    }
    out
}

/// Sliding minimum (or maximum) over `[i - r, i + r]` of one channel sequence, with a
/// monotonic queue: linear in the length whatever the radius.
fn slide(v: &[f32], r: usize, max: bool, out: &mut Vec<f32>) {
    out.clear();
    let mut q: VecDeque<usize> = VecDeque::new();
    let n = v.len();
    let better = |a: f32, b: f32| if max { a >= b } else { a <= b };
    let mut next = 0;
    for i in 0..n {
        let hi = (i + r).min(n - 1);
        while next <= hi {
            while q.back().is_some_and(|&j| better(v[next], v[j])) {
                q.pop_back();
            }
            q.push_back(next);
            next += 1;
        }
        while q.front().is_some_and(|&j| j + r < i) {
            q.pop_front();
        }
        out.push(v[*q.front().expect("window holds i")]);
    }
}

/// `feMorphology`: erode (minimum) or dilate (maximum) over a `2 rx + 1` by `2 ry + 1`
/// window, channel by channel; a zero radius clears the image.
pub(crate) fn morphology(mut img: Img, op: MorphologyOperator, rx: f64, ry: f64) -> Img {
    let px = Arc::make_mut(&mut img.px);
    if !(rx > 0.0 && ry > 0.0) {
        px.fill([0.0; 4]);
        return img;
    }
    let max = op == MorphologyOperator::Dilate;
    let (w, h) = (img.w, img.h);
    let (rx, ry) = (rx.min(w as f64) as usize, ry.min(h as f64) as usize);
    let (mut line, mut res) = (Vec::new(), Vec::new());
    for c in 0..4 {
        for y in 0..h {
            line.clear();
            line.extend(px[y * w..(y + 1) * w].iter().map(|p| p[c]));
            slide(&line, rx, max, &mut res);
            for (x, v) in res.iter().enumerate() {
                px[y * w + x][c] = *v;
            }
        }
        for x in 0..w {
            line.clear();
            line.extend((0..h).map(|y| px[y * w + x][c]));
            slide(&line, ry, max, &mut res);
            for (y, v) in res.iter().enumerate() {
                px[y * w + x][c] = *v;
            }
        }
    }
    img
}

/// `feDisplacementMap`: each pixel of `a` fetched from where the channels of `map` point,
/// `scale` user units at full value (nearest pixel).
pub(crate) fn displace(a: &Img, map: &Img, fe: &DisplacementMap, sx: f64, sy: f64) -> Img {
    let mut out = like(a);
    let px = Arc::make_mut(&mut out.px);
    let (w, h) = (a.w as i64, a.h as i64);
    let channel = |p: [f32; 4], c: ColorChannel| {
        let alpha = p[3];
        let un = |v: f32| if alpha > 0.0 { v / alpha } else { 0.0 };
        match c {
            ColorChannel::R => un(p[0]),
            ColorChannel::G => un(p[1]),
            ColorChannel::B => un(p[2]),
            ColorChannel::A => alpha,
        }
    };
    let scale = f64::from(fe.scale());
    for y in 0..h {
        for x in 0..w {
            let m = map.px[(y * w + x) as usize];
            let dx = f64::from(channel(m, fe.x_channel_selector())) - 0.5;
            let dy = f64::from(channel(m, fe.y_channel_selector())) - 0.5;
            let ox = (x as f64 + dx * sx * scale).round() as i64;
            let oy = (y as f64 + dy * sy * scale).round() as i64;
            if ox >= 0 && oy >= 0 && ox < w && oy < h {
                px[(y * w + x) as usize] = a.px[(oy * w + ox) as usize];
            }
        }
    }
    out
}
