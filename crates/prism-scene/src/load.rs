//! [`load`]: a scene file read by the reader its extension names.

use std::path::Path;

use crate::collada::read_collada;
use crate::error::SceneError;
use crate::obj::read_obj_scene;
use crate::render_config::read_render_config;
use crate::scene::{Scene, SceneOptions};

/// Reads the scene in `path` with the reader its extension names (in any letter case):
/// `.dae`, COLLADA (then [`Scene::from_collada`]); `.obj`, a Wavefront OBJ scene with its
/// MTL materials, unlit and not normalised ([`read_obj_scene`]); `.toml`, a Delft render
/// configuration, whose scene is loaded with its lights ([`crate::RenderConfig::load_scene`],
/// presets from the folder its `data_path` names or the copies built into prism); `.xml`, a
/// Mitsuba 3 scene ([`crate::read_mitsuba`], its `$name`s from their `<default>`s).
///
/// # Errors
/// [`SceneError::UnknownFormat`] for another extension, or the reader's located error.
pub fn load(path: &Path, opts: &SceneOptions) -> Result<Scene, SceneError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "dae" => {
            let doc = read_collada(path)?;
            Scene::from_collada(&doc, opts, &path.display().to_string())
        }
        "obj" => read_obj_scene(path, false),
        "toml" => read_render_config(path)?.load_scene(&[]),
        "xml" => Ok(crate::mitsuba::read_mitsuba(path, &[])?.scene),
        _ => Err(SceneError::UnknownFormat {
            path: path.display().to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The extension picks the reader; another is a named error.
    #[test]
    fn extensions_pick_readers() {
        let e = load(Path::new("scene.obj.txt"), &SceneOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "scene.obj.txt: expected a scene file (.dae, .obj, .toml, .xml)"
        );
        let e = load(Path::new("no-such-scene.DAE"), &SceneOptions::default()).unwrap_err();
        assert!(matches!(e, SceneError::Io { .. }), "{e}");
    }
}
