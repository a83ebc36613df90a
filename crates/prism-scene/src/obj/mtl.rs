//! Wavefront MTL material libraries as the Delft ray tracer reads them: `newmtl`, `Kd`,
//! `Ks`, `Ns`, `d` and `map_Kd`; every other statement is read past.

use prism_math::Loc;
use prism_math::Rgb;

use prism_mesh::obj::statements;

use crate::error::SceneError;

/// Largest colour value or exponent a material may give.
pub(crate) const MAX_MTL_VALUE: f32 = 1e6;

/// One `newmtl` block, before its texture is loaded.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MtlMaterial {
    /// The material's name.
    pub name: String,
    /// The library it is in, for messages.
    pub file: String,
    /// `Kd` (0 when absent).
    pub kd: Rgb,
    /// `Ks` (0 when absent).
    pub ks: Rgb,
    /// `Ns` (1 when absent).
    pub shininess: f32,
    /// `d` (1, opaque, when absent).
    pub dissolve: f32,
    /// `map_Kd`, relative to the OBJ, with the line it is on.
    pub kd_map: Option<(String, u32)>,
}

/// Parses MTL text; `file` names it in errors.
pub(crate) fn parse_mtl(text: &str, file: &str) -> Result<Vec<MtlMaterial>, SceneError> {
    let mut out: Vec<MtlMaterial> = Vec::new();
    for st in statements(text) {
        let (line, key, content) = (st.line, st.key, st.content);
        let err = |message: String| SceneError::Line {
            at: Loc::line(file, st.line),
            message,
        };
        let mut words = content.split_whitespace().skip(1);
        if key == "newmtl" {
            let name = content[key.len()..].trim();
            if name.is_empty() {
                return Err(err("newmtl: expected a material name".into()));
            }
            out.push(MtlMaterial {
                name: name.to_string(),
                file: file.to_string(),
                kd: Rgb::BLACK,
                ks: Rgb::BLACK,
                shininess: 1.0,
                dissolve: 1.0,
                kd_map: None,
            });
            continue;
        }
        let known = matches!(key, "Kd" | "Ks" | "Ns" | "d" | "map_Kd");
        let Some(m) = out.last_mut() else {
            if known {
                return Err(err(format!("{key}: expected `newmtl` before it")));
            }
            continue;
        };
        let number = |w: Option<&str>, what: &str| -> Result<f32, SceneError> {
            let w =
                w.ok_or_else(|| err(format!("{key}: expected {what}, found the line's end")))?;
            w.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| err(format!("{key}: expected a finite number, found {w:?}")))
        };
        match key {
            "Kd" | "Ks" => {
                let r = number(words.next(), "3 numbers")?;
                // One number stands for all three channels, as tinyobjloader reads it.
                let c = match words.next() {
                    None => Rgb::splat(r),
                    Some(g) => {
                        let g = number(Some(g), "3 numbers")?;
                        let b = number(words.next(), "3 numbers")?;
                        Rgb::new(r, g, b)
                    }
                };
                if !(c.r.min(c.g).min(c.b) >= 0.0 && c.r.max(c.g).max(c.b) <= MAX_MTL_VALUE) {
                    return Err(err(format!(
                        "{key}: expected values from 0 to {MAX_MTL_VALUE}, found {} {} {}",
                        c.r, c.g, c.b
                    )));
                }
                if key == "Kd" {
                    m.kd = c;
                } else {
                    m.ks = c;
                }
            }
            "Ns" => {
                let v = number(words.next(), "a number")?;
                if !(0.0..=MAX_MTL_VALUE).contains(&v) {
                    return Err(err(format!(
                        "Ns: expected an exponent from 0 to {MAX_MTL_VALUE}, found {v}"
                    )));
                }
                m.shininess = v;
            }
            "d" => {
                // `d -halo 0.5`: the factor is the last word.
                let w = content.split_whitespace().last().filter(|w| *w != "d");
                let v = number(w, "a number")?;
                if !(0.0..=1.0).contains(&v) {
                    return Err(err(format!("d: expected a value in [0, 1], found {v}")));
                }
                m.dissolve = v;
            }
            "map_Kd" => {
                // Options (`-s 1 1 1`, ...) come first; the file name is the last word.
                let name = content.split_whitespace().last().filter(|w| *w != "map_Kd");
                let name = name.ok_or_else(|| err("map_Kd: expected a file name".into()))?;
                m.kd_map = Some((name.to_string(), line));
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: the values written are the values read; absent keys take the
    /// documented defaults (0, `Ns` 1, `d` 1).
    #[test]
    fn keys_and_defaults() {
        let m = parse_mtl(
            "newmtl a\nKd 0.5 0.25 1\nKs 0.2\nNs 10\nd 0.45\nmap_Kd -s 1 1 1 tex.png\nnewmtl b\nillum 2\n",
            "t.mtl",
        )
        .unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[0].kd, Rgb::new(0.5, 0.25, 1.0));
        assert_eq!(m[0].ks, Rgb::splat(0.2));
        assert_eq!(m[0].shininess, 10.0);
        assert_eq!(m[0].dissolve, 0.45);
        assert_eq!(m[0].kd_map, Some(("tex.png".to_string(), 6)));
        assert_eq!(
            (m[1].kd, m[1].ks, m[1].shininess, m[1].dissolve),
            (Rgb::BLACK, Rgb::BLACK, 1.0, 1.0)
        );
    }

    /// Malformed values are located errors.
    #[test]
    fn bad_values_are_located() {
        let e = parse_mtl("newmtl a\nKd 1 nan 1\n", "t.mtl").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.mtl:2: Kd: expected a finite number, found \"nan\""
        );
        let e = parse_mtl("Kd 1 1 1\n", "t.mtl").unwrap_err();
        assert_eq!(e.to_string(), "t.mtl:1: Kd: expected `newmtl` before it");
        let e = parse_mtl("newmtl a\nKd 0.8 0.5 -0.5\n", "t.mtl").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.mtl:2: Kd: expected values from 0 to 1000000, found 0.8 0.5 -0.5"
        );
        let e = parse_mtl("newmtl a\nNs -1\n", "t.mtl").unwrap_err();
        assert!(e.to_string().contains("Ns: expected an exponent"), "{e}");
        let e = parse_mtl("newmtl a\nd 2\n", "t.mtl").unwrap_err();
        assert!(e.to_string().contains("[0, 1]"), "{e}");
    }
}
