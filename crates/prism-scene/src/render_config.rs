//! [`RenderConfig`], the Delft ray tracer's TOML render configuration: the scene (a preset
//! or an OBJ), data and output folders, window size, feature flags, cameras and lights.
//! Every key is checked: an unknown key, a value of the wrong type or an impossible value
//! is an error naming the file and line.

use std::path::{Path, PathBuf};

use prism_math::Loc;
use prism_math::{LineIndex, Rgb, Vec3};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::SceneError;
use crate::obj::{read_obj_scene, read_text_within};
use crate::presets::Preset;
use crate::scene::{Light, OrbitCamera, Scene};
pub use extras::{
    EnvironmentMapFile, Extras, ExtrasTable, MeshRef, Motion, MAX_EXTENT, MAX_EXTRA_SAMPLES,
};

/// Largest image side a config may ask for.
pub const MAX_WINDOW_SIDE: u32 = 16384;
/// Most pixels a config may ask for (64 M).
pub const MAX_WINDOW_PIXELS: u64 = 1 << 26;

/// Largest render config read: its TOML document takes about fifty times its size in
/// memory, so this bounds a config's reading at about 200 MB.
pub const MAX_CONFIG_BYTES: u64 = 4 << 20;

/// Largest colour value a light may have.
pub const MAX_COLOR: f32 = 1e6;

/// The template's feature switches; all default to off.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    /// Phong shading (off: the pixel is kd).
    pub shading: bool,
    /// Mirror reflection.
    pub recursive: bool,
    /// Shadows from point lights.
    pub hard_shadow: bool,
    /// Segment and parallelogram lights, sampled, with shadows.
    pub soft_shadow: bool,
    /// Interpolated vertex normals.
    pub normal_interp: bool,
    /// `map_Kd` textures.
    pub texture_mapping: bool,
    /// The BVH (off: every ray is tested against every primitive).
    pub accel_structure: bool,
    /// Bloom on the final image.
    pub bloom: bool,
    /// Several jittered rays per pixel.
    pub multiple_rays_per_pixel: bool,
    /// Transparency from the MTL's `d`.
    pub transparency: bool,
    /// Bilinear texture filtering (off: nearest).
    pub bilinear: bool,
    /// A thin lens: depth of field.
    pub depth_of_field: bool,
    /// Meshes that move over the shutter interval.
    pub motion_blur: bool,
    /// Reflections sampled from the Phong lobe instead of the one mirror ray.
    pub glossy_reflection: bool,
    /// Rays that miss see the environment map.
    pub environment_mapping: bool,
    /// Textures filtered by ray cones over a mip chain.
    pub mipmap: bool,
    /// The BVH built by binned SAH (off: split at the centroid median).
    pub sah_binning: bool,
}

impl Features {
    /// The switches' names, as `--enable` and the viewer's status line spell them.
    pub const NAMES: [&'static str; 17] = [
        "shading",
        "recursive",
        "hard-shadow",
        "soft-shadow",
        "normal-interp",
        "texture",
        "bilinear",
        "bvh",
        "bloom",
        "transparency",
        "multi-rays",
        "dof",
        "motion-blur",
        "glossy",
        "env-map",
        "mipmap",
        "sah",
    ];

    /// The switch called `name` (one of [`Features::NAMES`]).
    pub fn switch(&mut self, name: &str) -> Option<&mut bool> {
        Some(match name {
            "shading" => &mut self.shading,
            "recursive" => &mut self.recursive,
            "hard-shadow" => &mut self.hard_shadow,
            "soft-shadow" => &mut self.soft_shadow,
            "normal-interp" => &mut self.normal_interp,
            "texture" => &mut self.texture_mapping,
            "bilinear" => &mut self.bilinear,
            "bvh" => &mut self.accel_structure,
            "bloom" => &mut self.bloom,
            "transparency" => &mut self.transparency,
            "multi-rays" => &mut self.multiple_rays_per_pixel,
            "dof" => &mut self.depth_of_field,
            "motion-blur" => &mut self.motion_blur,
            "glossy" => &mut self.glossy_reflection,
            "env-map" => &mut self.environment_mapping,
            "mipmap" => &mut self.mipmap,
            "sah" => &mut self.sah_binning,
            _ => return None,
        })
    }

    /// prism's switches when no config sets them: the template's features and SAH binning
    /// on; bloom, transparency, multiple rays per pixel and the other extras off.
    #[must_use]
    pub fn prism_defaults() -> Features {
        Features {
            shading: true,
            recursive: true,
            hard_shadow: true,
            soft_shadow: true,
            normal_interp: true,
            texture_mapping: true,
            accel_structure: true,
            bilinear: true,
            sah_binning: true,
            ..Features::default()
        }
    }
}

/// What a config renders.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    /// A built-in scene with its own lights.
    Preset(Preset),
    /// An OBJ file (relative to the data folder), not normalised, lit by the config's lights.
    File(PathBuf),
}

/// A render configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderConfig {
    /// The file it was read from.
    pub file: String,
    /// `command_line_rendering` (prism always renders from the command line).
    pub command_line_rendering: bool,
    /// `window_size`, the image size.
    pub window_size: Option<[u32; 2]>,
    /// `data_path`, resolved against the config's folder; `None` for `"default"` or absent.
    pub data_path: Option<PathBuf>,
    /// `scene` (the single triangle when absent).
    pub scene: SceneSource,
    /// `output_dir`, resolved against the config's folder.
    pub output_dir: Option<PathBuf>,
    /// `[features]` and `[features.extra]`.
    pub features: Features,
    /// `[[cameras]]`, one image each (the default camera when there are none).
    pub cameras: Vec<OrbitCamera>,
    /// `[[lights]]`, used by OBJ scenes (presets bring their own).
    pub lights: Vec<Light>,
    /// `[extras]` and `[[motion]]`.
    pub extras: ExtrasTable,
    /// Keys read but without effect in prism, one message each.
    pub warnings: Vec<prism_math::Warning>,
}

/// Reads a render configuration.
///
/// # Errors
/// A located [`SceneError`] for unreadable or malformed files.
pub fn read_render_config(path: &Path) -> Result<RenderConfig, SceneError> {
    let text = read_text_within(path, MAX_CONFIG_BYTES)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_render_config(&text, &path.display().to_string(), &base)
}

/// Reads a render configuration from text; `file` names it in errors and `base` is the
/// folder relative paths start from.
///
/// # Errors
/// A located [`SceneError`] for malformed text, unknown keys, wrong types and impossible
/// values (zero field of view, zero-area light, absurd window size); text over
/// [`MAX_CONFIG_BYTES`].
pub fn parse_render_config(
    text: &str,
    file: &str,
    base: &Path,
) -> Result<RenderConfig, SceneError> {
    if text.len() as u64 > MAX_CONFIG_BYTES {
        return Err(SceneError::TooLarge {
            path: file.to_string(),
            bytes: text.len() as u64,
            limit: MAX_CONFIG_BYTES,
        });
    }
    let lines = LineIndex::new(text);
    let cx = Cx {
        file,
        lines: &lines,
    };
    let root = DeTable::parse(text).map_err(|e| SceneError::Line {
        at: Loc::line(file, lines.line(e.span().map_or(0, |s| s.start))),
        message: format!("expected TOML: {}", e.message()),
    })?;
    let root = root.get_ref();
    cx.known_keys(
        root,
        &[
            "command_line_rendering",
            "window_size",
            "data_path",
            "scene",
            "output_dir",
            "features",
            "cameras",
            "lights",
            "extras",
            "motion",
        ],
        "the top level",
    )?;
    let mut cfg = RenderConfig {
        file: file.to_string(),
        command_line_rendering: true,
        window_size: None,
        data_path: None,
        scene: SceneSource::Preset(Preset::SingleTriangle),
        output_dir: None,
        features: Features::default(),
        cameras: Vec::new(),
        lights: Vec::new(),
        extras: ExtrasTable::default(),
        warnings: Vec::new(),
    };
    if let Some(v) = root.get("command_line_rendering") {
        cfg.command_line_rendering = cx.boolean(v, "command_line_rendering")?;
    }
    if let Some(v) = root.get("window_size") {
        let [w, h] = cx.array::<2>(v, "window_size")?.map(|x| x.clone());
        let side = |x: &Spanned<DeValue<'_>>| -> Result<u32, SceneError> {
            let n = cx.integer(x, "window_size")?;
            if !(1..=i64::from(MAX_WINDOW_SIDE)).contains(&n) {
                return Err(cx.err(
                    x,
                    format!("window_size: expected sides from 1 to {MAX_WINDOW_SIDE}, found {n}"),
                ));
            }
            Ok(n as u32)
        };
        let (w, h) = (side(&w)?, side(&h)?);
        if u64::from(w) * u64::from(h) > MAX_WINDOW_PIXELS {
            return Err(cx.err(
                v,
                format!("window_size: {w} x {h} is over the limit of {MAX_WINDOW_PIXELS} pixels"),
            ));
        }
        cfg.window_size = Some([w, h]);
    }
    if let Some(v) = root.get("data_path") {
        let s = cx.string(v, "data_path")?;
        if s != "default" {
            cfg.data_path = Some(base.join(s));
        }
    }
    if let Some(v) = root.get("output_dir") {
        cfg.output_dir = Some(base.join(cx.string(v, "output_dir")?));
    }
    if let Some(v) = root.get("scene") {
        cfg.scene = match v.get_ref() {
            DeValue::Integer(_) => {
                let i = cx.integer(v, "scene")?;
                SceneSource::Preset(Preset::from_index(i).ok_or_else(|| {
                    cx.err(
                        v,
                        format!("scene: expected a preset number from 0 to 9, found {i}"),
                    )
                })?)
            }
            DeValue::String(s) => match Preset::from_name(s) {
                Some(p) => SceneSource::Preset(p),
                None if s.to_ascii_lowercase().ends_with(".obj") => {
                    SceneSource::File(PathBuf::from(s.as_ref()))
                }
                None => {
                    let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
                    return Err(cx.err(
                        v,
                        format!(
                            "scene: expected a preset ({}) or an .obj file, found {s:?}",
                            names.join(", ")
                        ),
                    ));
                }
            },
            other => {
                return Err(cx.err(
                    v,
                    format!(
                        "scene: expected a preset name or number or an .obj path, found {}",
                        other.type_str()
                    ),
                ))
            }
        };
    }
    if let Some(v) = root.get("features") {
        cfg.features = cx.features(v)?;
    }
    if let Some(v) = root.get("cameras") {
        for c in cx.tables(v, "cameras")? {
            cfg.cameras.push(cx.camera(c)?);
        }
    }
    if let Some(v) = root.get("lights") {
        for l in cx.tables(v, "lights")? {
            cfg.lights.push(cx.light(l)?);
        }
    }
    if let Some(v) = root.get("motion") {
        cx.motions(v, &mut cfg.extras)?;
    }
    if let Some(v) = root.get("extras") {
        cx.extras(v, base, &mut cfg.extras)?;
    }
    Ok(cfg)
}

impl RenderConfig {
    /// The folders a preset's or OBJ's file is looked for in: `data_path` if the config
    /// sets one, else `defaults`.
    #[must_use]
    pub fn data_dirs(&self, defaults: &[PathBuf]) -> Vec<PathBuf> {
        match &self.data_path {
            Some(p) => vec![p.clone()],
            None => defaults.to_vec(),
        }
    }

    /// Loads the scene: a preset with its own lights, or an OBJ from the first data folder
    /// that holds it (not normalised) with the config's lights.
    ///
    /// # Errors
    /// The reader's located error, or a missing file named with the folders searched.
    pub fn load_scene(&self, defaults: &[PathBuf]) -> Result<Scene, SceneError> {
        let dirs = self.data_dirs(defaults);
        match &self.scene {
            SceneSource::Preset(p) => p.load(&dirs),
            SceneSource::File(rel) => {
                let path = if rel.is_absolute() {
                    rel.clone()
                } else {
                    dirs.iter()
                        .map(|d| d.join(rel))
                        .find(|p| p.is_file())
                        .unwrap_or_else(|| dirs.first().map_or(rel.clone(), |d| d.join(rel)))
                };
                let mut scene = read_obj_scene(&path, false)?;
                scene.lights.clone_from(&self.lights);
                Ok(scene)
            }
        }
    }
}

/// The file and its line table, for located errors.
struct Cx<'a> {
    file: &'a str,
    lines: &'a LineIndex<'a>,
}

type Val<'i> = Spanned<DeValue<'i>>;

impl Cx<'_> {
    fn err<T>(&self, at: &Spanned<T>, message: String) -> SceneError {
        SceneError::Line {
            at: self.loc(at),
            message,
        }
    }

    fn loc<T>(&self, at: &Spanned<T>) -> Loc {
        Loc::line(self.file, self.lines.line(at.span().start))
    }

    fn known_keys(&self, t: &DeTable<'_>, known: &[&str], place: &str) -> Result<(), SceneError> {
        for (k, _) in t.iter() {
            if !known.contains(&k.get_ref().as_ref()) {
                return Err(self.err(
                    k,
                    format!(
                        "unknown key {:?} in {place} (expected one of: {})",
                        k.get_ref(),
                        known.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    fn boolean(&self, v: &Val<'_>, key: &str) -> Result<bool, SceneError> {
        v.get_ref().as_bool().ok_or_else(|| {
            self.err(
                v,
                format!(
                    "{key}: expected true or false, found {}",
                    v.get_ref().type_str()
                ),
            )
        })
    }

    fn string<'v>(&self, v: &'v Val<'_>, key: &str) -> Result<&'v str, SceneError> {
        v.get_ref().as_str().ok_or_else(|| {
            self.err(
                v,
                format!("{key}: expected a string, found {}", v.get_ref().type_str()),
            )
        })
    }

    fn integer(&self, v: &Val<'_>, key: &str) -> Result<i64, SceneError> {
        match v.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .map_err(|_| self.err(v, format!("{key}: integer {} is out of range", i.as_str()))),
            other => Err(self.err(
                v,
                format!("{key}: expected an integer, found {}", other.type_str()),
            )),
        }
    }

    /// A finite number, written as an integer or a float.
    fn number(&self, v: &Val<'_>, key: &str) -> Result<f32, SceneError> {
        let x = match v.get_ref() {
            DeValue::Integer(_) => self.integer(v, key)? as f64,
            DeValue::Float(f) => f
                .as_str()
                .replace('_', "")
                .parse::<f64>()
                .unwrap_or(f64::NAN),
            other => {
                return Err(self.err(
                    v,
                    format!("{key}: expected a number, found {}", other.type_str()),
                ))
            }
        };
        let y = x as f32;
        if !y.is_finite() {
            return Err(self.err(v, format!("{key}: expected a finite number, found {x}")));
        }
        Ok(y)
    }

    fn array<'v, 'i, const N: usize>(
        &self,
        v: &'v Val<'i>,
        key: &str,
    ) -> Result<[&'v Val<'i>; N], SceneError> {
        let a = v.get_ref().as_array().ok_or_else(|| {
            self.err(
                v,
                format!(
                    "{key}: expected an array of {N}, found {}",
                    v.get_ref().type_str()
                ),
            )
        })?;
        if a.len() != N {
            return Err(self.err(
                v,
                format!("{key}: expected {N} elements, found {}", a.len()),
            ));
        }
        Ok(std::array::from_fn(|i| &a[i]))
    }

    fn vec3(&self, v: &Val<'_>, key: &str) -> Result<Vec3, SceneError> {
        let [x, y, z] = self.array::<3>(v, key)?;
        Ok(Vec3::new(
            self.number(x, key)?,
            self.number(y, key)?,
            self.number(z, key)?,
        ))
    }

    fn color(&self, v: &Val<'_>, key: &str) -> Result<Rgb, SceneError> {
        let c = self.vec3(v, key)?;
        if c.min_element() < 0.0 || c.max_element() > MAX_COLOR {
            return Err(self.err(
                v,
                format!("{key}: expected colour values from 0 to {MAX_COLOR}, found {c}"),
            ));
        }
        Ok(Rgb::new(c.x, c.y, c.z))
    }

    fn tables<'v, 'i>(&self, v: &'v Val<'i>, key: &str) -> Result<Vec<&'v Val<'i>>, SceneError> {
        let a = v.get_ref().as_array().ok_or_else(|| {
            self.err(
                v,
                format!(
                    "{key}: expected [[{key}]] tables, found {}",
                    v.get_ref().type_str()
                ),
            )
        })?;
        a.iter()
            .map(|t| {
                if t.get_ref().is_table() {
                    Ok(t)
                } else {
                    Err(self.err(
                        t,
                        format!("{key}: expected a table, found {}", t.get_ref().type_str()),
                    ))
                }
            })
            .collect()
    }

    fn required<'v, 'i>(
        &self,
        t: &'v DeTable<'i>,
        at: &Val<'_>,
        key: &str,
        place: &str,
    ) -> Result<&'v Val<'i>, SceneError> {
        t.get(key)
            .ok_or_else(|| self.err(at, format!("{place}: missing required key {key:?}")))
    }

    fn features(&self, v: &Val<'_>) -> Result<Features, SceneError> {
        let t = v.get_ref().as_table().ok_or_else(|| {
            self.err(
                v,
                format!(
                    "features: expected a table, found {}",
                    v.get_ref().type_str()
                ),
            )
        })?;
        let main = [
            "enable_shading",
            "enable_recursive",
            "enable_hard_shadow",
            "enable_soft_shadow",
            "enable_normal_interp",
            "enable_texture_mapping",
            "enable_accel_structure",
            "extra",
        ];
        self.known_keys(t, &main, "[features]")?;
        let mut f = Features::default();
        let flag = |key: &str, t: &DeTable<'_>| -> Result<bool, SceneError> {
            t.get(key).map_or(Ok(false), |v| self.boolean(v, key))
        };
        f.shading = flag("enable_shading", t)?;
        f.recursive = flag("enable_recursive", t)?;
        f.hard_shadow = flag("enable_hard_shadow", t)?;
        f.soft_shadow = flag("enable_soft_shadow", t)?;
        f.normal_interp = flag("enable_normal_interp", t)?;
        f.texture_mapping = flag("enable_texture_mapping", t)?;
        f.accel_structure = flag("enable_accel_structure", t)?;
        if let Some(x) = t.get("extra") {
            let e = x.get_ref().as_table().ok_or_else(|| {
                self.err(
                    x,
                    format!(
                        "features.extra: expected a table, found {}",
                        x.get_ref().type_str()
                    ),
                )
            })?;
            let extra = [
                "enable_bloom_effect",
                "enable_multiple_rays_per_pixel",
                "enable_motion_blur",
                "enable_depth_of_field",
                "enable_glossy_reflection",
                "enable_transparency",
                "enable_bvh_sah_binning",
                "enable_environment_mapping",
                "enable_bilinear_texture_filtering",
                "enable_mipmap_texture_filtering",
            ];
            self.known_keys(e, &extra, "[features.extra]")?;
            f.bloom = flag("enable_bloom_effect", e)?;
            f.multiple_rays_per_pixel = flag("enable_multiple_rays_per_pixel", e)?;
            f.transparency = flag("enable_transparency", e)?;
            f.bilinear = flag("enable_bilinear_texture_filtering", e)?;
            f.sah_binning = flag("enable_bvh_sah_binning", e)?;
            f.motion_blur = flag("enable_motion_blur", e)?;
            f.depth_of_field = flag("enable_depth_of_field", e)?;
            f.glossy_reflection = flag("enable_glossy_reflection", e)?;
            f.environment_mapping = flag("enable_environment_mapping", e)?;
            f.mipmap = flag("enable_mipmap_texture_filtering", e)?;
        }
        Ok(f)
    }

    fn camera(&self, v: &Val<'_>) -> Result<OrbitCamera, SceneError> {
        let t = v.get_ref().as_table().expect("tables() checked");
        self.known_keys(
            t,
            &[
                "field_of_view",
                "distance_from_look_at",
                "look_at",
                "rotation",
            ],
            "[[cameras]]",
        )?;
        let mut c = OrbitCamera::default();
        if let Some(x) = t.get("field_of_view") {
            c.fov_y = self.number(x, "field_of_view")?;
            if !(c.fov_y > 0.0 && c.fov_y < 180.0) {
                return Err(self.err(
                    x,
                    format!(
                        "field_of_view: expected degrees strictly between 0 and 180, found {}",
                        c.fov_y
                    ),
                ));
            }
        }
        if let Some(x) = t.get("distance_from_look_at") {
            c.distance = self.number(x, "distance_from_look_at")?;
            if c.distance < 0.0 {
                return Err(self.err(
                    x,
                    format!(
                        "distance_from_look_at: expected at least 0, found {}",
                        c.distance
                    ),
                ));
            }
        }
        if let Some(x) = t.get("look_at") {
            c.look_at = self.vec3(x, "look_at")?;
        }
        if let Some(x) = t.get("rotation") {
            c.rotation = self.vec3(x, "rotation")?;
        }
        Ok(c)
    }

    fn light(&self, v: &Val<'_>) -> Result<Light, SceneError> {
        let t = v.get_ref().as_table().expect("tables() checked");
        let kind = self.required(t, v, "type", "[[lights]]")?;
        let kind_name = self.string(kind, "type")?;
        match kind_name {
            "point" => {
                self.known_keys(t, &["type", "position", "color"], "a point light")?;
                let position =
                    self.vec3(self.required(t, v, "position", "point light")?, "position")?;
                let intensity =
                    self.color(self.required(t, v, "color", "point light")?, "color")?;
                Ok(Light::Point {
                    position,
                    intensity,
                })
            }
            "segment" => {
                self.known_keys(t, &["type", "endpoints", "colors"], "a segment light")?;
                let e = self.required(t, v, "endpoints", "segment light")?;
                let [a, b] = self.array::<2>(e, "endpoints")?;
                let endpoints = [self.vec3(a, "endpoints")?, self.vec3(b, "endpoints")?];
                if endpoints[0] == endpoints[1] {
                    return Err(self.err(
                        e,
                        "endpoints: a segment light needs two different ends (its length is zero)"
                            .into(),
                    ));
                }
                let c = self.required(t, v, "colors", "segment light")?;
                let [ca, cb] = self.array::<2>(c, "colors")?;
                let colors = [self.color(ca, "colors")?, self.color(cb, "colors")?];
                Ok(Light::Segment { endpoints, colors })
            }
            "parallelogram" => {
                self.known_keys(
                    t,
                    &["type", "corner", "edges", "colors"],
                    "a parallelogram light",
                )?;
                let corner = self.vec3(
                    self.required(t, v, "corner", "parallelogram light")?,
                    "corner",
                )?;
                let e = self.required(t, v, "edges", "parallelogram light")?;
                let [e0, e1] = self.array::<2>(e, "edges")?;
                let edges = [self.vec3(e0, "edges")?, self.vec3(e1, "edges")?];
                let area = edges[0].cross(edges[1]).length();
                if !(area > 0.0 && area.is_finite()) {
                    return Err(self.err(
                        e,
                        format!("edges: a parallelogram light needs an area above 0, found {area}"),
                    ));
                }
                let c = self.required(t, v, "colors", "parallelogram light")?;
                let cs = self.array::<4>(c, "colors")?;
                let colors = [
                    self.color(cs[0], "colors")?,
                    self.color(cs[1], "colors")?,
                    self.color(cs[2], "colors")?,
                    self.color(cs[3], "colors")?,
                ];
                Ok(Light::Parallelogram {
                    corner,
                    edges,
                    colors,
                    facing: None,
                })
            }
            other => Err(self.err(
                kind,
                format!(
                    "type: expected \"point\", \"segment\" or \"parallelogram\", found {other:?}"
                ),
            )),
        }
    }
}

/// The `[extras]` table and `[[motion]]` entries.
impl Cx<'_> {
    /// A whole number of samples from 1 to [`MAX_EXTRA_SAMPLES`].
    fn samples(&self, v: &Val<'_>, key: &str) -> Result<u32, SceneError> {
        let n = self.integer(v, key)?;
        if !(1..=i64::from(MAX_EXTRA_SAMPLES)).contains(&n) {
            return Err(self.err(
                v,
                format!("{key}: expected 1 to {MAX_EXTRA_SAMPLES} samples, found {n}"),
            ));
        }
        Ok(n as u32)
    }

    /// A number in `[lo, MAX_EXTENT]` (above `lo` if `open`).
    fn bounded(&self, v: &Val<'_>, key: &str, lo: f32, open: bool) -> Result<f32, SceneError> {
        let x = self.number(v, key)?;
        let low_ok = if open { x > lo } else { x >= lo };
        if !low_ok || x > MAX_EXTENT {
            let from = if open { "above" } else { "from" };
            return Err(self.err(
                v,
                format!("{key}: expected a number {from} {lo} up to {MAX_EXTENT}, found {x}"),
            ));
        }
        Ok(x)
    }

    /// The `[extras]` table into `out` (its `motion` entries appended).
    fn extras(&self, v: &Val<'_>, base: &Path, out: &mut ExtrasTable) -> Result<(), SceneError> {
        let t = v.get_ref().as_table().ok_or_else(|| {
            self.err(
                v,
                format!("extras: expected a table, found {}", v.get_ref().type_str()),
            )
        })?;
        self.known_keys(
            t,
            &[
                "dof_aperture",
                "dof_focal_distance",
                "dof_samples",
                "motion_samples",
                "glossy_samples",
                "environment_map",
                "environment_strength",
                "motion",
            ],
            "[extras]",
        )?;
        let e = &mut out.extras;
        if let Some(x) = t.get("dof_aperture") {
            e.dof_aperture = self.bounded(x, "dof_aperture", 0.0, false)?;
        }
        if let Some(x) = t.get("dof_focal_distance") {
            e.dof_focal_distance = Some(self.bounded(x, "dof_focal_distance", 0.0, true)?);
        }
        if let Some(x) = t.get("dof_samples") {
            e.dof_samples = self.samples(x, "dof_samples")?;
        }
        if let Some(x) = t.get("motion_samples") {
            e.motion_samples = self.samples(x, "motion_samples")?;
        }
        if let Some(x) = t.get("glossy_samples") {
            e.glossy_samples = self.samples(x, "glossy_samples")?;
        }
        if let Some(x) = t.get("environment_strength") {
            e.environment_strength = self.bounded(x, "environment_strength", 0.0, false)?;
        }
        if let Some(x) = t.get("environment_map") {
            let s = self.string(x, "environment_map")?;
            out.environment_map = Some(EnvironmentMapFile {
                path: base.join(s),
                at: self.loc(x),
            });
        }
        if let Some(x) = t.get("motion") {
            self.motions(x, out)?;
        }
        Ok(())
    }

    /// `[[motion]]` tables into `out`.
    fn motions(&self, v: &Val<'_>, out: &mut ExtrasTable) -> Result<(), SceneError> {
        for m in self.tables(v, "motion")? {
            out.motion.push(self.motion(m)?);
        }
        Ok(())
    }

    fn motion(&self, v: &Val<'_>) -> Result<Motion, SceneError> {
        let t: &DeTable<'_> = v.get_ref().as_table().expect("tables() checked");
        self.known_keys(t, &["mesh", "velocity"], "[[motion]]")?;
        let m = self.required(t, v, "mesh", "[[motion]]")?;
        let mesh = match m.get_ref() {
            DeValue::Integer(_) => {
                let i = self.integer(m, "mesh")?;
                MeshRef::Index(usize::try_from(i).map_err(|_| {
                    self.err(
                        m,
                        format!("mesh: expected an index of 0 or more, found {i}"),
                    )
                })?)
            }
            DeValue::String(s) => MeshRef::Name(s.to_string()),
            other => {
                return Err(self.err(
                    m,
                    format!(
                        "mesh: expected a mesh's name or index, found {}",
                        other.type_str()
                    ),
                ))
            }
        };
        let vel = self.required(t, v, "velocity", "[[motion]]")?;
        let velocity = self.vec3(vel, "velocity")?;
        if velocity.abs().max_element() > MAX_EXTENT {
            return Err(self.err(
                vel,
                format!(
                    "velocity: expected components up to {MAX_EXTENT} in size, found {velocity}"
                ),
            ));
        }
        Ok(Motion {
            mesh,
            velocity,
            at: self.loc(v),
        })
    }
}

mod extras;
#[cfg(test)]
mod tests;
