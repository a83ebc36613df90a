//! Gaussian blur of a premultiplied image, separable: for deviations of 2 pixels or more,
//! five centred box blurs whose sizes give the Gaussian's variance (as resvg; SVG 1.1 allows
//! any box approximation), and an exact sampled kernel below.

use super::Img;

/// Blurs `img` with standard deviations `sx`, `sy` in pixels; a zero or negative deviation
/// leaves that axis alone, and both zero leave the image as it is.
pub(crate) fn gaussian(img: &mut Img, sx: f64, sy: f64) {
    let (w, h) = (img.w, img.h);
    let mut line = Vec::new();
    let mut tmp = Vec::new();
    let run_x = sx >= 0.05 && sx.is_finite();
    let run_y = sy >= 0.05 && sy.is_finite();
    if !(run_x || run_y) {
        return;
    }
    let px = std::sync::Arc::make_mut(&mut img.px);
    if run_x {
        for y in 0..h {
            line.clear();
            line.extend_from_slice(&px[y * w..(y + 1) * w]);
            blur_line(&mut line, &mut tmp, sx);
            px[y * w..(y + 1) * w].copy_from_slice(&line);
        }
    }
    if run_y {
        for x in 0..w {
            line.clear();
            line.extend((0..h).map(|y| px[y * w + x]));
            blur_line(&mut line, &mut tmp, sy);
            for (y, p) in line.iter().enumerate() {
                px[y * w + x] = *p;
            }
        }
    }
}

fn blur_line(line: &mut [[f32; 4]], tmp: &mut Vec<[f32; 4]>, sigma: f64) {
    if sigma >= 2.0 {
        for size in box_sizes(sigma.min(2.0 * line.len() as f64 + 1.0)) {
            let r = (size - 1) / 2;
            box_pass(line, tmp, r, r);
        }
    } else {
        kernel_pass(line, tmp, sigma);
    }
}

/// Five odd box sizes whose successive blurs have variance close to `sigma^2`: `m` boxes
/// of the odd width `wl` just below the ideal `sqrt(12 sigma^2 / 5 + 1)`, the rest of
/// `wl + 2`, with `m` chosen to match the variance (each box of width `w` adds
/// `(w^2 - 1) / 12`).
fn box_sizes(sigma: f64) -> [usize; 5] {
    let n = 5.0;
    let ideal = (12.0 * sigma * sigma / n + 1.0).sqrt();
    let mut wl = ideal.floor() as i64;
    if wl % 2 == 0 {
        wl -= 1;
    }
    let wlf = wl as f64;
    let m = ((12.0 * sigma * sigma - n * wlf * wlf - 4.0 * n * wlf - 3.0 * n) / (-4.0 * wlf - 4.0))
        .round()
        .max(0.0) as usize;
    std::array::from_fn(|i| {
        if i < m {
            wl.max(1) as usize
        } else {
            (wl + 2) as usize
        }
    })
}

/// The mean over `[i - left, i + right]` for each `i`, outside the line transparent.
fn box_pass(line: &mut [[f32; 4]], tmp: &mut Vec<[f32; 4]>, left: usize, right: usize) {
    let n = line.len();
    let k = 1.0 / (left + right + 1) as f32;
    tmp.clear();
    tmp.extend_from_slice(line);
    let mut sum = [0f32; 4];
    for p in tmp.iter().take(right.min(n)) {
        for c in 0..4 {
            sum[c] += p[c];
        }
    }
    for i in 0..n {
        if i + right < n {
            let p = tmp[i + right];
            for c in 0..4 {
                sum[c] += p[c];
            }
        }
        line[i] = sum.map(|v| (v * k).max(0.0));
        if i >= left {
            let p = tmp[i - left];
            for c in 0..4 {
                sum[c] -= p[c];
            }
        }
    }
}

/// Convolution with the sampled Gaussian of deviation `sigma`, cut at 3 sigma, normalised.
fn kernel_pass(line: &mut [[f32; 4]], tmp: &mut Vec<[f32; 4]>, sigma: f64) {
    let r = (3.0 * sigma).ceil() as usize;
    let mut kernel: Vec<f32> = (0..=2 * r)
        .map(|i| {
            let x = i as f64 - r as f64;
            (-x * x / (2.0 * sigma * sigma)).exp() as f32
        })
        .collect();
    let total: f32 = kernel.iter().sum();
    kernel.iter_mut().for_each(|v| *v /= total);
    let n = line.len();
    tmp.clear();
    tmp.extend_from_slice(line);
    for (i, out) in line.iter_mut().enumerate() {
        let mut sum = [0f32; 4];
        let lo = i.saturating_sub(r);
        let hi = (i + r).min(n - 1);
        for j in lo..=hi {
            let kv = kernel[j + r - i];
            for c in 0..4 {
                sum[c] += tmp[j][c] * kv;
            }
        }
        *out = sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::IRect;

    fn impulse(n: usize) -> Img {
        let mut img = Img {
            w: n,
            h: 1,
            px: std::sync::Arc::new(vec![[0.0; 4]; n]),
            region: IRect {
                x0: 0,
                y0: 0,
                x1: n as i32,
                y1: 1,
            },
            linear: false,
        };
        std::sync::Arc::make_mut(&mut img.px)[n / 2] = [1.0; 4];
        img
    }

    /// Closed form: blurring an impulse keeps its sum (1) and spreads it with the Gaussian's
    /// variance, within the box approximation's error for large deviations.
    #[test]
    fn blur_keeps_mass_and_has_the_gaussians_variance() {
        for sigma in [0.8f64, 1.5, 3.0, 7.5, 20.0] {
            let mut img = impulse(401);
            gaussian(&mut img, sigma, 0.0);
            let a: Vec<f64> = img.px.iter().map(|p| f64::from(p[3])).collect();
            let sum: f64 = a.iter().sum();
            let mean: f64 = a.iter().enumerate().map(|(i, v)| i as f64 * v).sum::<f64>() / sum;
            let var: f64 = a
                .iter()
                .enumerate()
                .map(|(i, v)| (i as f64 - mean).powi(2) * v)
                .sum::<f64>()
                / sum;
            assert!((sum - 1.0).abs() < 1e-4, "sigma {sigma}: sum {sum}");
            assert!((mean - 200.0).abs() < 0.51, "sigma {sigma}: mean {mean}");
            let rel = (var.sqrt() - sigma).abs() / sigma;
            assert!(rel < 0.08, "sigma {sigma}: deviation {}", var.sqrt());
        }
    }

    /// A huge deviation is bounded work and leaves a flat, mass-keeping line.
    #[test]
    fn huge_deviation_is_bounded() {
        let mut img = impulse(64);
        gaussian(&mut img, 1e6, 1e6);
        let sum: f32 = img.px.iter().map(|p| p[3]).sum();
        assert!((0.0..=1.0 + 1e-4).contains(&sum));
    }
}
