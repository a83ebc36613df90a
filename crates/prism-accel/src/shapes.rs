//! Primitives and their ray tests: the sphere, per-ray precomputation, the watertight
//! ray-triangle test and the ray-sphere test.

use prism_math::{Aabb, Ray, Vec3};

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (positive).
    pub radius: f32,
}

impl Sphere {
    /// Its bounding box.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.center - Vec3::splat(self.radius),
            max: self.center + Vec3::splat(self.radius),
        }
    }
}

/// Per-ray values of the watertight triangle test, computed once per ray.
#[derive(Clone, Copy, Debug)]
pub struct RayPre {
    /// The ray's origin.
    pub origin: Vec3,
    /// `1 / dir`, for slab tests.
    pub inv_dir: Vec3,
    pub(crate) perm: usize,
    pub(crate) shear: Vec3,
    /// The origin's coordinates on the axes `(kx, ky, kz)` of `perm`.
    pub(crate) origin_k: [f32; 3],
}

/// The axes `(kx, ky, kz)` of each permutation used by the watertight test.
pub(crate) static PERMS: [[usize; 3]; 6] = [
    [1, 2, 0],
    [2, 1, 0],
    [2, 0, 1],
    [0, 2, 1],
    [0, 1, 2],
    [1, 0, 2],
];

/// The axis of the largest of `a` (absolute direction components), ties going to the lower
/// axis; without branches.
#[inline(always)]
pub(crate) fn dominant_axis(a: [f32; 3]) -> usize {
    let x_wins = (a[0] >= a[1]) & (a[0] >= a[2]);
    usize::from(!x_wins) * (2 - usize::from(a[1] >= a[2]))
}

impl RayPre {
    /// Precomputes the shear that maps the ray to the +z axis.
    #[must_use]
    #[inline]
    pub fn new(ray: &Ray) -> RayPre {
        let d = ray.dir;
        let kz = dominant_axis(d.abs().to_array());
        let da = d.to_array();
        // Keep the winding: swap kx and ky when the dominant component is negative.
        let perm = 2 * kz + usize::from(da[kz] < 0.0);
        let [kx, ky, kz] = PERMS[perm];
        let inv_dir = d.recip();
        // `1 / da[kz]`, already computed.
        let inv_z = inv_dir.to_array()[kz];
        RayPre {
            origin: ray.origin,
            inv_dir,
            perm,
            shear: Vec3::new(da[kx] * inv_z, da[ky] * inv_z, inv_z),
            origin_k: {
                let o = ray.origin.to_array();
                [o[kx], o[ky], o[kz]]
            },
        }
    }

    /// The axes `(kx, ky, kz)` of the ray's permutation, `PERMS[perm]`, without a bounds
    /// check.
    #[inline(always)]
    pub(crate) fn axes(&self) -> &'static [usize; 3] {
        debug_assert!(self.perm < PERMS.len());
        // SAFETY: `perm` is `2 * kz + sign` with `kz < 3` (`RayPre::new`, `new_avx`), below
        // six.
        unsafe { PERMS.get_unchecked(self.perm) }
    }

    /// `v` with its axes reordered to `(kx, ky, kz)`.
    #[inline(always)]
    fn permute(&self, v: Vec3) -> Vec3 {
        match self.perm {
            0 => Vec3::new(v.y, v.z, v.x),
            1 => Vec3::new(v.z, v.y, v.x),
            2 => Vec3::new(v.z, v.x, v.y),
            3 => Vec3::new(v.x, v.z, v.y),
            4 => v,
            _ => Vec3::new(v.y, v.x, v.z),
        }
    }
}

/// The watertight ray-triangle test. Returns `(t, b1, b2)` for a hit with `tmin < t < tmax`,
/// where `b1` and `b2` are the barycentric weights of `v[1]` and `v[2]`. Edge functions that
/// are exactly zero in single precision are recomputed in double precision, so hits on shared
/// edges are decided consistently.
#[must_use]
#[inline]
pub fn intersect_triangle(
    r: &RayPre,
    v: &[Vec3; 3],
    tmin: f32,
    tmax: f32,
) -> Option<(f32, f32, f32)> {
    let a = r.permute(v[0] - r.origin);
    let b = r.permute(v[1] - r.origin);
    let c = r.permute(v[2] - r.origin);
    let s = r.shear;
    let ax = a.x - s.x * a.z;
    let ay = a.y - s.y * a.z;
    let bx = b.x - s.x * b.z;
    let by = b.y - s.y * b.z;
    let cx = c.x - s.x * c.z;
    let cy = c.y - s.y * c.z;
    let mut u = cx * by - cy * bx;
    let mut vv = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || vv == 0.0 || w == 0.0 {
        u = (f64::from(cx) * f64::from(by) - f64::from(cy) * f64::from(bx)) as f32;
        vv = (f64::from(ax) * f64::from(cy) - f64::from(ay) * f64::from(cx)) as f32;
        w = (f64::from(bx) * f64::from(ay) - f64::from(by) * f64::from(ax)) as f32;
    }
    if (u < 0.0 || vv < 0.0 || w < 0.0) && (u > 0.0 || vv > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + vv + w;
    if det == 0.0 {
        return None;
    }
    let t_scaled = s.z * (u * a.z + vv * b.z + w * c.z);
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t > tmin && t < tmax) {
        return None;
    }
    Some((t, vv * inv, w * inv))
}

/// Ray-sphere intersection: the nearest root in `(tmin, tmax)`, with the discriminant
/// computed from the distance between the centre and the ray's line (no cancellation for
/// rays far from small spheres) and the roots from the numerically stable quadratic form.
#[must_use]
#[inline]
pub fn intersect_sphere(ray: &Ray, s: &Sphere, tmin: f32, tmax: f32) -> Option<f32> {
    let o = ray.origin - s.center;
    let d = ray.dir;
    let r = s.radius;
    let a = d.length_squared();
    let b = 2.0 * o.dot(d);
    let c = o.length_squared() - r * r;
    let l = (o - (b / (2.0 * a)) * d).length();
    let disc = 4.0 * a * (r + l) * (r - l);
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (mut t0, mut t1) = (q / a, c / q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > tmin && t0 < tmax {
        Some(t0)
    } else if t1 > tmin && t1 < tmax {
        Some(t1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: a ray down the z axis hits the unit triangle at the expected t and
    /// barycentrics.
    #[test]
    fn triangle_closed_form() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -2.0));
        let (t, b1, b2) = intersect_triangle(&RayPre::new(&ray), &tri, 0.0, f32::INFINITY).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.5).abs() < 1e-6);
        assert!(intersect_triangle(&RayPre::new(&ray), &tri, 0.0, 0.9).is_none());
        let miss = Ray::new(Vec3::new(0.75, 0.5, 2.0), -Vec3::Z);
        assert!(intersect_triangle(&RayPre::new(&miss), &tri, 0.0, f32::INFINITY).is_none());
        // Backfaces hit too.
        let up = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
        assert!(intersect_triangle(&RayPre::new(&up), &tri, 0.0, f32::INFINITY).is_some());
    }

    /// Closed form: rays through a sphere's centre hit at distance - radius, from inside at
    /// the far root; a ray far from a tiny sphere at 1e4 distance keeps precision.
    #[test]
    fn sphere_closed_form() {
        let s = Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!((intersect_sphere(&ray, &s, 0.0, f32::INFINITY).unwrap() - 4.0).abs() < 1e-6);
        let inside = Ray::new(s.center, Vec3::X);
        assert!((intersect_sphere(&inside, &s, 0.0, f32::INFINITY).unwrap() - 1.0).abs() < 1e-6);
        let tiny = Sphere {
            center: Vec3::new(0.0, 0.0, 1e4),
            radius: 1e-2,
        };
        let t = intersect_sphere(&ray, &tiny, 0.0, f32::INFINITY).unwrap();
        assert!((t - (1e4 - 1e-2)).abs() < 1e-3, "{t}");
        assert!(intersect_sphere(&Ray::new(Vec3::ZERO, Vec3::X), &s, 0.0, f32::INFINITY).is_none());
    }

    /// Property (oracle: the portable `RayPre::new`): the AVX set-up gives the same values,
    /// bit for bit, for directions of every sign and scale, ties between axes, zeros of
    /// both signs, infinities and NaNs.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_set_up_equals_the_portable_one_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let bits = |p: &RayPre| {
            let v = |v: Vec3| v.to_array().map(f32::to_bits);
            (
                v(p.origin),
                v(p.inv_dir),
                p.perm,
                v(p.shear),
                p.origin_k.map(f32::to_bits),
            )
        };
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -2.0,
            1e-40,
            -1e38,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let mut rng = prism_math::Pcg32::new(41, 3);
        let mut count = 0;
        for k in 0..40_000 {
            let mut c = |i: usize| {
                if (k + i).is_multiple_of(5) {
                    specials[(k / 5 + 3 * i) % specials.len()]
                } else {
                    (rng.next_f32() * 2.0 - 1.0) * [1e-20, 1.0, 1e20][(k + i) % 3]
                }
            };
            let dir = Vec3::new(c(0), c(1), c(2));
            let origin = Vec3::new(c(3), c(4), c(5));
            let ray = Ray { origin, dir };
            // SAFETY: AVX was detected.
            let (fast, o, inv) = unsafe { RayPre::new_avx(&ray) };
            assert_eq!(bits(&fast), bits(&RayPre::new(&ray)), "case {k}: {ray:?}");
            let v = |v: Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(
                (v(Vec3::from(o)), v(Vec3::from(inv))),
                (v(origin), v(fast.inv_dir)),
                "case {k}"
            );
            count += 1;
        }
        assert_eq!(count, 40_000);
    }
}
