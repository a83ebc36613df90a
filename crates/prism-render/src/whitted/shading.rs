//! The Whitted tracer's shading formulas: the Phong response to one light sample, and the
//! sample grid and colour of a parallelogram light.

use prism_math::{Rgb, Vec3};

/// The Phong response `c (kd (n.l) + ks max(r.v, 0)^Ns)` to light of colour `c` from unit
/// direction `l`, seen along unit `v`; zero when `n.l <= 0`.
#[must_use]
pub fn phong(n: Vec3, l: Vec3, v: Vec3, kd: Rgb, ks: Rgb, shininess: f32, c: Rgb) -> Rgb {
    let nl = n.dot(l);
    if nl <= 0.0 {
        return Rgb::BLACK;
    }
    if ks == Rgb::BLACK {
        // The same value without the costly power: ks x (a finite number) is 0.
        return c * (kd * nl + ks);
    }
    let r = 2.0 * nl * n - l;
    let spec = r.dot(v).max(0.0).powf(shininess);
    c * (kd * nl + ks * spec)
}

/// The side `k` of the `k x k` grid of samples a parallelogram light takes for a target
/// of `n` samples: `ceil(sqrt(n))`, at least 1.
#[must_use]
pub fn parallelogram_grid(n: u32) -> u32 {
    let mut k = 1;
    while k * k < n.max(1) {
        k += 1;
    }
    k
}

/// The colour of a parallelogram light at `(a, b)`: bilinear in its corners' colours.
#[must_use]
pub fn parallelogram_color(c: &[Rgb; 4], a: f32, b: f32) -> Rgb {
    (c[0] * (1.0 - b) + c[2] * b) * (1.0 - a) + (c[1] * (1.0 - b) + c[3] * b) * a
}
