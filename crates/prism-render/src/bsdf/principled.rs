//! Mitsuba's `principled` BSDF (Disney's, as Mitsuba 3.9.1 writes it): a diffuse lobe with
//! retro-reflection, flatness and sheen, a GGX specular lobe tinted by metal and
//! `spec_tint`, a GGX transmission lobe, and a GTR1 clearcoat, each lobe chosen and weighed
//! as Mitsuba chooses and weighs it, so that images agree with Mitsuba's in expectation.

use std::f32::consts::{FRAC_1_PI, PI};

use prism_math::warp::cosine_hemisphere;
use prism_math::{Rgb, Vec2, Vec3};
use prism_scene::MicrofacetKind;

use super::microfacet::{reflect, Microfacet};
use super::BsdfSample;

/// A principled material's parameters besides its base colour (which a texture may vary).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledParams {
    /// Perceptual roughness (squared to GGX's alpha).
    pub roughness: f32,
    /// Anisotropy of the specular lobes, 0 to 1.
    pub anisotropic: f32,
    /// Metalness, 0 to 1.
    pub metallic: f32,
    /// Share of specular transmission, 0 to 1.
    pub spec_trans: f32,
    /// True if the material transmits at all (Mitsuba's `has_spec_trans`): `spec_trans`
    /// given other than 0, or by a texture, whose value here may be 0.
    pub transmits: bool,
    /// Tint of the dielectric specular lobe towards the base colour.
    pub spec_tint: f32,
    /// Sheen's weight.
    pub sheen: f32,
    /// Tint of the sheen towards the base colour.
    pub sheen_tint: f32,
    /// Blend of the diffuse lobe towards Hanrahan-Krueger's flat subsurface look.
    pub flatness: f32,
    /// Clearcoat's weight.
    pub clearcoat: f32,
    /// Clearcoat's glossiness (GTR1 alpha from 0.1 to 0.001).
    pub clearcoat_gloss: f32,
    /// Index of refraction inside over outside.
    pub eta: f32,
    /// Mitsuba's sampling rates of the main specular lobes, the clearcoat and the diffuse
    /// lobe.
    pub rates: [f32; 3],
}

impl PrincipledParams {
    /// The GGX distribution of the specular lobes (Mitsuba's `calc_dist_params`).
    fn distribution(&self) -> Microfacet {
        let r2 = self.roughness * self.roughness;
        let (ax, ay) = if self.anisotropic == 0.0 {
            (r2.max(0.001), r2.max(0.001))
        } else {
            let aspect = (1.0 - 0.9 * self.anisotropic).sqrt();
            ((r2 / aspect).max(0.001), (r2 * aspect).max(0.001))
        };
        Microfacet {
            kind: MicrofacetKind::Ggx,
            alpha_u: ax,
            alpha_v: ay,
        }
    }

    /// The weights of the reflective and the transmissive parts.
    fn weights(&self) -> (f32, f32) {
        let brdf = (1.0 - self.metallic) * (1.0 - self.spec_trans);
        let bsdf = (1.0 - self.metallic) * self.spec_trans;
        (brdf, bsdf)
    }

    /// The probabilities of the diffuse, clearcoat, transmission and reflection lobes for a
    /// dielectric Fresnel reflectance `f`, normalised.
    fn lobe_probabilities(&self, f: f32, front: bool) -> [f32; 4] {
        let (brdf, bsdf) = self.weights();
        let [spec_rate, cc_rate, diff_rate] = self.rates;
        let reflect = if front {
            spec_rate * (1.0 - bsdf * (1.0 - f))
        } else {
            f
        };
        let trans = match (self.transmits, front) {
            (false, _) => 0.0,
            (true, true) => spec_rate * bsdf * (1.0 - f),
            (true, false) => 1.0 - f,
        };
        let clearcoat = if self.clearcoat != 0.0 && front {
            0.25 * self.clearcoat * cc_rate
        } else {
            0.0
        };
        let diffuse = if front { brdf * diff_rate } else { 0.0 };
        let rcp = 1.0 / (reflect + trans + clearcoat + diffuse);
        [diffuse * rcp, clearcoat * rcp, trans * rcp, reflect * rcp]
    }

    /// The clearcoat's GTR1 alpha.
    fn clearcoat_alpha(&self) -> f32 {
        0.1 + self.clearcoat_gloss * (0.001 - 0.1)
    }
}

/// Mitsuba's dielectric Fresnel term for cosine `cos_i` to the normal and index `eta`: the
/// reflectance, the refracted cosine (of the other sign) and `eta_ti` (near over far).
fn fresnel(cos_i: f32, eta: f32) -> (f32, f32, f32) {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_t2 = 1.0 - eta_ti * eta_ti * (1.0 - cos_i * cos_i);
    let (ci, ct) = (cos_i.abs(), cos_t2.max(0.0).sqrt());
    let r = if eta == 1.0 {
        0.0
    } else if ci == 0.0 {
        1.0
    } else {
        let a_s = (eta_it * ct - ci) / (eta_it * ct + ci);
        let a_p = (eta_it * ci - ct) / (eta_it * ci + ct);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    (r, if cos_i >= 0.0 { -ct } else { ct }, eta_ti)
}

/// `(1 - cos)^5`, clamped.
fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    m * m * m * m * m
}

/// Schlick's Fresnel from `r0`, at the refracted angle when light leaves the denser side.
fn schlick(r0: Rgb, cos_i: f32, eta: f32) -> Rgb {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti)
        .max(0.0)
        .sqrt();
    let w = if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        schlick_weight(cos_t)
    };
    Rgb::splat(w) + (Rgb::WHITE - Rgb::splat(w)) * r0
}

/// Mitsuba's luminance of a linear sRGB colour.
fn luminance(c: Rgb) -> f32 {
    0.212671 * c.r + 0.715160 * c.g + 0.072169 * c.b
}

/// The base colour over its luminance (white where that is 0).
fn tint(base: Rgb) -> Rgb {
    let lum = luminance(base);
    if lum > 0.0 {
        base * (1.0 / lum)
    } else {
        Rgb::WHITE
    }
}

/// `m` flipped to the side `cos` points to.
fn side(m: Vec3, cos: f32) -> Vec3 {
    if cos < 0.0 {
        -m
    } else {
        m
    }
}

/// True if `v` and `l` both see the microfacet `m` from the macro surface's `v` side
/// (reflection) or from opposite sides (transmission).
fn compatible(m: Vec3, v: Vec3, l: Vec3, cos_v: f32, reflection: bool) -> bool {
    let m = side(m, cos_v);
    v.dot(m) > 0.0
        && if reflection {
            l.dot(m) > 0.0
        } else {
            l.dot(-m) > 0.0
        }
}

/// Smith's GGX masking of the clearcoat (alpha 0.25, isotropic).
fn clearcoat_g1(v: Vec3, m: Vec3) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let c2 = v.z * v.z;
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + 0.0625 * tan2).sqrt())
}

/// GTR1's density of normals (zero where it underflows, as Mitsuba clamps it).
fn gtr1_d(m: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z));
    if d * m.z > 1e-20 {
        d
    } else {
        0.0
    }
}

/// The principled BSDF times `|cos l|` for a view direction `v` and a light direction `l`
/// (local frame).
pub(super) fn eval(p: &PrincipledParams, base: Rgb, v: Vec3, l: Vec3) -> Rgb {
    let (cos_v, cos_l) = (v.z, l.z);
    if cos_v == 0.0 {
        return Rgb::BLACK;
    }
    let (brdf, bsdf) = p.weights();
    let reflect = cos_v * cos_l > 0.0;
    let refract = cos_v * cos_l < 0.0;
    let front = cos_v > 0.0;
    let eta_path = if front { p.eta } else { 1.0 / p.eta };
    let inv_eta_path = if front { 1.0 / p.eta } else { p.eta };
    let distr = p.distribution();
    let wh = (v + l * if reflect { 1.0 } else { eta_path }).normalize();
    let wh = side(wh, wh.z);
    let (f, _, _) = fresnel(v.dot(wh), p.eta);
    let compat_r = compatible(wh, v, l, cos_v, true);
    let compat_t = compatible(wh, v, l, cos_v, false);
    let d = distr.d(wh);
    let g = distr.g1(v, wh) * distr.g1(l, wh);
    let mut value = Rgb::BLACK;
    if reflect && compat_r && f > 0.0 {
        let fp = if front {
            let mut schlick_part = Rgb::BLACK;
            if p.metallic != 0.0 {
                schlick_part += schlick(base, v.dot(wh), p.eta) * p.metallic;
            }
            if p.spec_tint != 0.0 {
                let eta_it = if v.dot(wh) >= 0.0 { p.eta } else { 1.0 / p.eta };
                let r0 = ((eta_it - 1.0) / (eta_it + 1.0)).powi(2);
                schlick_part +=
                    schlick(tint(base) * r0, v.dot(wh), p.eta) * ((1.0 - p.metallic) * p.spec_tint);
            }
            Rgb::splat((1.0 - p.metallic) * (1.0 - p.spec_tint) * f) + schlick_part
        } else {
            Rgb::splat(bsdf * f)
        };
        value += fp * (d * g / (4.0 * cos_v.abs()));
    }
    if p.transmits && bsdf > 0.0 && refract && compat_t && f < 1.0 {
        let (dv, dl) = (v.dot(wh), l.dot(wh));
        let scale = inv_eta_path * inv_eta_path;
        let denom = dv + eta_path * dl;
        let t = (scale * (1.0 - f) * d * g * eta_path * eta_path * dv * dl
            / (cos_v * denom * denom))
            .abs();
        value += Rgb::new(base.r.sqrt(), base.g.sqrt(), base.b.sqrt()) * (bsdf * t);
    }
    if p.clearcoat != 0.0 && p.clearcoat > 0.0 && reflect && compat_r && front {
        let fcc = schlick(Rgb::splat(0.04), v.dot(wh), p.eta).r;
        let dcc = gtr1_d(wh, p.clearcoat_alpha());
        let gcc = clearcoat_g1(v, wh) * clearcoat_g1(l, wh);
        value += Rgb::splat(p.clearcoat * 0.25 * fcc * dcc * gcc * cos_l.abs());
    }
    let cos_d = wh.dot(l);
    if brdf > 0.0 && reflect && front {
        let (fo, fi) = (schlick_weight(cos_l.abs()), schlick_weight(cos_v.abs()));
        let f_diff = (1.0 - 0.5 * fi) * (1.0 - 0.5 * fo);
        let rr = 2.0 * p.roughness * cos_d * cos_d;
        let f_retro = rr * (fo + fi + fo * fi * (rr - 1.0));
        let lobe = if p.flatness != 0.0 {
            let fss90 = rr / 2.0;
            let fss = (1.0 + fo * (fss90 - 1.0)) * (1.0 + fi * (fss90 - 1.0));
            let f_ss = 1.25 * (fss * (1.0 / (cos_l.abs() + cos_v.abs()) - 0.5) + 0.5);
            (f_diff + f_retro) + p.flatness * (f_ss - (f_diff + f_retro))
        } else {
            f_diff + f_retro
        };
        value += base * (brdf * cos_l.abs() * FRAC_1_PI * lobe);
    }
    // (Mitsuba's vectorised variants add the sheen wherever it is active, whatever the
    // diffuse lobe's weight.)
    if p.sheen != 0.0 && p.sheen > 0.0 && reflect && 1.0 - p.metallic > 0.0 && front {
        let fd = schlick_weight(cos_d.abs());
        let c_sheen = if p.sheen_tint != 0.0 {
            Rgb::WHITE + (tint(base) - Rgb::WHITE) * p.sheen_tint
        } else {
            Rgb::WHITE
        };
        value += c_sheen * (p.sheen * (1.0 - p.metallic) * fd * cos_l.abs());
    }
    value
}

/// The density with which [`sample`] draws light direction `l` for view direction `v`.
pub(super) fn pdf(p: &PrincipledParams, v: Vec3, l: Vec3) -> f32 {
    let (cos_v, cos_l) = (v.z, l.z);
    if cos_v == 0.0 {
        return 0.0;
    }
    let front = cos_v > 0.0;
    let eta_path = if front { p.eta } else { 1.0 / p.eta };
    let reflect = cos_v * cos_l > 0.0;
    let refract = cos_v * cos_l < 0.0;
    let wh = (v + l * if reflect { 1.0 } else { eta_path }).normalize();
    let wh = side(wh, wh.z);
    let distr = p.distribution();
    let (f, _, _) = fresnel(v.dot(wh), p.eta);
    let [diffuse, clearcoat, trans, spec] = p.lobe_probabilities(f, front);
    let (dv, dl) = (v.dot(wh), l.dot(wh));
    let dwh_dl = if p.transmits && !reflect {
        (eta_path * eta_path * dl / ((dv + eta_path * dl) * (dv + eta_path * dl))).abs()
    } else {
        (1.0 / (4.0 * dl)).abs()
    };
    let visible = || distr.pdf_visible(side(v, cos_v), wh);
    let mut pdf = 0.0;
    let compat_r = compatible(wh, v, l, cos_v, true) && reflect;
    if compat_r {
        pdf += spec * visible() * dwh_dl;
    }
    if reflect {
        pdf += diffuse * FRAC_1_PI * l.z;
    }
    if p.transmits && compatible(wh, v, l, cos_v, false) && refract {
        pdf += trans * visible() * dwh_dl;
    }
    if p.clearcoat != 0.0 && compat_r {
        let cc = if wh.z < 0.0 {
            0.0
        } else {
            wh.z * gtr1_d(wh, p.clearcoat_alpha())
        };
        pdf += clearcoat * cc * dwh_dl;
    }
    pdf
}

/// Draws a light direction for view direction `v`: a lobe by `u1` with Mitsuba's
/// probabilities (their Fresnel term taken at a normal drawn from `u2`), then a direction
/// from that lobe with `u2` (the same `u2`, as Mitsuba uses it).
pub(super) fn sample(
    p: &PrincipledParams,
    base: Rgb,
    v: Vec3,
    u1: f32,
    u2: Vec2,
) -> Option<BsdfSample> {
    let cos_v = v.z;
    if cos_v == 0.0 {
        return None;
    }
    let (_, bsdf) = p.weights();
    let front = cos_v > 0.0;
    if !(front || bsdf > 0.0) {
        return None;
    }
    let distr = p.distribution();
    let m = distr.sample_visible(side(v, cos_v), u2);
    let (f, cos_t, eta_ti) = fresnel(v.dot(m), p.eta);
    let [diffuse, clearcoat, trans, _] = p.lobe_probabilities(f, front);
    let reflect_about = |m: Vec3| reflect(v, m, v.dot(m));
    let l = if u1 < diffuse {
        let l = cosine_hemisphere(u2);
        (cos_v * l.z > 0.0).then_some(l)?
    } else if p.clearcoat != 0.0 && u1 < diffuse + clearcoat {
        let alpha2 = p.clearcoat_alpha() * p.clearcoat_alpha();
        let (sin_phi, cos_phi) = (2.0 * PI * u2.x).sin_cos();
        let cos2 = (1.0 - alpha2.powf(1.0 - u2.y)) / (1.0 - alpha2);
        let (sin_t, cos_t) = ((1.0 - cos2).max(0.0).sqrt(), cos2.max(0.0).sqrt());
        let mcc = Vec3::new(cos_phi * sin_t, sin_phi * sin_t, cos_t);
        let l = reflect_about(mcc);
        (compatible(mcc, v, l, cos_v, true) && cos_v * l.z > 0.0).then_some(l)?
    } else if p.transmits && u1 < diffuse + clearcoat + trans {
        let l = m * (v.dot(m) * eta_ti + cos_t) - v * eta_ti;
        (compatible(m, v, l, cos_v, false) && cos_v * l.z < 0.0).then_some(l)?
    } else {
        let l = reflect_about(m);
        (compatible(m, v, l, cos_v, true) && cos_v * l.z > 0.0).then_some(l)?
    };
    let density = pdf(p, v, l);
    if density.is_nan() || density <= 0.0 {
        return None;
    }
    let value = eval(p, base, v, l);
    Some(BsdfSample {
        wi: l,
        weight: value * (1.0 / density),
        pdf: density,
        delta: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::Pcg32;

    fn params() -> PrincipledParams {
        PrincipledParams {
            roughness: 0.4,
            anisotropic: 0.3,
            metallic: 0.2,
            spec_trans: 0.3,
            transmits: true,
            spec_tint: 0.4,
            sheen: 0.5,
            sheen_tint: 0.5,
            flatness: 0.3,
            clearcoat: 0.6,
            clearcoat_gloss: 0.5,
            eta: 1.5,
            rates: [1.0, 1.0, 1.0],
        }
    }

    /// Brute force: the density `pdf` gives integrates to the probability that `sample`
    /// returns a direction at all (at most 1), checked by uniform sphere integration.
    #[test]
    fn the_density_integrates_to_at_most_one() {
        let p = params();
        let mut rng = Pcg32::new(5, 9);
        for &v in &[
            Vec3::new(0.3, 0.2, 0.93).normalize(),
            Vec3::new(-0.6, 0.1, 0.4).normalize(),
            Vec3::new(0.2, -0.5, -0.6).normalize(),
        ] {
            let n = 400_000;
            let mut total = 0.0f64;
            for _ in 0..n {
                let l = prism_math::warp::uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                total += f64::from(pdf(&p, v, l)) * 4.0 * std::f64::consts::PI;
            }
            let total = total / f64::from(n);
            assert!(total < 1.03 && total > 0.3, "{v}: {total}");
        }
    }

    /// Property: a sample's weight is `eval / pdf` of its direction.
    #[test]
    fn sample_weights_are_eval_over_pdf() {
        let p = params();
        let base = Rgb::new(0.8, 0.4, 0.2);
        let mut rng = Pcg32::new(3, 1);
        let v = Vec3::new(0.4, 0.1, 0.9).normalize();
        let mut taken = 0;
        for _ in 0..10_000 {
            let u1 = rng.next_f32();
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = sample(&p, base, v, u1, u2) {
                taken += 1;
                let f = eval(&p, base, v, s.wi);
                let expect = f * (1.0 / pdf(&p, v, s.wi));
                assert!(
                    (s.weight - expect).max_channel().abs() < 1e-4 * (1.0 + expect.max_channel())
                );
            }
        }
        assert!(taken > 9_000, "{taken}");
    }
}
