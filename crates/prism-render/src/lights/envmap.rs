//! [`EnvMap`], the environment-map light: radiance from a latitude-longitude map in every
//! direction, importance-sampled by luminance times `sin theta` (pbrt's infinite area
//! light), with the course's orientation.

use std::f32::consts::PI;

use prism_image::{PixelSampling, RgbImage, Texture, Wrap};
use prism_math::warp::Piecewise1D;
use prism_math::{Rgb, Vec2, Vec3};

/// A latitude-longitude environment map ready to look up and sample.
#[derive(Clone, Debug)]
pub struct EnvMap {
    texture: Texture,
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
        let (w, h) = (map.width(), map.height());
        let columns: Vec<Piecewise1D> = (0..h)
            .map(|y| {
                let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
                let row: Vec<f32> = map.row(y).iter().map(|p| p.luminance() * sin).collect();
                Piecewise1D::new(&row)
            })
            .collect();
        let row_weights: Vec<f32> = (0..h)
            .map(|y| {
                let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
                map.row(y).iter().map(|p| p.luminance() * sin).sum::<f32>() / w as f32
            })
            .collect();
        EnvMap {
            texture: Texture::new(map.clone()).with_wrap(Wrap::Repeat, Wrap::Clamp),
            rows: Piecewise1D::new(&row_weights),
            columns,
        }
    }

    /// Radiance arriving from direction `d` (towards the light), bilinear in the map.
    #[must_use]
    pub fn radiance(&self, d: Vec3) -> Rgb {
        self.radiance_at(direction_to_uv(d))
    }

    /// [`EnvMap::radiance`] at map position `uv`.
    fn radiance_at(&self, uv: Vec2) -> Rgb {
        self.texture.sample_level(uv, 0, PixelSampling::Bilinear)
    }

    /// A direction towards the light for uniform `u`, with its radiance and solid-angle
    /// density; `None` at a pole, where the density is undefined.
    #[must_use]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        let (v, pdf_v, row) = self.rows.sample(u.y);
        let (uu, pdf_u, _) = self.columns[row].sample(u.x);
        let d = uv_to_direction(Vec2::new(uu, v));
        let sin = (d.x * d.x + d.z * d.z).sqrt();
        let pdf = pdf_u * pdf_v / (2.0 * PI * PI * sin);
        if !(sin > 0.0 && pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some((d, self.radiance(d), pdf))
    }

    /// The solid-angle density with which [`EnvMap::sample`] picks direction `d`.
    #[must_use]
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.pdf_at(d, direction_to_uv(d))
    }

    /// [`EnvMap::radiance`] and [`EnvMap::pdf`] of direction `d` at once, its map position
    /// computed once.
    #[must_use]
    pub fn radiance_pdf(&self, d: Vec3) -> (Rgb, f32) {
        let uv = direction_to_uv(d);
        (self.radiance_at(uv), self.pdf_at(d, uv))
    }

    /// [`EnvMap::pdf`] of direction `d`, whose map position is `uv`.
    fn pdf_at(&self, d: Vec3, uv: Vec2) -> f32 {
        // sin theta from the direction itself: exact near the poles, where acos is not.
        let sin = (d.x * d.x + d.z * d.z).sqrt() / d.length();
        if sin <= 0.0 {
            return 0.0;
        }
        let row = ((uv.y * self.columns.len() as f32) as usize).min(self.columns.len() - 1);
        self.rows.pdf(uv.y) * self.columns[row].pdf(uv.x) / (2.0 * PI * PI * sin)
    }
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
}
