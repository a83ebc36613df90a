//! [`Interaction`], the record of a surface point hit by a ray, and what an integrator asks
//! of a hit: its shading frame, which sides the BSDF joins, and rays spawned from it.

use prism_math::{Frame, Ray, Rgb, Vec3};

use crate::bsdf::Bsdf;

/// A surface point hit by a ray.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (unit).
    pub ng: Vec3,
    /// Shading normal (unit, on the same side as `ng`).
    pub ns: Vec3,
    /// The BSDF there.
    pub bsdf: Bsdf,
    /// Radiance emitted towards the ray's origin.
    pub emitted: Rgb,
    /// The area light hit, if it is one (for MIS).
    pub light: Option<usize>,
    /// Distance along the ray.
    pub t: f32,
    /// The surface's first tangent (Mitsuba's `dp_du`) where an anisotropic BSDF needs it;
    /// `None` puts the shading frame's tangent where [`Frame::from_normal`] does.
    pub tangent: Option<Vec3>,
    /// The shading frame a bump or normal map tilts `ns` to, if the material has one.
    pub tilt: Option<Tilt>,
}

/// A bump or normal map's tilted shading frame at a hit (Mitsuba's `bumpmap` and
/// `normalmap`): the BSDF scatters in it, light reaches it only from the side that both
/// normals agree on, and grazing light is darkened by Estevez et al.'s shadowing term.
#[derive(Clone, Copy, Debug)]
pub struct Tilt {
    /// The tilted frame.
    pub frame: Frame,
    /// The shadowing term's roughness squared: `min(tan^2 theta / 8, 1)` of the tilted normal
    /// in the untilted frame (0 without the term).
    pub alpha2: f32,
}

impl Interaction {
    /// The shading frame (around `ns`, or tilted by a map) and `wo` expressed in it.
    pub(crate) fn shading_frame(&self, wo: Vec3) -> (Frame, Vec3) {
        let frame = match self.tilt {
            Some(tilt) => tilt.frame,
            None => frame_along(self.ns, self.tangent),
        };
        (frame, frame.to_local(wo))
    }

    /// The factor a bump or normal map puts on light scattered towards or from `wi`: 0
    /// where the tilted and untilted normals disagree on its side, else the shadowing
    /// term `2 / (1 + sqrt(1 + alpha^2 tan^2 theta))` of its angle to the untilted normal
    /// (1 without a map).
    #[inline(always)]
    pub(crate) fn tilt_factor(&self, wi: Vec3) -> f32 {
        let Some(tilt) = self.tilt else {
            return 1.0;
        };
        let cos = wi.dot(self.ns);
        if cos * wi.dot(tilt.frame.n) <= 0.0 {
            return 0.0;
        }
        let tan2 = (1.0 - cos * cos).max(0.0) / (cos * cos);
        2.0 / (1.0 + (1.0 + tilt.alpha2 * tan2).sqrt())
    }

    /// True if `wi` leaves on a side the BSDF allows, judged by the geometric normal (no light
    /// through an opaque surface because shading normals tilt).
    pub(crate) fn consistent(&self, wo: Vec3, wi: Vec3) -> bool {
        !self.bsdf.two_sided() || (wo.dot(self.ng) > 0.0) == (wi.dot(self.ng) > 0.0)
    }

    /// A ray leaving the hit along `dir`, its origin pushed off the surface along the
    /// geometric normal to the side `dir` points to, so that it does not hit the surface it
    /// starts on.
    pub(crate) fn spawn(&self, dir: Vec3) -> Ray {
        let (p, ng) = (self.p, self.ng);
        let eps = 1e-4 * (1.0 + p.abs().max_element());
        let side = if dir.dot(ng) >= 0.0 { ng } else { -ng };
        Ray::new(p + side * eps, dir)
    }
}

/// The frame around unit normal `n` whose first tangent is `dpdu` made perpendicular to it
/// (Gram-Schmidt), or where [`Frame::from_normal`] puts it without one (or for one along
/// `n`), as Mitsuba's shading frames are.
pub(crate) fn frame_along(n: Vec3, dpdu: Option<Vec3>) -> Frame {
    dpdu.and_then(|dpdu| {
        let s = (dpdu - n * n.dot(dpdu)).try_normalize()?;
        Some(Frame {
            s,
            t: n.cross(s),
            n,
        })
    })
    .unwrap_or_else(|| Frame::from_normal(n))
}
