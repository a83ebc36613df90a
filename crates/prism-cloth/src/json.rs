//! A small JSON reader that keeps the line of every value, for located errors: objects,
//! arrays, numbers, strings, booleans and null, nested at most [`MAX_JSON_DEPTH`] deep.

use crate::error::ClothError;
use prism_math::Loc;

/// Deepest nesting of arrays and objects read.
pub const MAX_JSON_DEPTH: usize = 64;

/// A JSON value with the 1-based line it starts on.
#[derive(Clone, Debug, PartialEq)]
pub struct Json {
    /// The value.
    pub value: JsonValue,
    /// Its line.
    pub line: u32,
}

/// The kinds of JSON value.
#[derive(Clone, Debug, PartialEq)]
pub enum JsonValue {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number, with whether it was written without a fraction or exponent.
    Number(f64, bool),
    /// A string.
    String(String),
    /// An array.
    Array(Vec<Json>),
    /// An object's keys (with their lines) and values, in file order.
    Object(Vec<(String, u32, Json)>),
}

impl JsonValue {
    /// What the value is, for messages.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            JsonValue::Null => "null",
            JsonValue::Bool(_) => "a boolean",
            JsonValue::Number(..) => "a number",
            JsonValue::String(_) => "a string",
            JsonValue::Array(_) => "an array",
            JsonValue::Object(_) => "an object",
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    line: u32,
    file: &'a str,
}

impl Parser<'_> {
    fn err(&self, message: String) -> ClothError {
        ClothError::Parse {
            at: Loc::line(self.file, self.line),
            message,
        }
    }

    fn ws(&mut self) {
        while let Some(&c) = self.s.get(self.i) {
            match c {
                b'\n' => self.line += 1,
                b' ' | b'\t' | b'\r' => {}
                _ => break,
            }
            self.i += 1;
        }
    }

    fn found(&self) -> String {
        match self.s.get(self.i) {
            None => "the end of the file".into(),
            Some(&c) if c.is_ascii_graphic() => format!("{:?}", c as char),
            Some(&c) => format!("byte {c:#04x}"),
        }
    }

    fn expect(&mut self, c: u8) -> Result<(), ClothError> {
        self.ws();
        if self.s.get(self.i) == Some(&c) {
            self.i += 1;
            Ok(())
        } else {
            Err(self.err(format!("expected {:?}, found {}", c as char, self.found())))
        }
    }

    fn value(&mut self, depth: usize) -> Result<Json, ClothError> {
        self.ws();
        let line = self.line;
        let Some(&c) = self.s.get(self.i) else {
            return Err(self.err("expected a value, found the end of the file".into()));
        };
        let value = match c {
            b'{' | b'[' if depth >= MAX_JSON_DEPTH => {
                return Err(self.err(format!("nested more than {MAX_JSON_DEPTH} levels deep")))
            }
            b'{' => {
                self.i += 1;
                let mut fields = Vec::new();
                self.ws();
                if self.s.get(self.i) == Some(&b'}') {
                    self.i += 1;
                } else {
                    loop {
                        self.ws();
                        let key_line = self.line;
                        if self.s.get(self.i) != Some(&b'"') {
                            return Err(self
                                .err(format!("expected a key in quotes, found {}", self.found())));
                        }
                        let key = self.string()?;
                        self.expect(b':')?;
                        let v = self.value(depth + 1)?;
                        fields.push((key, key_line, v));
                        self.ws();
                        match self.s.get(self.i) {
                            Some(b',') => self.i += 1,
                            Some(b'}') => {
                                self.i += 1;
                                break;
                            }
                            _ => {
                                return Err(self
                                    .err(format!("expected ',' or '}}', found {}", self.found())))
                            }
                        }
                    }
                }
                JsonValue::Object(fields)
            }
            b'[' => {
                self.i += 1;
                let mut items = Vec::new();
                self.ws();
                if self.s.get(self.i) == Some(&b']') {
                    self.i += 1;
                } else {
                    loop {
                        items.push(self.value(depth + 1)?);
                        self.ws();
                        match self.s.get(self.i) {
                            Some(b',') => self.i += 1,
                            Some(b']') => {
                                self.i += 1;
                                break;
                            }
                            _ => {
                                return Err(self
                                    .err(format!("expected ',' or ']', found {}", self.found())))
                            }
                        }
                    }
                }
                JsonValue::Array(items)
            }
            b'"' => JsonValue::String(self.string()?),
            b't' | b'f' | b'n' => {
                let rest = &self.s[self.i..];
                let (word, v) = if rest.starts_with(b"true") {
                    ("true", JsonValue::Bool(true))
                } else if rest.starts_with(b"false") {
                    ("false", JsonValue::Bool(false))
                } else if rest.starts_with(b"null") {
                    ("null", JsonValue::Null)
                } else {
                    return Err(self.err(format!("expected a value, found {}", self.found())));
                };
                self.i += word.len();
                v
            }
            b'-' | b'0'..=b'9' => {
                let start = self.i;
                while self.i < self.s.len()
                    && matches!(
                        self.s[self.i],
                        b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9'
                    )
                {
                    self.i += 1;
                }
                let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                let integral = !text.contains(['.', 'e', 'E']);
                let x: f64 = text
                    .parse()
                    .map_err(|_| self.err(format!("expected a number, found {text:?}")))?;
                if !x.is_finite() {
                    return Err(self.err(format!("expected a finite number, found {text:?}")));
                }
                JsonValue::Number(x, integral)
            }
            _ => return Err(self.err(format!("expected a value, found {}", self.found()))),
        };
        Ok(Json { value, line })
    }

    fn string(&mut self) -> Result<String, ClothError> {
        self.i += 1;
        let mut out = Vec::new();
        loop {
            let Some(&c) = self.s.get(self.i) else {
                return Err(self
                    .err("expected the string's closing quote, found the end of the file".into()));
            };
            self.i += 1;
            match c {
                b'"' => break,
                b'\n' => {
                    return Err(self
                        .err("expected the string's closing quote before the line's end".into()))
                }
                b'\\' => {
                    let Some(&e) = self.s.get(self.i) else {
                        return Err(
                            self.err("expected an escape, found the end of the file".into())
                        );
                    };
                    self.i += 1;
                    match e {
                        b'"' | b'\\' | b'/' => out.push(e),
                        b'n' => out.push(b'\n'),
                        b't' => out.push(b'\t'),
                        b'r' => out.push(b'\r'),
                        b'b' => out.push(8),
                        b'f' => out.push(12),
                        b'u' => {
                            let hex = self
                                .s
                                .get(self.i..self.i + 4)
                                .and_then(|h| std::str::from_utf8(h).ok());
                            let code = hex.and_then(|h| u32::from_str_radix(h, 16).ok());
                            let ch = code.and_then(char::from_u32).unwrap_or('\u{fffd}');
                            self.i += 4.min(self.s.len() - self.i);
                            let mut buf = [0; 4];
                            out.extend_from_slice(ch.encode_utf8(&mut buf).as_bytes());
                        }
                        _ => return Err(self.err(format!("unknown escape \\{}", e as char))),
                    }
                }
                _ => out.push(c),
            }
        }
        String::from_utf8(out).map_err(|_| self.err("expected UTF-8 text in a string".into()))
    }
}

/// Parses JSON text; `file` names it in errors.
///
/// # Errors
/// [`ClothError::Parse`] with the line of the first malformed part.
pub fn parse_json(text: &str, file: &str) -> Result<Json, ClothError> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
        line: 1,
        file,
    };
    let v = p.value(0)?;
    p.ws();
    if p.i != p.s.len() {
        return Err(p.err(format!("expected the end of the file, found {}", p.found())));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values and lines as written; malformed text and deep nesting are located errors.
    #[test]
    fn values_lines_and_errors() {
        let j = parse_json(
            "{\n \"a\": [1, 2.5, -3e2],\n \"b\": {\"c\": true, \"d\": null, \"e\": \"x\\\"y\"}\n}",
            "t.json",
        )
        .unwrap();
        let JsonValue::Object(f) = &j.value else {
            panic!()
        };
        assert_eq!(f[0].0, "a");
        assert_eq!(f[0].1, 2);
        let JsonValue::Array(a) = &f[0].2.value else {
            panic!()
        };
        assert_eq!(a[0].value, JsonValue::Number(1.0, true));
        assert_eq!(a[2].value, JsonValue::Number(-300.0, false));
        assert_eq!(f[1].2.line, 3);
        for (text, want) in [
            (
                "{\"a\": 1,}",
                "t.json:1: expected a key in quotes, found '}'",
            ),
            ("[1 2]", "t.json:1: expected ',' or ']', found '2'"),
            ("{\"a\"\n 1}", "t.json:2: expected ':', found '1'"),
            (
                "[1e999]",
                "t.json:1: expected a finite number, found \"1e999\"",
            ),
            ("{\"a\": tru}", "t.json:1: expected a value, found 't'"),
            ("[1] x", "t.json:1: expected the end of the file, found 'x'"),
        ] {
            assert_eq!(
                parse_json(text, "t.json").unwrap_err().to_string(),
                want,
                "{text}"
            );
        }
        let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
        assert!(parse_json(&deep, "t.json")
            .unwrap_err()
            .to_string()
            .contains("nested more than 64"));
    }
}
