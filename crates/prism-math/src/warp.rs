//! Warps from the unit square to directions and points, each with its density (pdf) with
//! respect to solid angle or area.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

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

/// Uniform point on the unit disk by Shirley and Chiu's concentric map.
#[must_use]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
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

/// Density of [`cosine_hemisphere`] for a direction with `cos_theta = z`: `z / pi`.
#[must_use]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform barycentric coordinates `(b1, b2)` on a triangle (the first vertex gets
/// `1 - b1 - b2`), by the square-root parametrisation.
#[must_use]
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let s = u.x.sqrt();
    Vec2::new(1.0 - s, u.y * s)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
