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
}

impl Interaction {
    /// The shading frame (around `ns`) and `wo` expressed in it.
    pub(crate) fn shading_frame(&self, wo: Vec3) -> (Frame, Vec3) {
        let frame = self
            .tangent
            .and_then(|dpdu| {
                // Gram-Schmidt: the tangent made perpendicular to the shading normal.
                let s = (dpdu - self.ns * self.ns.dot(dpdu)).try_normalize()?;
                Some(Frame {
                    s,
                    t: self.ns.cross(s),
                    n: self.ns,
                })
            })
            .unwrap_or_else(|| Frame::from_normal(self.ns));
        (frame, frame.to_local(wo))
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
