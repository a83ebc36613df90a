//! Rays, axis-aligned boxes and orthonormal frames in single precision, for ray tracing.

use glam::Vec3;

/// A ray `origin + t * dir` (the direction need not be normalized).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Its direction.
    pub dir: Vec3,
}

impl Ray {
    /// A ray from `origin` along `dir`.
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray { origin, dir }
    }

    /// The point at parameter `t`.
    #[must_use]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// An axis-aligned box; the empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Aabb {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box of one point.
    #[must_use]
    pub fn point(p: Vec3) -> Aabb {
        Aabb { min: p, max: p }
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The smallest box holding this one and `p`.
    #[must_use]
    pub fn extend(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// True if the box holds no point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// `max - min` (negative for the empty box).
    #[must_use]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// The centre.
    #[must_use]
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Surface area (0 for the empty box).
    #[must_use]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The axis of largest extent (0, 1 or 2).
    #[must_use]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// The parametric interval `[t0, t1]` of the ray inside the box, clipped to
    /// `[tmin, tmax]`, by the slab test with `inv_dir = 1 / dir` (infinities allowed).
    #[must_use]
    pub fn hit(&self, origin: Vec3, inv_dir: Vec3, tmin: f32, tmax: f32) -> Option<(f32, f32)> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        let near = t0.min(t1).max_element().max(tmin);
        let far = t0.max(t1).min_element().min(tmax);
        (near <= far).then_some((near, far))
    }
}

/// An orthonormal frame: `s`, `t` tangents and the normal `n` (the local z axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent (local x).
    pub s: Vec3,
    /// Second tangent (local y).
    pub t: Vec3,
    /// Normal (local z).
    pub n: Vec3,
}

impl Frame {
    /// A frame around unit normal `n`, continuous except at `n.z = -1` (Duff et al. 2017,
    /// "Building an Orthonormal Basis, Revisited").
    #[must_use]
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Frame {
            s: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            t: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World to local coordinates.
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local to world coordinates.
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: the frame is orthonormal and right-handed for normals all over the sphere.
    #[test]
    fn frames_are_orthonormal() {
        for i in 0..1000 {
            let u = (i as f32 + 0.5) / 1000.0;
            let z = 1.0 - 2.0 * u;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5);
            assert!((f.s.cross(f.t) - n).length() < 1e-5);
            let v = Vec3::new(0.3, -0.5, 0.8);
            assert!((f.to_local(f.to_world(v)) - v).length() < 1e-5);
        }
    }

    /// Closed form: slab intervals of axis-aligned rays through the unit box.
    #[test]
    fn slab_test() {
        let b = Aabb::point(Vec3::ZERO).extend(Vec3::ONE);
        let o = Vec3::new(-1.0, 0.5, 0.5);
        let d = Vec3::X;
        assert_eq!(b.hit(o, d.recip(), 0.0, f32::INFINITY), Some((1.0, 2.0)));
        assert_eq!(b.hit(o, d.recip(), 0.0, 0.5), None);
        assert_eq!(b.hit(Vec3::new(-1.0, 2.0, 0.5), d.recip(), 0.0, 10.0), None);
        assert_eq!(b.surface_area(), 6.0);
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert!(Aabb::EMPTY.union(b) == b);
    }
}
