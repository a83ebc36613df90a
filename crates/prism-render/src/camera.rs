//! [`Perspective`], the perspective camera: primary rays through image positions, from a
//! pinhole or across a thin lens, and the camera ray a sample's first dimensions choose.

use prism_math::lanes::{F16, V16};
use prism_math::{warp, Ray, Vec2, Vec3};
use prism_scene::Camera;

use crate::pixel_filter::PixelFilter;
use crate::sampler::Sampler;

/// A perspective camera for an image of `width` x `height` pixels: a pinhole, or a thin
/// lens focused on a plane (the course's thin-lens model).
#[derive(Clone, Debug)]
pub struct Perspective {
    eye: Vec3,
    forward: Vec3,
    /// Unit right and up vectors of the lens plane.
    right_unit: Vec3,
    up_unit: Vec3,
    /// The same, scaled to the half-extent of the image at unit depth.
    right: Vec3,
    up: Vec3,
    /// The image's centre off the view axis at unit depth (world units for an orthographic
    /// view): zero unless the image is a crop of a larger film.
    centre: Vec3,
    width: f32,
    height: f32,
    /// Lens radius and focal distance; `None` for a pinhole.
    lens: Option<(f32, f32)>,
    /// True for parallel rays from the plane through the eye (`right` and `up` are then the
    /// image's half extents in world units).
    orthographic: bool,
    /// Where in the image a pixel's samples fall.
    filter: PixelFilter,
}

impl Perspective {
    /// The camera with its fields of view widened to the image's aspect ratio. Image x grows
    /// along `normalize(up x (eye - target))`, image rows go down.
    #[must_use]
    pub fn new(c: &Camera, width: u32, height: u32) -> Perspective {
        // A crop sees the part of the whole film's view that its window covers.
        let (fw, fh) = c.crop.map_or((width, height), |crop| crop.full);
        let (hfov, vfov) = c.fov_for(fw, fh);
        let forward = (c.target - c.eye).normalize();
        let right = c.up.cross(-forward).normalize();
        let up = (-forward).cross(right);
        let (half_x, half_y) = match c.orthographic {
            Some((x, y)) => (x, y * fh as f32 / fw as f32),
            None => (
                (hfov.to_radians() / 2.0).tan(),
                (vfov.to_radians() / 2.0).tan(),
            ),
        };
        let (mut right_half, mut up_half, mut centre) = (right * half_x, up * half_y, Vec3::ZERO);
        if let Some(crop) = c.crop {
            let (ox, oy) = (crop.offset.0 as f32, crop.offset.1 as f32);
            let (w, h) = (width as f32, height as f32);
            let cx = (2.0 * ox + w) / fw as f32 - 1.0;
            let cy = 1.0 - (2.0 * oy + h) / fh as f32;
            centre = cx * right_half + cy * up_half;
            right_half *= w / fw as f32;
            up_half *= h / fh as f32;
        }
        Perspective {
            eye: c.eye,
            forward,
            right_unit: right,
            up_unit: up,
            right: right_half,
            up: up_half,
            centre,
            orthographic: c.orthographic.is_some(),
            width: width as f32,
            height: height as f32,
            lens: c
                .lens
                .filter(|l| l.radius > 0.0)
                .map(|l| (l.radius, l.focal_distance)),
            filter: PixelFilter::Box,
        }
    }

    /// The camera drawing its pixels' sample positions with `filter`.
    #[must_use]
    pub fn with_filter(mut self, filter: PixelFilter) -> Perspective {
        self.filter = filter;
        self
    }

    /// True if samples fall uniformly in their pixel (a box filter).
    #[must_use]
    pub(crate) fn box_filtered(&self) -> bool {
        matches!(self.filter, PixelFilter::Box)
    }

    /// The image position of a sample of pixel `(x, y)` drawn with `u`.
    #[inline]
    #[must_use]
    pub fn image_position(&self, (x, y): (u32, u32), u: Vec2) -> (f32, f32) {
        (
            self.filter.position(x, u.x, self.width as u32),
            self.filter.position(y, u.y, self.height as u32),
        )
    }

    /// True when rays leave a lens, so [`Perspective::ray`] uses its lens sample.
    #[must_use]
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The ray through image position `(x, y)` in pixels from the top-left corner. With a
    /// lens, it leaves the lens point `lens_sample` maps to (uniform on the disk for uniform
    /// samples) and passes through the point the pinhole ray meets on the plane of focus.
    #[must_use]
    pub fn ray(&self, x: f32, y: f32, lens_sample: Vec2) -> Ray {
        let sx = 2.0 * x / self.width - 1.0;
        let sy = 1.0 - 2.0 * y / self.height;
        if self.orthographic {
            return Ray::new(
                self.eye + self.centre + sx * self.right + sy * self.up,
                self.forward,
            );
        }
        // Direction at unit depth along the view axis.
        let d = self.forward + self.centre + sx * self.right + sy * self.up;
        match self.lens {
            None => Ray::new(self.eye, d.normalize()),
            Some((radius, focal_distance)) => {
                let focus = self.eye + focal_distance * d;
                let p = radius * warp::polar_disk(lens_sample);
                let origin = self.eye + p.x * self.right_unit + p.y * self.up_unit;
                Ray::new(origin, (focus - origin).normalize())
            }
        }
    }

    /// The point every ray leaves, for a pinhole camera (none with a lens).
    #[must_use]
    pub(crate) fn pinhole(&self) -> Option<Vec3> {
        (self.lens.is_none() && !self.orthographic).then_some(self.eye)
    }

    /// The directions of a pinhole camera's [`Perspective::ray`] through sixteen image
    /// positions at once, the same operations lane by lane: the same bits.
    #[inline(always)]
    pub(crate) fn pinhole_dirs(&self, x: F16, y: F16) -> V16 {
        let sx = x * 2.0 / self.width - 1.0;
        let sy = F16::splat(1.0) - y * 2.0 / self.height;
        let (f, r, u) = (self.forward + self.centre, self.right, self.up);
        V16 {
            x: F16::splat(f.x) + sx * r.x + sy * u.x,
            y: F16::splat(f.y) + sx * r.y + sy * u.y,
            z: F16::splat(f.z) + sx * r.z + sy * u.z,
        }
        .normalize()
    }
}

/// The camera ray through pixel `(x, y)` that a sample's first dimensions choose (the
/// position in the pixel, then the lens point if there is a lens).
pub(crate) fn camera_ray(camera: &Perspective, (x, y): (u32, u32), sampler: &mut Sampler) -> Ray {
    let u = sampler.next_2d();
    // The lens takes dimensions only when there is one: pinhole images keep their bytes.
    let lens = if camera.has_lens() {
        sampler.next_2d()
    } else {
        prism_math::Vec2::ZERO
    };
    let (px, py) = camera.image_position((x, y), u);
    camera.ray(px, py, lens)
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_scene::ThinLens;

    fn camera(lens: Option<ThinLens>) -> Perspective {
        let c = Camera {
            eye: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov: 60.0,
            vfov: 45.0,
            near: 0.001,
            far: 1000.0,
            lens,
            orthographic: None,
            crop: None,
        };
        Perspective::new(&c, 64, 48)
    }

    /// Closed form: an orthographic camera's rays are parallel to the view and leave the
    /// plane through the eye; the image's left and right edges lie the half width to either
    /// side, its top and bottom the half height over the aspect.
    #[test]
    fn orthographic_rays_are_parallel_across_the_extents() {
        let c = Camera {
            eye: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov: 60.0,
            vfov: 45.0,
            near: 0.001,
            far: 1000.0,
            lens: None,
            orthographic: Some((2.0, 3.0)),
            crop: None,
        };
        let cam = Perspective::new(&c, 64, 48);
        assert!(cam.pinhole().is_none() && !cam.has_lens());
        for (x, y, want) in [
            (0.0, 24.0, Vec3::new(-2.0, 0.0, 5.0)),
            (64.0, 24.0, Vec3::new(2.0, 0.0, 5.0)),
            (32.0, 0.0, Vec3::new(0.0, 2.25, 5.0)),
            (32.0, 48.0, Vec3::new(0.0, -2.25, 5.0)),
        ] {
            let r = cam.ray(x, y, Vec2::ZERO);
            assert!((r.origin - want).length() < 1e-5, "{x} {y}: {}", r.origin);
            assert!((r.dir - Vec3::NEG_Z).length() < 1e-6);
        }
    }

    /// Where a ray meets the plane `z = 5 - depth` (depth along the view axis, -z here).
    fn at_depth(r: &Ray, depth: f32) -> Vec3 {
        let t = (5.0 - depth - r.origin.z) / r.dir.z;
        r.origin + t * r.dir
    }

    fn lens_samples() -> impl Iterator<Item = Vec2> {
        (0..=8).flat_map(|i| (0..8).map(move |j| Vec2::new(i as f32 / 8.0, j as f32 / 8.0)))
    }

    /// Closed form: every ray through a film point meets the plane of focus at the point
    /// the pinhole ray meets it, so a point at the focal distance projects sharp.
    #[test]
    fn a_point_at_the_focal_distance_is_sharp() {
        let lens = ThinLens {
            radius: 0.3,
            focal_distance: 4.0,
        };
        let (pin, thin) = (camera(None), camera(Some(lens)));
        for (x, y) in [(32.0, 24.0), (3.5, 40.25), (60.0, 1.0)] {
            let want = at_depth(&pin.ray(x, y, Vec2::ZERO), 4.0);
            for u in lens_samples() {
                let got = at_depth(&thin.ray(x, y, u), 4.0);
                assert!((got - want).length() < 1e-5, "{got} != {want}");
            }
        }
    }

    /// Closed form: on a plane at depth `z`, the rays through one film point spread over a
    /// disk around the pinhole ray's point whose radius is the circle of confusion
    /// `R |z - d| / d` (lens radius R, focal distance d); the lens rim reaches it.
    #[test]
    fn the_blur_off_focus_is_the_circle_of_confusion() {
        let (radius, focal_distance) = (0.25f32, 3.0f32);
        let thin = camera(Some(ThinLens {
            radius,
            focal_distance,
        }));
        let pin = camera(None);
        for depth in [1.5f32, 6.0, 9.0] {
            let coc = radius * (depth - focal_distance).abs() / focal_distance;
            let centre = at_depth(&pin.ray(32.0, 24.0, Vec2::ZERO), depth);
            let mut widest = 0.0f32;
            for u in lens_samples() {
                let d = (at_depth(&thin.ray(32.0, 24.0, u), depth) - centre).length();
                assert!(d <= coc * (1.0 + 1e-4) + 1e-6, "{d} > {coc}");
                widest = widest.max(d);
            }
            assert!(
                (widest - coc).abs() <= coc * 1e-4 + 1e-6,
                "{widest} vs {coc}"
            );
        }
    }

    /// A lens of radius 0 is a pinhole: the same rays.
    #[test]
    fn a_zero_lens_is_a_pinhole() {
        let thin = camera(Some(ThinLens {
            radius: 0.0,
            focal_distance: 2.0,
        }));
        assert!(!thin.has_lens());
        let (a, b) = (
            thin.ray(7.0, 9.0, Vec2::splat(0.7)),
            camera(None).ray(7.0, 9.0, Vec2::ZERO),
        );
        assert_eq!((a.origin, a.dir), (b.origin, b.dir));
    }
}
