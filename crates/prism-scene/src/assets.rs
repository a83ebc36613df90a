//! Where the course's files (`shared/assets`: the path tracer's scenes, the Delft data, the
//! cloth scenes and textures, ...) are found, at run time and never at build time, so that an
//! installed or moved `prism` finds them as the checkout's does.
//!
//! In order: the folder given (`--data DIR`), then `PRISM_DATA`, then, from the executable's
//! folder and from the working folder upwards, the first `shared/assets` or `assets` folder
//! that holds one of the courses' folders. A folder given or named by `PRISM_DATA` that is not
//! a folder is an error, not passed over.

use std::path::{Path, PathBuf};

/// The environment variable that names the course's files.
pub const DATA_ENV: &str = "PRISM_DATA";

/// The folders a course assets folder holds at least one of.
const COURSE_FOLDERS: [&str; 5] = [
    "delft-raytracer",
    "pathtracer",
    "clothsim",
    "meshedit",
    "rasterizer",
];

/// Why the course's files were not found.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AssetsError {
    /// A folder was named (by `--data` or `PRISM_DATA`) that is not a folder.
    #[error("{from} {}: {}", path.display(), if path.exists() { "not a folder" } else { "no such folder" })]
    NotAFolder {
        /// What named it: `--data` or `PRISM_DATA`.
        from: &'static str,
        /// The path named.
        path: PathBuf,
    },
    /// None of the places looked in holds the course's files.
    #[error(
        "the course's files (shared/assets) are in none of {}; give their folder with --data DIR or PRISM_DATA",
        searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    NotFound {
        /// The folders looked in, in order.
        searched: Vec<PathBuf>,
    },
}

/// True if `dir` holds at least one of the courses' folders.
fn holds_course_files(dir: &Path) -> bool {
    COURSE_FOLDERS.iter().any(|f| dir.join(f).is_dir())
}

/// The course's files: `given` (a `--data DIR`), else the folder `PRISM_DATA` names, else the
/// first `shared/assets` or `assets` folder holding a course's folder, looked for from the
/// executable's folder and from the working folder upwards. The path is made plain (no `..`).
///
/// # Errors
/// [`AssetsError::NotAFolder`] if `given` or `PRISM_DATA` is not a folder;
/// [`AssetsError::NotFound`], naming every folder looked in, if none holds them.
pub fn course_assets(given: Option<&Path>) -> Result<PathBuf, AssetsError> {
    let env = std::env::var_os(DATA_ENV).filter(|v| !v.is_empty());
    let exe = std::env::current_exe().ok();
    let cwd = std::env::current_dir().ok();
    let starts = [exe.as_deref().and_then(Path::parent), cwd.as_deref()];
    let upwards = starts.into_iter().flatten().flat_map(Path::ancestors);
    find(given, env.as_deref().map(Path::new), upwards)
}

/// [`course_assets`] with its inputs given: the folder `--data` names, the one `PRISM_DATA`
/// names, and the folders to look in, in order.
fn find<'a>(
    given: Option<&Path>,
    env: Option<&Path>,
    dirs: impl IntoIterator<Item = &'a Path>,
) -> Result<PathBuf, AssetsError> {
    let plain = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    for (from, path) in [("--data", given), (DATA_ENV, env)] {
        if let Some(path) = path {
            if !path.is_dir() {
                return Err(AssetsError::NotAFolder {
                    from,
                    path: path.to_path_buf(),
                });
            }
            return Ok(plain(path));
        }
    }
    let mut searched = Vec::new();
    for dir in dirs {
        for candidate in [dir.join("shared/assets"), dir.join("assets")] {
            if holds_course_files(&candidate) {
                return Ok(plain(&candidate));
            }
            if !searched.contains(&candidate) {
                searched.push(candidate);
            }
        }
    }
    Err(AssetsError::NotFound { searched })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch tree: `root/checkout/target/release` (an executable's folder),
    /// `root/shared/assets/clothsim` (the course's files beside the checkout), `root/elsewhere`.
    fn tree(name: &str) -> PathBuf {
        let root = std::env::temp_dir().join(format!("prism-assets-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        for d in [
            "checkout/target/release",
            "shared/assets/clothsim",
            "elsewhere",
        ] {
            std::fs::create_dir_all(root.join(d)).unwrap();
        }
        root
    }

    /// The folders from `from` up to `root`, as the search walks them (kept inside the
    /// scratch tree, whatever lies above it on this machine).
    fn up(from: &Path, root: &Path) -> Vec<PathBuf> {
        from.ancestors()
            .take_while(|d| d.starts_with(root))
            .map(Path::to_path_buf)
            .collect()
    }

    /// The order of the rules: `--data`, then `PRISM_DATA`, then the folders upwards (from
    /// the executable's folder first).
    #[test]
    fn data_then_environment_then_upwards() {
        let root = tree("order");
        let assets = std::fs::canonicalize(root.join("shared/assets")).unwrap();
        let exe = root.join("checkout/target/release");
        let elsewhere = root.join("elsewhere");
        let from_exe = up(&exe, &root);
        let walk = |dirs: &[PathBuf]| find(None, None, dirs.iter().map(PathBuf::as_path));
        assert_eq!(walk(&from_exe), Ok(assets.clone()));
        assert_eq!(
            walk(&[up(&elsewhere, &root), from_exe.clone()].concat()),
            Ok(assets)
        );
        let given = std::fs::canonicalize(&elsewhere).unwrap();
        let dirs = from_exe.iter().map(PathBuf::as_path);
        assert_eq!(
            find(Some(&elsewhere), None, dirs.clone()),
            Ok(given.clone())
        );
        assert_eq!(find(None, Some(&elsewhere), dirs), Ok(given));
        std::fs::remove_dir_all(&root).unwrap();
    }

    /// A folder named that is not one is an error naming what named it; a search that finds
    /// nothing names every folder it looked in.
    #[test]
    fn what_is_missing_is_named() {
        let root = tree("missing");
        let gone = root.join("gone");
        let none: [&Path; 0] = [];
        assert_eq!(
            find(None, Some(&gone), none).unwrap_err().to_string(),
            format!("PRISM_DATA {}: no such folder", gone.display())
        );
        assert_eq!(
            find(Some(&gone), None, none).unwrap_err().to_string(),
            format!("--data {}: no such folder", gone.display())
        );
        std::fs::remove_dir_all(root.join("shared")).unwrap();
        let elsewhere = root.join("elsewhere");
        let dirs = up(&elsewhere, &root);
        let e = find(None, None, dirs.iter().map(PathBuf::as_path)).unwrap_err();
        let AssetsError::NotFound { searched } = &e else {
            panic!("{e}")
        };
        assert_eq!(searched[0], elsewhere.join("shared/assets"));
        assert!(searched.contains(&root.join("shared/assets")));
        assert!(e
            .to_string()
            .ends_with("give their folder with --data DIR or PRISM_DATA"));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
