//! Mitsuba's BSDFs as prism's materials: each plugin with Mitsuba's defaults and named
//! indices, `twosided`, the choices of `blendbsdf` and `mask`, the tilted normals of
//! `normalmap` and `bumpmap`, and microfacet roughness.

use super::document::Object;
use super::limits::{MAX_OBJECT_DEPTH, MAX_ROUGH_PLASTIC_COATS};
use super::props::{error, ior, not_supported, unsupported};
use super::to_scene::Builder;
use crate::error::SceneError;
use crate::scene::{
    Material, MicrofacetKind, PrincipledWeight, Roughness, ScalarTexture, TexturedParameter,
    TiltOptions,
};
use prism_math::Rgb;

impl Builder<'_> {
    /// The material of BSDF object `index` (translated once however often it is used).
    pub(super) fn bsdf(&mut self, index: usize, depth: usize) -> Result<usize, SceneError> {
        if let Some(&m) = self.bsdfs.get(&index) {
            return Ok(m);
        }
        match self.translate_bsdf(index, depth) {
            Ok(m) => Ok(m),
            Err(e) => {
                self.tolerate(e, "a grey diffuse BSDF stands in")?;
                let m = self.push_material(
                    Material::Diffuse {
                        reflectance: Rgb::splat(0.5),
                        texture: None,
                    },
                    "grey diffuse (--lenient)".into(),
                    true,
                );
                self.bsdfs.insert(index, m);
                Ok(m)
            }
        }
    }

    /// [`Builder::bsdf`]'s translation, without the lenient stand-in.
    fn translate_bsdf(&mut self, index: usize, depth: usize) -> Result<usize, SceneError> {
        let mut o = &self.doc.objects[index];
        let mut depth = depth;
        // `twosided` wraps one BSDF, which then scatters alike on both sides.
        let mut two_sided = false;
        while o.kind == "twosided" {
            two_sided = true;
            depth += 1;
            if depth > MAX_OBJECT_DEPTH {
                return Err(error(
                    o,
                    format!("objects nested more than {MAX_OBJECT_DEPTH} deep (a <ref> cycle?)"),
                ));
            }
            let inner: Vec<usize> = o
                .children
                .iter()
                .map(|&(_, c)| c)
                .filter(|&c| self.doc.objects[c].tag == "bsdf")
                .collect();
            match inner[..] {
                [one] => o = &self.doc.objects[one],
                _ => {
                    return Err(error(
                        o,
                        format!(
                            "{}: expected one nested <bsdf> (prism has no two-BSDF twosided)",
                            o.label()
                        ),
                    ))
                }
            }
        }
        if matches!(o.kind.as_str(), "blendbsdf" | "mask") {
            return self.choice(index, o, depth, two_sided);
        }
        if matches!(o.kind.as_str(), "normalmap" | "bumpmap") {
            return self.tilted(index, o, depth, two_sided);
        }
        // Nested plugins: textures in place of a diffuse albedo, specular scales and
        // microfacet roughness, where Mitsuba takes them.
        let mut reflectance_texture = None;
        let mut param_textures = Vec::new();
        for (slot, c) in &o.children {
            let c = &self.doc.objects[*c];
            let albedo_slot = match o.kind.as_str() {
                "diffuse" => "reflectance",
                "plastic" | "roughplastic" => "diffuse_reflectance",
                "principled" => "base_color",
                _ => "",
            };
            let slot = slot.as_deref().unwrap_or("");
            if c.tag == "texture" && !albedo_slot.is_empty() && slot == albedo_slot {
                reflectance_texture = Some(self.texture(c)?);
                continue;
            }
            let specular = !matches!(o.kind.as_str(), "diffuse" | "principled");
            let transmits = matches!(
                o.kind.as_str(),
                "dielectric" | "thindielectric" | "roughdielectric"
            );
            let rough = matches!(o.kind.as_str(), "roughconductor" | "roughdielectric");
            let weight = PrincipledWeight::named(slot)
                .filter(|_| o.kind == "principled")
                .map(TexturedParameter::Principled);
            let params: &[TexturedParameter] = match slot {
                _ if weight.is_some() => std::slice::from_ref(weight.as_ref().expect("a weight")),
                "specular_reflectance" if specular => &[TexturedParameter::SpecularReflectance],
                "specular_transmittance" if transmits => {
                    &[TexturedParameter::SpecularTransmittance]
                }
                "alpha" if rough => &[TexturedParameter::AlphaU, TexturedParameter::AlphaV],
                "alpha_u" if rough => &[TexturedParameter::AlphaU],
                "alpha_v" if rough => &[TexturedParameter::AlphaV],
                _ => &[],
            };
            if c.tag == "texture" && !params.is_empty() {
                // An alpha is a number: Mitsuba reads its texture with `eval_1`.
                let t = match (params[0], self.scalar_texture(c)?) {
                    (
                        TexturedParameter::AlphaU
                        | TexturedParameter::AlphaV
                        | TexturedParameter::Principled(_),
                        ScalarTexture::Image(t),
                    ) => t,
                    _ => self.texture(c)?,
                };
                param_textures.extend(params.iter().map(|&p| (p, t.clone())));
                continue;
            }
            return Err(not_supported(
                c,
                format!(
                    "{} in {}: not supported by prism yet (a bitmap or checkerboard as a diffuse albedo, a specular scale, a microfacet alpha or a principled weight is)",
                    c.label(),
                    o.label()
                ),
            ));
        }
        let name = o.id.clone().unwrap_or_else(|| o.label());
        let material = match o.kind.as_str() {
            "diffuse" => match reflectance_texture {
                Some(t) => Material::Diffuse {
                    reflectance: Rgb::WHITE,
                    texture: Some(t),
                },
                None => Material::Diffuse {
                    reflectance: o.rgb("reflectance", [0.5; 3])?,
                    texture: None,
                },
            },
            "dielectric" => {
                let int = ior(o, "int_ior", "bk7")?;
                let ext = ior(o, "ext_ior", "air")?;
                Material::Glass {
                    reflectance: o.rgb("specular_reflectance", [1.0; 3])?,
                    transmittance: o.rgb("specular_transmittance", [1.0; 3])?,
                    roughness: 0.0,
                    ior: (int / ext) as f32,
                }
            }
            "thindielectric" => {
                let int = ior(o, "int_ior", "bk7")?;
                let ext = ior(o, "ext_ior", "air")?;
                Material::ThinDielectric {
                    reflectance: o.rgb("specular_reflectance", [1.0; 3])?,
                    transmittance: o.rgb("specular_transmittance", [1.0; 3])?,
                    ior: (int / ext) as f32,
                }
            }
            "plastic" => {
                let (diffuse, nonlinear) = plastic_base(o, reflectance_texture.is_some())?;
                let int = ior(o, "int_ior", "polypropylene")?;
                let ext = ior(o, "ext_ior", "air")?;
                Material::Plastic {
                    diffuse,
                    specular: o.rgb("specular_reflectance", [1.0; 3])?,
                    eta: (int / ext) as f32,
                    texture: reflectance_texture.clone(),
                    nonlinear,
                }
            }
            "conductor" | "roughconductor" => {
                let roughness = if o.kind == "roughconductor" {
                    Some(roughness(o)?)
                } else {
                    None
                };
                let (eta, k) = conductor_index(o)?;
                let specular = o.rgb("specular_reflectance", [1.0; 3])?;
                match roughness {
                    // The collada path's Beckmann conductor, which the lanes run.
                    Some(Roughness {
                        kind: MicrofacetKind::Beckmann,
                        alpha_u,
                        alpha_v,
                    }) if alpha_u == alpha_v
                        && specular == Rgb::WHITE
                        && param_textures.is_empty() =>
                    {
                        Material::Microfacet {
                            alpha: alpha_u,
                            eta,
                            k,
                        }
                    }
                    // Mitsuba's default conductor reflects everything.
                    None if eta == Rgb::splat(0.0) && k == Rgb::WHITE => Material::Mirror {
                        reflectance: specular,
                    },
                    _ => Material::Conductor {
                        roughness,
                        eta,
                        k,
                        specular,
                    },
                }
            }
            "roughplastic" => {
                let (diffuse, nonlinear) = plastic_base(o, reflectance_texture.is_some())?;
                let roughness = roughness(o)?;
                if roughness.alpha_u != roughness.alpha_v {
                    return Err(error(
                        o,
                        format!(
                            "{}: an anisotropic roughplastic (Mitsuba refuses it too)",
                            o.label()
                        ),
                    ));
                }
                let int = ior(o, "int_ior", "polypropylene")?;
                let ext = ior(o, "ext_ior", "air")?;
                if !(int > 0.0 && ext > 0.0) || int == ext {
                    return Err(error(o, format!("{}: int_ior and ext_ior: expected positive indices that differ, found {int} and {ext}", o.label())));
                }
                // Each distinct coat is tabulated once per process: keep their number small.
                self.coats.insert((
                    roughness.kind == MicrofacetKind::Ggx,
                    roughness.alpha_u.to_bits(),
                    ((int / ext) as f32).to_bits(),
                ));
                if self.coats.len() > MAX_ROUGH_PLASTIC_COATS {
                    return Err(error(o, format!("{}: more than {MAX_ROUGH_PLASTIC_COATS} distinct rough plastic coats (distribution, alpha, index) in one scene", o.label())));
                }
                Material::RoughPlastic {
                    roughness,
                    diffuse,
                    specular: o.rgb("specular_reflectance", [1.0; 3])?,
                    eta: (int / ext) as f32,
                    texture: reflectance_texture.clone(),
                    nonlinear,
                }
            }
            "roughdielectric" => {
                let int = ior(o, "int_ior", "bk7")?;
                let ext = ior(o, "ext_ior", "air")?;
                if !(int > 0.0 && ext > 0.0) || int == ext {
                    return Err(error(o, format!("{}: int_ior and ext_ior: expected positive indices that differ, found {int} and {ext}", o.label())));
                }
                Material::RoughDielectric {
                    roughness: roughness(o)?,
                    reflectance: o.rgb("specular_reflectance", [1.0; 3])?,
                    transmittance: o.rgb("specular_transmittance", [1.0; 3])?,
                    ior: (int / ext) as f32,
                }
            }
            "principled" => {
                let textured = |w: PrincipledWeight| {
                    param_textures
                        .iter()
                        .any(|(p, _)| *p == TexturedParameter::Principled(w))
                };
                principled(o, reflectance_texture.clone(), two_sided, &textured)?
            }
            _ => return Err(unsupported(o)),
        };
        // Mitsuba's opaque BSDFs are black from behind unless wrapped in `twosided`.
        let opaque = matches!(
            o.kind.as_str(),
            "diffuse" | "plastic" | "roughplastic" | "conductor" | "roughconductor"
        );
        let mut material = material;
        // A plastic weighs its lobes by its specular scale's mean, as Mitsuba does.
        if let (
            Material::Plastic { specular, .. } | Material::RoughPlastic { specular, .. },
            Some((_, t)),
        ) = (
            &mut material,
            param_textures
                .iter()
                .find(|(p, _)| *p == TexturedParameter::SpecularReflectance),
        ) {
            let px = t.image.pixels();
            *specular = px.iter().fold(Rgb::BLACK, |a, &c| a + c) * (1.0 / px.len().max(1) as f32);
        }
        let mut m = self.push_material(material, name.clone(), opaque && !two_sided);
        if !param_textures.is_empty() {
            m = self.push_material(
                Material::Textured {
                    material: m,
                    textures: param_textures,
                },
                name,
                // The material's own sides decide.
                true,
            );
        }
        self.bsdfs.insert(index, m);
        Ok(m)
    }

    /// A `normalmap` (a nested BSDF and a `normalmap` texture) or a `bumpmap` (a nested BSDF,
    /// a bitmap of heights and their `scale`). The nested BSDF must be a plain one: prism
    /// tilts the shading normal once.
    fn tilted(
        &mut self,
        index: usize,
        o: &Object,
        depth: usize,
        two_sided: bool,
    ) -> Result<usize, SceneError> {
        if depth > MAX_OBJECT_DEPTH {
            return Err(error(
                o,
                format!("objects nested more than {MAX_OBJECT_DEPTH} deep (a <ref> cycle?)"),
            ));
        }
        let mut nested = Vec::new();
        let mut textures = Vec::new();
        for (name, c) in &o.children {
            let co = &self.doc.objects[*c];
            match co.tag.as_str() {
                "bsdf" => nested.push((self.bsdf(*c, depth + 1)?, co)),
                "texture" if o.kind == "bumpmap" || name.as_deref() == Some("normalmap") => {
                    if o.kind == "bumpmap" && co.kind != "bitmap" {
                        return Err(error(
                            co,
                            format!(
                                "{} in {}: expected a bitmap (Mitsuba has no gradient for others)",
                                co.label(),
                                o.label()
                            ),
                        ));
                    }
                    textures.push(self.texture(co)?);
                }
                _ => {
                    return Err(not_supported(
                        co,
                        format!(
                            "{} in {}: not supported by prism yet",
                            co.label(),
                            o.label()
                        ),
                    ))
                }
            }
        }
        let ([(material, inner)], [texture]) = (&nested[..], &textures[..]) else {
            return Err(error(
                o,
                format!(
                    "{}: expected one nested <bsdf> and one texture, found {} and {}",
                    o.label(),
                    nested.len(),
                    textures.len()
                ),
            ));
        };
        let (material, texture) = (*material, texture.clone());
        if matches!(
            self.scene.materials[material],
            Material::Blend { .. }
                | Material::Mask { .. }
                | Material::NormalMap { .. }
                | Material::BumpMap { .. }
        ) {
            return Err(not_supported(
                inner,
                format!(
                    "{} in {}: a blend, mask or map under a map: not supported by prism yet",
                    inner.label(),
                    o.label()
                ),
            ));
        }
        let tilt = TiltOptions {
            flip_invalid_normals: o.boolean("flip_invalid_normals", true)?,
            shadowing: o.boolean("use_shadowing_function", true)?,
        };
        let m = if o.kind == "normalmap" {
            Material::NormalMap {
                normals: texture,
                material,
                tilt,
            }
        } else {
            Material::BumpMap {
                height: texture,
                scale: o.float("scale", 1.0)? as f32,
                material,
                tilt,
            }
        };
        let name = o.id.clone().unwrap_or_else(|| o.label());
        let m = self.push_material(m, name, !two_sided);
        self.bsdfs.insert(index, m);
        Ok(m)
    }

    /// A `blendbsdf` (two nested BSDFs and a `weight`) or a `mask` (one nested BSDF and an
    /// `opacity`), its nested BSDFs translated first. Inside `twosided`, every BSDF it
    /// chooses scatters on both sides.
    fn choice(
        &mut self,
        index: usize,
        o: &Object,
        depth: usize,
        two_sided: bool,
    ) -> Result<usize, SceneError> {
        if depth > MAX_OBJECT_DEPTH {
            return Err(error(
                o,
                format!("objects nested more than {MAX_OBJECT_DEPTH} deep (a <ref> cycle?)"),
            ));
        }
        let (slot, wanted) = if o.kind == "mask" {
            ("opacity", 1)
        } else {
            ("weight", 2)
        };
        let mut nested = Vec::new();
        let mut texture = None;
        for (name, c) in &o.children {
            let co = &self.doc.objects[*c];
            match co.tag.as_str() {
                "bsdf" => nested.push(self.bsdf(*c, depth + 1)?),
                "texture" if name.as_deref() == Some(slot) => {
                    texture = Some(self.scalar_texture(co)?)
                }
                _ => {
                    return Err(not_supported(
                        co,
                        format!(
                            "{} in {}: not supported by prism yet (a bitmap or checkerboard as its {slot} is)",
                            co.label(),
                            o.label()
                        ),
                    ))
                }
            }
        }
        if nested.len() != wanted {
            return Err(error(
                o,
                format!(
                    "{}: expected {wanted} nested <bsdf>, found {}",
                    o.label(),
                    nested.len()
                ),
            ));
        }
        let value = match texture {
            Some(t) => t,
            None if o.kind == "mask" => ScalarTexture::Constant(o.float(slot, 0.5)? as f32),
            None => match o.value(slot) {
                Some(_) => ScalarTexture::Constant(o.float(slot, 0.0)? as f32),
                None => return Err(error(o, format!("{}: expected a {slot}", o.label()))),
            },
        };
        let material = if o.kind == "mask" {
            Material::Mask {
                opacity: value,
                material: nested[0],
            }
        } else {
            Material::Blend {
                weight: value,
                materials: [nested[0], nested[1]],
            }
        };
        let name = o.id.clone().unwrap_or_else(|| o.label());
        // A choice's own sidedness only widens its choices': one-sided unless wrapped.
        let m = self.push_material(material, name, !two_sided);
        self.bsdfs.insert(index, m);
        Ok(m)
    }
}

/// A microfacet BSDF's `distribution` (Beckmann unless given) and `alpha`, or `alpha_u` and
/// `alpha_v` together (0.1 unless given), as Mitsuba reads them.
fn roughness(o: &Object) -> Result<Roughness, SceneError> {
    let kind = match o
        .string("distribution")?
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        None | Some("beckmann") => MicrofacetKind::Beckmann,
        Some("ggx") => MicrofacetKind::Ggx,
        Some(other) => {
            return Err(error(
                o,
                format!(
                    "{}: distribution {other:?}: expected \"beckmann\" or \"ggx\"",
                    o.label()
                ),
            ))
        }
    };
    // Given as a number or as a texture (whose value each hit reads).
    let given = |name: &str| {
        o.prop(name).is_some() || o.children.iter().any(|(s, _)| s.as_deref() == Some(name))
    };
    let (has_u, has_v, has_alpha) = (given("alpha_u"), given("alpha_v"), given("alpha"));
    if (has_u || has_v) && (!(has_u && has_v) || has_alpha) {
        return Err(error(
            o,
            format!(
                "{}: expected either alpha or both alpha_u and alpha_v",
                o.label()
            ),
        ));
    }
    let (u, v) = if has_u {
        (o.float("alpha_u", 0.1)?, o.float("alpha_v", 0.1)?)
    } else {
        let a = o.float("alpha", 0.1)?;
        (a, a)
    };
    for (name, a) in [("alpha_u", u), ("alpha_v", v)] {
        if !(0.0..=4.0).contains(&a) {
            return Err(error(
                o,
                format!(
                    "{}: {name}: expected a roughness of at least 0 and at most 4, found {a}",
                    o.label()
                ),
            ));
        }
    }
    // Mitsuba clamps a zero roughness to 1e-4.
    Ok(Roughness {
        kind,
        alpha_u: u.max(1e-4) as f32,
        alpha_v: v.max(1e-4) as f32,
    })
}

/// A conductor's complex index: `eta` (0) and `k` (1) when `eta` is given or the material is
/// "none" (the default), else the named material's.
fn conductor_index(o: &Object) -> Result<(Rgb, Rgb), SceneError> {
    let material = o.string("material")?.unwrap_or("none");
    if o.prop("eta").is_some() || material == "none" {
        return Ok((o.rgb("eta", [0.0; 3])?, o.rgb("k", [1.0; 3])?));
    }
    let (e, k) = super::conductors::conductor(material).ok_or_else(|| {
        error(
            o,
            format!(
                "{}: material {material:?}: Mitsuba names no such conductor",
                o.label()
            ),
        )
    })?;
    Ok((Rgb::new(e[0], e[1], e[2]), Rgb::new(k[0], k[1], k[2])))
}

/// A plastic's base: its `diffuse_reflectance` (white under a texture, which gives it) and
/// `nonlinear`, which prism reads for an untextured base only.
fn plastic_base(o: &Object, textured: bool) -> Result<(Rgb, bool), SceneError> {
    let nonlinear = o.boolean("nonlinear", false)?;
    if nonlinear && textured {
        return Err(not_supported(
            o,
            format!(
                "{}: nonlinear with a textured diffuse_reflectance: not supported by prism yet",
                o.label()
            ),
        ));
    }
    let diffuse = if textured {
        Rgb::WHITE
    } else {
        o.rgb("diffuse_reflectance", [0.5; 3])?
    };
    Ok((diffuse, nonlinear))
}

/// A `principled` BSDF with Mitsuba's defaults: `base_color` 0.5, `roughness` 0.5, the
/// other weights 0, and `eta`, or else `specular` (0.5) mapped to an index as Mitsuba maps
/// it; transmission moves an index of 1 (or a specular of 0) just off it.
fn principled(
    o: &Object,
    texture: Option<crate::scene::MaterialTexture>,
    two_sided: bool,
    textured: &dyn Fn(PrincipledWeight) -> bool,
) -> Result<Material, SceneError> {
    let f = |name: &str, default: f64| -> Result<f32, SceneError> {
        let v = o.float(name, default)?;
        if !v.is_finite() {
            return Err(error(
                o,
                format!("{}: {name}: expected a finite number", o.label()),
            ));
        }
        Ok(v as f32)
    };
    // Weights outside [0, 1] would make light negative: refused.
    let weight = |name: &str, default: f64| -> Result<f32, SceneError> {
        let v = f(name, default)?;
        if !(0.0..=1.0).contains(&v) {
            return Err(error(
                o,
                format!("{}: {name}: expected 0 to 1, found {v}", o.label()),
            ));
        }
        Ok(v)
    };
    let spec_trans = weight("spec_trans", 0.0)?;
    // Mitsuba's `has_spec_trans`: a number other than 0, or a texture.
    let transmits = spec_trans != 0.0 || textured(PrincipledWeight::SpecTrans);
    let eta = match (o.value("eta"), o.value("specular")) {
        (Some(_), Some(_)) => {
            return Err(error(
                o,
                format!(
                    "{}: eta and specular: expected one of them, not both",
                    o.label()
                ),
            ))
        }
        (Some(_), None) => match f("eta", 1.5)? {
            eta if transmits && eta == 1.0 => 1.001,
            eta => eta,
        },
        (None, _) => {
            let specular = match f("specular", 0.5)? {
                s if transmits && s == 0.0 => 1e-3,
                s => s,
            };
            2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
        }
    };
    if !eta.is_finite() || eta <= 0.0 {
        return Err(error(
            o,
            format!("{}: expected a positive index, found {eta}", o.label()),
        ));
    }
    // The sampling rates choose among the lobes: none negative, the main one positive.
    let rates = [
        f("main_specular_sampling_rate", 1.0)?,
        f("clearcoat_sampling_rate", 1.0)?,
        f("diffuse_reflectance_sampling_rate", 1.0)?,
    ];
    if rates.iter().any(|&r| r < 0.0) || rates[0] <= 0.0 {
        return Err(error(o, format!("{}: sampling rates: expected none negative and main_specular_sampling_rate positive, found {rates:?}", o.label())));
    }
    let (sheen, clearcoat) = (f("sheen", 0.0)?, f("clearcoat", 0.0)?);
    if sheen < 0.0 || clearcoat < 0.0 {
        return Err(error(o, format!("{}: sheen and clearcoat: expected no negative weight, found {sheen} and {clearcoat}", o.label())));
    }
    Ok(Material::Principled {
        base_color: if texture.is_some() {
            Rgb::WHITE
        } else {
            o.rgb("base_color", [0.5; 3])?
        },
        texture,
        roughness: weight("roughness", 0.5)?,
        anisotropic: weight("anisotropic", 0.0)?,
        metallic: weight("metallic", 0.0)?,
        spec_trans,
        transmits,
        spec_tint: weight("spec_tint", 0.0)?,
        sheen,
        sheen_tint: weight("sheen_tint", 0.0)?,
        flatness: weight("flatness", 0.0)?,
        clearcoat,
        clearcoat_gloss: weight("clearcoat_gloss", 0.0)?,
        eta,
        rates,
        two_sided,
    })
}
