//! Output files: the format is chosen by the output's extension, and the extension and the
//! folder are checked before any work starts. prism does not create a missing folder (as
//! resvg does not): a mistyped path is an error, not a new directory.

use std::path::{Path, PathBuf};

use anyhow::Result;
use prism_scene::MeshFormat;

use crate::error::UserError;

/// An image file format prism writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`: 8-bit sRGB (with alpha where the picture has it).
    Png,
    /// `.jpg` / `.jpeg`: 8-bit sRGB, quality 95, no alpha.
    Jpeg,
    /// `.exr`: linear 32-bit float RGB.
    Exr,
    /// `.bmp`: 24-bit uncompressed bitmap.
    Bmp,
    /// `.gif`: an animation, 256 colours a frame.
    Gif,
}

impl ImageFormat {
    fn extensions(self) -> &'static str {
        match self {
            ImageFormat::Png => ".png",
            ImageFormat::Jpeg => ".jpg",
            ImageFormat::Exr => ".exr",
            ImageFormat::Bmp => ".bmp",
            ImageFormat::Gif => ".gif",
        }
    }
}

/// The lower-case extension of `path`, without the dot.
pub fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Checks a rendered picture's outputs before any work: the picture (`--output`: .png, .jpg
/// or .exr), the linear copy (`--exr`) and the sample-count heat map (`--heatmap`: .png or
/// .jpg), each a file of its own that is none of `inputs`; returns the picture's and the
/// heat map's formats.
pub fn picture_outputs(
    output: &Path,
    exr: Option<&Path>,
    heatmap: Option<&Path>,
    inputs: &[(&str, &Path)],
) -> Result<(ImageFormat, Option<ImageFormat>)> {
    let mut outputs = vec![("--output", output)];
    outputs.extend(exr.map(|p| ("--exr", p)));
    outputs.extend(heatmap.map(|p| ("--heatmap", p)));
    check_distinct(inputs, &outputs)?;
    let format = image_output(
        output,
        "--output",
        &[ImageFormat::Png, ImageFormat::Jpeg, ImageFormat::Exr],
    )?;
    if let Some(exr) = exr {
        image_output(exr, "--exr", &[ImageFormat::Exr])?;
    }
    let heatmap = heatmap
        .map(|p| image_output(p, "--heatmap", &[ImageFormat::Png, ImageFormat::Jpeg]))
        .transpose()?;
    Ok((format, heatmap))
}

/// The image format `path` names, if it is one of `allowed`; the folder must exist and
/// take new files. `flag` names the option in the message.
pub fn image_output(path: &Path, flag: &str, allowed: &[ImageFormat]) -> Result<ImageFormat> {
    let format = match extension(path).as_str() {
        "png" => Some(ImageFormat::Png),
        "jpg" | "jpeg" => Some(ImageFormat::Jpeg),
        "exr" => Some(ImageFormat::Exr),
        "bmp" => Some(ImageFormat::Bmp),
        "gif" => Some(ImageFormat::Gif),
        _ => None,
    };
    match format {
        Some(f) if allowed.contains(&f) => {
            check_folder(path, flag)?;
            Ok(f)
        }
        _ => {
            let names: Vec<&str> = allowed.iter().map(|f| f.extensions()).collect();
            Err(UserError::WrongKind {
                flag: Some(flag.to_string()),
                path: path.to_path_buf(),
                expected: format!("a {} file", names.join(" or ")),
            }
            .into())
        }
    }
}

/// The mesh format `path` names (`.obj`, `.ply` or `.dae`); the folder must exist and take
/// new files.
pub fn mesh_output(path: &Path, flag: &str) -> Result<MeshFormat> {
    let Some(format) = MeshFormat::from_path(path) else {
        return Err(UserError::WrongKind {
            flag: Some(flag.to_string()),
            path: path.to_path_buf(),
            expected: "an .obj, .ply or .dae file".into(),
        }
        .into());
    };
    check_folder(path, flag)?;
    Ok(format)
}

/// What kind of binary file `path` starts as (`a PNG image`, ...), if it is one of the
/// image and archive kinds a user may hand a text reader by mistake.
pub fn binary_kind(path: &Path) -> Option<&'static str> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let n = std::fs::File::open(path).ok()?.read(&mut head).ok()?;
    let head = &head[..n];
    [
        (&b"\x89PNG"[..], "a PNG image"),
        (&b"\xFF\xD8\xFF"[..], "a JPEG image"),
        (&b"GIF8"[..], "a GIF image"),
        (&b"\x76\x2F\x31\x01"[..], "an OpenEXR image"),
        (
            &b"\x1F\x8B"[..],
            "gzip-compressed (an .svgz? unpack it first)",
        ),
        (&b"PK\x03\x04"[..], "a zip archive"),
    ]
    .into_iter()
    .find(|(magic, _)| head.starts_with(magic))
    .map(|(_, kind)| kind)
}

/// Checks that `path` names a file in an existing folder where a new file can be made.
pub fn check_folder(path: &Path, flag: &str) -> Result<()> {
    if path.is_dir() || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(UserError::WrongKind {
            flag: Some(flag.to_string()),
            path: path.to_path_buf(),
            expected: "a file name, not a folder".into(),
        }
        .into());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(UserError::Refused(format!(
            "{flag} {}: {} is a file, not a folder",
            path.display(),
            dir.display()
        ))
        .into());
    }
    if !dir.is_dir() {
        return Err(UserError::MissingFolder {
            flag: flag.to_string(),
            path: path.to_path_buf(),
            folder: dir.to_path_buf(),
        }
        .into());
    }
    let probe = dir.join(format!(".prism-probe.{}", std::process::id()));
    match std::fs::File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(UserError::Refused(format!(
            "{flag} {}: cannot write in {}: {e}",
            path.display(),
            dir.display()
        ))
        .into()),
    }
}

/// Where `path` leads: the file's device and inode when it exists (hard links and symbolic
/// links alike lead to one file), else its canonical folder joined with its name.
#[derive(PartialEq, Eq)]
enum FileIdentity {
    Inode(u64, u64),
    Path(PathBuf),
}

fn identity(path: &Path) -> FileIdentity {
    use std::os::unix::fs::MetadataExt;
    if let Ok(meta) = std::fs::metadata(path) {
        return FileIdentity::Inode(meta.dev(), meta.ino());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    FileIdentity::Path(dir.join(path.file_name().unwrap_or_default()))
}

/// Checks, before any work, that no output names an input or another output of the same
/// command (compared as files: links and other spellings of a path count); each pair is
/// `(flag or role, path)`, a role such as `the scene`.
pub fn check_distinct(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<()> {
    let ids: Vec<FileIdentity> = outputs.iter().map(|(_, p)| identity(p)).collect();
    for (i, (flag, path)) in outputs.iter().enumerate() {
        for (role, input) in inputs {
            if identity(input) == ids[i] {
                return Err(UserError::Refused(format!(
                    "{flag} {}: it names {role} {}, an input (prism never writes over an input)",
                    path.display(),
                    input.display()
                ))
                .into());
            }
        }
        if let Some(((other, _), _)) = outputs[..i].iter().zip(&ids).find(|(_, id)| **id == ids[i])
        {
            return Err(UserError::Refused(format!(
                "{flag} {}: it names the same file as {other}",
                path.display()
            ))
            .into());
        }
    }
    Ok(())
}

/// Writes an 8-bit picture as PNG, JPEG or BMP, atomically.
pub fn write_rgb8(path: &Path, format: ImageFormat, image: &prism_image::Rgb8Image) -> Result<()> {
    match format {
        ImageFormat::Jpeg => prism_image::write_jpeg(path, image)?,
        ImageFormat::Bmp => prism_image::write_bmp(path, image)?,
        _ => prism_image::write_png(path, image)?,
    }
    Ok(())
}

/// Writes text to `path` through a temporary file and a rename.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    use std::io::Write;
    prism_image::write_atomic(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|source| prism_image::ImageError::Io {
                path: path.to_path_buf(),
                source,
            })
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_name_formats_case_blind() {
        let dir = std::env::temp_dir();
        let all = [ImageFormat::Png, ImageFormat::Jpeg, ImageFormat::Exr];
        for (name, want) in [
            ("a.PNG", ImageFormat::Png),
            ("a.jpeg", ImageFormat::Jpeg),
            ("a.JPG", ImageFormat::Jpeg),
            ("a.exr", ImageFormat::Exr),
        ] {
            assert_eq!(image_output(&dir.join(name), "-o", &all).unwrap(), want);
        }
        let e = image_output(&dir.join("a.exr"), "-o", &[ImageFormat::Png]).unwrap_err();
        assert!(e.to_string().ends_with("expected a .png file"), "{e}");
        assert!(image_output(&dir.join("a.obj"), "-o", &all).is_err());
        assert!(mesh_output(&dir.join("a.png"), "-o").is_err());
        assert_eq!(
            mesh_output(&dir.join("m.Ply"), "-o").unwrap(),
            MeshFormat::Ply
        );
    }

    #[test]
    fn missing_folders_are_named() {
        let path = std::env::temp_dir().join("prism-no-such-folder-xyz/out.png");
        let e = image_output(&path, "-o", &[ImageFormat::Png]).unwrap_err();
        assert!(e.to_string().contains("no such folder"), "{e}");
        assert!(!path.parent().unwrap().exists());
    }
}
