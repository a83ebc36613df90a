//! [`Pinhole`], the pinhole camera: primary rays through image positions.

use prism_math::{Ray, Vec3};
use prism_scene::Camera;

/// A pinhole camera for an image of `width` x `height` pixels.
#[derive(Clone, Copy, Debug)]
pub struct Pinhole {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    width: f32,
    height: f32,
}

impl Pinhole {
    /// The camera with its fields of view widened to the image's aspect ratio. Image x grows
    /// along `normalize(up x (eye - target))`, image rows go down.
    #[must_use]
    pub fn new(c: &Camera, width: u32, height: u32) -> Pinhole {
        let (hfov, vfov) = c.fov_for(width, height);
        let forward = (c.target - c.eye).normalize();
        let right = c.up.cross(-forward).normalize();
        let up = (-forward).cross(right);
        Pinhole {
            eye: c.eye,
            forward,
            right: right * (hfov.to_radians() / 2.0).tan(),
            up: up * (vfov.to_radians() / 2.0).tan(),
            width: width as f32,
            height: height as f32,
        }
    }

    /// The ray through image position `(x, y)` in pixels from the top-left corner.
    #[must_use]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let sx = 2.0 * x / self.width - 1.0;
        let sy = 1.0 - 2.0 * y / self.height;
        Ray::new(
            self.eye,
            (self.forward + sx * self.right + sy * self.up).normalize(),
        )
    }
}
