//! Places in text files for the readers' errors and warnings: [`Loc`] (a file, line and
//! column, one type every reader's errors share), [`Warning`] (what a reader read past, and
//! where) and [`LineIndex`] (the line number of a byte offset, in
//! constant time per query).

use std::fmt;

/// Where in a text file something is: the file's name as given, a 1-based line, and a
/// 1-based column (0 when only the line is known). Shown as `file:line` or
/// `file:line:column`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Loc {
    /// The file (or `<memory>`).
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column; 0 if unknown.
    pub column: u32,
}

impl Loc {
    /// Line `line` of `file`.
    #[must_use]
    pub fn line(file: &str, line: u32) -> Loc {
        Loc {
            file: file.to_string(),
            line,
            column: 0,
        }
    }

    /// Line `line`, column `column` of `file`.
    #[must_use]
    pub fn at(file: &str, line: u32, column: u32) -> Loc {
        Loc {
            file: file.to_string(),
            line,
            column,
        }
    }
}

/// Something a reader read past or could not honour, and where: shown as `file:line: message`
/// (or the message alone when it has no one place).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Warning {
    /// Where, if at one place.
    pub at: Option<Loc>,
    /// What was read past, and what was done instead.
    pub message: String,
}

impl Warning {
    /// A warning at `at`.
    #[must_use]
    pub fn at(at: Loc, message: impl Into<String>) -> Warning {
        Warning {
            at: Some(at),
            message: message.into(),
        }
    }

    /// A warning about the whole input (or one whose message names its place itself, as an
    /// error read past does).
    #[must_use]
    pub fn new(message: impl Into<String>) -> Warning {
        Warning {
            at: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.at {
            Some(at) => write!(f, "{at}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.column == 0 {
            write!(f, "{}:{}", self.file, self.line)
        } else {
            write!(f, "{}:{}:{}", self.file, self.line, self.column)
        }
    }
}

/// Bytes between checkpoints: a query scans at most this many bytes.
const STRIDE: usize = 4096;

/// Line numbers of byte offsets in a text. Built in one pass; each query counts newlines
/// from the nearest checkpoint at or before the offset, so it costs at most 4096 bytes
/// whatever the offset (a scan from the start would make reading a large file quadratic).
#[derive(Clone, Debug)]
pub struct LineIndex<'t> {
    text: &'t [u8],
    /// Newlines before each multiple of the stride.
    newlines_before: Vec<u32>,
}

impl<'t> LineIndex<'t> {
    /// Indexes `text`.
    #[must_use]
    pub fn new(text: &'t str) -> Self {
        let text = text.as_bytes();
        let mut newlines_before = Vec::with_capacity(text.len() / STRIDE + 1);
        let mut count = 0u32;
        for chunk in text.chunks(STRIDE) {
            newlines_before.push(count);
            let n = chunk.iter().filter(|&&b| b == b'\n').count();
            count = count.saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
        }
        newlines_before.push(count);
        LineIndex {
            text,
            newlines_before,
        }
    }

    /// The 1-based line holding byte `offset` (offsets past the end count as the end).
    #[must_use]
    pub fn line(&self, offset: usize) -> u32 {
        let offset = offset.min(self.text.len());
        let k = offset / STRIDE;
        let tail = &self.text[k * STRIDE..offset];
        let n = tail.iter().filter(|&&b| b == b'\n').count() as u32;
        1 + self.newlines_before[k] + n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A location shows as the compilers show theirs: `file:line`, `file:line:column`.
    #[test]
    fn locations_show_file_line_and_column() {
        assert_eq!(Loc::line("a.obj", 3).to_string(), "a.obj:3");
        assert_eq!(Loc::at("b.svg", 2, 14).to_string(), "b.svg:2:14");
        let w = Warning::at(Loc::line("a.dae", 7), "<skew> is not read");
        assert_eq!(w.to_string(), "a.dae:7: <skew> is not read");
        assert_eq!(Warning::new("no light").to_string(), "no light");
    }

    /// Brute force: every offset of a text with lines of varied lengths (some longer than
    /// the stride) gets the line a scan from the start gives.
    #[test]
    fn lines_match_a_scan_from_the_start() {
        let mut text = String::new();
        for i in 0..300 {
            text.push_str(&"x".repeat((i * 97) % 9000));
            text.push('\n');
        }
        let index = LineIndex::new(&text);
        let mut line = 1;
        for (offset, b) in text.bytes().enumerate() {
            assert_eq!(index.line(offset), line, "offset {offset}");
            if b == b'\n' {
                line += 1;
            }
        }
        assert_eq!(index.line(text.len()), line);
        assert_eq!(index.line(usize::MAX), line);
        assert_eq!(LineIndex::new("").line(0), 1);
    }
}
