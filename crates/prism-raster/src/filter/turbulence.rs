//! `feTurbulence`: Perlin turbulence and fractal noise as the SVG 1.1 specification defines
//! them (its lattice, gradients, seeded generator and stitching).

use prism_math::DAffine2;

use super::{IRect, Img};

const RAND_M: i64 = 2_147_483_647;
const RAND_A: i64 = 16_807;
const RAND_Q: i64 = 127_773;
const RAND_R: i64 = 2_836;
const B: usize = 0x100;
const BM: i64 = 0xff;
const PERLIN_N: f64 = 4096.0;

fn random(seed: &mut i64) -> i64 {
    *seed = RAND_A * (*seed % RAND_Q) - RAND_R * (*seed / RAND_Q);
    if *seed <= 0 {
        *seed += RAND_M;
    }
    *seed
}

struct Lattice {
    sel: Vec<usize>,
    grad: Vec<Vec<[f64; 2]>>,
}

fn init(seed: i32) -> Lattice {
    let mut s = i64::from(seed);
    if s <= 0 {
        s = -(s % (RAND_M - 1)) + 1;
    }
    if s > RAND_M - 1 {
        s = RAND_M - 1;
    }
    let mut sel = vec![0usize; B + B + 2];
    let mut grad = vec![vec![[0.0f64; 2]; B + B + 2]; 4];
    for g in grad.iter_mut() {
        for (i, gi) in g.iter_mut().enumerate().take(B) {
            sel[i] = i;
            for v in gi.iter_mut() {
                *v = ((random(&mut s) % (2 * B as i64)) - B as i64) as f64 / B as f64;
            }
            let n = (gi[0] * gi[0] + gi[1] * gi[1]).sqrt();
            if n > 0.0 {
                gi[0] /= n;
                gi[1] /= n;
            }
        }
    }
    for i in (1..B).rev() {
        let j = (random(&mut s) % B as i64) as usize;
        sel.swap(i, j);
    }
    for i in 0..B + 2 {
        sel[B + i] = sel[i];
        for g in grad.iter_mut() {
            g[B + i] = g[i];
        }
    }
    Lattice { sel, grad }
}

#[derive(Clone, Copy)]
struct Stitch {
    width: i64,
    height: i64,
    wrap_x: i64,
    wrap_y: i64,
}

fn noise2(l: &Lattice, k: usize, x: f64, y: f64, st: Option<Stitch>) -> f64 {
    let t = x + PERLIN_N;
    let (mut bx0, rx0) = (t as i64, t - (t as i64) as f64);
    let mut bx1 = bx0 + 1;
    let rx1 = rx0 - 1.0;
    let t = y + PERLIN_N;
    let (mut by0, ry0) = (t as i64, t - (t as i64) as f64);
    let mut by1 = by0 + 1;
    let ry1 = ry0 - 1.0;
    if let Some(s) = st {
        if bx0 >= s.wrap_x {
            bx0 -= s.width;
        }
        if bx1 >= s.wrap_x {
            bx1 -= s.width;
        }
        if by0 >= s.wrap_y {
            by0 -= s.height;
        }
        if by1 >= s.wrap_y {
            by1 -= s.height;
        }
    }
    let (bx0, bx1, by0, by1) = (
        (bx0 & BM) as usize,
        (bx1 & BM) as usize,
        (by0 & BM) as usize,
        (by1 & BM) as usize,
    );
    let (i, j) = (l.sel[bx0], l.sel[bx1]);
    let (b00, b10, b01, b11) = (
        l.sel[i + by0],
        l.sel[j + by0],
        l.sel[i + by1],
        l.sel[j + by1],
    );
    let curve = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (curve(rx0), curve(ry0));
    let g = &l.grad[k];
    let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
    let a = lerp(
        sx,
        rx0 * g[b00][0] + ry0 * g[b00][1],
        rx1 * g[b10][0] + ry0 * g[b10][1],
    );
    let b = lerp(
        sx,
        rx0 * g[b01][0] + ry1 * g[b01][1],
        rx1 * g[b11][0] + ry1 * g[b11][1],
    );
    lerp(sy, a, b)
}

#[allow(clippy::too_many_arguments)]
fn turbulence(
    l: &Lattice,
    k: usize,
    p: (f64, f64),
    freq: (f64, f64),
    octaves: u32,
    fractal: bool,
    tile: Option<[f64; 4]>,
) -> f64 {
    let (mut fx, mut fy) = freq;
    let mut st = None;
    if let Some([tx, ty, tw, th]) = tile {
        if fx != 0.0 {
            let lo = (tw * fx).floor() / tw;
            let hi = (tw * fx).ceil() / tw;
            fx = if lo > 0.0 && fx / lo < hi / fx {
                lo
            } else {
                hi
            };
        }
        if fy != 0.0 {
            let lo = (th * fy).floor() / th;
            let hi = (th * fy).ceil() / th;
            fy = if lo > 0.0 && fy / lo < hi / fy {
                lo
            } else {
                hi
            };
        }
        let width = (tw * fx + 0.5) as i64;
        let height = (th * fy + 0.5) as i64;
        st = Some(Stitch {
            width,
            height,
            wrap_x: (tx * fx + PERLIN_N) as i64 + width,
            wrap_y: (ty * fy + PERLIN_N) as i64 + height,
        });
    }
    let (mut x, mut y) = (p.0 * fx, p.1 * fy);
    let (mut sum, mut ratio) = (0.0, 1.0);
    for _ in 0..octaves {
        let n = noise2(l, k, x, y, st);
        sum += if fractal { n } else { n.abs() } / ratio;
        x *= 2.0;
        y *= 2.0;
        ratio *= 2.0;
        if let Some(s) = st.as_mut() {
            s.width *= 2;
            s.wrap_x = 2 * s.wrap_x - PERLIN_N as i64;
            s.height *= 2;
            s.wrap_y = 2 * s.wrap_y - PERLIN_N as i64;
        }
    }
    sum
}

/// Fills `region` of `img` with the primitive's noise; pixel `(x, y)` samples user-space
/// point `((x - tx) / sx, (y - ty) / sy)` of the canvas transform `ts`.
pub(crate) fn fill(img: &mut Img, fe: &usvg::filter::Turbulence, ts: &DAffine2, region: IRect) {
    let (sx, sy) = super::scale_of(ts);
    if !(sx > 1e-12 && sy > 1e-12) {
        return;
    }
    let l = init(fe.seed());
    let fractal = fe.kind() == usvg::filter::TurbulenceKind::FractalNoise;
    let freq = (
        f64::from(fe.base_frequency_x().get()),
        f64::from(fe.base_frequency_y().get()),
    );
    // Octaves past 24 change nothing visible in f64 and would only cost time.
    let octaves = fe.num_octaves().min(24);
    let (tx, ty) = (ts.translation.x, ts.translation.y);
    let tile = fe.stitch_tiles().then(|| {
        [
            (f64::from(region.x0) - tx) / sx,
            (f64::from(region.y0) - ty) / sy,
            f64::from(region.x1 - region.x0) / sx,
            f64::from(region.y1 - region.y0) / sy,
        ]
    });
    let w = img.w;
    let px = std::sync::Arc::make_mut(&mut img.px);
    for y in region.y0.max(0)..region.y1.min(img.h as i32) {
        for x in region.x0.max(0)..region.x1.min(w as i32) {
            let p = ((f64::from(x) - tx) / sx, (f64::from(y) - ty) / sy);
            let c: [f32; 4] = std::array::from_fn(|k| {
                let n = turbulence(&l, k, p, freq, octaves, fractal, tile);
                let v = if fractal { (n + 1.0) / 2.0 } else { n };
                v.clamp(0.0, 1.0) as f32
            });
            px[y as usize * w + x as usize] = [c[0] * c[3], c[1] * c[3], c[2] * c[3], c[3]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Properties of the specification's noise: zero at lattice points, within [-1, 1],
    /// the same for the same seed and different for another.
    #[test]
    fn noise_properties() {
        let l = init(7);
        for i in 0..10 {
            assert!(noise2(&l, 0, f64::from(i), 3.0, None).abs() < 1e-12);
        }
        let mut differs = false;
        let l2 = init(8);
        for i in 0..200 {
            let p = (f64::from(i) * 0.173, f64::from(i) * 0.071);
            let n = noise2(&l, 1, p.0, p.1, None);
            assert!(n.abs() <= 1.0);
            assert_eq!(n, noise2(&init(7), 1, p.0, p.1, None));
            differs |= n != noise2(&l2, 1, p.0, p.1, None);
        }
        assert!(differs);
    }
}
