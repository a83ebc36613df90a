//! Lengths and the viewport: units and percentages resolved against the viewport's width,
//! height or diagonal, and the `viewBox` / `preserveAspectRatio` mapping into it.

use roxmltree::Node;

use super::common::{number_list, number_with_unit, ElementAt, PlainAttribute, SvgError};
use super::number::Precision;
use crate::document::Mat3;

/// Standard SVG reads numbers as `f64`.
const P: Precision = Precision::F64;

/// Viewport size used to resolve percentages.
#[derive(Clone, Copy)]
pub(super) struct Viewport {
    /// Width, in user units.
    pub(super) w: f64,
    /// Height, in user units.
    pub(super) h: f64,
}

impl Viewport {
    /// The diagonal length percentages of neither axis refer to: sqrt((w^2 + h^2) / 2).
    fn diag(&self) -> f64 {
        ((self.w * self.w + self.h * self.h) / 2.0).sqrt()
    }
}

/// Which viewport length a percentage refers to.
#[derive(Clone, Copy)]
pub(super) enum Axis {
    /// The width.
    X,
    /// The height.
    Y,
    /// The normalized diagonal (radii, stroke widths).
    Diag,
}

/// Reads a length with an optional unit (`px`, `pt`, `pc`, `mm`, `cm`, `in`, `em`, `ex`,
/// `%` of the viewport along `axis`) into user units.
pub(super) fn length(
    s: &str,
    loc: &ElementAt,
    attr: &str,
    vp: Viewport,
    axis: Axis,
) -> Result<f64, SvgError> {
    let (v, unit) = number_with_unit(s, P, loc, attr)?;
    let k = match unit {
        "" | "px" => 1.0,
        "pt" => 4.0 / 3.0,
        "pc" => 16.0,
        "mm" => 96.0 / 25.4,
        "cm" => 96.0 / 2.54,
        "in" => 96.0,
        "em" => 16.0,
        "ex" => 8.0,
        "%" => {
            let base = match axis {
                Axis::X => vp.w,
                Axis::Y => vp.h,
                Axis::Diag => vp.diag(),
            };
            base / 100.0
        }
        other => return Err(loc.err(format!("{attr}: unknown unit {other:?} in {s:?}"))),
    };
    Ok(v * k)
}

/// The transform a `viewBox` and `preserveAspectRatio` give an element of size `w` x `h`;
/// `None` without a `viewBox`.
pub(super) fn view_box_transform(
    node: &Node,
    loc: &ElementAt,
    w: f64,
    h: f64,
) -> Result<Option<Mat3>, SvgError> {
    let Some(vb) = node.attr("viewBox") else {
        return Ok(None);
    };
    let v = number_list(vb, P, loc, "viewBox")?;
    if v.len() != 4 || v[2] <= 0.0 || v[3] <= 0.0 {
        return Err(loc.err(format!(
            "viewBox: expected min-x min-y width height with positive size, found {vb:?}"
        )));
    }
    let par = node.attr("preserveAspectRatio").unwrap_or("xMidYMid meet");
    let mut words = par.split_whitespace();
    let align = words.next().unwrap_or("xMidYMid");
    let slice = words.next() == Some("slice");
    let (sx, sy) = (w / v[2], h / v[3]);
    if align == "none" {
        return Ok(Some(
            Mat3::scale(sx, sy).mul(&Mat3::translate(-v[0], -v[1])),
        ));
    }
    if align.len() != 8 {
        return Err(loc.err(format!(
            "preserveAspectRatio: expected an alignment such as xMidYMid, found {align:?}"
        )));
    }
    let s = if slice { sx.max(sy) } else { sx.min(sy) };
    let frac = |a: &str| match a {
        "Min" => Ok(0.0),
        "Mid" => Ok(0.5),
        "Max" => Ok(1.0),
        _ => Err(loc.err(format!("preserveAspectRatio: bad alignment {align:?}"))),
    };
    let (fx, fy) = (frac(&align[1..4])?, frac(&align[5..8])?);
    let tx = (w - v[2] * s) * fx;
    let ty = (h - v[3] * s) * fy;
    Ok(Some(
        Mat3::translate(tx, ty)
            .mul(&Mat3::scale(s, s))
            .mul(&Mat3::translate(-v[0], -v[1])),
    ))
}
