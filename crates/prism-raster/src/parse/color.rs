//! CSS colour syntax as SVG uses it: `#rgb`, `#rrggbb`, `#rgba`, `#rrggbbaa`, `rgb()`,
//! `rgba()`, the 148 named colours, and `transparent`.

use prism_math::Rgb;

include!("named_colors.in");

/// A parsed colour with its alpha in [0, 1].
pub(crate) fn parse_color(s: &str) -> Option<(Rgb, f32)> {
    let t = s.trim();
    if let Some(hex) = t.strip_prefix('#') {
        if !hex.chars().all(|c| c.is_ascii_hexdigit()) {
            return None;
        }
        let v = u32::from_str_radix(hex, 16).ok()?;
        let nib = |i: u32| ((v >> (4 * i)) & 0xf) * 17;
        let byte = |i: u32| (v >> (8 * i)) & 0xff;
        let (r, g, b, a) = match hex.len() {
            3 => (nib(2), nib(1), nib(0), 255),
            4 => (nib(3), nib(2), nib(1), nib(0)),
            6 => (byte(2), byte(1), byte(0), 255),
            8 => (byte(3), byte(2), byte(1), byte(0)),
            _ => return None,
        };
        return Some((Rgb::from_u8([r as u8, g as u8, b as u8]), a as f32 / 255.0));
    }
    let lower = t.to_ascii_lowercase();
    if let Some(args) = lower
        .strip_prefix("rgba(")
        .or_else(|| lower.strip_prefix("rgb("))
        .and_then(|r| r.strip_suffix(')'))
    {
        let parts: Vec<&str> = args
            .split(|c: char| c == ',' || c == '/' || c.is_whitespace())
            .filter(|p| !p.is_empty())
            .collect();
        if parts.len() != 3 && parts.len() != 4 {
            return None;
        }
        let chan = |p: &str| -> Option<f32> {
            let v = if let Some(pc) = p.strip_suffix('%') {
                pc.parse::<f32>().ok()? / 100.0
            } else {
                p.parse::<f32>().ok()? / 255.0
            };
            v.is_finite().then(|| v.clamp(0.0, 1.0))
        };
        let q = |v: f32| (v * 255.0).round() / 255.0;
        let (r, g, b) = (q(chan(parts[0])?), q(chan(parts[1])?), q(chan(parts[2])?));
        let a = match parts.get(3) {
            None => 1.0,
            Some(p) => {
                let v = if let Some(pc) = p.strip_suffix('%') {
                    pc.parse::<f32>().ok()? / 100.0
                } else {
                    p.parse::<f32>().ok()?
                };
                if !v.is_finite() {
                    return None;
                }
                v.clamp(0.0, 1.0)
            }
        };
        return Some((Rgb::new(r, g, b), a));
    }
    if lower == "transparent" {
        return Some((Rgb::BLACK, 0.0));
    }
    let i = NAMED
        .binary_search_by(|(n, _)| n.cmp(&lower.as_str()))
        .ok()?;
    let v = NAMED[i].1;
    Some((
        Rgb::from_u8([(v >> 16) as u8, (v >> 8) as u8, v as u8]),
        1.0,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_css_forms() {
        let red = Rgb::new(1.0, 0.0, 0.0);
        for s in [
            "#f00",
            "#ff0000",
            "rgb(255,0,0)",
            "rgb(100%, 0%, 0%)",
            "red",
            "RED",
            " Red ",
        ] {
            assert_eq!(parse_color(s), Some((red, 1.0)), "{s}");
        }
        assert_eq!(parse_color("#ff000080").unwrap().1, 128.0 / 255.0);
        assert_eq!(
            parse_color("rgba(0,0,255,0.5)"),
            Some((Rgb::new(0.0, 0.0, 1.0), 0.5))
        );
        assert_eq!(
            parse_color("rebeccapurple"),
            Some((Rgb::from_u8([0x66, 0x33, 0x99]), 1.0))
        );
        assert_eq!(parse_color("transparent").unwrap().1, 0.0);
        for bad in [
            "#ff000",
            "#gg0000",
            "rgb(1,2)",
            "notacolor",
            "",
            "rgb(nan,0,0)",
        ] {
            assert_eq!(parse_color(bad), None, "{bad}");
        }
    }
}
