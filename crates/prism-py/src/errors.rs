//! Rust errors as Python exceptions: `prism.Error` and one subclass per kind, with the
//! `file` and `line` the library's message names.

use std::error::Error as StdError;

use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// The kinds of error, one Python class each (defined in `prism/_errors.py`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A malformed or unsupported input: `prism.InputError`.
    Input,
    /// A file that cannot be read or written: `prism.FileError` (an `OSError`).
    File,
    /// A request over a limit or the memory budget: `prism.LimitError`.
    Limit,
    /// A mesh edit the mesh's topology refuses: `prism.TopologyError`.
    Topology,
    /// A bad argument: `prism.ArgumentError` (a `ValueError`).
    Argument,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Input => "InputError",
            Kind::File => "FileError",
            Kind::Limit => "LimitError",
            Kind::Topology => "TopologyError",
            Kind::Argument => "ArgumentError",
        }
    }
}

/// The file and line a message opens with, as `file:line: ...` or `file:line:column: ...`
/// (how [`prism_math::Loc`] shows itself); else the file alone when the message opens with
/// `known: `.
pub fn location(message: &str, known: Option<&str>) -> (Option<String>, Option<u32>) {
    let bytes = message.as_bytes();
    let mut i = 0;
    while let Some(off) = message[i..].find(':') {
        let colon = i + off;
        let digits = bytes[colon + 1..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        if digits > 0 && colon > 0 {
            let after = colon + 1 + digits;
            let rest = &message[after..];
            let column_digits = rest
                .strip_prefix(':')
                .map_or(0, |r| r.bytes().take_while(u8::is_ascii_digit).count());
            let column_end = if column_digits > 0 {
                1 + column_digits
            } else {
                0
            };
            if rest[column_end..].starts_with(": ") || rest[column_end..].is_empty() {
                let line = message[colon + 1..after].parse().ok();
                return (Some(message[..colon].to_string()), line);
            }
        }
        if message[colon..].starts_with(": ") {
            break;
        }
        i = colon + 1;
    }
    match known {
        Some(k) if message.starts_with(k) && message[k.len()..].starts_with(':') => {
            (Some(k.to_string()), None)
        }
        _ => (None, None),
    }
}

/// The kind an error is, from what its chain of sources holds: the operating system's
/// refusal to read or write, a request over the memory budget, or else a bad input.
pub fn kind_of(e: &(dyn StdError + 'static)) -> Kind {
    let mut next: Option<&(dyn StdError + 'static)> = Some(e);
    while let Some(err) = next {
        if err.is::<prism_math::limits::OverBudget>() {
            return Kind::Limit;
        }
        let io = err.downcast_ref::<std::io::Error>().or_else(|| {
            err.downcast_ref::<std::sync::Arc<std::io::Error>>()
                .map(AsRef::as_ref)
        });
        if let Some(io) = io {
            if let Some(refused) = io
                .get_ref()
                .and_then(|inner| inner.downcast_ref::<prism_math::limits::InputRefused>())
            {
                return match refused {
                    prism_math::limits::InputRefused::NotAFile => Kind::File,
                    _ => Kind::Limit,
                };
            }
            if !matches!(
                io.kind(),
                std::io::ErrorKind::InvalidData | std::io::ErrorKind::InvalidInput
            ) {
                return Kind::File;
            }
        }
        if err.is::<prism_mesh::TopologyError>() {
            return Kind::Topology;
        }
        if let Some(r) = err.downcast_ref::<prism_raster::RasterError>() {
            return match r {
                prism_raster::RasterError::BadSize(..) => Kind::Limit,
                _ => Kind::Argument,
            };
        }
        if let Some(prism_cloth::ClothError::Io { .. }) = err.downcast_ref() {
            return Kind::File;
        }
        next = err.source();
    }
    Kind::Input
}

/// A Python exception of `kind` carrying `message`, with the file and line it names.
pub fn raise(kind: Kind, message: impl Into<String>, known_file: Option<&str>) -> PyErr {
    let message = message.into();
    let (file, line) = location(&message, known_file);
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let class = py.import("prism._errors")?.getattr(kind.class_name())?;
            let args = PyTuple::new(
                py,
                [
                    message.clone().into_pyobject(py)?.into_any(),
                    file.into_pyobject(py)?.into_any(),
                    line.into_pyobject(py)?.into_any(),
                ],
            )?;
            Ok(PyErr::from_value(class.call1(args)?))
        })();
        made.unwrap_or_else(|e| e)
    })
}

/// A Python exception for a library error: its kind from [`kind_of`], its message the
/// error's own.
pub fn from_error(e: &(dyn StdError + 'static), known_file: Option<&str>) -> PyErr {
    raise(kind_of(e), e.to_string(), known_file)
}

/// A `prism.ArgumentError` (a `ValueError`) with this message.
pub fn argument(message: impl Into<String>) -> PyErr {
    raise(Kind::Argument, message, None)
}

/// A Python exception for an I/O error reading or writing `file`, naming it.
pub fn from_io(e: &std::io::Error, file: &str) -> PyErr {
    raise(kind_of(e), format!("{file}: {e}"), Some(file))
}
