//! [`EnvMap`], the environment-map light: radiance from a latitude-longitude map in every
//! direction, importance-sampled by luminance times `sin theta` (pbrt's infinite area
//! light), with the course's orientation or Mitsuba's.

use std::f32::consts::PI;

use prism_image::{PixelSampling, RgbImage, Texture, Wrap};
use prism_math::glam::Mat3;
use prism_math::warp::Piecewise1D;
use prism_math::{Rgb, Vec2, Vec3};
use prism_scene::EnvMapping;

/// A latitude-longitude environment map ready to look up and sample.
#[derive(Clone, Debug)]
pub struct EnvMap {
    texture: Texture,
    /// The map's frame (`to_local`, its inverse) and texels, when it is Mitsuba's.
    mitsuba: Option<(Mat3, Mat3, RgbImage)>,
    /// Density of map rows (v).
    rows: Piecewise1D,
    /// Density of columns (u) within each row.
    columns: Vec<Piecewise1D>,
}

/// The map position `(u, v)` of direction `d`: `theta = acos(d.y)`,
/// `phi = atan2(-d.z, d.x) + pi`, `u = phi / 2 pi`, `v = theta / pi` (the course's).
#[must_use]
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let theta = d.y.clamp(-1.0, 1.0).acos();
    let phi = (-d.z).atan2(d.x) + PI;
    Vec2::new(phi / (2.0 * PI), theta / PI)
}

/// The direction at map position `(u, v)`: the inverse of [`direction_to_uv`].
#[must_use]
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (theta, phi) = (uv.y * PI, uv.x * 2.0 * PI);
    let s = theta.sin();
    Vec3::new(-s * phi.cos(), theta.cos(), s * phi.sin())
}

impl EnvMap {
    /// Prepares `map` (linear radiance): bilinear lookups that repeat across the seam at
    /// u = 0 and clamp at the poles, and sampling densities over its texels.
    #[must_use]
    pub fn new(map: &RgbImage) -> EnvMap {
        EnvMap::with_mapping(map, EnvMapping::Course)
    }

    /// Prepares `map` laid over the sphere as `mapping` says. A Mitsuba map's lookups reach
    /// across cells: each cell is sampled by the mean of 16 lookups inside it, plus a
    /// thousandth of the brightest texel around it, so that no direction with radiance has
    /// density 0.
    #[must_use]
    pub fn with_mapping(map: &RgbImage, mapping: EnvMapping) -> EnvMap {
        let (w, h) = (map.width(), map.height());
        let mitsuba = match mapping {
            EnvMapping::Course => None,
            EnvMapping::Mitsuba { to_local } => Some((to_local, to_local.inverse(), map.clone())),
        };
        let weight = |x: u32, y: u32| -> f32 {
            if mitsuba.is_none() {
                return map.get(x, y).luminance();
            }
            let mut most = 0.0f32;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let yy = (i64::from(y) + dy).clamp(0, i64::from(h) - 1) as u32;
                    let xx = (i64::from(x) + dx).rem_euclid(i64::from(w)) as u32;
                    most = most.max(map.get(xx, yy).luminance());
                }
            }
            let mut mean = 0.0f32;
            for j in 0..4 {
                for i in 0..4 {
                    let uv = Vec2::new(
                        (x as f32 + (i as f32 + 0.5) / 4.0) / w as f32,
                        (y as f32 + (j as f32 + 0.5) / 4.0) / h as f32,
                    );
                    mean += mitsuba_lookup(map, uv).luminance() / 16.0;
                }
            }
            mean + 1e-3 * most
        };
        let columns: Vec<Piecewise1D> = (0..h)
            .map(|y| {
                let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
                let row: Vec<f32> = (0..w).map(|x| weight(x, y) * sin).collect();
                Piecewise1D::new(&row)
            })
            .collect();
        let row_weights: Vec<f32> = (0..h)
            .map(|y| {
                let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
                (0..w).map(|x| weight(x, y) * sin).sum::<f32>() / w as f32
            })
            .collect();
        EnvMap {
            texture: Texture::new(map.clone()).with_wrap(Wrap::Repeat, Wrap::Clamp),
            mitsuba,
            rows: Piecewise1D::new(&row_weights),
            columns,
        }
    }

    /// Radiance arriving from direction `d` (towards the light), bilinear in the map.
    #[must_use]
    pub fn radiance(&self, d: Vec3) -> Rgb {
        self.radiance_at(self.to_uv(d))
    }

    /// The map position of direction `d`.
    fn to_uv(&self, d: Vec3) -> Vec2 {
        match self.mitsuba {
            None => direction_to_uv(d),
            Some((to_local, ..)) => mitsuba_position(&to_local, d).0,
        }
    }

    /// The direction at map position `uv` (the inverse of `to_uv`), and its sine of theta.
    fn direction_at(&self, uv: Vec2) -> (Vec3, f32) {
        match self.mitsuba {
            None => {
                let d = uv_to_direction(uv);
                (d, (d.x * d.x + d.z * d.z).sqrt())
            }
            Some((_, to_world, _)) => {
                let (theta, phi) = (uv.y * PI, uv.x * 2.0 * PI);
                let s = theta.sin();
                let l = Vec3::new(phi.sin() * s, theta.cos(), -phi.cos() * s);
                ((to_world * l).normalize_or_zero(), s)
            }
        }
    }

    /// The sine of direction `d`'s angle to the map's pole, from the direction itself
    /// (exact near the poles, where acos is not).
    fn sin_theta(&self, d: Vec3) -> f32 {
        match self.mitsuba {
            None => (d.x * d.x + d.z * d.z).sqrt() / d.length(),
            Some((to_local, ..)) => mitsuba_position(&to_local, d).1,
        }
    }

    /// [`EnvMap::radiance`] at map position `uv`: bilinear between texel centres at
    /// `(i + 0.5) / n` for the course's map; for Mitsuba's, the same across and with the
    /// first and last rows at the poles down.
    fn radiance_at(&self, uv: Vec2) -> Rgb {
        let Some((_, _, map)) = &self.mitsuba else {
            return self.texture.sample_level(uv, 0, PixelSampling::Bilinear);
        };
        mitsuba_lookup(map, uv)
    }

    /// A direction towards the light for uniform `u`, with its radiance and solid-angle
    /// density; `None` at a pole, where the density is undefined.
    #[must_use]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        let (v, pdf_v, row) = self.rows.sample(u.y);
        let (uu, pdf_u, _) = self.columns[row].sample(u.x);
        let uv = Vec2::new(uu, v);
        let (d, sin) = self.direction_at(uv);
        let pdf = pdf_u * pdf_v / (2.0 * PI * PI * sin);
        if !(sin > 0.0 && pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let radiance = match self.mitsuba {
            None => self.radiance(d),
            Some(_) => self.radiance_at(uv),
        };
        Some((d, radiance, pdf))
    }

    /// The solid-angle density with which [`EnvMap::sample`] picks direction `d`.
    #[must_use]
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.pdf_at(d, self.to_uv(d))
    }

    /// [`EnvMap::radiance`] and [`EnvMap::pdf`] of direction `d` at once, its map position
    /// computed once.
    #[must_use]
    pub fn radiance_pdf(&self, d: Vec3) -> (Rgb, f32) {
        let uv = self.to_uv(d);
        (self.radiance_at(uv), self.pdf_at(d, uv))
    }

    /// [`EnvMap::radiance_pdf`] of each direction of `dirs`, in `out` (cleared first): the
    /// same numbers, with a Mitsuba map's positions computed sixteen or eight at a time
    /// where the processor allows.
    pub fn radiance_pdf_batch(&self, dirs: &[Vec3], out: &mut Vec<(Rgb, f32)>) {
        out.clear();
        let Some((to_local, ..)) = &self.mitsuba else {
            out.extend(dirs.iter().map(|&d| self.radiance_pdf(d)));
            return;
        };
        let mut positions = vec![(Vec2::ZERO, 0.0); dirs.len()];
        mitsuba_positions(to_local, dirs, &mut positions);
        out.extend(
            positions
                .iter()
                .map(|&(uv, sin)| (self.radiance_at(uv), self.pdf_with_sin(uv, sin))),
        );
    }

    /// [`EnvMap::pdf`] of direction `d`, whose map position is `uv`.
    fn pdf_at(&self, d: Vec3, uv: Vec2) -> f32 {
        self.pdf_with_sin(uv, self.sin_theta(d))
    }

    /// [`EnvMap::pdf`] at map position `uv`, whose sine of theta is `sin`.
    fn pdf_with_sin(&self, uv: Vec2, sin: f32) -> f32 {
        if sin <= 0.0 {
            return 0.0;
        }
        let row = ((uv.y * self.columns.len() as f32) as usize).min(self.columns.len() - 1);
        self.rows.pdf(uv.y) * self.columns[row].pdf(uv.x) / (2.0 * PI * PI * sin)
    }
}

/// The position on a Mitsuba map of direction `d`, and its sine of theta: `l = to_local d`,
/// `u = atan2(l.x, -l.z) / 2 pi` wrapped to [0, 1), `v = acos(l.y) / pi` of the unit `l`,
/// and `sin theta` from `l.x` and `l.z` (exact near the poles, where acos is not).
#[inline(always)]
fn mitsuba_position(to_local: &Mat3, d: Vec3) -> (Vec2, f32) {
    let l = *to_local * d;
    let sin = (l.x * l.x + l.z * l.z).sqrt() / l.length();
    let l = l.normalize_or_zero();
    let u = prism_math::atan2(l.x, -l.z) / (2.0 * PI);
    let uv = Vec2::new(u - u.floor(), prism_math::acos(l.y.clamp(-1.0, 1.0)) / PI);
    (uv, sin)
}

/// [`mitsuba_position`] of each of `dirs` into `out`, on the widest instructions the
/// processor has (the same operations, so the same numbers).
fn mitsuba_positions(to_local: &Mat3, dirs: &[Vec3], out: &mut [(Vec2, f32)]) {
    #[inline(always)]
    fn each(to_local: &Mat3, dirs: &[Vec3], out: &mut [(Vec2, f32)]) {
        for (o, &d) in out.iter_mut().zip(dirs) {
            *o = mitsuba_position(to_local, d);
        }
    }
    /// [`each`] compiled for AVX-512.
    ///
    /// # Safety
    /// The processor must support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn each_avx512(to_local: &Mat3, dirs: &[Vec3], out: &mut [(Vec2, f32)]) {
        each(to_local, dirs, out);
    }
    /// [`each`] compiled for AVX2.
    ///
    /// # Safety
    /// The processor must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn each_avx2(to_local: &Mat3, dirs: &[Vec3], out: &mut [(Vec2, f32)]) {
        each(to_local, dirs, out);
    }
    #[cfg(target_arch = "x86_64")]
    {
        if prism_math::Isa::avx512() {
            // SAFETY: the processor has AVX-512F.
            return unsafe { each_avx512(to_local, dirs, out) };
        }
        if prism_math::Isa::avx2() {
            // SAFETY: the processor has AVX2.
            return unsafe { each_avx2(to_local, dirs, out) };
        }
    }
    each(to_local, dirs, out);
}

/// Mitsuba's lookup of a lat-long map at `uv`: bilinear between texel centres at
/// `(i + 0.5) / w` across (repeating), and between rows whose first and last sit at the
/// poles down.
fn mitsuba_lookup(map: &RgbImage, uv: Vec2) -> Rgb {
    let (w, h) = (map.width() as i64, map.height() as i64);
    let gx = uv.x * w as f32 - 0.5;
    let gy = uv.y.clamp(0.0, 1.0) * (h - 1) as f32;
    if !(gx.is_finite() && gy.is_finite()) {
        return map.get(0, 0);
    }
    let (x0, y0) = (gx.floor(), gy.floor());
    let (tx, ty) = (gx - x0, gy - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let xs = [x0.rem_euclid(w) as u32, (x0 + 1).rem_euclid(w) as u32];
    let ys = [y0.clamp(0, h - 1) as u32, (y0 + 1).clamp(0, h - 1) as u32];
    let top = map.get(xs[0], ys[0]).lerp(map.get(xs[1], ys[0]), tx);
    let bottom = map.get(xs[0], ys[1]).lerp(map.get(xs[1], ys[1]), tx);
    top.lerp(bottom, ty)
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_image::Image;

    /// A map with a gradient, a bright spot and a black band, to give the sampling shape.
    fn test_map() -> RgbImage {
        Image::from_fn(32, 16, |x, y| {
            let spot = if (x as i32 - 24).abs() < 3 && (y as i32 - 5).abs() < 2 {
                20.0
            } else {
                0.0
            };
            let band = if y == 12 { 0.0 } else { 1.0 };
            Rgb::new(
                0.2 + x as f32 / 32.0 + spot,
                0.5 * band,
                0.1 + y as f32 / 16.0,
            ) * band
        })
    }

    /// The orientation, closed form: +y is the top row's middle, and the map's u runs the
    /// way the course's `atan2(-z, x) + pi` does; the two maps invert each other.
    #[test]
    fn directions_and_map_positions_invert() {
        assert!((direction_to_uv(Vec3::Y).y).abs() < 1e-6);
        assert!((direction_to_uv(Vec3::NEG_Y).y - 1.0).abs() < 1e-6);
        assert!(
            (direction_to_uv(Vec3::NEG_X) - Vec2::new(0.0, 0.5)).length() < 1e-6
                || (direction_to_uv(Vec3::NEG_X) - Vec2::new(1.0, 0.5)).length() < 1e-6
        );
        assert!((direction_to_uv(Vec3::X) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((direction_to_uv(Vec3::Z) - Vec2::new(0.25, 0.5)).length() < 1e-6);
        for (i, j) in [(1, 1), (5, 3), (9, 7), (13, 2)] {
            let uv = Vec2::new(i as f32 / 16.0, j as f32 / 8.0);
            let back = direction_to_uv(uv_to_direction(uv));
            assert!((back - uv).length() < 1e-5, "{uv} -> {back}");
        }
    }

    /// Pearson's chi-square test of sampled directions against the density, integrated
    /// over a grid of (theta, phi) cells (pbrt's test of every sampling routine).
    #[test]
    fn sampling_matches_its_density_chi_square() {
        let map = EnvMap::new(&test_map());
        let (nt, np) = (16usize, 32usize);
        let mut observed = vec![0.0f64; nt * np];
        let n = 200_000u32;
        let mut rng = prism_math::Pcg32::new(7, 11);
        for _ in 0..n {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some((d, _, pdf)) = map.sample(u) {
                assert!(
                    (pdf - map.pdf(d)).abs() <= 1e-3 * pdf,
                    "{pdf} vs {}",
                    map.pdf(d)
                );
                let uv = direction_to_uv(d);
                let (i, j) = (
                    ((uv.y * nt as f32) as usize).min(nt - 1),
                    ((uv.x * np as f32) as usize).min(np - 1),
                );
                observed[i * np + j] += 1.0;
            }
        }
        // Expected counts: the density integrated over each cell's solid angle.
        let sub = 8;
        let mut expected = vec![0.0f64; nt * np];
        for i in 0..nt {
            for j in 0..np {
                let mut sum = 0.0f64;
                for a in 0..sub {
                    for b in 0..sub {
                        let v = (i as f32 + (a as f32 + 0.5) / sub as f32) / nt as f32;
                        let u = (j as f32 + (b as f32 + 0.5) / sub as f32) / np as f32;
                        let d = uv_to_direction(Vec2::new(u, v));
                        let domega = (2.0 * PI / np as f32) * (PI / nt as f32) * (v * PI).sin()
                            / (sub * sub) as f32;
                        sum += f64::from(map.pdf(d) * domega);
                    }
                }
                expected[i * np + j] = sum * f64::from(n);
            }
        }
        let (stat, critical) = prism_testkit::chi_square(&observed, &expected);
        assert!(stat < critical, "chi-square {stat} over {critical}");
    }

    /// A constant map is the constant environment: the same radiance every way, and the
    /// density integrates to 1 over the sphere.
    #[test]
    fn constant_map_is_uniform_radiance() {
        let map = EnvMap::new(&Image::new(16, 8, Rgb::splat(2.0)));
        let mut total = 0.0f64;
        let (nt, np) = (64, 128);
        for i in 0..nt {
            for j in 0..np {
                let uv = Vec2::new((j as f32 + 0.5) / np as f32, (i as f32 + 0.5) / nt as f32);
                let d = uv_to_direction(uv);
                assert_eq!(map.radiance(d), Rgb::splat(2.0));
                let domega = (2.0 * PI / np as f32) * (PI / nt as f32) * (uv.y * PI).sin();
                total += f64::from(map.pdf(d) * domega);
            }
        }
        assert!((total - 1.0).abs() < 1e-3, "{total}");
    }

    /// Mitsuba's orientation, closed form: with no rotation, +y reads the top row, -z the
    /// map's left edge (u = 0) and +x a quarter across; the first and last rows sit at the
    /// poles (a map whose rows differ reads exactly the top row straight up), and a turned
    /// frame moves the lookup with it. The sampling matches its density (chi-square).
    #[test]
    fn mitsuba_maps_are_oriented_as_mitsubas() {
        let mapping = |to_local| EnvMapping::Mitsuba { to_local };
        let map = EnvMap::with_mapping(&test_map(), mapping(Mat3::IDENTITY));
        assert!((map.to_uv(Vec3::Y).y).abs() < 1e-6);
        assert!((map.to_uv(Vec3::NEG_Z) - Vec2::new(0.0, 0.5)).length() < 1e-6);
        assert!((map.to_uv(Vec3::X) - Vec2::new(0.25, 0.5)).length() < 1e-6);
        for uv in [Vec2::new(0.1, 0.3), Vec2::new(0.7, 0.8)] {
            assert!((map.to_uv(map.direction_at(uv).0) - uv).length() < 1e-5);
        }
        let rows = Image::from_fn(8, 4, |_, y| Rgb::splat(y as f32));
        let poles = EnvMap::with_mapping(&rows, mapping(Mat3::IDENTITY));
        assert_eq!(poles.radiance(Vec3::Y), Rgb::splat(0.0));
        assert_eq!(poles.radiance(Vec3::NEG_Y), Rgb::splat(3.0));
        assert!((poles.radiance(Vec3::X).r - 1.5).abs() < 1e-5);
        // Turned a quarter about x, the map's north pole lies along world +z.
        let turn = Mat3::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let turned = EnvMap::with_mapping(&rows, mapping(turn.inverse()));
        assert!(turned.radiance(Vec3::Z).r.abs() < 1e-5);
        // Sampling against the density, over cells of the map.
        let (nt, np) = (16usize, 32usize);
        let mut observed = vec![0.0f64; nt * np];
        let n = 200_000u32;
        let mut rng = prism_math::Pcg32::new(3, 5);
        for _ in 0..n {
            if let Some((d, _, pdf)) = map.sample(Vec2::new(rng.next_f32(), rng.next_f32())) {
                assert!(
                    (pdf - map.pdf(d)).abs() <= 1e-3 * pdf,
                    "{pdf} vs {}",
                    map.pdf(d)
                );
                let uv = map.to_uv(d);
                let (i, j) = (
                    ((uv.y * nt as f32) as usize).min(nt - 1),
                    ((uv.x * np as f32) as usize).min(np - 1),
                );
                observed[i * np + j] += 1.0;
            }
        }
        let sub = 8;
        let mut expected = vec![0.0f64; nt * np];
        for i in 0..nt {
            for j in 0..np {
                let mut sum = 0.0f64;
                for a in 0..sub {
                    for b in 0..sub {
                        let v = (i as f32 + (a as f32 + 0.5) / sub as f32) / nt as f32;
                        let u = (j as f32 + (b as f32 + 0.5) / sub as f32) / np as f32;
                        let (d, _) = map.direction_at(Vec2::new(u, v));
                        let domega = (2.0 * PI / np as f32) * (PI / nt as f32) * (v * PI).sin()
                            / (sub * sub) as f32;
                        sum += f64::from(map.pdf(d) * domega);
                    }
                }
                expected[i * np + j] = sum * f64::from(n);
            }
        }
        let (stat, critical) = prism_testkit::chi_square(&observed, &expected);
        assert!(stat < critical, "chi-square {stat} over {critical}");
    }
}
