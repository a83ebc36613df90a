//! The rough BSDFs built on [`Microfacet`]: a conductor (reflection only) and a dielectric
//! (reflection and refraction through the same microfacets), as Mitsuba's `roughconductor`
//! and `roughdielectric` define them, sampling the normals visible from `wo`.

use prism_math::{Rgb, Vec2, Vec3};

use super::microfacet::{reflect, refract, Microfacet};
use super::{fresnel_conductor, fresnel_dielectric, upper, BsdfSample};

/// A rough conductor's value (times `|cos wi|`) and sampling density.
pub(super) fn conductor_eval_pdf(
    distr: &Microfacet,
    (eta, k, specular): (Rgb, Rgb, Rgb),
    wo: Vec3,
    wi: Vec3,
) -> (Rgb, f32) {
    if wo.z * wi.z <= 0.0 {
        return (Rgb::BLACK, 0.0);
    }
    let (wo, wi) = upper(wo, wi);
    let h = (wo + wi).normalize();
    let d = distr.d(h);
    if d == 0.0 {
        return (Rgb::BLACK, 0.0);
    }
    let g1_wo = distr.g1(wo, h);
    let g = g1_wo * distr.g1(wi, h);
    let f = fresnel_conductor(wi.dot(h), eta, k) * specular;
    (f * (d * g / (4.0 * wo.z)), g1_wo * d / (4.0 * wo.z))
}

/// Samples a rough conductor: a visible normal, `wo` mirrored about it.
pub(super) fn conductor_sample(
    distr: &Microfacet,
    params: (Rgb, Rgb, Rgb),
    wo: Vec3,
    u: Vec2,
) -> Option<BsdfSample> {
    let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
    let wo_up = Vec3::new(wo.x, wo.y, wo.z * side);
    let h = distr.sample_visible(wo_up, u);
    let wi = reflect(wo_up, h, wo_up.dot(h));
    if wi.z <= 0.0 || wo_up.dot(h) <= 0.0 {
        return None;
    }
    let wi = Vec3::new(wi.x, wi.y, wi.z * side);
    let (f, pdf) = conductor_eval_pdf(distr, params, wo, wi);
    (pdf > 0.0).then(|| BsdfSample {
        wi,
        weight: f * (1.0 / pdf),
        pdf,
        delta: false,
    })
}

/// The parameters of a rough dielectric: distribution, reflected and refracted scales, and
/// the index inside over outside.
pub(super) type DielectricParams = (Microfacet, Rgb, Rgb, f32);

/// A rough dielectric's value (times `|cos wi|`) and sampling density. Reflection keeps
/// `wi` on `wo`'s side, refraction crosses; the half vector of a refraction is
/// `wo + eta wi` (eta the far side's index over the near side's), turned up; radiance
/// crossing into a denser medium is scaled by `1 / eta^2`.
pub(super) fn dielectric_eval_pdf(
    (distr, reflectance, transmittance, ior): DielectricParams,
    wo: Vec3,
    wi: Vec3,
) -> (Rgb, f32) {
    let (cos_o, cos_i) = (wo.z, wi.z);
    if cos_o == 0.0 || cos_i == 0.0 {
        return (Rgb::BLACK, 0.0);
    }
    let reflect = cos_o * cos_i > 0.0;
    let eta = if cos_o > 0.0 { ior } else { 1.0 / ior };
    let m = (wo + wi * if reflect { 1.0 } else { eta }).normalize();
    let m = if m.z < 0.0 { -m } else { m };
    let d = distr.d(m);
    let (dot_o, dot_i) = (wo.dot(m), wi.dot(m));
    let g1_o = distr.g1(wo, m);
    let g = g1_o * distr.g1(wi, m);
    if d == 0.0 || g == 0.0 {
        return (Rgb::BLACK, 0.0);
    }
    let f = fresnel_dielectric(dot_o, ior);
    // The density of the visible normal, seen from `wo` turned to the upper side.
    let pdf_m = g1_o * dot_o.abs() * d / cos_o.abs();
    if reflect {
        let value = reflectance * (f * d * g / (4.0 * cos_o.abs()));
        (value, (pdf_m * f / (4.0 * dot_i.abs())).abs())
    } else {
        let denom = dot_o + eta * dot_i;
        let denom2 = denom * denom;
        let value =
            transmittance * ((1.0 - f) * d * g * (dot_o * dot_i).abs() / (cos_o.abs() * denom2));
        let pdf = pdf_m * (1.0 - f) * eta * eta * dot_i.abs() / denom2;
        (value, pdf.abs())
    }
}

/// Samples a rough dielectric: a normal visible from `wo`, then reflection about it with the
/// Fresnel probability, else refraction through it.
pub(super) fn dielectric_sample(
    params: DielectricParams,
    wo: Vec3,
    u1: f32,
    u2: Vec2,
) -> Option<BsdfSample> {
    let (distr, reflectance, transmittance, ior) = params;
    let cos_o = wo.z;
    if cos_o == 0.0 {
        return None;
    }
    let wo_up = if cos_o < 0.0 { -wo } else { wo };
    let m = distr.sample_visible(wo_up, u2);
    let c = wo.dot(m);
    let f = fresnel_dielectric(c, ior);
    let (wi, weight) = if u1 <= f {
        let wi = reflect(wo, m, c);
        if wi.z * cos_o <= 0.0 {
            return None;
        }
        (wi, reflectance * distr.g1(wi, m))
    } else {
        let (wi, eta_ti) = refract(wo, m, c, ior)?;
        if wi.z * cos_o >= 0.0 {
            return None;
        }
        (wi, transmittance * (distr.g1(wi, m) * eta_ti * eta_ti))
    };
    let (_, pdf) = dielectric_eval_pdf(params, wo, wi);
    (pdf > 0.0 && weight.max_channel() > 0.0).then_some(BsdfSample {
        wi,
        weight,
        pdf,
        delta: false,
    })
}
