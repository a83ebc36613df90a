//! The errors of the command line: [`UserError`], a mistake of the user's (exit code 2), in
//! one wording per class; and the one-line form every error is printed in.

use std::path::{Path, PathBuf};

/// A mistake of the user's (bad input or arguments), found before or while reading the
/// inputs: exit code 2. Each class has one wording on every subcommand.
#[derive(Debug)]
pub enum UserError {
    /// An input file that does not exist: `PATH: no such file`.
    MissingFile {
        /// The flag that named it (`--texture`), if not the positional input.
        flag: Option<String>,
        /// The path given.
        path: PathBuf,
    },
    /// An input that is not a regular file (a folder, a device, a FIFO).
    NotAFile {
        /// The flag that named it, if not the positional input.
        flag: Option<String>,
        /// The path given.
        path: PathBuf,
    },
    /// A file whose extension (or content) is of a kind the command does not take:
    /// `PATH: expected a .png or .jpg file`.
    WrongKind {
        /// The flag that named it, if not the positional input.
        flag: Option<String>,
        /// The path given.
        path: PathBuf,
        /// What the command takes there, as `a .png or .jpg file`.
        expected: String,
    },
    /// A folder that does not exist: the one named, or the one a named file would be in.
    MissingFolder {
        /// The flag that named it.
        flag: String,
        /// The path given.
        path: PathBuf,
        /// The folder that is missing (the path itself, or its parent).
        folder: PathBuf,
    },
    /// A value outside what its flag takes: `FLAG: expected WHAT, found VALUE`.
    BadValue {
        /// The flag (`--spp`).
        flag: String,
        /// What it takes (`1 to 1048576`).
        expected: String,
        /// The value given.
        found: String,
    },
    /// An input that cannot be used, in its reader's words (which name the file, and the
    /// line and element where they can).
    Input(String),
    /// A name that is neither a file nor one of the names the command knows:
    /// `NAME: no such file or preset (did you mean cornell-box?); presets: ...`.
    UnknownName {
        /// The name given.
        name: String,
        /// What else it could have named (`preset`).
        kind: &'static str,
        /// The nearest known name, if one is near.
        nearest: Option<String>,
        /// Every known name, comma-separated.
        known: String,
    },
    /// A request the command cannot carry out as given (flags that conflict, an output that
    /// would replace an input, ...), in a sentence naming the flag and saying why.
    Refused(String),
}

/// `FLAG PATH` or `PATH`.
fn named(flag: Option<&str>, path: &Path) -> String {
    match flag {
        Some(f) => format!("{f} {}", path.display()),
        None => path.display().to_string(),
    }
}

impl std::fmt::Display for UserError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            UserError::MissingFile { flag, path } => {
                write!(f, "{}: no such file", named(flag.as_deref(), path))
            }
            UserError::NotAFile { flag, path } => write!(
                f,
                "{}: not a regular file (only regular files are read)",
                named(flag.as_deref(), path)
            ),
            UserError::WrongKind {
                flag,
                path,
                expected,
            } => write!(f, "{}: expected {expected}", named(flag.as_deref(), path)),
            UserError::MissingFolder { flag, path, folder } => {
                if path == folder {
                    write!(f, "{flag} {}: no such folder", path.display())
                } else {
                    write!(
                        f,
                        "{flag} {}: no such folder {} (prism does not create it)",
                        path.display(),
                        folder.display()
                    )
                }
            }
            UserError::BadValue {
                flag,
                expected,
                found,
            } => write!(f, "{flag}: expected {expected}, found {found}"),
            UserError::UnknownName {
                name,
                kind,
                nearest,
                known,
            } => {
                write!(f, "{name}: no such file or {kind}")?;
                if let Some(n) = nearest {
                    write!(f, " (did you mean {n}?)")?;
                }
                write!(f, "; {kind}s: {known}")
            }
            UserError::Input(m) | UserError::Refused(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for UserError {}

impl UserError {
    /// An input's error in its reader's words.
    pub fn input(e: impl std::fmt::Display) -> UserError {
        UserError::Input(plain_os_errors(&e.to_string()))
    }

    /// A value outside what `flag` takes.
    pub fn bad_value(
        flag: impl Into<String>,
        expected: impl Into<String>,
        found: impl std::fmt::Display,
    ) -> UserError {
        UserError::BadValue {
            flag: flag.into(),
            expected: expected.into(),
            found: found.to_string(),
        }
    }
}

/// Checks that `path`, an input named by `flag` (or the positional input), is a regular
/// file: [`UserError::MissingFile`] or [`UserError::NotAFile`] otherwise.
pub fn check_input(path: &Path, flag: Option<&str>) -> Result<(), UserError> {
    let flag = flag.map(str::to_string);
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(()),
        Ok(_) => Err(UserError::NotAFile {
            flag,
            path: path.to_path_buf(),
        }),
        Err(_) => Err(UserError::MissingFile {
            flag,
            path: path.to_path_buf(),
        }),
    }
}

/// Checks a Delft scene name (`prism raytrace`, `prism view`): a preset name, else a file
/// that must exist; a bare word that is neither is an unknown preset, with the nearest
/// preset's name suggested.
pub fn check_scene_name(name: &str) -> Result<(), UserError> {
    if prism_scene::Preset::from_name(name).is_some() {
        return Ok(());
    }
    let path = Path::new(name);
    if path.exists() || path.extension().is_some() || name.contains('/') {
        return check_input(path, None);
    }
    let known: Vec<&str> = prism_scene::Preset::ALL.iter().map(|p| p.name()).collect();
    Err(UserError::UnknownName {
        name: name.to_string(),
        kind: "preset",
        nearest: prism_scene::Preset::nearest(name).map(|p| p.name().to_string()),
        known: known.join(", "),
    })
}

/// Checks that `path`, named by `flag`, is an existing folder.
pub fn check_folder_input(path: &Path, flag: &str) -> Result<(), UserError> {
    if path.is_dir() {
        return Ok(());
    }
    if path.exists() {
        return Err(UserError::WrongKind {
            flag: Some(flag.to_string()),
            path: path.to_path_buf(),
            expected: "a folder".into(),
        });
    }
    Err(UserError::MissingFolder {
        flag: flag.to_string(),
        path: path.to_path_buf(),
        folder: path.to_path_buf(),
    })
}

/// `text` with the operating system's wording of a file error (`No such file or directory
/// (os error 2)`) replaced by prism's (`no such file`), so that a file missing deep inside
/// an input (a texture a scene names) is worded as one named on the command line.
pub fn plain_os_errors(text: &str) -> String {
    let mut out = text.to_string();
    let mut from = 0;
    while let Some(at) = out[from..].find("(os error ").map(|i| i + from) {
        let digits: String = out[at + 10..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        let Ok(code) = digits.parse::<i32>() else {
            from = at + 10;
            continue;
        };
        let os = std::io::Error::from_raw_os_error(code);
        let full = os.to_string();
        let words = match os.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            std::io::ErrorKind::IsADirectory => {
                "not a regular file (only regular files are read)".to_string()
            }
            _ => full[..full.find(" (os error").unwrap_or(full.len())].to_lowercase(),
        };
        match out[..at + 10 + digits.len() + 1].rfind(&full) {
            Some(start) if out[start..].starts_with(&full) => {
                out.replace_range(start..start + full.len(), &words);
                from = start + words.len();
            }
            _ => from = at + 10,
        }
    }
    out
}

/// The subcommands, for the suggestion after a typo.
pub const SUBCOMMANDS: [&str; 10] = [
    "svg", "bezier", "mesh", "render", "raytrace", "shade", "cloth", "merge", "view", "demo",
];

/// A command-line parsing error in prism's words, for the errors that are a user's value or
/// name (`--spp: expected a whole number, found "abc"`); `None` leaves clap's own text (usage
/// errors, help and version).
pub fn clap_error_line(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let context = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    match e.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation => {
            let arg = context(ContextKind::InvalidArg)?;
            let flag = arg.split([' ', '=']).next().unwrap_or(&arg).to_string();
            let value = context(ContextKind::InvalidValue).unwrap_or_default();
            let expected = match context(ContextKind::ValidValue) {
                Some(valid) => format!("one of {valid}"),
                None => {
                    let why = std::error::Error::source(e).map(ToString::to_string);
                    match why.as_deref() {
                        Some(w) if w.contains(" is not in ") => {
                            format!(
                                "a whole number in {}",
                                &w[w.find(" is not in ").unwrap_or(0) + 11..]
                            )
                        }
                        Some(w) if w.contains("too large") || w.contains("too small") => {
                            "a whole number within its range".to_string()
                        }
                        Some(w) if w.contains("digit") || w.contains("empty") => {
                            "a whole number".to_string()
                        }
                        Some(w) if w.contains("float") => "a number".to_string(),
                        Some(w) => w.to_string(),
                        None => "a valid value".to_string(),
                    }
                }
            };
            Some(UserError::bad_value(flag, expected, format!("{value:?}")).to_string())
        }
        ErrorKind::InvalidSubcommand => {
            let name = context(ContextKind::InvalidSubcommand)?;
            let mut line = format!("{name}: no such subcommand");
            let nearest = SUBCOMMANDS
                .iter()
                .map(|s| (prism_math::edit_distance(&name, s), s))
                .filter(|&(d, _)| d <= 2)
                .min_by_key(|&(d, _)| d);
            if let Some((_, s)) = nearest {
                line.push_str(&format!(" (did you mean {s}?)"));
            }
            line.push_str("; `prism --help` lists them");
            Some(line)
        }
        _ => None,
    }
}

/// An error and its causes on one line, `a: b: c`, leaving out a cause whose text the line
/// already holds (library errors often show their source in their own message), with the
/// operating system's file errors in prism's words.
pub fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut line = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !line.contains(&text) {
            line = format!("{line}: {text}");
        }
        cause = c.source();
    }
    plain_os_errors(&line)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: the operating system's wordings become prism's, wherever they sit in
    /// the line, and other text is left as it is.
    #[test]
    fn os_errors_are_worded_as_prism_words_them() {
        let missing = std::io::Error::from_raw_os_error(2).to_string();
        assert_eq!(
            plain_os_errors(&format!("scene.dae:4: texture a.png: {missing}")),
            "scene.dae:4: texture a.png: no such file"
        );
        let denied = std::io::Error::from_raw_os_error(13).to_string();
        assert_eq!(
            plain_os_errors(&format!("a: {denied}; b: {missing}")),
            "a: permission denied; b: no such file"
        );
        assert_eq!(plain_os_errors("(os error x) fine"), "(os error x) fine");
    }
}
