//! Mitsuba's `<transform>`: `translate`, `rotate`, `scale`, `matrix` and `lookat`, each
//! applied after the ones before it (the matrix of a later operation multiplies on the
//! left), as Mitsuba composes them.

use prism_math::glam::{DMat4, DVec3, DVec4};
use roxmltree::Node as XmlNode;

use super::values::{number, numbers};
use crate::error::SceneError;

/// The matrix of the operations in `<transform>` element `node`; `subst` substitutes
/// `$params` in an attribute, `err` makes a located error at an element.
pub fn read_transform(
    node: XmlNode,
    subst: &dyn Fn(&str) -> Result<String, SceneError>,
    err: &dyn Fn(XmlNode, String) -> SceneError,
) -> Result<DMat4, SceneError> {
    let mut m = DMat4::IDENTITY;
    for op in node.children().filter(XmlNode::is_element) {
        let attr = |name: &str| op.attribute(name).map(subst).transpose();
        let nums = |text: &str| numbers(text).map_err(|e| err(op, e));
        let vec3 = |name: &str| -> Result<Option<DVec3>, SceneError> {
            match attr(name)? {
                None => Ok(None),
                Some(t) => match nums(&t)?[..] {
                    [x, y, z] => Ok(Some(DVec3::new(x, y, z))),
                    _ => Err(err(
                        op,
                        format!("{name}: expected three numbers, found {t:?}"),
                    )),
                },
            }
        };
        // x, y and z attributes, each `default` when absent.
        let axes = |default: f64| -> Result<DVec3, SceneError> {
            let mut c = [default; 3];
            for (i, a) in ["x", "y", "z"].into_iter().enumerate() {
                if let Some(t) = attr(a)? {
                    c[i] = number(&t).map_err(|e| err(op, e))?;
                }
            }
            Ok(DVec3::from_array(c))
        };
        let step = match op.tag_name().name() {
            "translate" => DMat4::from_translation(match vec3("value")? {
                Some(v) => v,
                None => axes(0.0)?,
            }),
            "scale" => {
                let s = match attr("value")? {
                    Some(t) => match nums(&t)?[..] {
                        [s] => DVec3::splat(s),
                        [x, y, z] => DVec3::new(x, y, z),
                        _ => {
                            return Err(err(op, format!("value: expected 1 or 3 numbers, found {t:?}")))
                        }
                    },
                    None => axes(1.0)?,
                };
                DMat4::from_scale(s)
            }
            "rotate" => {
                let axis = match vec3("axis")?.or(vec3("value")?) {
                    Some(a) => a,
                    None => axes(0.0)?,
                };
                let angle = match attr("angle")? {
                    Some(t) => number(&t).map_err(|e| err(op, e))?,
                    None => return Err(err(op, "expected an angle attribute (degrees)".into())),
                };
                if axis.length_squared() == 0.0 {
                    return Err(err(op, "the rotation axis is zero".into()));
                }
                rotation(axis, angle)
            }
            "matrix" => {
                let t = attr("value")?
                    .ok_or_else(|| err(op, "expected a value attribute".into()))?;
                let v = nums(&t)?;
                match v.len() {
                    16 => DMat4::from_cols_array(&v.try_into().expect("16 numbers")).transpose(),
                    9 => {
                        let r = |i: usize| DVec4::new(v[3 * i], v[3 * i + 1], v[3 * i + 2], 0.0);
                        DMat4::from_cols(r(0), r(1), r(2), DVec4::W).transpose()
                    }
                    n => {
                        return Err(err(op, format!("value: expected 16 or 9 numbers (row by row), found {n}")))
                    }
                }
            }
            "lookat" => {
                let origin = vec3("origin")?
                    .ok_or_else(|| err(op, "expected an origin attribute".into()))?;
                let target = vec3("target")?
                    .ok_or_else(|| err(op, "expected a target attribute".into()))?;
                let up = vec3("up")?;
                look_at(origin, target, up).map_err(|m| err(op, m))?
            }
            other => {
                return Err(err(
                    op,
                    format!("unknown transform <{other}> (expected translate, rotate, scale, matrix or lookat)"),
                ))
            }
        };
        if !step.is_finite() {
            return Err(err(op, "the operation's matrix is not finite".into()));
        }
        m = step * m;
    }
    Ok(m)
}

/// The rotation by `degrees` about `axis` (right-handed: counter-clockwise looking down the
/// axis towards the origin).
#[must_use]
pub fn rotation(axis: DVec3, degrees: f64) -> DMat4 {
    DMat4::from_axis_angle(axis.normalize(), degrees.to_radians())
}

/// Mitsuba's `look_at`: the camera at `origin` looking at `target`, its local +z towards
/// the target, +y up and +x to the left (`cross(up, dir)`). Without an `up`, one
/// perpendicular to the view, as Mitsuba picks it.
///
/// # Errors
/// A message if the origin is the target or `up` is parallel to the view.
pub fn look_at(origin: DVec3, target: DVec3, up: Option<DVec3>) -> Result<DMat4, String> {
    let dir = target - origin;
    if dir.length_squared() == 0.0 {
        return Err("the origin is the target".into());
    }
    let dir = dir.normalize();
    let up = match up {
        Some(u) => u,
        None => coordinate_system(dir).0,
    };
    let left = up.cross(dir);
    if left.length_squared() == 0.0 {
        return Err("up is parallel to the view direction".into());
    }
    let left = left.normalize();
    let new_up = dir.cross(left);
    Ok(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

/// Two unit vectors perpendicular to unit `n` and to each other (Duff et al. 2017), as
/// Mitsuba's `coordinate_system` builds them.
#[must_use]
pub fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}
