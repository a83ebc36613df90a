//! [`OrbitView`], the Delft ray tracer's camera: rays through pixel corners counted from the
//! bottom-left, a row of corner rays at a time, thin-lens rays, ray cones' spread,
//! and world points projected back to pixels for overlays.

use prism_math::lanes::{F16, LANES};
use prism_math::{Ray, Vec2, Vec3};

/// The Delft ray tracer's camera over an image of `width` x `height` pixels: pixel
/// `(x, y)`, `y = 0` the **bottom** row, maps to `ndc = (2x/W - 1, 2y/H - 1)` with no
/// half-pixel offset, and the ray leaves the eye along
/// `normalize(R normalize(-ndc.x hw, ndc.y hh, 1))` with `hh = tan(fov / 2)`,
/// `hw = (W / H) hh` (screen-right is camera -x).
#[derive(Clone, Copy, Debug)]
pub struct OrbitView {
    eye: Vec3,
    world_from_camera: prism_math::Transform,
    hw: f32,
    hh: f32,
    width: f32,
    height: f32,
}

impl OrbitView {
    /// The view of `c` on a `width` x `height` image.
    #[must_use]
    pub fn new(c: &prism_scene::OrbitCamera, width: u32, height: u32) -> OrbitView {
        let hh = (c.fov_y.to_radians() / 2.0).tan();
        OrbitView {
            eye: c.eye(),
            world_from_camera: c.world_from_camera(),
            hw: width as f32 / height as f32 * hh,
            hh,
            width: width as f32,
            height: height as f32,
        }
    }

    /// The eye.
    #[must_use]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The ray through image position `(x, y)`, measured in pixels from the bottom-left
    /// corner (a pixel's integer corner is its lower-left).
    #[must_use]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let ndc = Vec2::new(2.0 * x / self.width - 1.0, 2.0 * y / self.height - 1.0);
        let local = Vec3::new(-ndc.x * self.hw, ndc.y * self.hh, 1.0).normalize();
        Ray::new(self.eye, self.world_from_camera.vector(local).normalize())
    }

    /// The thin-lens ray for image position `(x, y)` (as [`OrbitView::ray`]): from the lens
    /// point `aperture * lens` (`lens` on the unit disk, in the camera's x/y plane about the
    /// eye) through the pinhole ray's point on the plane in focus, `focus` along the view
    /// axis.
    #[must_use]
    pub fn lens_ray(&self, x: f32, y: f32, lens: Vec2, aperture: f32, focus: f32) -> Ray {
        let ndc = Vec2::new(2.0 * x / self.width - 1.0, 2.0 * y / self.height - 1.0);
        let on_plane = Vec3::new(-ndc.x * self.hw, ndc.y * self.hh, 1.0) * focus;
        let focal = self.eye + self.world_from_camera.vector(on_plane);
        let at = aperture * lens;
        let origin = self.eye + self.world_from_camera.vector(Vec3::new(at.x, at.y, 0.0));
        Ray::new(origin, (focal - origin).normalize())
    }

    /// How fast a camera ray's cone widens: `2 tan(alpha / 2)` per unit distance, for the
    /// spread angle `alpha = atan(2 hh / H)` of one pixel at the image centre.
    #[must_use]
    pub fn cone_spread(&self) -> f32 {
        let alpha = (2.0 * self.hh / self.height).atan();
        2.0 * (0.5 * alpha).tan()
    }

    /// The rays through the lower-left corners of the pixels `x = 0, 1, ...` of row `y`
    /// (counted from the bottom), the same bits as [`OrbitView::ray`] gives, computed
    /// sixteen at a time so that the square roots and divisions run on SIMD lanes.
    pub fn corner_rays(&self, y: u32, out: &mut Vec<Ray>) {
        let n = self.width as usize;
        let ly = F16::splat((2.0 * y as f32 / self.height - 1.0) * self.hh);
        let one = F16::splat(1.0);
        // The rotation's columns, for `Mat4::transform_vector3` on lanes: the same products
        // and sums (x column first) as `Transform::vector` takes.
        let m = self.world_from_camera.matrix();
        let col = |c: prism_math::glam::Vec4| [F16::splat(c.x), F16::splat(c.y), F16::splat(c.z)];
        let (cx, cy, cz) = (col(m.x_axis), col(m.y_axis), col(m.z_axis));
        out.clear();
        for start in (0..n).step_by(LANES) {
            let mut lx = [0f32; LANES];
            for (k, v) in lx.iter_mut().enumerate() {
                *v = -(2.0 * (start + k) as f32 / self.width - 1.0) * self.hw;
            }
            let lx = F16(lx);
            // As `Vec3::normalize`: times the reciprocal of the length, x, y, z summed in order.
            let r1 = one / (lx * lx + ly * ly + one).sqrt();
            let local = [lx * r1, ly * r1, r1];
            let w: [F16; 3] =
                std::array::from_fn(|i| cx[i] * local[0] + cy[i] * local[1] + cz[i] * local[2]);
            let r2 = one / (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            let (dx, dy, dz) = (w[0] * r2, w[1] * r2, w[2] * r2);
            out.extend(
                (0..LANES.min(n - start))
                    .map(|k| Ray::new(self.eye, Vec3::new(dx.0[k], dy.0[k], dz.0[k]))),
            );
        }
    }

    /// Where a world point lands: `(x, y from the top, depth along the view axis)` in
    /// pixels of the written image (row 0 at the top), or `None` behind the eye.
    #[must_use]
    pub fn project(&self, p: Vec3) -> Option<(f32, f32, f32)> {
        let local = self.world_from_camera.inverse().point(p);
        if local.z <= 1e-6 {
            return None;
        }
        let ndc_x = -local.x / local.z / self.hw;
        let ndc_y = local.y / local.z / self.hh;
        let x = (ndc_x + 1.0) * 0.5 * self.width;
        let y_up = (ndc_y + 1.0) * 0.5 * self.height;
        Some((x, self.height - y_up, local.z))
    }
}
