//! The libraries a renderer needs: effects (materials), lights and cameras.

use prism_math::Rgb;
use prism_math::{Loc, Warning};
use roxmltree::Node as XmlNode;
use std::collections::HashMap;

use super::xml::{child, children, floats, Cx};
use crate::error::SceneError;
use crate::scene::Material;

/// A `<camera>` with a perspective projection.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDef {
    /// Its id.
    pub id: String,
    /// Line of its start tag.
    pub line: u32,
    /// Horizontal field of view in degrees, if given.
    pub xfov: Option<f64>,
    /// Vertical field of view in degrees, if given.
    pub yfov: Option<f64>,
    /// Width over height, if given.
    pub aspect_ratio: Option<f64>,
    /// Near clipping distance.
    pub znear: f64,
    /// Far clipping distance.
    pub zfar: f64,
    /// Why it cannot be read, if it cannot (the other fields are then the defaults); using
    /// it is then an error.
    pub defect: Option<SceneError>,
}

impl CameraDef {
    /// A camera whose optics could not be read: its id and line, default optics.
    pub(super) fn unread(cx: &Cx, c: XmlNode) -> CameraDef {
        CameraDef {
            id: c.attribute("id").unwrap_or("").to_string(),
            line: cx.line(c),
            xfov: None,
            yfov: None,
            aspect_ratio: None,
            znear: 0.001,
            zfar: 1000.0,
            defect: None,
        }
    }
}

/// Which kind of light a `<light>` is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    /// `point`.
    Point,
    /// `directional`.
    Directional,
    /// The CGL `area` extra: a rectangle sized by its node's matrix.
    Area,
    /// `ambient`: the course's hemisphere light.
    Ambient,
    /// `spot` (the course renders it black).
    Spot,
}

/// A `<light>`: the CGL extra technique if present, else `technique_common`.
#[derive(Clone, Debug, PartialEq)]
pub struct LightDef {
    /// Its id.
    pub id: String,
    /// Line of its start tag.
    pub line: u32,
    /// Kind.
    pub kind: LightKind,
    /// `<color>`: radiance, intensity or irradiance by kind.
    pub color: Rgb,
    /// Why it cannot be read, if it cannot (the kind and colour are then placeholders);
    /// using it is then an error.
    pub defect: Option<SceneError>,
}

impl LightDef {
    /// A light that could not be read: its id and line, a black point light.
    pub(super) fn unread(cx: &Cx, l: XmlNode) -> LightDef {
        LightDef {
            id: l.attribute("id").unwrap_or("").to_string(),
            line: cx.line(l),
            kind: LightKind::Point,
            color: Rgb::BLACK,
            defect: None,
        }
    }
}

/// An `<effect>` read as a material.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectDef {
    /// Its id.
    pub id: String,
    /// Line of its start tag.
    pub line: u32,
    /// The material: the CGL extra's BSDF (the last one if several), else the common
    /// profile's diffuse colour, else diffuse 0.5.
    pub material: Material,
    /// Why it cannot be read, if it cannot (the material is then diffuse 0.5); using it is
    /// then an error.
    pub defect: Option<SceneError>,
    /// The image file of the common profile's diffuse `<texture>` (as written, relative to
    /// the document), with the line of the `<texture>`: the material is then diffuse white
    /// times that image.
    pub diffuse_texture: Option<(String, u32)>,
}

impl EffectDef {
    /// An effect that could not be read: its id and line, diffuse 0.5.
    pub(super) fn unread(cx: &Cx, e: XmlNode) -> EffectDef {
        EffectDef {
            id: e.attribute("id").unwrap_or("").to_string(),
            line: cx.line(e),
            material: Material::Diffuse {
                reflectance: Rgb::splat(0.5),
                texture: None,
            },
            defect: None,
            diffuse_texture: None,
        }
    }
}

fn color3(cx: &Cx, n: XmlNode) -> Result<Rgb, SceneError> {
    let v = floats(cx, n)?;
    if v.len() < 3 || v.len() > 4 {
        return Err(cx.err(
            n,
            format!(
                "expected 3 colour values (or 4 with alpha), found {}",
                v.len()
            ),
        ));
    }
    if v[..3].iter().any(|&c| c < 0.0) {
        return Err(cx.err(n, "expected non-negative colour values"));
    }
    Ok(Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32))
}

fn scalar(cx: &Cx, n: XmlNode) -> Result<f64, SceneError> {
    let v = floats(cx, n)?;
    if v.len() != 1 {
        return Err(cx.err(n, format!("expected one number, found {}", v.len())));
    }
    Ok(v[0])
}

fn required<'a, 'i>(
    cx: &Cx,
    n: XmlNode<'a, 'i>,
    name: &str,
) -> Result<XmlNode<'a, 'i>, SceneError> {
    child(n, name).ok_or_else(|| cx.err(n, format!("expected a <{name}>")))
}

fn positive(cx: &Cx, n: XmlNode, v: f64, what: &str) -> Result<f32, SceneError> {
    if v > 0.0 {
        Ok(v as f32)
    } else {
        Err(cx.err(n, format!("expected a positive {what}, found {v}")))
    }
}

fn cgl_bsdf(cx: &Cx, b: XmlNode) -> Result<Option<Material>, SceneError> {
    let c = |name: &str| -> Result<Rgb, SceneError> { color3(cx, required(cx, b, name)?) };
    let s = |name: &str| -> Result<f64, SceneError> { scalar(cx, required(cx, b, name)?) };
    let ior = || {
        positive(
            cx,
            required(cx, b, "ior")?,
            s("ior")?,
            "index of refraction",
        )
    };
    Ok(Some(match b.tag_name().name() {
        "diffuse" => Material::Diffuse {
            reflectance: c("albedo").or_else(|_| c("reflectance"))?,
            texture: None,
        },
        "emission" => Material::Emission {
            radiance: c("radiance")?,
        },
        "mirror" => Material::Mirror {
            reflectance: c("reflectance")?,
        },
        "glass" => Material::Glass {
            reflectance: c("reflectance")?,
            transmittance: c("transmittance")?,
            roughness: s("roughness")? as f32,
            ior: ior()?,
        },
        "refraction" => Material::Refraction {
            transmittance: c("transmittance")?,
            roughness: s("roughness")? as f32,
            ior: ior()?,
        },
        "microfacet" => Material::Microfacet {
            alpha: positive(
                cx,
                required(cx, b, "alpha")?,
                s("alpha")?,
                "roughness alpha",
            )?,
            eta: c("eta")?,
            k: c("k")?,
        },
        _ => return Ok(None),
    }))
}

/// The image file a common-profile `<texture texture="X">` reads: `X` names a `<newparam>`
/// of the effect holding a `<sampler2D>`, whose `<source>` names a `<newparam>` holding a
/// `<surface>` whose `<init_from>` is an image id (COLLADA 1.4.1); or the sampler's
/// `<instance_image url="#id">` (1.5); or `X` is an image id itself (as some exporters
/// write it). `images` maps image ids to their files.
fn texture_file(
    cx: &Cx,
    e: XmlNode,
    t: XmlNode,
    images: &HashMap<String, String>,
) -> Result<String, SceneError> {
    let name = t
        .attribute("texture")
        .ok_or_else(|| cx.err(t, "expected a texture attribute"))?;
    let param = |sid: &str| {
        e.descendants()
            .find(|n| n.has_tag_name("newparam") && n.attribute("sid") == Some(sid))
    };
    let image_id = match param(name).and_then(|p| child(p, "sampler2D")) {
        Some(sampler) => {
            if let Some(url) = child(sampler, "instance_image").and_then(|i| i.attribute("url")) {
                url.trim_start_matches('#').to_string()
            } else {
                let source = child(sampler, "source")
                    .and_then(|s| s.text())
                    .map(str::trim)
                    .ok_or_else(|| cx.err(sampler, "expected a <source> in the <sampler2D>"))?;
                let surface = param(source)
                    .and_then(|p| child(p, "surface"))
                    .ok_or_else(|| {
                        cx.err(
                            sampler,
                            format!("no <newparam> {source:?} with a <surface>"),
                        )
                    })?;
                child(surface, "init_from")
                    .and_then(|i| i.text())
                    .map(|s| s.trim().to_string())
                    .ok_or_else(|| cx.err(surface, "expected an <init_from> in the <surface>"))?
            }
        }
        None => name.to_string(),
    };
    images.get(&image_id).cloned().ok_or_else(|| {
        cx.err(
            t,
            format!("no <image> with id {image_id:?} for texture {name:?}"),
        )
    })
}

/// Reads one `<effect>`; `images` maps `<image>` ids to their files.
pub(super) fn effect(
    cx: &Cx,
    e: XmlNode,
    images: &HashMap<String, String>,
    warn: &mut dyn FnMut(&str, Warning),
) -> Result<EffectDef, SceneError> {
    let mut material = None;
    let mut diffuse_texture = None;
    for t in e
        .children()
        .filter(|c| c.has_tag_name("extra"))
        .flat_map(|x| children(x, "technique"))
        .filter(|t| t.attribute("profile") == Some("CGL"))
    {
        for b in t.children().filter(|c| c.is_element()) {
            match cgl_bsdf(cx, b)? {
                Some(m) => material = Some(m),
                None => warn(
                    &format!("bsdf:{}", b.tag_name().name()),
                    Warning::at(Loc::line(cx.file, cx.line(b)), format!("CGL BSDF <{}> is not known; the effect falls back to its common profile", b.tag_name().name())),
                ),
            }
        }
    }
    if material.is_none() {
        let shading = child(e, "profile_COMMON")
            .and_then(|p| child(p, "technique"))
            .and_then(|t| {
                t.children()
                    .find(|c| matches!(c.tag_name().name(), "phong" | "lambert" | "blinn"))
            });
        let diffuse = shading.and_then(|s| child(s, "diffuse"));
        if let Some(colour) = diffuse.and_then(|d| child(d, "color")) {
            material = Some(Material::Diffuse {
                reflectance: color3(cx, colour)?,
                texture: None,
            });
        } else if let Some(t) = diffuse.and_then(|d| child(d, "texture")) {
            diffuse_texture = Some((texture_file(cx, e, t, images)?, cx.line(t)));
            material = Some(Material::Diffuse {
                reflectance: Rgb::WHITE,
                texture: None,
            });
        }
    }
    Ok(EffectDef {
        id: e.attribute("id").unwrap_or("").to_string(),
        line: cx.line(e),
        material: material.unwrap_or(Material::Diffuse {
            reflectance: Rgb::splat(0.5),
            texture: None,
        }),
        defect: None,
        diffuse_texture,
    })
}

/// Reads one `<light>`; `None` (with a warning) for a kind prism does not know.
pub(super) fn light(
    cx: &Cx,
    l: XmlNode,
    warn: &mut dyn FnMut(&str, Warning),
) -> Result<Option<LightDef>, SceneError> {
    let cgl = l
        .children()
        .filter(|c| c.has_tag_name("extra"))
        .flat_map(|x| children(x, "technique"))
        .find(|t| t.attribute("profile") == Some("CGL"));
    let technique = cgl
        .or_else(|| child(l, "technique_common"))
        .ok_or_else(|| cx.err(l, "expected a <technique_common> or a CGL <extra>"))?;
    let shape = technique
        .children()
        .find(|c| c.is_element())
        .ok_or_else(|| cx.err(technique, "expected a light type element"))?;
    let kind = match shape.tag_name().name() {
        "point" => LightKind::Point,
        "directional" => LightKind::Directional,
        "area" => LightKind::Area,
        "ambient" => LightKind::Ambient,
        "spot" => LightKind::Spot,
        other => {
            warn(
                &format!("light:{other}"),
                Warning::at(
                    Loc::line(cx.file, cx.line(shape)),
                    format!("light type <{other}> is not known; the light is skipped"),
                ),
            );
            return Ok(None);
        }
    };
    Ok(Some(LightDef {
        id: l.attribute("id").unwrap_or("").to_string(),
        line: cx.line(l),
        kind,
        color: color3(cx, required(cx, shape, "color")?)?,
        defect: None,
    }))
}

/// Reads one `<camera>`.
pub(super) fn camera(cx: &Cx, c: XmlNode) -> Result<CameraDef, SceneError> {
    let optics = required(cx, c, "optics")?;
    let common = required(cx, optics, "technique_common")?;
    let p = child(common, "perspective").ok_or_else(|| {
        cx.err(
            common,
            "expected a <perspective> camera (orthographic cameras are not supported)",
        )
    })?;
    let opt = |name: &str| -> Result<Option<f64>, SceneError> {
        child(p, name).map(|n| scalar(cx, n)).transpose()
    };
    let xfov = opt("xfov")?;
    let yfov = opt("yfov")?;
    let aspect_ratio = opt("aspect_ratio")?;
    if xfov.is_none() && yfov.is_none() {
        return Err(cx.err(p, "expected an <xfov> or a <yfov>"));
    }
    for (n, v) in [("xfov", xfov), ("yfov", yfov)] {
        if let Some(v) = v {
            if !(v > 0.0 && v < 180.0) {
                let node = child(p, n).unwrap_or(p);
                return Err(cx.err(
                    node,
                    format!("expected a field of view between 0 and 180 degrees, found {v}"),
                ));
            }
        }
    }
    if let Some(a) = aspect_ratio {
        if a <= 0.0 {
            return Err(cx.err(
                child(p, "aspect_ratio").unwrap_or(p),
                format!("expected a positive aspect ratio, found {a}"),
            ));
        }
    }
    Ok(CameraDef {
        id: c.attribute("id").unwrap_or("").to_string(),
        line: cx.line(c),
        xfov,
        yfov,
        aspect_ratio,
        znear: opt("znear")?.unwrap_or(0.001),
        zfar: opt("zfar")?.unwrap_or(1000.0),
        defect: None,
    })
}
