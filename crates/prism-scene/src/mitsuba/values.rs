//! The numbers of Mitsuba attribute values: lists written with commas and/or spaces, one
//! finite number, three, or a colour of one or three.

use prism_math::glam::DVec3;

/// The numbers of a list written with commas and/or spaces.
pub fn numbers(text: &str) -> Result<Vec<f64>, String> {
    text.split(|c: char| c == ',' || c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .map(number)
        .collect()
}

/// One finite number.
pub fn number(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("value: expected a finite number, found {text:?}")),
    }
}

/// Three numbers.
pub fn triple(text: &str) -> Result<DVec3, String> {
    match numbers(text)?[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(format!("value: expected three numbers, found {text:?}")),
    }
}

/// An RGB colour: three numbers, or one for all three channels.
pub fn colour(text: &str) -> Result<[f64; 3], String> {
    match numbers(text)?[..] {
        [v] => Ok([v; 3]),
        [r, g, b] => Ok([r, g, b]),
        _ => Err(format!(
            "value: expected one or three numbers, found {text:?}"
        )),
    }
}
