//! The SVG path-data mini-language (`d` attribute), all commands, arcs included.

use prism_math::DVec2;

use super::number::{number_prefix_len, to_num, Precision};
use crate::path::Path;

/// What is wrong with path data, at a byte offset into the `d` attribute.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PathDataError {
    /// A coordinate or radius is missing or malformed.
    #[error("expected a number at offset {offset}")]
    ExpectedNumber {
        /// Byte offset of the token.
        offset: usize,
    },
    /// A number overflows to infinity.
    #[error("number {text:?} at offset {offset} is not finite")]
    NotFinite {
        /// The number as written.
        text: String,
        /// Byte offset of the number.
        offset: usize,
    },
    /// An arc's large-arc or sweep flag is not `0` or `1`.
    #[error("expected an arc flag 0 or 1 at offset {offset}")]
    ExpectedFlag {
        /// Byte offset of the token.
        offset: usize,
    },
    /// Numbers before any command letter.
    #[error("expected a command letter at offset {offset}")]
    ExpectedCommand {
        /// Byte offset of the token.
        offset: usize,
    },
    /// A character that is neither a command nor a number.
    #[error("unexpected {found:?} at offset {offset}")]
    Unexpected {
        /// The character found.
        found: char,
        /// Its byte offset.
        offset: usize,
    },
    /// Numbers after a `Z`, which takes none.
    #[error("expected a command after Z at offset {offset}")]
    ExpectedCommandAfterClose {
        /// Byte offset of the number.
        offset: usize,
    },
    /// A letter that is not a path command.
    #[error("unknown path command {found:?} at offset {offset}")]
    UnknownCommand {
        /// The letter found.
        found: char,
        /// Its byte offset.
        offset: usize,
    },
    /// The first command is not a moveto.
    #[error("path data must begin with a moveto")]
    NoInitialMoveTo,
}

struct Cursor<'a> {
    s: &'a str,
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn skip_ws(&mut self) {
        let b = self.s.as_bytes();
        while self.pos < b.len() && (b[self.pos] as char).is_ascii_whitespace() {
            self.pos += 1;
        }
    }
    fn skip_sep(&mut self) {
        self.skip_ws();
        if self.s.as_bytes().get(self.pos) == Some(&b',') {
            self.pos += 1;
            self.skip_ws();
        }
    }
    fn at_number(&mut self) -> bool {
        self.skip_ws();
        matches!(self.s.as_bytes().get(self.pos), Some(c) if c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.'))
    }
    fn number(&mut self) -> Result<f64, PathDataError> {
        self.skip_ws();
        let rest = &self.s[self.pos..];
        let n = number_prefix_len(rest);
        if n == 0 {
            return Err(PathDataError::ExpectedNumber { offset: self.pos });
        }
        let v = to_num(&rest[..n], Precision::F64).ok_or_else(|| PathDataError::NotFinite {
            text: rest[..n].to_string(),
            offset: self.pos,
        })?;
        self.pos += n;
        self.skip_sep();
        Ok(v)
    }
    fn flag(&mut self) -> Result<bool, PathDataError> {
        self.skip_ws();
        let v = match self.s.as_bytes().get(self.pos) {
            Some(b'0') => false,
            Some(b'1') => true,
            _ => return Err(PathDataError::ExpectedFlag { offset: self.pos }),
        };
        self.pos += 1;
        self.skip_sep();
        Ok(v)
    }
    fn point(&mut self) -> Result<DVec2, PathDataError> {
        Ok(DVec2::new(self.number()?, self.number()?))
    }
}

/// Parses SVG path data into a [`Path`] (quadratics as exact cubics, arcs as cubics).
///
/// # Errors
/// [`PathDataError`] with the byte offset of the first malformed token; the SVG spec's "render up to
/// the error" is not applied, so bad data is reported rather than silently truncated.
pub fn parse_path_data(d: &str) -> Result<Path, PathDataError> {
    match parse_path_data_prefix(d) {
        (path, None) => Ok(path),
        (_, Some(e)) => Err(e),
    }
}

/// Parses path data up to its first error, as the SVG specification has it drawn: the path
/// of every command before the one in error, and that error (`None` when there is none).
/// Data that does not begin with a moveto gives an empty path.
#[must_use]
pub fn parse_path_data_prefix(d: &str) -> (Path, Option<PathDataError>) {
    let mut path = Path::default();
    let result = read_commands(d, &mut path);
    if !matches!(
        path.segments.first(),
        Some(crate::path::Segment::MoveTo(_)) | None
    ) {
        return (Path::default(), Some(PathDataError::NoInitialMoveTo));
    }
    (path, result.err())
}

/// Reads the commands of `d` into `path`, each command's segments only once all its
/// numbers have read, until the end or the first error.
fn read_commands(d: &str, path: &mut Path) -> Result<(), PathDataError> {
    let mut c = Cursor { s: d, pos: 0 };
    let mut cur = DVec2::ZERO;
    let mut start = DVec2::ZERO;
    // Reflection points for S/s and T/t.
    let mut last_cubic_ctrl: Option<DVec2> = None;
    let mut last_quad_ctrl: Option<DVec2> = None;
    let mut cmd: Option<u8> = None;
    loop {
        c.skip_ws();
        let Some(&b) = c.s.as_bytes().get(c.pos) else {
            break;
        };
        if b.is_ascii_alphabetic() {
            c.pos += 1;
            cmd = Some(b);
        } else if cmd.is_none() {
            return Err(PathDataError::ExpectedCommand { offset: c.pos });
        } else if !c.at_number() {
            return Err(PathDataError::Unexpected {
                found: b as char,
                offset: c.pos,
            });
        }
        let k = cmd.expect("set above");
        let rel = k.is_ascii_lowercase();
        let base = if rel { cur } else { DVec2::ZERO };
        let mut cubic_ctrl = None;
        let mut quad_ctrl = None;
        match k.to_ascii_uppercase() {
            b'M' => {
                cur = base + c.point()?;
                start = cur;
                path.move_to(cur);
                // Further pairs are implicit line-tos.
                cmd = Some(if rel { b'l' } else { b'L' });
            }
            b'L' => {
                cur = base + c.point()?;
                path.line_to(cur);
            }
            b'H' => {
                let x = c.number()?;
                cur = DVec2::new(if rel { cur.x + x } else { x }, cur.y);
                path.line_to(cur);
            }
            b'V' => {
                let y = c.number()?;
                cur = DVec2::new(cur.x, if rel { cur.y + y } else { y });
                path.line_to(cur);
            }
            b'C' => {
                let (c1, c2, p) = (base + c.point()?, base + c.point()?, base + c.point()?);
                path.cubic_to(c1, c2, p);
                cubic_ctrl = Some(c2);
                cur = p;
            }
            b'S' => {
                let c1 = last_cubic_ctrl.map_or(cur, |q| 2.0 * cur - q);
                let (c2, p) = (base + c.point()?, base + c.point()?);
                path.cubic_to(c1, c2, p);
                cubic_ctrl = Some(c2);
                cur = p;
            }
            b'Q' => {
                let (q, p) = (base + c.point()?, base + c.point()?);
                path.quad_to(cur, q, p);
                quad_ctrl = Some(q);
                cur = p;
            }
            b'T' => {
                let q = last_quad_ctrl.map_or(cur, |q| 2.0 * cur - q);
                let p = base + c.point()?;
                path.quad_to(cur, q, p);
                quad_ctrl = Some(q);
                cur = p;
            }
            b'A' => {
                let (rx, ry, rot) = (c.number()?, c.number()?, c.number()?);
                let (large, sweep) = (c.flag()?, c.flag()?);
                let p = base + c.point()?;
                path.arc_to(cur, rx, ry, rot, large, sweep, p);
                cur = p;
            }
            b'Z' => {
                path.close();
                cur = start;
                // A command letter must follow.
                c.skip_ws();
                if c.at_number() {
                    return Err(PathDataError::ExpectedCommandAfterClose { offset: c.pos });
                }
            }
            other => {
                return Err(PathDataError::UnknownCommand {
                    found: other as char,
                    offset: c.pos - 1,
                })
            }
        }
        last_cubic_ctrl = cubic_ctrl;
        last_quad_ctrl = quad_ctrl;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Segment;

    #[test]
    fn implicit_commands_and_relative_forms() {
        let p = parse_path_data("m10 10 20 0 0 20z h5 v-5 H0").unwrap();
        let s = &p.segments;
        assert_eq!(s[0], Segment::MoveTo(DVec2::new(10.0, 10.0)));
        assert_eq!(s[1], Segment::LineTo(DVec2::new(30.0, 10.0)));
        assert_eq!(s[2], Segment::LineTo(DVec2::new(30.0, 30.0)));
        assert_eq!(s[3], Segment::Close);
        assert_eq!(s[4], Segment::LineTo(DVec2::new(15.0, 10.0)));
        assert_eq!(s[5], Segment::LineTo(DVec2::new(15.0, 5.0)));
        assert_eq!(s[6], Segment::LineTo(DVec2::new(0.0, 5.0)));
    }

    #[test]
    fn smooth_curves_reflect_control_points() {
        let p = parse_path_data("M0,0 C0,10 10,10 10,0 S20,-10 20,0").unwrap();
        match p.segments[2] {
            Segment::CubicTo(c1, _, _) => assert_eq!(c1, DVec2::new(10.0, -10.0)),
            ref s => panic!("{s:?}"),
        }
        // Compact arc flags: "a1 1 0 1,0 400,0" and "a5,5 0 0110,0".
        assert!(parse_path_data("M0 0 a200,200 0 1,0 400,0 a5,5 0 0110,0").is_ok());
    }

    #[test]
    fn errors_name_offsets() {
        assert!(parse_path_data("L1 1").is_err());
        assert_eq!(
            parse_path_data("M0 0 L1 x").unwrap_err(),
            PathDataError::ExpectedNumber { offset: 8 }
        );
        assert_eq!(
            parse_path_data("M0 0 L1 x").unwrap_err().to_string(),
            "expected a number at offset 8"
        );
        assert!(parse_path_data("M0 0 A1 1 0 2 0 3 3").is_err());
        assert!(parse_path_data("M0 0 L1e999 0").is_err());
        assert!(parse_path_data("M0 0 K1").is_err());
        assert!(parse_path_data("").unwrap().segments.is_empty());
    }

    /// The specification's error handling: everything before the command in error is kept.
    #[test]
    fn prefix_keeps_the_commands_before_an_error() {
        let (p, e) = parse_path_data_prefix("M0 0 L10 0 L10 x L0 10");
        assert_eq!(e, Some(PathDataError::ExpectedNumber { offset: 15 }));
        assert_eq!(p, parse_path_data("M0 0 L10 0").unwrap());
        let (p, e) = parse_path_data_prefix("L5 5 M0 0");
        assert!(p.segments.is_empty());
        assert_eq!(e, Some(PathDataError::NoInitialMoveTo));
        assert_eq!(parse_path_data_prefix("M1 2 z").1, None);
    }
}
