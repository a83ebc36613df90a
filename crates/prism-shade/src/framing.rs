//! [`View::fit`]: a view that frames a bounding sphere, the way `prism shade` and the gallery
//! place their camera when none is given.

use prism_math::Vec3;

use crate::pipeline::View;

/// The smallest radius [`View::fit`] frames: a mesh with no extent is framed as a sphere this
/// large.
pub const MIN_FIT_RADIUS: f32 = 1e-3;

/// How far [`View::fit`] puts the eye from a sphere of radius `r`. Both fit the sphere in the
/// field of view; they round differently and are kept apart so that each caller's pictures
/// stay the same to the bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Framing {
    /// `margin * r / sin(fit)` away, `fit` being the half field of view across the narrower
    /// image side: `atan(tan(fov_y / 2) * min(width / height, 1))` (`prism shade`, margin 1.1).
    NarrowerSide {
        /// The distance over the one at which the sphere touches the frame.
        margin: f32,
    },
    /// `r / sin(fov_y / 2) * margin` away: the vertical field of view, for images at least as
    /// wide as tall (the gallery's meshes, margin 1.05).
    Vertical {
        /// The distance over the one at which the sphere touches the frame.
        margin: f32,
    },
}

impl View {
    /// A `width` x `height` view with a vertical field of view of `fov_y` degrees that looks
    /// at `target` from along `direction` (a unit vector from the target towards the eye),
    /// far enough, as `framing` says, that a sphere of `radius` (at least
    /// [`MIN_FIT_RADIUS`]) around the target fits the picture.
    #[must_use]
    #[allow(clippy::too_many_arguments)]
    pub fn fit(
        target: Vec3,
        radius: f32,
        direction: Vec3,
        up: Vec3,
        fov_y: f32,
        width: u32,
        height: u32,
        framing: Framing,
    ) -> View {
        let r = radius.max(MIN_FIT_RADIUS);
        let half = fov_y.to_radians() * 0.5;
        let distance = match framing {
            Framing::NarrowerSide { margin } => {
                let aspect = (width as f32 / height as f32).min(1.0);
                let fit = (half.tan() * aspect).atan();
                margin * r / fit.sin()
            }
            Framing::Vertical { margin } => r / half.sin() * margin,
        };
        View {
            eye: target + direction * distance,
            target,
            up,
            fov_y,
            width,
            height,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sphere touches the frame at margin 1 and fits inside it with a margin: the angle
    /// the sphere subtends from the eye is the half field of view across the narrower side.
    #[test]
    fn the_sphere_fits_the_narrower_side() {
        let target = Vec3::new(1.0, -2.0, 0.5);
        for (w, h) in [(800, 600), (300, 300), (200, 400)] {
            let v = View::fit(
                target,
                2.0,
                Vec3::Z,
                Vec3::Y,
                45.0,
                w,
                h,
                Framing::NarrowerSide { margin: 1.0 },
            );
            let d = (v.eye - target).length();
            let seen = (2.0 / d).asin();
            let half = 22.5f32.to_radians();
            let across = (half.tan() * (w as f32 / h as f32).min(1.0)).atan();
            assert!((seen - across).abs() < 1e-5, "{w}x{h}: {seen} vs {across}");
        }
        let v = View::fit(
            target,
            2.0,
            Vec3::Z,
            Vec3::Y,
            45.0,
            300,
            300,
            Framing::Vertical { margin: 1.0 },
        );
        let d = (v.eye - target).length();
        assert!(((2.0 / d).asin() - 22.5f32.to_radians()).abs() < 1e-5);
    }

    /// Oracle: each framing is the formula its caller used, to the bit, along the direction
    /// given.
    #[test]
    fn framings_keep_their_formulas() {
        let (c, r) = (Vec3::new(0.1, 0.2, 0.3), 0.7f32);
        let v = View::fit(
            c,
            r,
            Vec3::Z,
            Vec3::Y,
            45.0,
            800,
            600,
            Framing::NarrowerSide { margin: 1.1 },
        );
        let fit = (22.5f32.to_radians().tan() * 1.0).atan();
        assert_eq!(v.eye, c + Vec3::new(0.0, 0.0, 1.1 * r / fit.sin()));
        let dir = Vec3::new(0.35, 0.45, 1.0).normalize();
        let v = View::fit(
            c,
            r,
            dir,
            Vec3::Y,
            45.0,
            300,
            300,
            Framing::Vertical { margin: 1.05 },
        );
        assert_eq!(v.eye, c + dir * (r / (22.5f32.to_radians().sin()) * 1.05));
        assert_eq!(
            (v.target, v.up, v.fov_y, v.width, v.height),
            (c, Vec3::Y, 45.0, 300, 300)
        );
    }

    /// A point is framed as a sphere of the smallest radius, not from the target itself.
    #[test]
    fn a_point_is_framed_from_a_distance() {
        let v = View::fit(
            Vec3::ZERO,
            0.0,
            Vec3::Z,
            Vec3::Y,
            45.0,
            10,
            10,
            Framing::Vertical { margin: 1.0 },
        );
        assert!(v.eye.z > MIN_FIT_RADIUS);
        assert!(v.clip_from_world().is_ok());
    }
}
