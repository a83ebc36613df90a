//! [`load_delft`]: how a Delft ray-tracer scene named on the command line is found and lit.
//! A name is a TOML render config, an OBJ scene (lit by [`default_obj_lights`]) or a
//! [`Preset`]; preset and config files are looked for in the data folder given, else the
//! staged `delft-raytracer/data` folder ([`staged_data`]), else the copies built into prism.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use prism_image::RgbImage;
use prism_math::{Rgb, Vec3};

use crate::error::SceneError;
use crate::obj::read_obj_scene;
use crate::presets::Preset;
use crate::render_config::{read_render_config, Extras, Features, MeshRef, SceneSource};
use crate::scene::{Light, OrbitCamera, Scene};

/// A Delft scene ready to trace: the scene, its cameras, the features that start on and the
/// config's image size.
#[derive(Clone, Debug)]
pub struct DelftScene {
    /// The scene.
    pub scene: Scene,
    /// The config's cameras (one default camera without a config, or when it has none).
    pub cameras: Vec<OrbitCamera>,
    /// The features that start on: the config's, else [`Features::prism_defaults`].
    pub features: Features,
    /// The config's window size.
    pub window: Option<[u32; 2]>,
    /// The extras' settings (the defaults without a config).
    pub extras: Extras,
    /// The moving meshes: index into the scene's meshes and translation over the shutter.
    pub motion: Vec<(usize, Vec3)>,
    /// The config's environment map, read.
    pub environment: Option<Arc<RgbImage>>,
    /// The file it was read from.
    pub environment_file: Option<PathBuf>,
}

impl MeshRef {
    /// The indices of the meshes of `scene` it names (none if it names none).
    #[must_use]
    pub fn resolve(&self, scene: &Scene) -> Vec<usize> {
        match self {
            MeshRef::Index(i) => (*i < scene.meshes.len())
                .then_some(*i)
                .into_iter()
                .collect(),
            MeshRef::Name(n) => (0..scene.meshes.len())
                .filter(|&i| scene.meshes[i].name == *n)
                .collect(),
        }
    }
}

/// The names of `scene`'s meshes, in order, for messages: `0 "floor", 1 "tallBox"`.
#[must_use]
pub fn mesh_names(scene: &Scene) -> String {
    let names: Vec<String> = (scene.meshes.iter().enumerate())
        .map(|(i, m)| format!("{i} {:?}", m.name))
        .collect();
    if names.is_empty() {
        "none: the scene has no mesh".to_string()
    } else {
        names.join(", ")
    }
}

/// Reads an environment map: a latitude-longitude PNG or JPEG (bytes / 255), OpenEXR or
/// Radiance HDR image, told apart by their first bytes.
///
/// # Errors
/// The file's error: unreadable, not an image, over the decoders' limits, or holding a
/// texel that is negative or not finite.
pub fn read_environment_map(path: &Path) -> Result<RgbImage, SceneError> {
    let bytes = crate::obj::read_bytes(path)?;
    let file = path.display().to_string();
    let bad = |message: String| SceneError::Image {
        path: file.clone(),
        message,
    };
    let image = if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        prism_image::decode_exr(&bytes, &file).map_err(|e| SceneError::Decode(Arc::new(e)))?
    } else if prism_image::is_hdr(&bytes) {
        prism_image::decode_hdr(&bytes, &file).map_err(|e| SceneError::Decode(Arc::new(e)))?
    } else {
        use crate::texture_file::TextureFileError;
        crate::texture_file::decode_texture(&bytes, &file).map_err(|e| match e {
            TextureFileError::Decode(d) => SceneError::Decode(Arc::new(d)),
            TextureFileError::NotAnImage => bad(format!(
                "{e} (an environment map is a PNG, JPEG, OpenEXR or Radiance HDR image)"
            )),
        })?
    };
    if let Some(i) = (image.pixels().iter())
        .position(|p| !(p.r >= 0.0 && p.g >= 0.0 && p.b >= 0.0 && (p.r + p.g + p.b).is_finite()))
    {
        let (x, y) = (i as u32 % image.width(), i as u32 / image.width());
        return Err(bad(format!(
            "texel ({x}, {y}) is {:?}; expected finite, non-negative radiance",
            image.get(x, y)
        )));
    }
    Ok(image)
}

/// What cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum DelftError {
    /// The data folder given is not a folder.
    #[error("--data {}: expected a folder", .0.display())]
    NotAFolder(PathBuf),
    /// The name is no preset, OBJ scene or config.
    #[error(
        "{name}: expected a preset ({}), an .obj scene or a .toml config",
        preset_names()
    )]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The config, OBJ or preset file could not be read.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// `PRISM_DATA` names no folder.
    #[error(transparent)]
    Assets(#[from] crate::AssetsError),
}

/// Something a run should be told while a scene loads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DelftWarning {
    /// A config key without effect in prism.
    Config(prism_math::Warning),
    /// A data folder was given, but the config's `data_path` wins.
    DataFolderIgnored,
    /// The config renders an OBJ and has no lights.
    UnlitObj {
        /// The config file.
        config: String,
    },
}

impl std::fmt::Display for DelftWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DelftWarning::Config(w) => w.fmt(f),
            DelftWarning::DataFolderIgnored => {
                f.write_str("--data has no effect: the config's data_path is used")
            }
            DelftWarning::UnlitObj { config } => write!(
                f,
                "{config}: the scene is an OBJ and the config has no [[lights]]; it renders \
                 black under shading"
            ),
        }
    }
}

/// The presets' names, comma-separated.
fn preset_names() -> String {
    let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
    names.join(", ")
}

/// The course's `delft-raytracer/data` folder, if the course's files are found
/// ([`crate::course_assets`]: `PRISM_DATA`, or a `shared/assets` folder above the executable
/// or the working folder).
///
/// # Errors
/// [`crate::AssetsError::NotAFolder`] if `PRISM_DATA` names no folder (not finding the files
/// at all is no error: the presets have copies built in).
pub fn staged_data() -> Result<Option<PathBuf>, crate::AssetsError> {
    match crate::course_assets(None) {
        Ok(assets) => {
            let dir = assets.join("delft-raytracer/data");
            Ok(dir.is_dir().then_some(dir))
        }
        Err(crate::AssetsError::NotFound { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The light an OBJ scene named on its own gets: a white point light at (-1, 1, -1).
#[must_use]
pub fn default_obj_lights() -> Vec<Light> {
    vec![Light::Point {
        position: Vec3::new(-1.0, 1.0, -1.0),
        intensity: Rgb::WHITE,
    }]
}

/// Loads a Delft scene by name: a `.toml` render config, an `.obj` scene (lit by
/// [`default_obj_lights`]) or a preset name. Preset files come from `data` (the course's
/// files, whose `delft-raytracer/data` is used, or a folder of OBJ files), else the staged
/// folder, else the copies built in; a config's `data_path` replaces both folders. Each
/// warning is handed to `warn` as soon as it is known.
///
/// # Errors
/// [`DelftError::NotAFolder`] if `data` is not a folder, [`DelftError::Unknown`] for a name
/// that is none of the three, [`DelftError::Scene`] for a file that cannot be read.
pub fn load_delft(
    name: &str,
    data: Option<&Path>,
    warn: &mut dyn FnMut(DelftWarning),
) -> Result<DelftScene, DelftError> {
    let mut dirs = Vec::new();
    if let Some(d) = data {
        if !d.is_dir() {
            return Err(DelftError::NotAFolder(d.to_path_buf()));
        }
        // The course's files hold the data folder; a folder of OBJ files is the folder.
        let inner = d.join("delft-raytracer/data");
        dirs.push(if inner.is_dir() {
            inner
        } else {
            d.to_path_buf()
        });
    }
    dirs.extend(staged_data()?);
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".toml") {
        let cfg = read_render_config(Path::new(name))?;
        for w in &cfg.warnings {
            warn(DelftWarning::Config(w.clone()));
        }
        if data.is_some() && cfg.data_path.is_some() {
            warn(DelftWarning::DataFolderIgnored);
        }
        let scene = cfg.load_scene(&dirs)?;
        if matches!(cfg.scene, SceneSource::File(_)) && cfg.lights.is_empty() {
            warn(DelftWarning::UnlitObj {
                config: cfg.file.clone(),
            });
        }
        let cameras = if cfg.cameras.is_empty() {
            vec![OrbitCamera::default()]
        } else {
            cfg.cameras.clone()
        };
        let mut motion = Vec::new();
        for m in &cfg.extras.motion {
            let found = m.mesh.resolve(&scene);
            if found.is_empty() {
                return Err(SceneError::Line {
                    at: m.at.clone(),
                    message: format!(
                        "[[motion]] mesh {}: no such mesh (the scene's meshes: {})",
                        match &m.mesh {
                            MeshRef::Index(i) => i.to_string(),
                            MeshRef::Name(n) => format!("{n:?}"),
                        },
                        mesh_names(&scene)
                    ),
                }
                .into());
            }
            motion.extend(found.into_iter().map(|i| (i, m.velocity)));
        }
        let environment = match &cfg.extras.environment_map {
            Some(e) => Some(Arc::new(read_environment_map(&e.path).map_err(|err| {
                SceneError::Line {
                    at: e.at.clone(),
                    message: format!("environment_map: {err}"),
                }
            })?)),
            None => None,
        };
        return Ok(DelftScene {
            scene,
            cameras,
            features: cfg.features,
            window: cfg.window_size,
            extras: cfg.extras.extras,
            motion,
            environment,
            environment_file: cfg.extras.environment_map.map(|e| e.path),
        });
    }
    let scene = if lower.ends_with(".obj") {
        let mut s = read_obj_scene(Path::new(name), false)?;
        s.lights = default_obj_lights();
        s
    } else {
        let preset = Preset::from_name(name).ok_or_else(|| DelftError::Unknown {
            name: name.to_string(),
        })?;
        preset.load(&dirs)?
    };
    Ok(DelftScene {
        scene,
        cameras: vec![OrbitCamera::default()],
        features: Features::prism_defaults(),
        window: None,
        extras: Extras::default(),
        motion: Vec::new(),
        environment: None,
        environment_file: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A preset loads with the default camera and features, and warns of nothing.
    #[test]
    fn preset_loads_with_defaults() {
        let mut warnings = Vec::new();
        let d = load_delft("single-triangle", None, &mut |w| warnings.push(w)).unwrap();
        assert_eq!(d.cameras, vec![OrbitCamera::default()]);
        assert_eq!(d.features, Features::prism_defaults());
        assert_eq!(d.window, None);
        assert!(warnings.is_empty());
        assert!(!d.scene.meshes.is_empty() || !d.scene.spheres.is_empty());
    }

    /// Unknown names list the presets; a data folder that is not one is refused.
    #[test]
    fn bad_names_and_folders_are_refused() {
        let e = load_delft("no-such-scene", None, &mut |_| {}).unwrap_err();
        assert!(matches!(e, DelftError::Unknown { .. }));
        assert!(e.to_string().contains("single-triangle"), "{e}");
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
        let e = load_delft("cube", Some(&file), &mut |_| {}).unwrap_err();
        assert!(matches!(e, DelftError::NotAFolder(_)), "{e}");
    }

    /// An OBJ config without lights warns that it renders black, and takes the config's
    /// window and cameras.
    #[test]
    fn config_warnings_reach_the_caller() {
        let dir = std::env::temp_dir().join(format!("prism-delft-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let cfg = dir.join("r.toml");
        std::fs::write(
            &cfg,
            "data_path = \".\"\nscene = \"tri.obj\"\nwindow_size = [8, 6]\n",
        )
        .unwrap();
        let mut warnings = Vec::new();
        let d = load_delft(cfg.to_str().unwrap(), Some(&dir), &mut |w| warnings.push(w));
        let d = d.unwrap();
        assert_eq!(d.window, Some([8, 6]));
        assert!(warnings.contains(&DelftWarning::DataFolderIgnored));
        assert!(warnings
            .iter()
            .any(|w| matches!(w, DelftWarning::UnlitObj { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A lone OBJ is lit by the default point light.
    #[test]
    fn lone_obj_gets_the_default_light() {
        let dir = std::env::temp_dir().join(format!("prism-delft-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("tri.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let d = load_delft(obj.to_str().unwrap(), None, &mut |_| {}).unwrap();
        assert_eq!(d.scene.lights, default_obj_lights());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
