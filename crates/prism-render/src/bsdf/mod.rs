//! Scattering models in the local shading frame (the normal is +z). Every BSDF has
//! `eval` (the BSDF times the cosine of `wi`), `pdf` (solid angle density of `sample`) and
//! `sample`, whose weight is `eval / pdf` (or the delta lobe's weight).

use prism_math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use prism_math::{acos, exp, ln, Rgb, Vec2, Vec3};
use prism_scene::{Material, PrincipledWeight, TexturedParameter};
use std::f32::consts::PI;

/// A BSDF ready to evaluate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflection, two-sided.
    Diffuse {
        /// Albedo.
        albedo: Rgb,
    },
    /// A perfect mirror, two-sided.
    Mirror {
        /// Reflectance.
        reflectance: Rgb,
    },
    /// A smooth dielectric with exact Fresnel reflection and refraction. The outside is
    /// where the normal points (index 1).
    Glass {
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Index of refraction inside.
        ior: f32,
    },
    /// Refraction only, without Fresnel reflection; total internal reflection is black.
    Refraction {
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Index of refraction inside.
        ior: f32,
    },
    /// A rough conductor: Beckmann microfacets, Smith shadowing (Walter et al. 2007) and
    /// the exact conductor Fresnel term per channel; two-sided.
    Conductor {
        /// Beckmann roughness.
        alpha: f32,
        /// Real part of the index of refraction.
        eta: Rgb,
        /// Absorption.
        k: Rgb,
    },
    /// Mitsuba's smooth plastic: Fresnel-weighted mirror reflection off a dielectric coat
    /// of index `eta`, over a diffuse base seen through it.
    Plastic {
        /// The base's albedo over `(1 - Fdr_int) eta^2`: the diffuse lobe's scale.
        diffuse: Rgb,
        /// Scale of the mirror reflection.
        specular: Rgb,
        /// Index of refraction of the coat.
        eta: f32,
        /// The share of samples the mirror lobe is weighted by (mean specular over mean
        /// specular plus mean diffuse albedo).
        specular_weight: f32,
    },
    /// A thin dielectric pane: mirror reflection of `2F / (1 + F)`, the rest passing
    /// straight through.
    ThinDielectric {
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the transmitted part.
        transmittance: Rgb,
        /// Index of refraction of the pane.
        ior: f32,
    },
    /// A smooth conductor: mirror reflection scaled by the conductor Fresnel term and
    /// `specular`; two-sided.
    SmoothConductor {
        /// Real part of the index of refraction.
        eta: Rgb,
        /// Absorption.
        k: Rgb,
        /// Scale of the reflection.
        specular: Rgb,
    },
    /// A rough conductor with any microfacet distribution, its reflection scaled by
    /// `specular`; two-sided.
    RoughConductor {
        /// The microfacets.
        distr: Microfacet,
        /// Real part of the index of refraction.
        eta: Rgb,
        /// Absorption.
        k: Rgb,
        /// Scale of the reflection.
        specular: Rgb,
    },
    /// A rough dielectric boundary: reflection and refraction through microfacets. The
    /// outside is where the normal points.
    RoughDielectric {
        /// The microfacets.
        distr: Microfacet,
        /// Scale of the reflected part.
        reflectance: Rgb,
        /// Scale of the refracted part.
        transmittance: Rgb,
        /// Index of refraction inside over outside.
        ior: f32,
    },
    /// Mitsuba's rough plastic: a rough dielectric coat over a diffuse base.
    RoughPlastic {
        /// The coat's microfacets.
        distr: Microfacet,
        /// Index of refraction of the coat.
        eta: f32,
        /// The base's albedo over `(1 - internal reflectance) eta^2`.
        diffuse: Rgb,
        /// Scale of the coat's reflection.
        specular: Rgb,
        /// Mean specular over mean specular plus mean diffuse albedo.
        specular_weight: f32,
        /// The coat's transmittance table and internal reflectance.
        tables: &'static rough_plastic::CoatTables,
    },
    /// Mitsuba's principled BSDF.
    Principled {
        /// The base colour (times the texture's texel).
        base: Rgb,
        /// The other parameters.
        params: principled::PrincipledParams,
        /// True if the back scatters as the front (inside `twosided`, without transmission).
        two_sided: bool,
    },
    /// Absorbs everything (the surface of an emitter).
    Black,
    /// No surface: light passes on unchanged (where a mask lets a ray through).
    Null,
}

/// The result of sampling a BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Sampled incident direction (local frame).
    pub wi: Vec3,
    /// `eval / pdf` (for delta lobes, the lobe's weight).
    pub weight: Rgb,
    /// Solid-angle density (the lobe's selection probability for delta lobes).
    pub pdf: f32,
    /// True for a delta lobe (mirror reflection or refraction).
    pub delta: bool,
}

impl Bsdf {
    /// The BSDF of a scene material (emitters are black surfaces; a Phong material is
    /// Lambertian with its untextured `kd`, its specular lobe being no energy-conserving
    /// BSDF).
    #[must_use]
    pub fn from_material(m: &Material) -> Bsdf {
        match *m {
            Material::Diffuse { reflectance, .. } => Bsdf::Diffuse {
                albedo: reflectance,
            },
            Material::Emission { .. } => Bsdf::Black,
            // An area emitter's surface scatters as its own material does (the render scene
            // takes that at each hit); without one it is black.
            Material::AreaEmitter { .. } => Bsdf::Black,
            Material::Mirror { reflectance } => Bsdf::Mirror { reflectance },
            Material::Glass {
                reflectance,
                transmittance,
                ior,
                ..
            } => Bsdf::Glass {
                reflectance,
                transmittance,
                ior,
            },
            Material::Refraction {
                transmittance, ior, ..
            } => Bsdf::Refraction { transmittance, ior },
            Material::Microfacet { alpha, eta, k } => Bsdf::Conductor { alpha, eta, k },
            Material::ThinDielectric {
                reflectance,
                transmittance,
                ior,
            } => Bsdf::ThinDielectric {
                reflectance,
                transmittance,
                ior,
            },
            Material::Plastic {
                diffuse,
                specular,
                eta,
                ref texture,
                nonlinear,
            } => {
                let fdr_int = fresnel_diffuse_reflectance(1.0 / eta);
                Bsdf::Plastic {
                    diffuse: coat_scaled(diffuse, fdr_int, eta, nonlinear),
                    specular,
                    eta,
                    specular_weight: specular_weight(diffuse, texture.as_ref(), specular),
                }
            }
            Material::Conductor {
                roughness: Some(roughness),
                eta,
                k,
                specular,
            } => Bsdf::RoughConductor {
                distr: roughness.into(),
                eta,
                k,
                specular,
            },
            Material::Conductor {
                roughness: None,
                eta,
                k,
                specular,
            } => Bsdf::SmoothConductor { eta, k, specular },
            Material::RoughDielectric {
                roughness,
                reflectance,
                transmittance,
                ior,
            } => Bsdf::RoughDielectric {
                distr: roughness.into(),
                reflectance,
                transmittance,
                ior,
            },
            Material::RoughPlastic {
                roughness,
                diffuse,
                specular,
                eta,
                ref texture,
                nonlinear,
            } => {
                let distr: Microfacet = roughness.into();
                let tables = rough_plastic::coat_tables(&distr, eta);
                Bsdf::RoughPlastic {
                    distr,
                    eta,
                    diffuse: coat_scaled(diffuse, tables.internal_reflectance, eta, nonlinear),
                    specular,
                    specular_weight: specular_weight(diffuse, texture.as_ref(), specular),
                    tables,
                }
            }
            Material::Phong { kd, .. } => Bsdf::Diffuse { albedo: kd },
            // A blend or a mask is a choice among other materials, and a map tilts another
            // material's normal, at each hit in the render scene: alone they have no BSDF of
            // their own.
            Material::Blend { .. }
            | Material::Mask { .. }
            | Material::NormalMap { .. }
            | Material::BumpMap { .. }
            | Material::Textured { .. } => Bsdf::Black,
            Material::Principled {
                base_color,
                roughness,
                anisotropic,
                metallic,
                spec_trans,
                transmits,
                spec_tint,
                sheen,
                sheen_tint,
                flatness,
                clearcoat,
                clearcoat_gloss,
                eta,
                rates,
                two_sided,
                ..
            } => Bsdf::Principled {
                base: base_color,
                params: principled::PrincipledParams {
                    roughness,
                    anisotropic,
                    metallic,
                    spec_trans,
                    transmits,
                    spec_tint,
                    sheen,
                    sheen_tint,
                    flatness,
                    clearcoat,
                    clearcoat_gloss,
                    eta,
                    rates,
                },
                two_sided: two_sided && !transmits,
            },
        }
    }

    /// True if the BSDF has a non-delta part that light sampling can reach.
    #[must_use]
    pub fn is_smooth(&self) -> bool {
        matches!(
            self,
            Bsdf::Diffuse { .. }
                | Bsdf::Conductor { .. }
                | Bsdf::Plastic { .. }
                | Bsdf::RoughConductor { .. }
                | Bsdf::RoughDielectric { .. }
                | Bsdf::RoughPlastic { .. }
                | Bsdf::Principled { .. }
        )
    }

    /// The diffuse albedo a texture multiplies (of a diffuse BSDF or a plastic's base).
    pub(crate) fn albedo_mut(&mut self) -> Option<&mut Rgb> {
        match self {
            Bsdf::Diffuse { albedo } => Some(albedo),
            Bsdf::Plastic { diffuse, .. } | Bsdf::RoughPlastic { diffuse, .. } => Some(diffuse),
            Bsdf::Principled { base, .. } => Some(base),
            _ => None,
        }
    }

    /// Sets `param` to `value` (its luminance for a number: at least 1e-4 for an alpha,
    /// within 0 to 1 for a principled weight, at least 0 for sheen and clearcoat), where
    /// the BSDF has it.
    pub(crate) fn set(&mut self, param: TexturedParameter, value: Rgb) {
        let luminance = 0.212671 * value.r + 0.715160 * value.g + 0.072169 * value.b;
        let alpha = || luminance.max(1e-4);
        match (self, param) {
            (
                Bsdf::Mirror { reflectance }
                | Bsdf::Glass { reflectance, .. }
                | Bsdf::ThinDielectric { reflectance, .. }
                | Bsdf::RoughDielectric { reflectance, .. }
                | Bsdf::SmoothConductor {
                    specular: reflectance,
                    ..
                }
                | Bsdf::RoughConductor {
                    specular: reflectance,
                    ..
                }
                | Bsdf::Plastic {
                    specular: reflectance,
                    ..
                }
                | Bsdf::RoughPlastic {
                    specular: reflectance,
                    ..
                },
                TexturedParameter::SpecularReflectance,
            ) => *reflectance = value,
            (
                Bsdf::Glass { transmittance, .. }
                | Bsdf::ThinDielectric { transmittance, .. }
                | Bsdf::RoughDielectric { transmittance, .. },
                TexturedParameter::SpecularTransmittance,
            ) => *transmittance = value,
            (
                Bsdf::RoughConductor { distr, .. } | Bsdf::RoughDielectric { distr, .. },
                TexturedParameter::AlphaU,
            ) => distr.alpha_u = alpha(),
            (
                Bsdf::RoughConductor { distr, .. } | Bsdf::RoughDielectric { distr, .. },
                TexturedParameter::AlphaV,
            ) => distr.alpha_v = alpha(),
            (Bsdf::Principled { params, .. }, TexturedParameter::Principled(w)) => {
                // Weights as Mitsuba's `eval_1` reads them, kept where they are defined.
                let v = luminance.max(0.0);
                let v = if w.unbounded() { v } else { v.min(1.0) };
                let slot = match w {
                    PrincipledWeight::Roughness => &mut params.roughness,
                    PrincipledWeight::Anisotropic => &mut params.anisotropic,
                    PrincipledWeight::Metallic => &mut params.metallic,
                    PrincipledWeight::SpecTrans => &mut params.spec_trans,
                    PrincipledWeight::SpecTint => &mut params.spec_tint,
                    PrincipledWeight::Sheen => &mut params.sheen,
                    PrincipledWeight::SheenTint => &mut params.sheen_tint,
                    PrincipledWeight::Flatness => &mut params.flatness,
                    PrincipledWeight::Clearcoat => &mut params.clearcoat,
                    PrincipledWeight::ClearcoatGloss => &mut params.clearcoat_gloss,
                };
                *slot = v;
            }
            _ => {}
        }
    }

    /// True if the BSDF depends on the direction around the normal, so the shading frame's
    /// tangent matters.
    #[must_use]
    pub fn anisotropic(&self) -> bool {
        match self {
            Bsdf::RoughConductor { distr, .. } | Bsdf::RoughDielectric { distr, .. } => {
                distr.alpha_u != distr.alpha_v
            }
            Bsdf::Principled { params, .. } => params.anisotropic != 0.0,
            _ => false,
        }
    }

    /// True for BSDFs that scatter the same on both sides of the surface.
    #[must_use]
    pub fn two_sided(&self) -> bool {
        !matches!(
            self,
            Bsdf::Glass { .. }
                | Bsdf::Refraction { .. }
                | Bsdf::ThinDielectric { .. }
                | Bsdf::RoughDielectric { .. }
                | Bsdf::Null
        ) && !matches!(self, Bsdf::Principled { params, .. } if params.transmits)
    }

    /// The BSDF times `|cos wi|`. Zero for delta lobes.
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if let Some((f, _)) = self.rough_eval_pdf(wo, wi) {
            return f;
        }
        if wo.z * wi.z <= 0.0 {
            return Rgb::splat(0.0);
        }
        let (wo, wi) = upper(wo, wi);
        match *self {
            Bsdf::Diffuse { albedo } => albedo * (wi.z / PI),
            Bsdf::Plastic { diffuse, eta, .. } => {
                let f_i = fresnel_dielectric(wo.z, eta);
                let f_o = fresnel_dielectric(wi.z, eta);
                diffuse * (wi.z / PI * (1.0 - f_i) * (1.0 - f_o))
            }
            Bsdf::Conductor { alpha, eta, k } => {
                let h = (wo + wi).normalize();
                let d = beckmann_d(h, alpha);
                let g = smith_g1(wo, h, alpha) * smith_g1(wi, h, alpha);
                let f = fresnel_conductor(wi.dot(h), eta, k);
                f * (d * g / (4.0 * wo.z))
            }
            _ => Rgb::splat(0.0),
        }
    }

    /// [`Bsdf::eval`] and [`Bsdf::pdf`] together, the terms they share computed once (the
    /// same values, bit for bit).
    #[must_use]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if let Some(fp) = self.rough_eval_pdf(wo, wi) {
            return fp;
        }
        if wo.z * wi.z <= 0.0 {
            return (Rgb::splat(0.0), 0.0);
        }
        let (wo, wi) = upper(wo, wi);
        match *self {
            Bsdf::Diffuse { albedo } => (albedo * (wi.z / PI), cosine_hemisphere_pdf(wi.z)),
            Bsdf::Conductor { alpha, eta, k } => {
                let h = (wo + wi).normalize();
                let d = beckmann_d(h, alpha);
                let g1_wo = smith_g1(wo, h, alpha);
                let g = g1_wo * smith_g1(wi, h, alpha);
                let f = fresnel_conductor(wi.dot(h), eta, k);
                (f * (d * g / (4.0 * wo.z)), g1_wo * d / (4.0 * wo.z))
            }
            Bsdf::Plastic { .. } => (self.eval(wo, wi), self.pdf(wo, wi)),
            _ => (Rgb::splat(0.0), 0.0),
        }
    }

    /// The density of [`Bsdf::sample`] choosing `wi`. Zero for delta lobes.
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if let Some((_, pdf)) = self.rough_eval_pdf(wo, wi) {
            return pdf;
        }
        if wo.z * wi.z <= 0.0 {
            return 0.0;
        }
        let (wo, wi) = upper(wo, wi);
        match *self {
            Bsdf::Diffuse { .. } => cosine_hemisphere_pdf(wi.z),
            Bsdf::Conductor { alpha, .. } => {
                // Visible normals: D_wo(h) / (4 wo.h) = G1(wo, h) D(h) / (4 wo.z).
                let h = (wo + wi).normalize();
                smith_g1(wo, h, alpha) * beckmann_d(h, alpha) / (4.0 * wo.z)
            }
            Bsdf::Plastic {
                eta,
                specular_weight,
                ..
            } => {
                let f_i = fresnel_dielectric(wo.z, eta);
                cosine_hemisphere_pdf(wi.z) * plastic_diffuse_share(f_i, specular_weight)
            }
            _ => 0.0,
        }
    }

    /// Samples an incident direction for outgoing `wo` from `u1` (lobe choice) and `u2`.
    #[must_use]
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let flip = |v: Vec3| {
            if wo.z < 0.0 {
                Vec3::new(v.x, v.y, -v.z)
            } else {
                v
            }
        };
        match *self {
            Bsdf::Diffuse { albedo } => {
                let wi = cosine_hemisphere(u2);
                if wi.z <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi: flip(wi),
                    weight: albedo,
                    pdf: cosine_hemisphere_pdf(wi.z),
                    delta: false,
                })
            }
            Bsdf::Mirror { reflectance } => Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: reflectance,
                pdf: 1.0,
                delta: true,
            }),
            Bsdf::Null => Some(BsdfSample {
                wi: -wo,
                weight: Rgb::WHITE,
                pdf: 1.0,
                delta: true,
            }),
            Bsdf::Conductor { alpha, .. } => {
                let wo_up = flip(wo);
                let h = sample_beckmann_visible(wo_up, alpha, u2);
                let wi = 2.0 * wo_up.dot(h) * h - wo_up;
                if wi.z <= 0.0 || wo_up.dot(h) <= 0.0 {
                    return None;
                }
                let wi = flip(wi);
                let (f, pdf) = self.eval_pdf(wo, wi);
                if pdf <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: f * (1.0 / pdf),
                    pdf,
                    delta: false,
                })
            }
            Bsdf::Glass {
                reflectance,
                transmittance,
                ior,
            } => {
                let f = fresnel_dielectric(wo.z, ior);
                if u1 < f {
                    Some(BsdfSample {
                        wi: Vec3::new(-wo.x, -wo.y, wo.z),
                        weight: reflectance,
                        pdf: f,
                        delta: true,
                    })
                } else {
                    let (wi, scale) = refract(wo, ior)?;
                    Some(BsdfSample {
                        wi,
                        weight: transmittance * scale,
                        pdf: 1.0 - f,
                        delta: true,
                    })
                }
            }
            Bsdf::Refraction { transmittance, ior } => {
                let (wi, scale) = refract(wo, ior)?;
                Some(BsdfSample {
                    wi,
                    weight: transmittance * scale,
                    pdf: 1.0,
                    delta: true,
                })
            }
            Bsdf::Plastic {
                diffuse,
                specular,
                eta,
                specular_weight,
            } => {
                let wo_up = flip(wo);
                let f_i = fresnel_dielectric(wo_up.z, eta);
                let diffuse_share = plastic_diffuse_share(f_i, specular_weight);
                if u1 >= diffuse_share {
                    let p = 1.0 - diffuse_share;
                    return Some(BsdfSample {
                        wi: Vec3::new(-wo.x, -wo.y, wo.z),
                        weight: specular * (f_i / p),
                        pdf: p,
                        delta: true,
                    });
                }
                let wi = cosine_hemisphere(u2);
                if wi.z <= 0.0 {
                    return None;
                }
                let f_o = fresnel_dielectric(wi.z, eta);
                Some(BsdfSample {
                    wi: flip(wi),
                    weight: diffuse * ((1.0 - f_i) * (1.0 - f_o) / diffuse_share),
                    pdf: diffuse_share * cosine_hemisphere_pdf(wi.z),
                    delta: false,
                })
            }
            Bsdf::ThinDielectric {
                reflectance,
                transmittance,
                ior,
            } => {
                let f = fresnel_dielectric(wo.z.abs(), ior);
                let r = f * 2.0 / (1.0 + f);
                Some(if u1 <= r {
                    BsdfSample {
                        wi: Vec3::new(-wo.x, -wo.y, wo.z),
                        weight: reflectance,
                        pdf: r,
                        delta: true,
                    }
                } else {
                    BsdfSample {
                        wi: -wo,
                        weight: transmittance,
                        pdf: 1.0 - r,
                        delta: true,
                    }
                })
            }
            Bsdf::SmoothConductor { eta, k, specular } => Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: fresnel_conductor(wo.z.abs(), eta, k) * specular,
                pdf: 1.0,
                delta: true,
            }),
            Bsdf::RoughConductor {
                distr,
                eta,
                k,
                specular,
            } => rough::conductor_sample(&distr, (eta, k, specular), wo, u2),
            Bsdf::RoughDielectric {
                distr,
                reflectance,
                transmittance,
                ior,
            } => rough::dielectric_sample((distr, reflectance, transmittance, ior), wo, u1, u2),
            Bsdf::RoughPlastic {
                distr,
                eta,
                diffuse,
                specular,
                specular_weight,
                tables,
            } => rough_plastic::sample(
                (distr, eta, diffuse, specular, specular_weight, tables),
                wo,
                u1,
                u2,
            ),
            Bsdf::Principled {
                base,
                params,
                two_sided,
            } => {
                if two_sided && wo.z < 0.0 {
                    let s = principled::sample(&params, base, flip(wo), u1, u2)?;
                    Some(BsdfSample {
                        wi: flip(s.wi),
                        ..s
                    })
                } else {
                    principled::sample(&params, base, wo, u1, u2)
                }
            }
            Bsdf::Black => None,
        }
    }

    /// `eval_pdf` of the rough BSDFs, `None` for the others.
    fn rough_eval_pdf(&self, wo: Vec3, wi: Vec3) -> Option<(Rgb, f32)> {
        match *self {
            Bsdf::RoughConductor {
                distr,
                eta,
                k,
                specular,
            } => Some(rough::conductor_eval_pdf(
                &distr,
                (eta, k, specular),
                wo,
                wi,
            )),
            Bsdf::RoughDielectric {
                distr,
                reflectance,
                transmittance,
                ior,
            } => Some(rough::dielectric_eval_pdf(
                (distr, reflectance, transmittance, ior),
                wo,
                wi,
            )),
            Bsdf::RoughPlastic {
                distr,
                eta,
                diffuse,
                specular,
                specular_weight,
                tables,
            } => Some(rough_plastic::eval_pdf(
                (distr, eta, diffuse, specular, specular_weight, tables),
                wo,
                wi,
            )),
            Bsdf::Principled {
                base,
                params,
                two_sided,
            } => {
                let (wo, wi) = if two_sided { upper(wo, wi) } else { (wo, wi) };
                Some((
                    principled::eval(&params, base, wo, wi),
                    principled::pdf(&params, wo, wi),
                ))
            }
            _ => None,
        }
    }
}

/// A plastic base's albedo `diffuse` seen through its coat of index `eta` and internal
/// reflectance `fdr`: over `(1 - fdr) eta^2`, or channel by channel over
/// `(1 - diffuse fdr) eta^2` when `nonlinear` (Mitsuba's two models).
fn coat_scaled(diffuse: Rgb, fdr: f32, eta: f32, nonlinear: bool) -> Rgb {
    if nonlinear {
        let f = |d: f32| d / ((1.0 - d * fdr) * eta * eta);
        Rgb::new(f(diffuse.r), f(diffuse.g), f(diffuse.b))
    } else {
        diffuse * (1.0 / ((1.0 - fdr) * eta * eta))
    }
}

/// A plastic's share of samples for its specular lobe: the mean specular scale over it plus
/// the mean albedo (times the texture's mean), as Mitsuba weighs them.
fn specular_weight(
    diffuse: Rgb,
    texture: Option<&prism_scene::MaterialTexture>,
    specular: Rgb,
) -> f32 {
    let mean = |c: Rgb| (c.r + c.g + c.b) / 3.0;
    let albedo = diffuse * texture_mean(texture);
    mean(specular) / (mean(albedo) + mean(specular))
}

/// The mean texel of a texture (white without one): what Mitsuba weighs a textured
/// plastic's lobes by.
fn texture_mean(texture: Option<&prism_scene::MaterialTexture>) -> Rgb {
    texture.map_or(Rgb::WHITE, |t| {
        let px = t.image.pixels();
        px.iter().fold(Rgb::BLACK, |a, &c| a + c) * (1.0 / px.len().max(1) as f32)
    })
}

/// The share of a plastic's samples taken by its diffuse lobe, for an incident Fresnel
/// reflectance `f_i` (Mitsuba's lobe choice).
fn plastic_diffuse_share(f_i: f32, specular_weight: f32) -> f32 {
    let specular = f_i * specular_weight;
    let diffuse = (1.0 - f_i) * (1.0 - specular_weight);
    diffuse / (specular + diffuse)
}

/// The hemispherically averaged Fresnel reflectance of a dielectric boundary of relative
/// index `eta` (Egan and Hilgeman's fit below 1, d'Eon and Irving's above, as Mitsuba uses).
#[must_use]
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        0.0636 / eta + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        let x = 1.0 / eta;
        0.919_317 + x * (-3.4793 + x * (6.75335 + x * (-7.80989 + x * (4.98554 + x * -1.36881))))
    }
}

/// Both directions mirrored to the upper hemisphere when `wo` is below it (two-sided BSDFs).
fn upper(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 {
        (Vec3::new(wo.x, wo.y, -wo.z), Vec3::new(wi.x, wi.y, -wi.z))
    } else {
        (wo, wi)
    }
}

/// The Beckmann distribution of microfacet normals.
fn beckmann_d(h: Vec3, alpha: f32) -> f32 {
    let c2 = h.z * h.z;
    if c2 <= 0.0 {
        return 0.0;
    }
    let tan2 = (1.0 - c2) / c2;
    exp(-tan2 / (alpha * alpha)) / (PI * alpha * alpha * c2 * c2)
}

/// Samples a Beckmann normal visible from `wo` (upper hemisphere), with density
/// `D_wo(h) = G1(wo, h) max(0, wo.h) D(h) / wo.z` (Heitz and d'Eon 2014, the default in
/// Mitsuba): `wo` is stretched to roughness 1, a slope is drawn from the distribution of
/// slopes seen from there, rotated back to `wo`'s azimuth and unstretched.
fn sample_beckmann_visible(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let stretched = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let (sx, sy) = beckmann_visible_slopes(stretched.z, u);
    let r = (stretched.x * stretched.x + stretched.y * stretched.y).sqrt();
    let (cos_phi, sin_phi) = if r > 0.0 {
        (stretched.x / r, stretched.y / r)
    } else {
        (1.0, 0.0)
    };
    let tx = alpha * (cos_phi * sx - sin_phi * sy);
    let ty = alpha * (sin_phi * sx + cos_phi * sy);
    Vec3::new(-tx, -ty, 1.0).normalize()
}

/// Slopes `(x, y)` of roughness-1 Beckmann normals visible from a direction with cosine
/// `cos` to the normal, azimuth 0. `y` is Gaussian; `x` inverts its conditional CDF
/// `(1 + b + tan e^(-s^2) / sqrt(pi)) / (1 + erf(cot) + tan e^(-cot^2) / sqrt(pi))`, `b =
/// erf(s)`, by Newton's method in `b` from a fitted first guess.
fn beckmann_visible_slopes(cos: f32, u: Vec2) -> (f32, f32) {
    let y = erf_inv(2.0 * u.y.clamp(1e-6, 1.0 - 1e-6) - 1.0);
    if cos > 0.9999 {
        // Seen from above: the plain distribution of slopes, x Gaussian too.
        return (erf_inv(2.0 * u.x.clamp(1e-6, 1.0 - 1e-6) - 1.0), y);
    }
    let ux = u.x.clamp(1e-6, 1.0 - 1e-6);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let tan = sin / cos;
    let cot = cos / sin;
    let top = erf(cot);
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let norm = 1.0 / (1.0 + top + inv_sqrt_pi * tan * exp(-cot * cot));
    let theta = acos(cos);
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = top - (1.0 + top) * exp(fit * ln(1.0 - ux));
    for _ in 0..3 {
        let s = erf_inv(b);
        let value = norm * (1.0 + b + inv_sqrt_pi * tan * exp(-s * s)) - ux;
        let slope = norm * (1.0 - s * tan);
        if slope.abs() > 1e-12 {
            b = (b - value / slope).clamp(-1.0 + 1e-6, top.min(1.0 - 1e-6));
        }
    }
    (erf_inv(b), y)
}

/// The error function, to 1.5e-7 (Abramowitz and Stegun 7.1.26).
fn erf(x: f32) -> f32 {
    let a = x.abs();
    let t = 1.0 / (1.0 + 0.327_591_1 * a);
    let poly = t
        * (0.254_829_6
            + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152 + t * 1.061_405_4))));
    (1.0 - poly * exp(-a * a)).copysign(x)
}

/// The inverse error function on (-1, 1) (Giles' single-precision approximation, 2010).
fn erf_inv(x: f32) -> f32 {
    let w = -ln((1.0 - x) * (1.0 + x));
    let p = if w < 5.0 {
        let w = w - 2.5;
        ERF_INV_NEAR
            .iter()
            .fold(ERF_INV_NEAR_LEAD, |p, c| c + p * w)
    } else {
        let w = w.sqrt() - 3.0;
        ERF_INV_FAR.iter().fold(ERF_INV_FAR_LEAD, |p, c| c + p * w)
    };
    p * x
}

/// [`erf_inv`]'s polynomial in `w - 2.5` for `w < 5`: the leading coefficient, then the
/// others in Horner order.
const ERF_INV_NEAR_LEAD: f32 = 2.810_226_4e-8;
const ERF_INV_NEAR: [f32; 8] = [
    3.432_739_4e-7,
    -3.523_387_7e-6,
    -4.391_506_5e-6,
    2.185_808_7e-4,
    -1.253_725e-3,
    -4.177_681_6e-3,
    0.246_640_73,
    1.501_409_4,
];
/// [`erf_inv`]'s polynomial in `sqrt(w) - 3` for `w >= 5`.
const ERF_INV_FAR_LEAD: f32 = -2.002_142_6e-4;
const ERF_INV_FAR: [f32; 8] = [
    1.009_505_6e-4,
    1.349_343_2e-3,
    -3.673_428_4e-3,
    5.739_507_7e-3,
    -7.622_461_3e-3,
    9.438_870_5e-3,
    1.001_674,
    2.832_976_8,
];

/// Smith's masking for Beckmann with Walter's rational approximation.
fn smith_g1(v: Vec3, h: Vec3, alpha: f32) -> f32 {
    if v.dot(h) * v.z <= 0.0 {
        return 0.0;
    }
    let tan = (1.0 - v.z * v.z).max(0.0).sqrt() / v.z;
    if tan == 0.0 {
        return 1.0;
    }
    let a = 1.0 / (alpha * tan);
    if a >= 1.6 {
        1.0
    } else {
        (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
    }
}

/// Unpolarised Fresnel reflectance of a conductor with index `eta + i k` (outside index 1).
fn fresnel_conductor(cos: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c = cos.clamp(0.0, 1.0);
    let one = |eta: f32, k: f32| -> f32 {
        let c2 = c * c;
        let s2 = 1.0 - c2;
        let t0 = eta * eta - k * k - s2;
        let a2b2 = (t0 * t0 + 4.0 * eta * eta * k * k).max(0.0).sqrt();
        let t1 = a2b2 + c2;
        let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
        let t2 = 2.0 * c * a;
        let rs = (t1 - t2) / (t1 + t2);
        let t3 = c2 * a2b2 + s2 * s2;
        let t4 = t2 * s2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        0.5 * (rs + rp)
    };
    Rgb::new(one(eta.r, k.r), one(eta.g, k.g), one(eta.b, k.b))
}

/// Fresnel reflectance of a dielectric boundary for a direction with cosine `cos_o` to the
/// normal (positive outside, index 1; negative inside, index `ior`).
#[must_use]
pub fn fresnel_dielectric(cos_o: f32, ior: f32) -> f32 {
    let (eta_i, eta_t, ci) = if cos_o > 0.0 {
        (1.0, ior, cos_o)
    } else {
        (ior, 1.0, -cos_o)
    };
    let sin_t = eta_i / eta_t * (1.0 - ci * ci).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let rs = (eta_i * ci - eta_t * ct) / (eta_i * ci + eta_t * ct);
    let rp = (eta_t * ci - eta_i * ct) / (eta_t * ci + eta_i * ct);
    0.5 * (rs * rs + rp * rp)
}

/// The refracted direction of `wo` and the radiance scale `(eta_o / eta_i)^2`, or `None`
/// under total internal reflection.
fn refract(wo: Vec3, ior: f32) -> Option<(Vec3, f32)> {
    let entering = wo.z > 0.0;
    let eta = if entering { 1.0 / ior } else { ior }; // eta_o / eta_i
    let n = if entering { Vec3::Z } else { Vec3::NEG_Z };
    let cos_o = wo.dot(n);
    let sin2_i = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    if sin2_i >= 1.0 {
        return None;
    }
    let cos_i = (1.0 - sin2_i).sqrt();
    let wi = -eta * wo + (eta * cos_o - cos_i) * n;
    Some((wi, eta * eta))
}

pub(crate) mod lanes;
mod microfacet;
pub mod principled;
mod rough;
pub mod rough_plastic;

pub use microfacet::Microfacet;
#[cfg(test)]
mod rough_tests;
#[cfg(test)]
mod tests;
