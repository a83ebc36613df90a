//! [`ClothScene`], the course's scene JSON: a cloth, and optionally a sphere and a plane,
//! every key required (`pinned` aside), unknown keys refused, values checked; and `--set`
//! overrides applied to the text's values before they are checked.

use prism_math::Loc;
use std::path::Path;

use prism_math::glam::DVec3;

use crate::error::ClothError;
use crate::json::{parse_json, Json, JsonValue};

/// Most masses along one side of the grid.
pub const MAX_GRID_SIDE: usize = 4096;
/// Most masses in a cloth.
pub const MAX_MASSES: usize = 1 << 22;
/// Largest size, coordinate or radius in metres.
pub const MAX_SIZE: f64 = 1e6;
/// Largest density.
pub const MAX_DENSITY: f64 = 1e9;
/// Largest spring constant.
pub const MAX_KS: f64 = 1e12;
/// Largest scene file read (16 MiB).
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// How the cloth lies at the start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Orientation {
    /// All masses at y = 1, over x and z.
    Horizontal,
    /// Over x and y, z a small random offset.
    Vertical,
}

/// The cloth's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothParams {
    /// Width in metres.
    pub width: f64,
    /// Height in metres.
    pub height: f64,
    /// Masses along the width.
    pub num_width_points: usize,
    /// Masses along the height.
    pub num_height_points: usize,
    /// Collision thickness, as the course app's 32-bit float holds it.
    pub thickness: f64,
    /// Starting orientation.
    pub orientation: Orientation,
    /// Pinned masses as `[x, y]` grid indices.
    pub pinned: Vec<[usize; 2]>,
    /// Structural springs exert force.
    pub enable_structural: bool,
    /// Shearing springs exert force.
    pub enable_shearing: bool,
    /// Bending springs exert force.
    pub enable_bending: bool,
    /// Verlet damping, in percent.
    pub damping: f64,
    /// Density (kg/m² as the course uses it).
    pub density: f64,
    /// Spring constant in N/m (bending springs use 0.2 of it).
    pub ks: f64,
}

/// A sphere to collide with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereParams {
    /// Centre.
    pub origin: DVec3,
    /// Radius.
    pub radius: f64,
    /// Friction in [0, 1].
    pub friction: f64,
}

/// A plane to collide with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneParams {
    /// A point on it.
    pub point: DVec3,
    /// Its unit normal.
    pub normal: DVec3,
    /// Friction in [0, 1].
    pub friction: f64,
}

/// A scene: the cloth and what it collides with.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothScene {
    /// The cloth.
    pub cloth: ClothParams,
    /// A sphere, if any.
    pub sphere: Option<SphereParams>,
    /// A plane, if any.
    pub plane: Option<PlaneParams>,
}

/// Reads a scene file with `--set` overrides (`KEY=VALUE`, `KEY` one of an object's keys as
/// `cloth.ks`, or a cloth key alone as `ks`; `VALUE` JSON).
///
/// # Errors
/// A located [`ClothError`].
pub fn read_scene(path: &Path, overrides: &[String]) -> Result<ClothScene, ClothError> {
    let name = path.display().to_string();
    let io = |e: std::io::Error| ClothError::Io {
        path: name.clone(),
        message: e.to_string(),
    };
    let text = prism_math::limits::read_input_text(path, MAX_SCENE_BYTES).map_err(io)?;
    parse_scene(&text, &name, overrides)
}

/// Parses scene text; `file` names it in errors.
///
/// # Errors
/// A located [`ClothError`].
pub fn parse_scene(text: &str, file: &str, overrides: &[String]) -> Result<ClothScene, ClothError> {
    let mut root = parse_json(text, file)?;
    for (i, o) in overrides.iter().enumerate() {
        apply_override(&mut root, o, override_line(i))?;
    }
    // A value an override set is checked as the file's are; its errors name the override,
    // not a line of the file.
    let overridden = |e: ClothError| match e {
        ClothError::Parse { at, message } if at.line >= override_line(overrides.len()) => {
            ClothError::Override {
                setting: overrides[(u32::MAX - at.line) as usize].clone(),
                message,
            }
        }
        e => e,
    };
    parse_checked(&root, file).map_err(overridden)
}

/// The line number standing for override `i`: counted down from the largest, where no file
/// reaches.
fn override_line(i: usize) -> u32 {
    u32::MAX - u32::try_from(i).unwrap_or(u32::MAX)
}

/// Gives `json` and every value inside it the line `line` (without recursion).
fn relabel(json: &mut Json, line: u32) {
    let mut stack = vec![json];
    while let Some(j) = stack.pop() {
        j.line = line;
        match &mut j.value {
            JsonValue::Array(items) => stack.extend(items.iter_mut()),
            JsonValue::Object(fields) => {
                for (_, l, v) in fields.iter_mut() {
                    *l = line;
                    stack.push(v);
                }
            }
            _ => {}
        }
    }
}

/// Checks a scene's values, every required key present.
fn parse_checked(root: &Json, file: &str) -> Result<ClothScene, ClothError> {
    let cx = Cx { file };
    let top = cx.object(root, "the top level", &["cloth", "sphere", "plane"])?;
    let get = |k: &str| top.iter().find(|(n, _, _)| n == k).map(|(_, _, v)| v);
    let cloth = get("cloth").ok_or_else(|| {
        cx.err(
            root.line,
            "the top level: missing required key \"cloth\"".into(),
        )
    })?;
    let cloth = cx.cloth(cloth)?;
    let sphere = get("sphere").map(|s| cx.sphere(s)).transpose()?;
    let plane = get("plane").map(|p| cx.plane(p)).transpose()?;
    Ok(ClothScene {
        cloth,
        sphere,
        plane,
    })
}

/// Replaces (or adds) the value a `KEY=VALUE` override names, giving it (and what it holds)
/// the line `line`.
fn apply_override(root: &mut Json, setting: &str, line: u32) -> Result<(), ClothError> {
    let bad = |message: &str| ClothError::Override {
        setting: setting.to_string(),
        message: message.to_string(),
    };
    let (key, value) = setting
        .split_once('=')
        .ok_or_else(|| bad("expected KEY=VALUE"))?;
    let (object, key) = match key.trim().split_once('.') {
        Some((o, k)) => (o.to_string(), k.to_string()),
        None => ("cloth".to_string(), key.trim().to_string()),
    };
    let mut value =
        parse_json(value, "the value").map_err(|e| bad(&format!("expected a JSON value: {e}")))?;
    relabel(&mut value, line);
    let JsonValue::Object(top) = &mut root.value else {
        return Err(bad("the scene is not a JSON object"));
    };
    let Some((_, _, obj)) = top.iter_mut().find(|(n, _, _)| *n == object) else {
        return Err(bad(&format!("the scene has no \"{object}\"")));
    };
    let JsonValue::Object(fields) = &mut obj.value else {
        return Err(bad(&format!("\"{object}\" is not an object")));
    };
    match fields.iter_mut().find(|(n, _, _)| *n == key) {
        Some((_, l, v)) => {
            *l = line;
            *v = value;
        }
        None => fields.push((key, line, value)),
    }
    Ok(())
}

struct Cx<'a> {
    file: &'a str,
}

type Fields = [(String, u32, Json)];

impl Cx<'_> {
    fn err(&self, line: u32, message: String) -> ClothError {
        ClothError::Parse {
            at: Loc::line(self.file, line),
            message,
        }
    }

    fn object<'j>(
        &self,
        v: &'j Json,
        place: &str,
        known: &[&str],
    ) -> Result<&'j Fields, ClothError> {
        let JsonValue::Object(fields) = &v.value else {
            return Err(self.err(
                v.line,
                format!("{place}: expected an object, found {}", v.value.kind()),
            ));
        };
        for (k, line, _) in fields {
            if !known.contains(&k.as_str()) {
                return Err(self.err(
                    *line,
                    format!(
                        "{place}: unknown key {k:?} (expected one of: {})",
                        known.join(", ")
                    ),
                ));
            }
        }
        for (i, (k, line, _)) in fields.iter().enumerate() {
            if fields[..i].iter().any(|(o, _, _)| o == k) {
                return Err(self.err(*line, format!("{place}: key {k:?} appears twice")));
            }
        }
        Ok(fields)
    }

    fn field<'j>(
        &self,
        f: &'j Fields,
        at: u32,
        place: &str,
        key: &str,
    ) -> Result<&'j Json, ClothError> {
        f.iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, _, v)| v)
            .ok_or_else(|| self.err(at, format!("{place}: missing required key {key:?}")))
    }

    fn number(&self, v: &Json, key: &str) -> Result<f64, ClothError> {
        match v.value {
            JsonValue::Number(x, _) => Ok(x),
            ref o => Err(self.err(
                v.line,
                format!("{key}: expected a number, found {}", o.kind()),
            )),
        }
    }

    fn ranged(&self, v: &Json, key: &str, lo: f64, hi: f64, what: &str) -> Result<f64, ClothError> {
        let x = self.number(v, key)?;
        if !(x >= lo && x <= hi) {
            return Err(self.err(v.line, format!("{key}: expected {what}, found {x}")));
        }
        Ok(x)
    }

    fn positive(&self, v: &Json, key: &str) -> Result<f64, ClothError> {
        let x = self.number(v, key)?;
        if x <= 0.0 {
            return Err(self.err(
                v.line,
                format!("{key}: expected a number above 0, found {x}"),
            ));
        }
        Ok(x)
    }

    fn integer(&self, v: &Json, key: &str) -> Result<i64, ClothError> {
        match v.value {
            JsonValue::Number(x, _) if x.fract() == 0.0 && x.abs() < 9e15 => Ok(x as i64),
            ref o => Err(self.err(
                v.line,
                format!(
                    "{key}: expected an integer, found {}",
                    match o {
                        JsonValue::Number(x, _) => x.to_string(),
                        o => o.kind().to_string(),
                    }
                ),
            )),
        }
    }

    fn boolean(&self, v: &Json, key: &str) -> Result<bool, ClothError> {
        match v.value {
            JsonValue::Bool(b) => Ok(b),
            ref o => Err(self.err(
                v.line,
                format!("{key}: expected true or false, found {}", o.kind()),
            )),
        }
    }

    fn vec3(&self, v: &Json, key: &str) -> Result<DVec3, ClothError> {
        match &v.value {
            JsonValue::Array(a) if a.len() == 3 => {
                let p = DVec3::new(
                    self.number(&a[0], key)?,
                    self.number(&a[1], key)?,
                    self.number(&a[2], key)?,
                );
                if p.abs().max_element() > MAX_SIZE {
                    return Err(self.err(
                        v.line,
                        format!(
                            "{key}: expected coordinates of at most {MAX_SIZE} in size, found {p}"
                        ),
                    ));
                }
                Ok(p)
            }
            o => Err(self.err(
                v.line,
                format!(
                    "{key}: expected [x, y, z], found {}",
                    match o {
                        JsonValue::Array(a) => format!("{} elements", a.len()),
                        o => o.kind().to_string(),
                    }
                ),
            )),
        }
    }

    fn cloth(&self, v: &Json) -> Result<ClothParams, ClothError> {
        let keys = [
            "width",
            "height",
            "num_width_points",
            "num_height_points",
            "thickness",
            "orientation",
            "pinned",
            "enable_structural",
            "enable_shearing",
            "enable_bending",
            "damping",
            "density",
            "ks",
        ];
        let f = self.object(v, "cloth", &keys)?;
        let req = |k: &str| self.field(f, v.line, "cloth", k);
        let size = |k: &str| -> Result<f64, ClothError> {
            let j = req(k)?;
            let x = self.positive(j, k)?;
            if x > MAX_SIZE {
                return Err(self.err(
                    j.line,
                    format!("{k}: expected at most {MAX_SIZE} m, found {x}"),
                ));
            }
            Ok(x)
        };
        let width = size("width")?;
        let height = size("height")?;
        let side = |k: &str| -> Result<usize, ClothError> {
            let j = req(k)?;
            let n = self.integer(j, k)?;
            if !(2..=MAX_GRID_SIDE as i64).contains(&n) {
                return Err(self.err(
                    j.line,
                    format!("{k}: expected 2 to {MAX_GRID_SIDE} masses, found {n}"),
                ));
            }
            Ok(n as usize)
        };
        let nw = side("num_width_points")?;
        let nh = side("num_height_points")?;
        if nw * nh > MAX_MASSES {
            return Err(self.err(
                v.line,
                format!("cloth: {nw} x {nh} masses is over the limit of {MAX_MASSES}"),
            ));
        }
        let thickness = self.ranged(
            req("thickness")?,
            "thickness",
            0.0,
            width.max(height),
            "a thickness from 0 to the cloth's larger side",
        )?;
        let o = req("orientation")?;
        let orientation = match self.integer(o, "orientation")? {
            0 => Orientation::Horizontal,
            1 => Orientation::Vertical,
            n => {
                return Err(self.err(
                    o.line,
                    format!("orientation: expected 0 (horizontal) or 1 (vertical), found {n}"),
                ))
            }
        };
        let mut pinned = Vec::new();
        if let Some((_, _, p)) = f.iter().find(|(k, _, _)| k == "pinned") {
            let JsonValue::Array(items) = &p.value else {
                return Err(self.err(
                    p.line,
                    format!(
                        "pinned: expected an array of [x, y], found {}",
                        p.value.kind()
                    ),
                ));
            };
            for item in items {
                let pair = match &item.value {
                    JsonValue::Array(a) if a.len() == 2 => [
                        self.integer(&a[0], "pinned")?,
                        self.integer(&a[1], "pinned")?,
                    ],
                    o => {
                        return Err(self.err(
                            item.line,
                            format!("pinned: expected [x, y], found {}", o.kind()),
                        ))
                    }
                };
                if !(0..nw as i64).contains(&pair[0]) || !(0..nh as i64).contains(&pair[1]) {
                    return Err(self.err(
                        item.line,
                        format!(
                            "pinned: [{}, {}] is outside the {nw} x {nh} grid",
                            pair[0], pair[1]
                        ),
                    ));
                }
                pinned.push([pair[0] as usize, pair[1] as usize]);
            }
        }
        Ok(ClothParams {
            width,
            height,
            num_width_points: nw,
            num_height_points: nh,
            // The course app holds it in a 32-bit float.
            thickness: f64::from(thickness as f32),
            orientation,
            pinned,
            enable_structural: self.boolean(req("enable_structural")?, "enable_structural")?,
            enable_shearing: self.boolean(req("enable_shearing")?, "enable_shearing")?,
            enable_bending: self.boolean(req("enable_bending")?, "enable_bending")?,
            damping: self.ranged(
                req("damping")?,
                "damping",
                0.0,
                100.0,
                "a percentage from 0 to 100",
            )?,
            density: self.ranged(
                req("density")?,
                "density",
                f64::MIN_POSITIVE,
                MAX_DENSITY,
                "a density above 0 and at most 1e9",
            )?,
            ks: self.ranged(
                req("ks")?,
                "ks",
                0.0,
                MAX_KS,
                "a spring constant from 0 to 1e12",
            )?,
        })
    }

    fn sphere(&self, v: &Json) -> Result<SphereParams, ClothError> {
        let f = self.object(v, "sphere", &["origin", "radius", "friction"])?;
        let req = |k: &str| self.field(f, v.line, "sphere", k);
        Ok(SphereParams {
            origin: self.vec3(req("origin")?, "origin")?,
            radius: self.ranged(
                req("radius")?,
                "radius",
                f64::MIN_POSITIVE,
                MAX_SIZE,
                "a radius above 0 and at most 1e6",
            )?,
            friction: self.friction(req("friction")?)?,
        })
    }

    fn friction(&self, v: &Json) -> Result<f64, ClothError> {
        self.ranged(v, "friction", 0.0, 1.0, "a friction from 0 to 1")
    }

    fn plane(&self, v: &Json) -> Result<PlaneParams, ClothError> {
        let f = self.object(v, "plane", &["point", "normal", "friction"])?;
        let req = |k: &str| self.field(f, v.line, "plane", k);
        let n = req("normal")?;
        let normal = self.vec3(n, "normal")?;
        let len = normal.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(self.err(n.line, "normal: expected a non-zero vector".into()));
        }
        Ok(PlaneParams {
            point: self.vec3(req("point")?, "point")?,
            normal: normal / len,
            friction: self.friction(req("friction")?)?,
        })
    }
}

#[cfg(test)]
mod tests;
