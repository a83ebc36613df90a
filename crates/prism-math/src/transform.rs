//! [`Transform`], a 4x4 transform of points, vectors and normals kept with its inverse, named
//! destination-from-source (`world_from_object`, `clip_from_camera`) as pbrt names them.

use std::ops::Mul;

use glam::{Mat4, Vec3, Vec4};

/// A 4x4 transform with its inverse. Composition reads right to left, like the names:
/// `world_from_camera * camera_from_object` is `world_from_object`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    m: Mat4,
    inv: Mat4,
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Transform = Transform {
        m: Mat4::IDENTITY,
        inv: Mat4::IDENTITY,
    };

    /// The transform of matrix `m` (column vectors: `p' = m p`), or `None` when `m` is not
    /// finite or not invertible.
    #[must_use]
    pub fn from_matrix(m: Mat4) -> Option<Transform> {
        let det = m.determinant();
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        let inv = m.inverse();
        inv.is_finite().then_some(Transform { m, inv })
    }

    /// A translation by `d`.
    #[must_use]
    pub fn translate(d: Vec3) -> Transform {
        Transform {
            m: Mat4::from_translation(d),
            inv: Mat4::from_translation(-d),
        }
    }

    /// A scale by `s` per axis, or `None` when a factor is 0 or not finite.
    #[must_use]
    pub fn scale(s: Vec3) -> Option<Transform> {
        (s.is_finite() && s.x != 0.0 && s.y != 0.0 && s.z != 0.0).then(|| Transform {
            m: Mat4::from_scale(s),
            inv: Mat4::from_scale(s.recip()),
        })
    }

    /// A rotation by `degrees` about `axis` (right-handed), or `None` for a zero axis.
    #[must_use]
    pub fn rotate(axis: Vec3, degrees: f32) -> Option<Transform> {
        let axis = axis.try_normalize()?;
        let m = Mat4::from_axis_angle(axis, degrees.to_radians());
        Some(Transform {
            m,
            inv: m.transpose(),
        })
    }

    /// The camera-from-world transform of a camera at `eye` looking at `target` with `up`
    /// (OpenGL's `lookAt`: the camera looks down its -z axis, +y up), or `None` when the eye
    /// is the target or `up` is along the view.
    #[must_use]
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Option<Transform> {
        let forward = (target - eye).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let true_up = right.cross(forward);
        let world_from_camera = Mat4::from_cols(
            right.extend(0.0),
            true_up.extend(0.0),
            (-forward).extend(0.0),
            eye.extend(1.0),
        );
        Some(Transform {
            m: world_from_camera.inverse(),
            inv: world_from_camera,
        })
    }

    /// The clip-from-camera transform of a perspective camera (OpenGL's `perspective`): a
    /// vertical field of view `fov_y` in degrees, `aspect` = width / height, and near and far
    /// planes at distances `near` < `far` mapped to clip depth -1 and 1; `None` for values
    /// outside those ranges.
    #[must_use]
    pub fn perspective(fov_y: f32, aspect: f32, near: f32, far: f32) -> Option<Transform> {
        let valid = fov_y > 0.0 && fov_y < 180.0 && aspect > 0.0 && near > 0.0 && far > near;
        if !(valid && aspect.is_finite() && far.is_finite()) {
            return None;
        }
        Transform::from_matrix(Mat4::perspective_rh_gl(
            fov_y.to_radians(),
            aspect,
            near,
            far,
        ))
    }

    /// The matrix.
    #[must_use]
    pub fn matrix(&self) -> Mat4 {
        self.m
    }

    /// The inverse transform: source-from-destination.
    #[must_use]
    pub fn inverse(&self) -> Transform {
        Transform {
            m: self.inv,
            inv: self.m,
        }
    }

    /// A point, homogeneous: `(x, y, z, 1)` transformed, before any division.
    #[must_use]
    pub fn point_homogeneous(&self, p: Vec3) -> Vec4 {
        self.m * p.extend(1.0)
    }

    /// A point, divided by its w (for projective transforms).
    #[must_use]
    pub fn point(&self, p: Vec3) -> Vec3 {
        let q = self.point_homogeneous(p);
        q.truncate() / q.w
    }

    /// A direction (no translation).
    #[must_use]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// A surface normal: by the inverse transpose, so it stays perpendicular to the
    /// transformed surface (not renormalised).
    #[must_use]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.inv.transpose().transform_vector3(n)
    }
}

impl Mul for Transform {
    type Output = Transform;

    /// `a * b` applies `b`, then `a`.
    fn mul(self, b: Transform) -> Transform {
        Transform {
            m: self.m * b.m,
            inv: b.inv * self.inv,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    /// Closed form: composition applies right to left, and the kept inverse undoes it.
    #[test]
    fn composition_reads_right_to_left_and_inverts() {
        let world_from_object = Transform::translate(Vec3::new(1.0, 2.0, 3.0))
            * Transform::rotate(Vec3::Z, 90.0).unwrap()
            * Transform::scale(Vec3::new(2.0, 3.0, 4.0)).unwrap();
        let p = Vec3::new(1.0, 1.0, 1.0);
        // Scale to (2, 3, 4), rotate about z to (-3, 2, 4), translate to (-2, 4, 7).
        assert!(close(world_from_object.point(p), Vec3::new(-2.0, 4.0, 7.0)));
        let back = world_from_object
            .inverse()
            .point(world_from_object.point(p));
        assert!(close(back, p));
        let m = (world_from_object * world_from_object.inverse()).matrix();
        assert!(m.abs_diff_eq(Mat4::IDENTITY, 1e-5));
        assert!(close(
            world_from_object.vector(Vec3::X),
            Vec3::new(0.0, 2.0, 0.0)
        ));
        assert!(Transform::scale(Vec3::new(1.0, 0.0, 1.0)).is_none());
        assert!(Transform::rotate(Vec3::ZERO, 10.0).is_none());
        assert!(Transform::from_matrix(Mat4::ZERO).is_none());
    }

    /// Property: a transformed normal stays perpendicular to transformed tangents, under a
    /// non-uniform scale where transforming the normal as a vector would not.
    #[test]
    fn normals_stay_perpendicular() {
        let t = Transform::rotate(Vec3::new(1.0, 1.0, 0.0), 30.0).unwrap()
            * Transform::scale(Vec3::new(1.0, 5.0, 0.5)).unwrap();
        let n = Vec3::new(1.0, 1.0, 1.0).normalize();
        let tangents = [Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, -1.0)];
        for tangent in tangents {
            assert!(t.normal(n).dot(t.vector(tangent)).abs() < 1e-4);
        }
        assert!(t.vector(n).dot(t.vector(tangents[0])).abs() > 1e-2);
    }

    /// Closed form: look-at puts the eye at the origin and the target on -z at its distance;
    /// the perspective maps the near and far planes to depth -1 and 1 and the field of
    /// view's edge to y = 1.
    #[test]
    fn camera_transforms_follow_opengl() {
        let eye = Vec3::new(3.0, 4.0, 5.0);
        let target = Vec3::new(3.0, 4.0, -1.0);
        let camera_from_world = Transform::look_at(eye, target, Vec3::Y).unwrap();
        assert!(close(camera_from_world.point(eye), Vec3::ZERO));
        assert!(close(
            camera_from_world.point(target),
            Vec3::new(0.0, 0.0, -6.0)
        ));
        assert!(close(camera_from_world.point(eye + Vec3::X), Vec3::X));
        assert!(Transform::look_at(eye, eye, Vec3::Y).is_none());
        let clip_from_camera = Transform::perspective(90.0, 2.0, 0.5, 10.0).unwrap();
        assert!((clip_from_camera.point(Vec3::new(0.0, 0.0, -0.5)).z + 1.0).abs() < 1e-5);
        assert!((clip_from_camera.point(Vec3::new(0.0, 0.0, -10.0)).z - 1.0).abs() < 1e-5);
        // At depth 2 a 90 degree field of view reaches y = 2; aspect 2 reaches x = 4.
        let edge = clip_from_camera.point(Vec3::new(4.0, 2.0, -2.0));
        assert!((edge.x - 1.0).abs() < 1e-5 && (edge.y - 1.0).abs() < 1e-5);
        assert!(Transform::perspective(0.0, 1.0, 0.1, 1.0).is_none());
        assert!(Transform::perspective(60.0, 1.0, 1.0, 1.0).is_none());
    }
}
