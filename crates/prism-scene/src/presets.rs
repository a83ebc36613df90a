//! [`Preset`], the Delft ray tracer's built-in scenes: which OBJ each loads, whether it is
//! normalised, its own lights, and the small files built into prism.

use std::path::PathBuf;

use prism_math::{Rgb, Vec3};

use crate::error::SceneError;
use crate::obj::{parse_obj_scene, read_obj_scene};
use crate::scene::{Light, Material, OrbitCamera, Scene, SceneSphere};

/// One of the template's scenes, in the order of its enum (the config's integer).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Preset {
    /// `triangle.obj`, kd forced to 1, a point light at (-1, 1, -1).
    SingleTriangle,
    /// `cube.obj`, a segment light.
    Cube,
    /// `cube-textured.obj`, a point light at (-1, 1.5, -1).
    CubeTextured,
    /// The mirror Cornell box, normalised, a point light at (0, 0.58, 0).
    CornellBox,
    /// The mirror Cornell box, normalised, a parallelogram light with four colours.
    CornellBoxParallelogramLight,
    /// `monkey.obj`, normalised, two point lights.
    Monkey,
    /// `teapot.obj`, normalised, a point light at (-1, 1, -1).
    Teapot,
    /// `dragon.obj` (not shipped), normalised, a point light at (-1, 1, -1).
    Dragon,
    /// Three analytic spheres, a point light of colour 15 at (3, 0, 3).
    Spheres,
    /// `custom.obj`, not normalised, a point light at (-1, 1, -1).
    Custom,
}

/// The files built into prism, by name.
const EMBEDDED: [(&str, &[u8]); 8] = [
    ("triangle.obj", include_bytes!("../data/delft/triangle.obj")),
    ("cube.obj", include_bytes!("../data/delft/cube.obj")),
    ("cube.mtl", include_bytes!("../data/delft/cube.mtl")),
    (
        "cube-textured.obj",
        include_bytes!("../data/delft/cube-textured.obj"),
    ),
    (
        "cube-textured.mtl",
        include_bytes!("../data/delft/cube-textured.mtl"),
    ),
    ("default.png", include_bytes!("../data/delft/default.png")),
    (
        "CornellBox-Mirror-Rotated.obj",
        include_bytes!("../data/delft/CornellBox-Mirror-Rotated.obj"),
    ),
    (
        "CornellBox-Mirror-Rotated.mtl",
        include_bytes!("../data/delft/CornellBox-Mirror-Rotated.mtl"),
    ),
];

impl Preset {
    /// Every preset, in the template's order.
    pub const ALL: [Preset; 10] = [
        Preset::SingleTriangle,
        Preset::Cube,
        Preset::CubeTextured,
        Preset::CornellBox,
        Preset::CornellBoxParallelogramLight,
        Preset::Monkey,
        Preset::Teapot,
        Preset::Dragon,
        Preset::Spheres,
        Preset::Custom,
    ];

    /// The name prism prints, in kebab case (`cornell-box-parallelogram-light`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Preset::SingleTriangle => "single-triangle",
            Preset::Cube => "cube",
            Preset::CubeTextured => "cube-textured",
            Preset::CornellBox => "cornell-box",
            Preset::CornellBoxParallelogramLight => "cornell-box-parallelogram-light",
            Preset::Monkey => "monkey",
            Preset::Teapot => "teapot",
            Preset::Dragon => "dragon",
            Preset::Spheres => "spheres",
            Preset::Custom => "custom",
        }
    }

    /// The preset named `s`, in any letter case, with words joined by `_`, `-` or nothing.
    #[must_use]
    pub fn from_name(s: &str) -> Option<Preset> {
        let key: String = s
            .chars()
            .filter(|&c| c != '_' && c != '-')
            .collect::<String>()
            .to_ascii_lowercase();
        Preset::ALL
            .into_iter()
            .find(|p| p.name().replace('-', "") == key)
    }

    /// The preset whose name is nearest to `s` by edit distance (letters inserted, deleted
    /// or changed), if it is at most 3 away: the suggestion for a mistyped name.
    #[must_use]
    pub fn nearest(s: &str) -> Option<Preset> {
        let key = s.to_ascii_lowercase();
        Preset::ALL
            .into_iter()
            .map(|p| (prism_math::edit_distance(&key, p.name()), p))
            .filter(|&(d, _)| d <= 3)
            .min_by_key(|&(d, _)| d)
            .map(|(_, p)| p)
    }

    /// The preset with the template's enum value `i` (0 to 9).
    #[must_use]
    pub fn from_index(i: i64) -> Option<Preset> {
        usize::try_from(i)
            .ok()
            .and_then(|i| Preset::ALL.get(i).copied())
    }

    /// The OBJ file it loads (`None` for the spheres).
    #[must_use]
    pub fn file(self) -> Option<&'static str> {
        match self {
            Preset::SingleTriangle => Some("triangle.obj"),
            Preset::Cube => Some("cube.obj"),
            Preset::CubeTextured => Some("cube-textured.obj"),
            Preset::CornellBox | Preset::CornellBoxParallelogramLight => {
                Some("CornellBox-Mirror-Rotated.obj")
            }
            Preset::Monkey => Some("monkey.obj"),
            Preset::Teapot => Some("teapot.obj"),
            Preset::Dragon => Some("dragon.obj"),
            Preset::Spheres => None,
            Preset::Custom => Some("custom.obj"),
        }
    }

    /// True if its mesh is moved to its vertices' mean and scaled to the unit sphere.
    #[must_use]
    pub fn normalized(self) -> bool {
        matches!(
            self,
            Preset::CornellBox
                | Preset::CornellBoxParallelogramLight
                | Preset::Monkey
                | Preset::Teapot
                | Preset::Dragon
        )
    }

    /// Its own lights (the template's table).
    #[must_use]
    pub fn lights(self) -> Vec<Light> {
        let point = |x: f32, y: f32, z: f32, c: f32| Light::Point {
            position: Vec3::new(x, y, z),
            intensity: Rgb::splat(c),
        };
        match self {
            Preset::SingleTriangle | Preset::Teapot | Preset::Dragon | Preset::Custom => {
                vec![point(-1.0, 1.0, -1.0, 1.0)]
            }
            Preset::Cube => vec![Light::Segment {
                endpoints: [Vec3::new(1.5, 0.5, -0.6), Vec3::new(-1.0, 0.5, -0.5)],
                colors: [Rgb::new(0.9, 0.2, 0.1), Rgb::new(0.2, 1.0, 0.3)],
            }],
            Preset::CubeTextured => vec![point(-1.0, 1.5, -1.0, 1.0)],
            Preset::CornellBox => vec![point(0.0, 0.58, 0.0, 1.0)],
            Preset::CornellBoxParallelogramLight => vec![Light::Parallelogram {
                corner: Vec3::new(-0.2, 0.5, 0.0),
                edges: [Vec3::new(0.4, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.4)],
                colors: [
                    Rgb::new(1.0, 0.0, 0.0),
                    Rgb::new(0.0, 1.0, 0.0),
                    Rgb::new(0.0, 0.0, 1.0),
                    Rgb::new(0.0, 1.0, 1.0),
                ],
                facing: None,
            }],
            Preset::Monkey => vec![point(-1.0, 1.0, -1.0, 1.0), point(1.0, -1.0, -1.0, 1.0)],
            Preset::Spheres => vec![point(3.0, 0.0, 3.0, 15.0)],
        }
    }

    /// Loads the preset: its OBJ from the first of `data_dirs` that holds it, else from
    /// the copy built into prism (triangle, cubes, Cornell box), with its own lights.
    ///
    /// # Errors
    /// [`SceneError::PresetFileMissing`] if no folder holds the file and none is built in;
    /// else the OBJ reader's located error.
    pub fn load(self, data_dirs: &[PathBuf]) -> Result<Scene, SceneError> {
        let mut scene = match self.file() {
            None => spheres(),
            Some(name) => {
                let found = data_dirs.iter().map(|d| d.join(name)).find(|p| p.is_file());
                match found {
                    Some(path) => read_obj_scene(&path, self.normalized())?,
                    None => {
                        // `custom.obj` is a copy of the cube.
                        let embedded_name = if self == Preset::Custom {
                            "cube.obj"
                        } else {
                            name
                        };
                        let Some(bytes) = embedded(embedded_name) else {
                            return Err(SceneError::PresetFileMissing {
                                preset: self.name(),
                                file: name,
                                searched: data_dirs
                                    .iter()
                                    .map(|d| d.display().to_string())
                                    .collect(),
                            });
                        };
                        let text = String::from_utf8_lossy(bytes);
                        let companions = |n: &str| {
                            embedded(n)
                                .map(<[u8]>::to_vec)
                                .ok_or_else(|| SceneError::NotAFile {
                                    path: format!("(built in) {n}"),
                                })
                        };
                        parse_obj_scene(
                            &text,
                            &format!("(built in) {name}"),
                            &companions,
                            self.normalized(),
                        )?
                    }
                }
            }
        };
        if self == Preset::SingleTriangle {
            for m in &mut scene.materials {
                if let Material::Phong { kd, .. } = m {
                    *kd = Rgb::WHITE;
                }
            }
        }
        scene.lights = self.lights();
        Ok(scene)
    }
}

/// A file built into prism.
fn embedded(name: &str) -> Option<&'static [u8]> {
    EMBEDDED.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
}

/// The spheres preset: three diffuse spheres, ks 0.
fn spheres() -> Scene {
    let phong = |r: f32, g: f32, b: f32| Material::Phong {
        kd: Rgb::new(r, g, b),
        ks: Rgb::BLACK,
        shininess: 1.0,
        kd_texture: None,
        transparency: 1.0,
    };
    let sphere = |x: f32, y: f32, z: f32, radius: f32, material: usize| SceneSphere {
        center: Vec3::new(x, y, z),
        radius,
        material,
        inward: false,
        to_local: None,
    };
    Scene {
        meshes: Vec::new(),
        spheres: vec![
            sphere(3.0, -2.0, 10.2, 1.0, 0),
            sphere(-2.0, 2.0, 4.0, 2.0, 1),
            sphere(0.0, 0.0, 6.0, 0.75, 2),
        ],
        materials: vec![
            phong(0.8, 0.2, 0.2),
            phong(0.6, 0.8, 0.2),
            phong(0.2, 0.2, 0.8),
        ],
        material_names: vec!["red".into(), "green".into(), "blue".into()],
        one_sided: Vec::new(),
        lights: Vec::new(),
        camera: OrbitCamera::default().to_camera(1.0),
        warnings: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The config's names and integers reach every preset; other spellings do not.
    #[test]
    fn names_and_indices() {
        for (i, p) in Preset::ALL.into_iter().enumerate() {
            assert_eq!(Preset::from_index(i as i64), Some(p));
            assert_eq!(Preset::from_name(p.name()), Some(p));
            assert_eq!(Preset::from_name(&p.name().replace('-', "_")), Some(p));
            assert_eq!(Preset::from_name(&p.name().to_uppercase()), Some(p));
        }
        assert_eq!(
            Preset::from_name("CornellBoxParallelogramLight"),
            Some(Preset::CornellBoxParallelogramLight)
        );
        assert_eq!(Preset::from_name("cornell"), None);
        assert_eq!(Preset::from_index(10), None);
        assert_eq!(Preset::from_index(-1), None);
    }

    /// The built-in presets load with no data folder; the Cornell box is normalised (its
    /// vertices' mean at the origin, the farthest at distance 1).
    #[test]
    fn built_in_presets_load_anywhere() {
        for p in [
            Preset::SingleTriangle,
            Preset::Cube,
            Preset::CubeTextured,
            Preset::CornellBox,
            Preset::CornellBoxParallelogramLight,
            Preset::Spheres,
            Preset::Custom,
        ] {
            let s = p.load(&[]).unwrap();
            assert_eq!(s.lights, p.lights());
        }
        let s = Preset::CornellBox.load(&[]).unwrap();
        let all: Vec<Vec3> = s.meshes.iter().flat_map(|m| m.positions.clone()).collect();
        let mean = all.iter().fold(Vec3::ZERO, |a, &p| a + p) / all.len() as f32;
        assert!(mean.length() < 1e-5, "{mean}");
        let far = all.iter().map(|p| p.length()).fold(0.0, f32::max);
        assert!((far - 1.0).abs() < 1e-5);
        assert_eq!(s.materials.len(), 8);
        let e = Preset::Monkey
            .load(&[PathBuf::from("/nonexistent")])
            .unwrap_err();
        assert!(e.to_string().contains("monkey.obj"), "{e}");
    }
}

#[cfg(test)]
mod suggestion_tests {
    use super::*;

    /// Closed forms of the edit distance, and the suggestion for typical typos.
    #[test]
    fn mistyped_preset_names_find_the_preset() {
        assert_eq!(
            Preset::nearest("cornel-box"),
            Some(Preset::from_name("cornell-box").unwrap())
        );
        assert_eq!(
            Preset::nearest("tepot"),
            Some(Preset::from_name("teapot").unwrap())
        );
        assert_eq!(Preset::nearest("zzzzzzzzzz"), None);
    }
}
