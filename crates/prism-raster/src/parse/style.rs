//! The standard dialect's presentation properties: paints (`fill`, `stroke`, with
//! `url(#id)` references kept for later), opacities, the fill rule and the stroke's width,
//! joins, caps, miter limit and dashes, read from presentation attributes and `style`
//! declarations into an inherited [`Style`].

use prism_math::Rgb;
use roxmltree::Node;

use super::color::parse_color;
use super::common::{number_with_unit, ElementAt, PlainAttribute, SvgError};
use super::number::Precision;
use super::viewport::{length, Axis, Viewport};
use crate::document::FillRule;
use crate::path::{LineCap, LineJoin, StrokeStyle};

/// Standard SVG reads numbers as `f64`.
const P: Precision = Precision::F64;

/// A `fill` or `stroke` value as written, before `url(#id)` references are resolved.
#[derive(Clone, Debug)]
pub(super) enum PaintSpec {
    /// `none`.
    None,
    /// A colour and its alpha.
    Color(Rgb, f32),
    /// `currentColor`: the inherited `color` property.
    CurrentColor,
    /// `url(#id)` with its fallback paint, if any.
    Url(String, Option<Box<PaintSpec>>),
}

/// The inherited presentation properties of an element.
#[derive(Clone, Debug)]
pub(super) struct Style {
    pub(super) fill: PaintSpec,
    pub(super) fill_opacity: f32,
    pub(super) fill_rule: FillRule,
    pub(super) stroke_paint: PaintSpec,
    pub(super) stroke_opacity: f32,
    pub(super) stroke: StrokeStyle,
    pub(super) color: Rgb,
    pub(super) visible: bool,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            fill: PaintSpec::Color(Rgb::BLACK, 1.0),
            fill_opacity: 1.0,
            fill_rule: FillRule::NonZero,
            stroke_paint: PaintSpec::None,
            stroke_opacity: 1.0,
            stroke: StrokeStyle::default(),
            color: Rgb::BLACK,
            visible: true,
        }
    }
}

/// Reads a paint: `none`, `currentColor`, `url(#id)` with an optional fallback, or a colour.
fn parse_paint(s: &str, loc: &ElementAt, attr: &str) -> Result<PaintSpec, SvgError> {
    let t = s.trim();
    if t == "none" {
        return Ok(PaintSpec::None);
    }
    if t == "currentColor" {
        return Ok(PaintSpec::CurrentColor);
    }
    if let Some(rest) = t.strip_prefix("url(") {
        let close = rest
            .find(')')
            .ok_or_else(|| loc.err(format!("{attr}: expected ')' in {t:?}")))?;
        let id = rest[..close].trim().trim_matches(|c| c == '\'' || c == '"');
        let id = id.strip_prefix('#').unwrap_or(id).to_string();
        let fallback = rest[close + 1..].trim();
        let fb = if fallback.is_empty() {
            None
        } else {
            Some(Box::new(parse_paint(fallback, loc, attr)?))
        };
        return Ok(PaintSpec::Url(id, fb));
    }
    parse_color(t)
        .map(|(c, a)| PaintSpec::Color(c, a))
        .ok_or_else(|| {
            loc.err(format!(
                "{attr}: expected a colour, 'none' or url(#id), found {t:?}"
            ))
        })
}

/// Reads an opacity (a number or a percentage), clamped to [0, 1].
pub(super) fn opacity_value(s: &str, loc: &ElementAt, attr: &str) -> Result<f32, SvgError> {
    let (v, unit) = number_with_unit(s, P, loc, attr)?;
    let v = match unit {
        "" => v,
        "%" => v / 100.0,
        _ => return Err(loc.err(format!("{attr}: expected a number in [0, 1], found {s:?}"))),
    };
    Ok(v.clamp(0.0, 1.0) as f32)
}

/// The element's own declarations: presentation attributes, overridden by `style`.
pub(super) fn declarations<'a>(node: &Node<'a, 'a>) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = node
        .attributes()
        .filter(|a| a.namespace().is_none())
        .map(|a| (a.name().to_string(), a.value().to_string()))
        .collect();
    if let Some(style) = node.attr("style") {
        for decl in style.split(';') {
            if let Some((k, v)) = decl.split_once(':') {
                let v = v.trim().trim_end_matches("!important").trim();
                out.push((k.trim().to_string(), v.to_string()));
            }
        }
    }
    out
}

/// Properties this reader resolves; anything else in `style` is ignored. An invalid value
/// is treated as absent, as the SVG specification and browsers do: the property keeps the
/// value it had, and the error is returned with the property's name, for one warning.
pub(super) fn apply_declarations(
    style: &mut Style,
    decls: &[(String, String)],
    loc: &ElementAt,
    vp: Viewport,
) -> (f32, bool, Vec<(String, SvgError)>) {
    let mut opacity = 1.0;
    let mut display = true;
    let mut invalid = Vec::new();
    for (k, v) in decls {
        let v = v.as_str();
        if v.trim() == "inherit" {
            continue;
        }
        let mut apply = || -> Result<(), SvgError> {
            match k.as_str() {
                "fill" => style.fill = parse_paint(v, loc, k)?,
                "stroke" => style.stroke_paint = parse_paint(v, loc, k)?,
                "color" => {
                    if let Some((c, _)) = parse_color(v) {
                        style.color = c;
                    }
                }
                "fill-opacity" => style.fill_opacity = opacity_value(v, loc, k)?,
                "stroke-opacity" => style.stroke_opacity = opacity_value(v, loc, k)?,
                "opacity" => opacity = opacity_value(v, loc, k)?,
                "fill-rule" => {
                    style.fill_rule = match v.trim() {
                        "evenodd" => FillRule::EvenOdd,
                        "nonzero" => FillRule::NonZero,
                        other => {
                            return Err(loc.err(format!(
                                "fill-rule: expected nonzero or evenodd, found {other:?}"
                            )))
                        }
                    }
                }
                "stroke-width" => {
                    let w = length(v, loc, k, vp, Axis::Diag)?;
                    if w < 0.0 {
                        return Err(loc.err(format!(
                            "stroke-width: expected a non-negative length, found {v:?}"
                        )));
                    }
                    style.stroke.width = w;
                }
                "stroke-linejoin" => {
                    style.stroke.join = match v.trim() {
                        "miter" | "miter-clip" | "arcs" => LineJoin::Miter,
                        "round" => LineJoin::Round,
                        "bevel" => LineJoin::Bevel,
                        other => {
                            return Err(loc.err(format!(
                                "stroke-linejoin: expected miter, round or bevel, found {other:?}"
                            )))
                        }
                    }
                }
                "stroke-linecap" => {
                    style.stroke.cap = match v.trim() {
                        "butt" => LineCap::Butt,
                        "round" => LineCap::Round,
                        "square" => LineCap::Square,
                        other => {
                            return Err(loc.err(format!(
                                "stroke-linecap: expected butt, round or square, found {other:?}"
                            )))
                        }
                    }
                }
                "stroke-miterlimit" => {
                    let m = number_with_unit(v, P, loc, k)?.0;
                    if m < 1.0 {
                        return Err(loc.err(format!(
                            "stroke-miterlimit: expected a number >= 1, found {v:?}"
                        )));
                    }
                    style.stroke.miter_limit = m;
                }
                "stroke-dasharray" => {
                    if v.trim() == "none" {
                        style.stroke.dashes.clear();
                    } else {
                        let mut d = Vec::new();
                        for part in v
                            .split(|c: char| c == ',' || c.is_whitespace())
                            .filter(|p| !p.is_empty())
                        {
                            d.push(length(part, loc, k, vp, Axis::Diag)?);
                        }
                        if d.iter().any(|x| *x < 0.0) {
                            return Err(loc.err("stroke-dasharray: expected non-negative lengths"));
                        }
                        if d.len() % 2 == 1 {
                            let copy = d.clone();
                            d.extend(copy);
                        }
                        style.stroke.dashes = d;
                    }
                }
                "stroke-dashoffset" => {
                    style.stroke.dash_offset = length(v, loc, k, vp, Axis::Diag)?
                }
                "visibility" => style.visible = v.trim() == "visible",
                "display" => display = v.trim() != "none",
                _ => {}
            }
            Ok(())
        };
        if let Err(e) = apply() {
            invalid.push((k.clone(), e));
        }
    }
    (opacity, display, invalid)
}
