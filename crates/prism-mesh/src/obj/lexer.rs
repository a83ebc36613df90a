//! The lexer of OBJ and MTL text: statements (a line's first word and the rest, comments
//! removed) and the numbers they hold.

use std::str::FromStr;

/// A float type the documents are read in (`f32` or `f64`), each number parsed directly to
/// it (correctly rounded: never through the other type).
pub trait ObjFloat: FromStr + Copy + Default + PartialEq + std::fmt::Debug {
    /// True unless infinite or NaN.
    fn finite(self) -> bool;
}

impl ObjFloat for f32 {
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl ObjFloat for f64 {
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// One non-empty line of OBJ or MTL text, its comment (from `#`) removed.
#[derive(Clone, Copy, Debug)]
pub struct Statement<'t> {
    /// 1-based line.
    pub line: u32,
    /// The first word.
    pub key: &'t str,
    /// The whole line, trimmed, the key included.
    pub content: &'t str,
}

impl<'t> Statement<'t> {
    /// What follows the key, trimmed.
    #[must_use]
    pub fn rest(&self) -> &'t str {
        self.content[self.key.len()..].trim()
    }

    /// The words after the key.
    pub fn words(&self) -> std::str::SplitWhitespace<'t> {
        self.content[self.key.len()..].split_whitespace()
    }

    /// The statement's numbers: at least `min`, at most `N` read (more are left for the
    /// caller to ignore), the ones not given 0. The message names what is wrong.
    ///
    /// # Errors
    /// Fewer than `min` words, or a word that is not a finite number.
    pub fn numbers<F: ObjFloat, const N: usize>(&self, min: usize) -> Result<[F; N], String> {
        let mut out = [F::default(); N];
        let mut words = self.words();
        for (k, slot) in out.iter_mut().enumerate() {
            let Some(w) = words.next() else {
                if k < min {
                    return Err(format!("{}: expected {min} numbers, found {k}", self.key));
                }
                break;
            };
            *slot =
                w.parse::<F>().ok().filter(|v| v.finite()).ok_or_else(|| {
                    format!("{}: expected a finite number, found {w:?}", self.key)
                })?;
        }
        Ok(out)
    }
}

/// The statements of OBJ or MTL text, in order.
pub fn statements(text: &str) -> impl Iterator<Item = Statement<'_>> {
    text.lines().enumerate().filter_map(|(ln, raw)| {
        let content = raw.split('#').next().unwrap_or("").trim();
        let key = content.split_whitespace().next()?;
        Some(Statement {
            line: u32::try_from(ln + 1).unwrap_or(u32::MAX),
            key,
            content,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Comments, blank lines and surrounding space are dropped; lines keep their numbers.
    #[test]
    fn statements_skip_comments_and_blank_lines() {
        let text = "# header\n\n  v 1 2 3 # a point\nf 1 2 3\n";
        let got: Vec<(u32, &str, &str)> = statements(text)
            .map(|s| (s.line, s.key, s.rest()))
            .collect();
        assert_eq!(got, [(3, "v", "1 2 3"), (4, "f", "1 2 3")]);
    }

    /// Numbers: the required count, optional ones 0, non-finite values refused by name.
    #[test]
    fn numbers_are_counted_and_checked() {
        let st = |t: &'static str| statements(t).next().unwrap();
        assert_eq!(st("vt 0.5").numbers::<f64, 3>(1), Ok([0.5, 0.0, 0.0]));
        assert_eq!(
            st("v 1 2").numbers::<f32, 3>(3),
            Err("v: expected 3 numbers, found 2".to_string())
        );
        assert_eq!(
            st("vn 1 inf 0").numbers::<f32, 3>(3),
            Err("vn: expected a finite number, found \"inf\"".to_string())
        );
    }
}
