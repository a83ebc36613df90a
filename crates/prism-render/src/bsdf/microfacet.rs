//! Microfacet distributions (Beckmann and GGX, anisotropic): the density of normals, Smith's
//! masking, and sampling of the normals visible from a direction, as Mitsuba's rough BSDFs
//! use them; and reflection and refraction about one microfacet. Directions are in the
//! shading frame, the macro-surface normal being +z.

use prism_math::{exp, Vec2, Vec3};
use prism_scene::{MicrofacetKind, Roughness};
use std::f32::consts::PI;

/// A microfacet distribution ready to evaluate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// Beckmann or GGX.
    pub kind: MicrofacetKind,
    /// Roughness along the frame's first tangent.
    pub alpha_u: f32,
    /// Roughness along the second tangent.
    pub alpha_v: f32,
}

impl From<Roughness> for Microfacet {
    fn from(r: Roughness) -> Microfacet {
        Microfacet {
            kind: r.kind,
            alpha_u: r.alpha_u,
            alpha_v: r.alpha_v,
        }
    }
}

impl Microfacet {
    /// The density of normals `m` per projected area, `D(m)` (zero below the surface and
    /// where it underflows, as Mitsuba clamps it).
    #[must_use]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let (au, av) = (self.alpha_u, self.alpha_v);
        let c2 = m.z * m.z;
        let xy = m.x * m.x / (au * au) + m.y * m.y / (av * av);
        let d = match self.kind {
            MicrofacetKind::Beckmann => exp(-xy / c2) / (PI * au * av * c2 * c2),
            MicrofacetKind::Ggx => {
                let t = xy + c2;
                1.0 / (PI * au * av * t * t)
            }
        };
        if d * m.z > 1e-20 {
            d
        } else {
            0.0
        }
    }

    /// Smith's masking of direction `v` by normals `m` (Walter et al.'s rational fit for
    /// Beckmann, the exact form for GGX); zero where `v` sees `m`'s back.
    #[must_use]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy = self.alpha_u * self.alpha_u * v.x * v.x + self.alpha_v * self.alpha_v * v.y * v.y;
        if xy == 0.0 {
            return 1.0;
        }
        let tan2 = xy / (v.z * v.z);
        match self.kind {
            MicrofacetKind::Beckmann => {
                let a = 1.0 / tan2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
                }
            }
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + tan2).sqrt()),
        }
    }

    /// The density of [`Microfacet::sample_visible`] drawing `m` seen from `v` (`v.z > 0`):
    /// `G1(v, m) |v.m| D(m) / v.z`.
    #[must_use]
    pub fn pdf_visible(&self, v: Vec3, m: Vec3) -> f32 {
        if v.z <= 0.0 {
            return 0.0;
        }
        self.g1(v, m) * v.dot(m).abs() * self.d(m) / v.z
    }

    /// A normal drawn from those visible from `v` (`v.z > 0`): Beckmann by stretching to
    /// roughness 1 and drawing visible slopes (Heitz and d'Eon 2014), GGX by Heitz's 2018
    /// projected-hemisphere construction. Both draw exactly the visible distribution.
    #[must_use]
    pub fn sample_visible(&self, v: Vec3, u: Vec2) -> Vec3 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let stretched = Vec3::new(au * v.x, av * v.y, v.z).normalize();
        match self.kind {
            MicrofacetKind::Beckmann => {
                let (sx, sy) = super::beckmann_visible_slopes(stretched.z, u);
                let r = (stretched.x * stretched.x + stretched.y * stretched.y).sqrt();
                let (cos_phi, sin_phi) = if r > 0.0 {
                    (stretched.x / r, stretched.y / r)
                } else {
                    (1.0, 0.0)
                };
                let tx = au * (cos_phi * sx - sin_phi * sy);
                let ty = av * (sin_phi * sx + cos_phi * sy);
                Vec3::new(-tx, -ty, 1.0).normalize()
            }
            MicrofacetKind::Ggx => {
                let len2 = stretched.x * stretched.x + stretched.y * stretched.y;
                let t1 = if len2 > 0.0 {
                    Vec3::new(-stretched.y, stretched.x, 0.0) * (1.0 / len2.sqrt())
                } else {
                    Vec3::X
                };
                let t2 = stretched.cross(t1);
                let r = u.x.sqrt();
                let phi = 2.0 * PI * u.y;
                let p1 = r * phi.cos();
                let s = 0.5 * (1.0 + stretched.z);
                let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
                let pz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
                let n = t1 * p1 + t2 * p2 + stretched * pz;
                Vec3::new(au * n.x, av * n.y, n.z.max(1e-7)).normalize()
            }
        }
    }
}

/// `w` reflected about the microfacet normal `m`, where `c = w.m`.
#[inline]
pub(super) fn reflect(w: Vec3, m: Vec3, c: f32) -> Vec3 {
    2.0 * c * m - w
}

/// `w` refracted through a microfacet of normal `m` (`c = w.m`) on a boundary of relative
/// index `eta` (the side `m` points away from over the side it points to), with the ratio
/// of the index `w` leaves over the one it enters; none under total internal reflection.
#[inline]
pub(super) fn refract(w: Vec3, m: Vec3, c: f32, eta: f32) -> Option<(Vec3, f32)> {
    let eta_ti = if c > 0.0 { 1.0 / eta } else { eta };
    let sin2_t = eta_ti * eta_ti * (1.0 - c * c).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-eta_ti * w + (eta_ti * c - cos_t.copysign(c)) * m, eta_ti))
}
