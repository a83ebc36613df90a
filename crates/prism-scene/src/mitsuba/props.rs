//! Reading a Mitsuba object's properties with Mitsuba's defaults and kinds, named indices of
//! refraction, and the located errors of the scene builder.

use prism_math::glam::{DMat4, DVec3};
use prism_math::{Loc, Rgb};

use super::document::{Object, Value};
use crate::error::SceneError;

/// `<tag type="...">: not supported by prism`.
pub(super) fn unsupported(o: &Object) -> SceneError {
    not_supported(o, format!("{}: not supported by prism", o.label()))
}

/// A located refusal at object `o`: something Mitsuba renders that prism does not
/// (`--lenient` reads past these).
pub(super) fn not_supported(o: &Object, message: String) -> SceneError {
    SceneError::Unsupported {
        at: o.at.clone(),
        element: o.tag.clone(),
        message,
    }
}

/// A located error at object `o`.
pub(super) fn error(o: &Object, message: String) -> SceneError {
    SceneError::Element {
        at: o.at.clone(),
        element: o.tag.clone(),
        message,
    }
}

/// Typed property reads, with Mitsuba's defaults.
impl Object {
    pub(super) fn value(&self, name: &str) -> Option<(&Value, &Loc)> {
        self.prop(name).map(|p| (&p.value, &p.at))
    }

    pub(super) fn kind_error(&self, name: &str, want: &str, got: &Value) -> SceneError {
        error(
            self,
            format!(
                "{}: {name}: expected {want}, found <{}>",
                self.label(),
                got.kind()
            ),
        )
    }

    pub(super) fn float(&self, name: &str, default: f64) -> Result<f64, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Float(v), _)) => Ok(*v),
            Some((Value::Integer(v), _)) => Ok(*v as f64),
            Some((v, _)) => Err(self.kind_error(name, "a <float>", v)),
        }
    }

    pub(super) fn integer(&self, name: &str, default: i64) -> Result<i64, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Integer(v), _)) => Ok(*v),
            Some((v, _)) => Err(self.kind_error(name, "an <integer>", v)),
        }
    }

    pub(super) fn boolean(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Boolean(v), _)) => Ok(*v),
            Some((v, _)) => Err(self.kind_error(name, "a <boolean>", v)),
        }
    }

    pub(super) fn string(&self, name: &str) -> Result<Option<&str>, SceneError> {
        match self.value(name) {
            None => Ok(None),
            Some((Value::String(v), _)) => Ok(Some(v)),
            Some((v, _)) => Err(self.kind_error(name, "a <string>", v)),
        }
    }

    pub(super) fn rgb(&self, name: &str, default: [f64; 3]) -> Result<Rgb, SceneError> {
        let c = match self.value(name) {
            None => default,
            Some((Value::Rgb(c), _)) => *c,
            Some((Value::Float(v), _)) => [*v; 3],
            Some((v, _)) => return Err(self.kind_error(name, "an <rgb> or <float>", v)),
        };
        if c.iter().any(|x| *x < 0.0) {
            return Err(error(
                self,
                format!("{}: {name}: expected values of at least 0", self.label()),
            ));
        }
        Ok(Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32))
    }

    pub(super) fn point(&self, name: &str) -> Result<Option<DVec3>, SceneError> {
        match self.value(name) {
            None => Ok(None),
            Some((Value::Point(p) | Value::Vector(p), _)) => Ok(Some(*p)),
            Some((v, _)) => Err(self.kind_error(name, "a <point>", v)),
        }
    }

    pub(super) fn transform(&self, name: &str) -> Result<DMat4, SceneError> {
        match self.value(name) {
            None => Ok(DMat4::IDENTITY),
            Some((Value::Transform(m), _)) => Ok(*m),
            Some((v, _)) => Err(self.kind_error(name, "a <transform>", v)),
        }
    }

    /// Fails on a property prism would ignore but that changes the picture in Mitsuba.
    pub(super) fn refuse(&self, names: &[&str]) -> Result<(), SceneError> {
        for n in names {
            if self.prop(n).is_some() {
                return Err(not_supported(
                    self,
                    format!("{}: {n}: not supported by prism", self.label()),
                ));
            }
        }
        Ok(())
    }
}

/// A named index of refraction (Mitsuba's table), or a number.
pub(super) fn ior(o: &Object, name: &str, default: &str) -> Result<f64, SceneError> {
    let named = |n: &str| -> Option<f64> {
        Some(match n {
            "vacuum" => 1.0,
            "helium" => 1.000_036,
            "hydrogen" => 1.000_132,
            "air" => 1.000_277,
            "carbon dioxide" => 1.000_45,
            "water" => 1.3330,
            "acetone" => 1.36,
            "ethanol" => 1.361,
            "carbon tetrachloride" => 1.461,
            "glycerol" => 1.4729,
            "benzene" => 1.501,
            "silicone oil" => 1.520_45,
            "bromine" => 1.661,
            "water ice" => 1.31,
            "fused quartz" => 1.458,
            "pyrex" => 1.470,
            "acrylic glass" => 1.49,
            "polypropylene" => 1.49,
            "bk7" => 1.5046,
            "sodium chloride" => 1.544,
            "amber" => 1.55,
            "pet" => 1.5750,
            "diamond" => 2.419,
            _ => return None,
        })
    };
    match o.value(name) {
        None => Ok(named(default).expect("a known default")),
        Some((Value::Float(v), _)) => Ok(*v),
        Some((Value::String(s), _)) => named(s).ok_or_else(|| {
            error(
                o,
                format!(
                    "{}: {name}: no index of refraction is named {s:?}",
                    o.label()
                ),
            )
        }),
        Some((v, _)) => Err(o.kind_error(name, "a <float> or a named material", v)),
    }
}
