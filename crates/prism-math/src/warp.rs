//! Warps from the unit square to directions and points, each with its density (pdf) with
//! respect to solid angle or area.

use glam::{Vec2, Vec3};

use crate::lanes::{F16, V16};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

/// Uniform direction on the upper hemisphere (z >= 0).
#[must_use]
pub fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`uniform_hemisphere`]: `1 / 2pi`.
#[must_use]
pub fn uniform_hemisphere_pdf() -> f32 {
    0.5 * FRAC_1_PI
}

/// Uniform direction on the sphere.
#[must_use]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`uniform_sphere`]: `1 / 4pi`.
#[must_use]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Coefficients of the odd polynomial for `sin x` on `[-pi/4, pi/4]` (terms x^3, x^5, x^7).
const SIN: [f32; 3] = [-1.666_665_5e-1, 8.332_161e-3, -1.951_529_6e-4];
/// Coefficients of the even polynomial for `cos x` on `[-pi/4, pi/4]` (terms x^4, x^6, x^8).
const COS: [f32; 3] = [4.166_664_6e-2, -1.388_731_6e-3, 2.443_315_7e-5];

/// `(sin x, cos x)` for `|x| <= pi/4` by minimax polynomials, within one ulp: the same
/// operations on every platform (no libm), and on lanes in [`cosine_hemisphere_lanes`].
#[must_use]
#[inline]
pub fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let s = ((SIN[2] * z + SIN[1]) * z + SIN[0]) * z * x + x;
    let c = ((COS[2] * z + COS[1]) * z + COS[0]) * z * z - 0.5 * z + 1.0;
    (s, c)
}

/// Uniform point on the unit disk by Shirley and Chiu's concentric map. The angle within
/// each quarter is at most pi/4 from an axis, so its sine and cosine come from
/// [`sin_cos_quarter`].
#[must_use]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    if o.x.abs() > o.y.abs() {
        // theta = pi/4 (y / x).
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        // theta = pi/2 - phi with phi = pi/4 (x / y): cos theta = sin phi, sin theta = cos phi.
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// A uniform point on the unit disk by the polar map `r = sqrt(u.x)`, `phi = 2 pi u.y`
/// (the course's thin-lens sampling); density `1 / pi`.
#[must_use]
pub fn polar_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    Vec2::new(r * phi.cos(), r * phi.sin())
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method).
#[must_use]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// [`cosine_hemisphere`] for sixteen samples `(ux, uy)` at once, bit for bit: the same
/// operations on lanes.
#[must_use]
#[inline(always)]
pub fn cosine_hemisphere_lanes(ux: F16, uy: F16) -> V16 {
    let one = F16::splat(1.0);
    let (ox, oy) = (F16::splat(2.0) * ux - one, F16::splat(2.0) * uy - one);
    let zero = F16::splat(0.0);
    let centre = ox.eq(zero) & oy.eq(zero);
    let wide = oy.abs().lt(ox.abs());
    let r = F16::select(wide, ox, oy);
    let phi = F16::splat(FRAC_PI_4) * F16::select(wide, oy / ox, ox / oy);
    let z2 = phi * phi;
    let sin =
        ((F16::splat(SIN[2]) * z2 + F16::splat(SIN[1])) * z2 + F16::splat(SIN[0])) * z2 * phi + phi;
    let cos = ((F16::splat(COS[2]) * z2 + F16::splat(COS[1])) * z2 + F16::splat(COS[0])) * z2 * z2
        - F16::splat(0.5) * z2
        + one;
    // In the narrow quarters the angle is pi/2 - phi: its cosine and sine swap.
    let (c, s) = (F16::select(wide, cos, sin), F16::select(wide, sin, cos));
    let x = F16::select(centre, zero, r * c);
    let y = F16::select(centre, zero, r * s);
    let z = (one - (x * x + y * y)).max_num(zero).sqrt();
    V16 { x, y, z }
}

/// Density of [`cosine_hemisphere`] for a direction with `cos_theta = z`: `z / pi`.
#[must_use]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// A direction about +z from the normalised Phong lobe `cos^n`: `cos theta = u.x^(1/(n+1))`,
/// `phi = 2 pi u.y`. Its density is [`cosine_power_pdf`].
#[must_use]
pub fn cosine_power(u: Vec2, n: f32) -> Vec3 {
    let z = u.x.powf(1.0 / (n + 1.0));
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`cosine_power`] over solid angle: `(n + 1) / (2 pi) cos^n theta` on the
/// upper hemisphere, 0 below.
#[must_use]
pub fn cosine_power_pdf(cos_theta: f32, n: f32) -> f32 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    (n + 1.0) * 0.5 * FRAC_1_PI * cos_theta.powf(n)
}

/// Uniform barycentric coordinates `(b1, b2)` on a triangle (the first vertex gets
/// `1 - b1 - b2`), by the square-root parametrisation.
#[must_use]
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let s = u.x.sqrt();
    Vec2::new(1.0 - s, u.y * s)
}

/// A piecewise-constant density on `[0, 1)` proportional to non-negative weights, one per
/// equal cell, sampled by inverting its cumulative distribution (pbrt's
/// `PiecewiseConstant1D`).
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise1D {
    weights: Vec<f32>,
    /// `cdf[i]`: the probability of the cells before `i`; `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// The weights' mean: the density of cell `i` is `weights[i] / mean`.
    mean: f32,
    /// `guide[k]`: how many entries of `cdf` are at or below `k / n` (`k` in `0..=n`), so
    /// that a sample searches a few entries, not the whole table.
    guide: Vec<u32>,
}

impl Piecewise1D {
    /// The density of `weights` (negative and non-finite weights count as 0). With no
    /// positive weight it is uniform.
    #[must_use]
    pub fn new(weights: &[f32]) -> Piecewise1D {
        let mut weights: Vec<f32> = weights
            .iter()
            .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        if weights.is_empty() {
            weights.push(1.0);
        }
        let n = weights.len() as f64;
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        if total <= 0.0 {
            weights.iter_mut().for_each(|w| *w = 1.0);
        }
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &w in &weights {
            acc += f64::from(w);
            cdf.push((acc / total) as f32);
        }
        *cdf.last_mut().expect("non-empty") = 1.0;
        let cells = weights.len();
        let guide = (0..=cells)
            .map(|k| cdf.partition_point(|&c| c <= k as f32 / cells as f32) as u32)
            .collect();
        Piecewise1D {
            weights,
            cdf,
            mean: (total / n) as f32,
            guide,
        }
    }

    /// The number of cells.
    #[must_use]
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// False: there is always at least one cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// A point `x` in `[0, 1)` for uniform `u`, its density, and its cell.
    #[must_use]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.weights.len();
        // The last cell whose start is at or below u, skipping empty cells.
        let mut i = self.count_at_or_below(u).saturating_sub(1).min(n - 1);
        while self.weights[i] == 0.0 && i + 1 < n {
            i += 1;
        }
        while self.weights[i] == 0.0 && i > 0 {
            i -= 1;
        }
        let width = self.cdf[i + 1] - self.cdf[i];
        let t = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let x = ((i as f32 + t) / n as f32).min(1.0 - f32::EPSILON);
        (x, self.weights[i] / self.mean, i)
    }

    /// How many entries of the cumulative table are at or below `u` (`partition_point`),
    /// searched between the guide's entries around `u`: `u` lies at or above `(k - 1) / n`
    /// and below `(k + 2) / n` for `k = floor(u n)`, whatever the rounding.
    #[inline]
    fn count_at_or_below(&self, u: f32) -> usize {
        let g = self.guide.len() - 1;
        // A cast saturates: negative u and NaN give cell 0.
        let k = ((u * g as f32) as usize).min(g - 1);
        let lo = k.checked_sub(1).map_or(0, |j| self.guide[j] as usize);
        let hi = self.guide[(k + 2).min(g)] as usize;
        lo + self.cdf[lo..hi].partition_point(|&c| c <= u)
    }

    /// The density at `x` in `[0, 1)`.
    #[must_use]
    pub fn pdf(&self, x: f32) -> f32 {
        let n = self.weights.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        self.weights[i] / self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: double-precision sine and cosine. Over a million angles across
    /// `[-pi/4, pi/4]`, the polynomials are within one ulp of the correctly rounded values,
    /// and exact at 0.
    /// Oracle: a search of the whole cumulative table. The guided search finds the same
    /// cell for numbers across [0, 1), at cell edges, outside the range and NaN, with empty
    /// cells and a very uneven density.
    #[test]
    fn guided_search_equals_whole_table_search() {
        let mut rng = crate::Pcg32::new(3, 5);
        for n in [1usize, 2, 3, 7, 64, 1000] {
            let weights: Vec<f32> = (0..n)
                .map(|i| match i % 5 {
                    0 => 0.0,
                    1 => 1e-6,
                    _ => rng.next_f32() * 100.0,
                })
                .collect();
            let d = Piecewise1D::new(&weights);
            let mut us: Vec<f32> = (0..20_000).map(|_| rng.next_f32()).collect();
            us.extend(d.cdf.iter().flat_map(|&c| [c, c.next_up(), c.next_down()]));
            us.extend((0..=n).map(|k| k as f32 / n as f32));
            us.extend([
                -1.0,
                -0.0,
                1.0,
                1.5,
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
            ]);
            for u in us {
                let whole = d.cdf.partition_point(|&c| c <= u);
                assert_eq!(d.count_at_or_below(u), whole, "n {n}, u {u}");
            }
        }
    }

    #[test]
    fn sin_cos_quarter_is_within_one_ulp() {
        let ulps = |got: f32, want: f64| {
            let w = want as f32;
            (got.to_bits() as i64 - w.to_bits() as i64).abs()
        };
        let mut worst = 0;
        let n = 1 << 20;
        for i in 0..=n {
            let x = (i as f32 / n as f32 * 2.0 - 1.0) * std::f32::consts::FRAC_PI_4;
            let (s, c) = sin_cos_quarter(x);
            let (ws, wc) = f64::from(x).sin_cos();
            if x != 0.0 {
                worst = worst.max(ulps(s, ws));
            }
            worst = worst.max(ulps(c, wc));
        }
        assert!(worst <= 1, "{worst} ulps");
        assert_eq!(sin_cos_quarter(0.0), (0.0, 1.0));
    }

    /// Property: the lane version equals the scalar warp bit for bit, the disk's centre and
    /// its diagonals included.
    #[test]
    fn cosine_hemisphere_lanes_equal_scalar() {
        use crate::lanes::LANES;
        let mut rng = crate::Pcg32::new(3, 4);
        for round in 0..64 {
            let u: Vec<Vec2> = (0..LANES)
                .map(|i| match (round, i) {
                    (0, 0) => Vec2::splat(0.5),
                    (0, 1) => Vec2::new(0.75, 0.75),
                    (0, 2) => Vec2::new(0.25, 0.75),
                    (0, 3) => Vec2::new(0.5, 0.0),
                    _ => Vec2::new(rng.next_f32(), rng.next_f32()),
                })
                .collect();
            let lanes = cosine_hemisphere_lanes(
                F16(std::array::from_fn(|i| u[i].x)),
                F16(std::array::from_fn(|i| u[i].y)),
            );
            for (i, &u) in u.iter().enumerate() {
                let d = cosine_hemisphere(u);
                let got = Vec3::new(lanes.x.0[i], lanes.y.0[i], lanes.z.0[i]);
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    d.to_array().map(f32::to_bits),
                    "{u}"
                );
            }
        }
    }

    fn grid(n: u32) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    /// Closed form: integrating a function against each warp's samples, divided by the pdf,
    /// recovers the known integral (cos over the hemisphere is pi; 1 over the sphere is 4pi).
    #[test]
    fn warps_integrate_known_functions() {
        let n = 200;
        let count = (n * n) as f32;
        let cos_int: f32 = grid(n)
            .map(|u| uniform_hemisphere(u).z / uniform_hemisphere_pdf())
            .sum::<f32>()
            / count;
        assert!((cos_int - PI).abs() < 1e-3, "{cos_int}");
        let cos_int: f32 = grid(n)
            .map(|u| {
                let d = cosine_hemisphere(u);
                d.z / cosine_hemisphere_pdf(d.z).max(1e-12)
            })
            .sum::<f32>()
            / count;
        assert!((cos_int - PI).abs() < 1e-3, "{cos_int}");
        let z2: f32 = grid(n)
            .map(|u| uniform_sphere(u).z.powi(2) / uniform_sphere_pdf())
            .sum::<f32>()
            / count;
        assert!((z2 - 4.0 * PI / 3.0).abs() < 1e-2, "{z2}");
        // x^2 over the unit disk is pi/4; the polar map's density is 1/pi.
        let x2: f32 = grid(n).map(|u| polar_disk(u).x.powi(2) * PI).sum::<f32>() / count;
        assert!((x2 - PI / 4.0).abs() < 1e-3, "{x2}");
        for u in grid(20) {
            assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            assert!(polar_disk(u).length() <= 1.0 + 1e-6);
            let b = uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
        }
    }

    /// Inversion, closed form: uniform u lands in each cell in proportion to its weight,
    /// and the density is the weight over the mean; empty cells are never picked.
    #[test]
    fn piecewise_density_inverts_its_cdf() {
        let d = Piecewise1D::new(&[1.0, 0.0, 3.0, 4.0]);
        let mut counts = [0usize; 4];
        let n = 8000;
        for k in 0..n {
            let (x, pdf, i) = d.sample((k as f32 + 0.5) / n as f32);
            assert_eq!((x * 4.0) as usize, i);
            assert_eq!(pdf, d.pdf(x));
            counts[i] += 1;
        }
        assert_eq!(counts, [1000, 0, 3000, 4000]);
        assert_eq!(d.pdf(0.6), 1.5);
        // The density integrates to 1.
        let total: f32 = (0..400)
            .map(|k| d.pdf((k as f32 + 0.5) / 400.0) / 400.0)
            .sum();
        assert!((total - 1.0).abs() < 1e-5);
        let flat = Piecewise1D::new(&[0.0, -1.0]);
        assert_eq!(flat.pdf(0.1), 1.0);
    }
}
