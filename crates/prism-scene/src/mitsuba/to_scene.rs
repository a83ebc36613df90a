//! A Mitsuba [`Document`] as a prism [`Scene`] with the render settings it names: shapes
//! placed by their `to_world`, BSDFs and emitters as prism's materials and lights, the
//! sensor as the camera, the film's size, the sampler's count and the integrator's depth.
//! A plugin prism does not render is a located error naming it.

use prism_math::glam::{DMat4, DVec3};
use prism_math::{Rgb, Vec2, Vec3};

use super::document::{Document, Object};
use super::limits::{MAX_OBJECT_DEPTH, MAX_SCENE_PRIMITIVES};
use super::meshes;
use super::props::{error, not_supported, unsupported};
use crate::error::SceneError;
use std::sync::Arc;

use crate::scene::{Camera, Light, Material, Scene, SceneSphere, Shading, TriangleMesh};

/// How the film turns samples into pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Each sample counts for its own pixel only (Mitsuba's `box`, radius 0.5).
    Box,
    /// Mitsuba's `gaussian` of this standard deviation (the default, 0.5), cut at four.
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f64,
    },
    /// Mitsuba's `tent` of this radius (default 1).
    Tent {
        /// Radius in pixels.
        radius: f64,
    },
}

/// What a Mitsuba scene says about how it is rendered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MitsubaSettings {
    /// The film's width and height (`hdrfilm`: 768 x 576 unless given).
    pub size: (u32, u32),
    /// The reconstruction filter.
    pub filter: Filter,
    /// The sampler's `sample_count` (4 unless given).
    pub spp: u32,
    /// Most bounces (`max_depth - 1`; `None` for `max_depth = -1`, unbounded).
    pub max_bounces: Option<u32>,
    /// Russian roulette's start (`rr_depth`, default 5; prism counts it as Mitsuba does).
    pub rr_bounces: u32,
    /// The integrator's `hide_emitters`: emitters seen from the camera show black.
    pub hide_emitters: bool,
}

impl Default for MitsubaSettings {
    fn default() -> MitsubaSettings {
        MitsubaSettings {
            size: (768, 576),
            filter: Filter::Gaussian { stddev: 0.5 },
            spp: 4,
            max_bounces: None,
            rr_bounces: 5,
            hide_emitters: false,
        }
    }
}

/// A Mitsuba scene ready to render.
#[derive(Clone, Debug, PartialEq)]
pub struct MitsubaScene {
    /// The scene.
    pub scene: Scene,
    /// How the file asks for it to be rendered.
    pub settings: MitsubaSettings,
    /// Every file the scene reads (its XML files, meshes and images), which no output may
    /// replace.
    pub inputs: Vec<std::path::PathBuf>,
    /// How many sensors the file has (the camera and settings are those of the one asked
    /// for).
    pub sensors: usize,
}

/// How a Mitsuba scene is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MitsubaOptions {
    /// Read past what prism does not render: an unsupported BSDF becomes a grey diffuse one,
    /// an unsupported shape, emitter or other plugin is left out, an unsupported integrator
    /// is the path tracer; one warning per kind, in the scene's warnings.
    pub lenient: bool,
    /// Which sensor (in document order, from 0) is the camera.
    pub sensor: usize,
}

/// The scene `doc` describes.
///
/// # Errors
/// [`SceneError::Unsupported`] at a plugin or property prism does not render (unless
/// `lenient`); [`SceneError::Element`] at a property of the wrong kind or out of range, a
/// mesh file that cannot be read, a reference cycle, a sensor the file does not have.
pub fn to_scene(doc: &Document, options: MitsubaOptions) -> Result<MitsubaScene, SceneError> {
    let MitsubaOptions { lenient, sensor } = options;
    let mut b = Builder {
        doc,
        scene: Scene::new(Camera {
            eye: Vec3::ZERO,
            target: Vec3::Z,
            up: Vec3::Y,
            hfov: 39.6,
            vfov: 30.0,
            near: 0.01,
            far: 1e4,
            lens: None,
            orthographic: None,
            crop: None,
        }),
        settings: MitsubaSettings::default(),
        sensors: 0,
        sensor_wanted: sensor,
        bsdfs: std::collections::HashMap::new(),
        primitives: 0,
        default_material: None,
        coats: std::collections::HashSet::new(),
        images: std::collections::HashMap::new(),
        inputs: doc.files.clone(),
        lenient,
        warned: std::collections::HashSet::new(),
    };
    let root = &doc.objects[0];
    for &(_, child) in &root.children {
        let o = &doc.objects[child];
        match o.tag.as_str() {
            "shape" if o.kind == "shapegroup" => {}
            "shape" => {
                if let Err(e) = b.shape(child, DMat4::IDENTITY, 0) {
                    b.tolerate(e, "left out")?;
                }
            }
            "emitter" => {
                if let Err(e) = b.emitter(o) {
                    b.tolerate(e, "left out")?;
                }
            }
            "sensor" => b.sensor(o)?,
            "integrator" => {
                if let Err(e) = b.integrator(o) {
                    b.tolerate(e, "the path tracer renders the scene")?;
                }
            }
            // Objects defined at the top level to be referenced are used where referenced
            // (a shapegroup where an instance places it).
            "bsdf" | "texture" => {}
            _ => b.tolerate(unsupported(o), "left out")?,
        }
    }
    if b.sensors == 0 {
        return Err(SceneError::Element {
            at: root.at.clone(),
            element: "scene".into(),
            message: "no <sensor>: the scene has no camera".into(),
        });
    }
    if sensor >= b.sensors {
        return Err(SceneError::Element {
            at: root.at.clone(),
            element: "scene".into(),
            message: format!(
                "sensor {sensor}: the scene has {} (0 to {})",
                b.sensors,
                b.sensors - 1
            ),
        });
    }
    Ok(MitsubaScene {
        scene: b.scene,
        settings: b.settings,
        inputs: b.inputs,
        sensors: b.sensors,
    })
}

/// The scene being built.
pub(super) struct Builder<'d> {
    pub(super) doc: &'d Document,
    pub(super) scene: Scene,
    pub(super) settings: MitsubaSettings,
    /// Sensors read so far.
    pub(super) sensors: usize,
    /// The sensor whose camera and settings the scene takes.
    pub(super) sensor_wanted: usize,
    /// Material index of each BSDF object already translated.
    pub(super) bsdfs: std::collections::HashMap<usize, usize>,
    /// Triangles and spheres placed so far.
    primitives: usize,
    /// The material of shapes without a BSDF, once one needs it.
    default_material: Option<usize>,
    /// The distinct rough plastic coats (distribution, alpha, index) read so far.
    pub(super) coats: std::collections::HashSet<(bool, u32, u32)>,
    /// The mesh and image files read so far.
    pub(super) inputs: Vec<std::path::PathBuf>,
    /// The images read so far, by file and `raw`: one decoded copy however often used.
    pub(super) images:
        std::collections::HashMap<(std::path::PathBuf, bool), Arc<prism_image::RgbImage>>,
    /// Read past what prism does not render.
    lenient: bool,
    /// The refusals already warned of.
    warned: std::collections::HashSet<String>,
}

impl Builder<'_> {
    /// `e` itself, unless the reading is lenient and `e` is a refusal: then a warning
    /// (once per message) that says what was done instead.
    pub(super) fn tolerate(&mut self, e: SceneError, instead: &str) -> Result<(), SceneError> {
        match e {
            SceneError::Unsupported {
                at,
                element,
                message,
            } if self.lenient => {
                let what = format!("<{element}>: {message}");
                if self.warned.insert(what.clone()) {
                    self.scene.warnings.push(prism_math::Warning::at(
                        at,
                        format!("{what}; {instead} (--lenient)"),
                    ));
                }
                Ok(())
            }
            e => Err(e),
        }
    }

    /// The shape object `index`, placed by `outer` (an instance's transform) and then its own.
    fn shape(&mut self, index: usize, outer: DMat4, depth: usize) -> Result<(), SceneError> {
        let o = &self.doc.objects[index];
        if depth > MAX_OBJECT_DEPTH {
            return Err(error(
                o,
                format!("objects nested more than {MAX_OBJECT_DEPTH} deep (a <ref> cycle?)"),
            ));
        }
        let to_world = outer * o.transform("to_world")?;
        if o.kind == "instance" {
            return self.instance(o, to_world, depth);
        }
        // Its BSDF and its area emitter.
        let mut material = None;
        let mut emission = None;
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            match c.tag.as_str() {
                "bsdf" => material = Some(self.bsdf(child, depth + 1)?),
                "emitter" if c.kind == "area" => {
                    c.refuse(&["to_world"])?;
                    // The radiance may be a texture, as in Mitsuba.
                    let mut texture = None;
                    for (slot, t) in &c.children {
                        let t = &self.doc.objects[*t];
                        if t.tag != "texture" || slot.as_deref() != Some("radiance") {
                            return Err(not_supported(
                                t,
                                format!("{} in {}: not supported by prism yet (a texture as the radiance is)", t.label(), c.label()),
                            ));
                        }
                        texture = Some(self.texture(t)?);
                    }
                    let radiance = match texture {
                        Some(_) => Rgb::WHITE,
                        None => c.rgb("radiance", [1.0; 3])?,
                    };
                    emission = Some((radiance, texture));
                }
                _ => self.tolerate(unsupported(c), "read past")?,
            }
        }
        // Mitsuba's default BSDF: diffuse, reflectance 0.5.
        let default_diffuse = Material::Diffuse {
            reflectance: Rgb::splat(0.5),
            texture: None,
        };
        let material = match (emission, material) {
            // An area emitter keeps a BSDF given to its shape: light meeting it scatters too.
            (Some((radiance, texture)), surface) => self.push_material(
                Material::AreaEmitter {
                    radiance,
                    texture,
                    surface,
                },
                format!("{} area emitter", o.label()),
                // The surface's BSDF says which of its sides scatter.
                true,
            ),
            (None, Some(m)) => m,
            // One default material, however many shapes lack a BSDF.
            (None, None) => match self.default_material {
                Some(m) => m,
                None => {
                    let m = self.push_material(default_diffuse, "default diffuse".into(), true);
                    self.default_material = Some(m);
                    m
                }
            },
        };
        let flip = o.boolean("flip_normals", false)?;
        let face_normals = o.boolean("face_normals", false)?;
        let name = o.id.clone().unwrap_or_else(|| o.label());
        let mesh = match o.kind.as_str() {
            "sphere" => {
                let center = o.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = o.float("radius", 1.0)?;
                // The unit sphere placed by to_world must stay a sphere.
                let m = to_world
                    * DMat4::from_translation(center)
                    * DMat4::from_scale(DVec3::splat(radius));
                let cols = [
                    m.x_axis.truncate(),
                    m.y_axis.truncate(),
                    m.z_axis.truncate(),
                ];
                let r = cols[0].length();
                let similar = cols.iter().all(|c| (c.length() - r).abs() <= 1e-6 * r)
                    && cols[0].dot(cols[1]).abs() <= 1e-6 * r * r
                    && cols[1].dot(cols[2]).abs() <= 1e-6 * r * r
                    && cols[0].dot(cols[2]).abs() <= 1e-6 * r * r;
                if !similar || r <= 0.0 {
                    return Err(error(o, format!("{}: to_world must keep the sphere round (rotation, uniform scale, translation)", o.label())));
                }
                // A turned sphere keeps its own axes, which its texture coordinates follow.
                let turned = (0..3).any(|i| (cols[i] - DVec3::AXES[i] * r).length() > 1e-6 * r);
                let to_local = turned.then(|| {
                    prism_math::glam::Mat3::from_cols(
                        (cols[0] / r).as_vec3(),
                        (cols[1] / r).as_vec3(),
                        (cols[2] / r).as_vec3(),
                    )
                    .transpose()
                });
                let c = m.w_axis.truncate();
                if !(c.as_vec3().is_finite() && (r as f32).is_finite()) {
                    return Err(error(
                        o,
                        format!(
                            "{}: to_world places the shape beyond the finite numbers",
                            o.label()
                        ),
                    ));
                }
                self.place(o, 1)?;
                self.scene.spheres.push(SceneSphere {
                    center: c.as_vec3(),
                    radius: r as f32,
                    material,
                    inward: flip,
                    to_local,
                });
                return Ok(());
            }
            "rectangle" => meshes::unit_mesh(
                vec![
                    DVec3::new(-1.0, -1.0, 0.0),
                    DVec3::new(1.0, -1.0, 0.0),
                    DVec3::new(1.0, 1.0, 0.0),
                    DVec3::new(-1.0, 1.0, 0.0),
                ],
                vec![[0, 1, 2], [2, 3, 0]],
                // Mitsuba's (u, v) is ((x + 1) / 2, (y + 1) / 2), v running down the image;
                // prism's v runs up it.
                Some(vec![
                    Vec2::new(0.0, 1.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.0, 0.0),
                ]),
            ),
            "cube" => meshes::cube(),
            "disk" => meshes::disk(),
            "serialized" => {
                let file = o
                    .string("filename")?
                    .ok_or_else(|| error(o, format!("{}: expected a filename", o.label())))?;
                let index = o.integer("shape_index", 0)?;
                let index = u32::try_from(index).map_err(|_| {
                    error(
                        o,
                        format!(
                            "{}: shape_index: expected 0 or more, found {index}",
                            o.label()
                        ),
                    )
                })?;
                let path = self.doc.resolve(file);
                self.inputs.push(path.clone());
                let bytes = prism_math::limits::read_input(&path, prism_mesh::MAX_MESH_FILE_BYTES)
                    .map_err(|e| error(o, format!("{}: {}: {e}", o.label(), path.display())))?;
                super::serialized::read_serialized(&bytes, index)
                    .map_err(|e| error(o, format!("{}: {file}: {e}", o.label())))?
            }
            "cylinder" => {
                let p0 = o.point("p0")?.unwrap_or(DVec3::ZERO);
                let p1 = o.point("p1")?.unwrap_or(DVec3::Z);
                let radius = o.float("radius", 1.0)?;
                if !(radius > 0.0 && radius.is_finite()) || (p1 - p0).length_squared() == 0.0 {
                    return Err(error(
                        o,
                        format!(
                            "{}: expected a positive radius and p0 apart from p1",
                            o.label()
                        ),
                    ));
                }
                meshes::cylinder(p0, p1, radius)
            }
            "obj" | "ply" => {
                let file = o
                    .string("filename")?
                    .ok_or_else(|| error(o, format!("{}: expected a filename", o.label())))?;
                let path = self.doc.resolve(file);
                self.inputs.push(path.clone());
                let failed = |e: String| error(o, format!("{}: {e}", o.label()));
                if o.kind == "obj" {
                    let text =
                        prism_math::limits::read_input_text(&path, prism_mesh::MAX_MESH_FILE_BYTES)
                            .map_err(|e| failed(format!("{}: {e}", path.display())))?;
                    let options = prism_mesh::obj::ObjOptions {
                        attributes: true,
                        ..Default::default()
                    };
                    let doc = prism_mesh::obj::ObjDocument::<f64>::parse(
                        &text,
                        &path.display().to_string(),
                        options,
                    )
                    .map_err(|e| failed(e.to_string()))?;
                    meshes::from_obj(&doc).map_err(failed)?
                } else {
                    let poly = prism_mesh::read_ply(&path).map_err(|e| failed(e.to_string()))?;
                    meshes::from_polymesh(&poly)
                }
            }
            _ => return Err(unsupported(o)),
        };
        let (positions, mut triangles, normals, uvs) = mesh;
        // Each shape counts at least once: an empty mesh instanced without end still costs.
        self.place(o, triangles.len().max(1))?;
        let normal_matrix = to_world.inverse().transpose();
        let world: Vec<Vec3> = positions
            .iter()
            .map(|p| to_world.transform_point3(*p).as_vec3())
            .collect();
        if !world.iter().all(|p| p.is_finite()) {
            return Err(error(
                o,
                format!(
                    "{}: to_world places the shape beyond the finite numbers",
                    o.label()
                ),
            ));
        }
        if flip {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        // Mitsuba computes vertex normals for file meshes that have none.
        let compute_normals = normals.is_none()
            && !face_normals
            && matches!(o.kind.as_str(), "obj" | "ply" | "serialized");
        let mut shading = match normals {
            Some(n) if !face_normals => Shading::Smooth(
                n.iter()
                    .map(|v| {
                        let w = normal_matrix
                            .transform_vector3(*v)
                            .normalize_or_zero()
                            .as_vec3();
                        if flip {
                            -w
                        } else {
                            w
                        }
                    })
                    .collect(),
            ),
            _ => Shading::Flat,
        };
        // A mirroring to_world turns the winding over: keep the normals' side.
        if to_world.determinant() < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        if compute_normals {
            shading = Shading::Smooth(meshes::angle_weighted_normals(&world, &triangles));
        }
        self.scene.meshes.push(TriangleMesh {
            name,
            positions: world,
            triangles,
            shading,
            material,
            uvs,
        });
        Ok(())
    }

    /// An `instance`: the shapes of the one `shapegroup` it references, each placed by the
    /// instance's `to_world` and then its own (copies of the geometry, within the scene's
    /// triangle budget).
    fn instance(&mut self, o: &Object, to_world: DMat4, depth: usize) -> Result<(), SceneError> {
        let groups: Vec<usize> = o
            .children
            .iter()
            .map(|&(_, c)| c)
            .filter(|&c| self.doc.objects[c].kind == "shapegroup")
            .collect();
        if groups.len() != 1 || groups.len() != o.children.len() {
            return Err(error(
                o,
                format!("{}: expected a reference to one shapegroup", o.label()),
            ));
        }
        let group = &self.doc.objects[groups[0]];
        for &(_, c) in &group.children {
            let shape = &self.doc.objects[c];
            if shape.tag != "shape" || matches!(shape.kind.as_str(), "shapegroup" | "instance") {
                return Err(error(
                    shape,
                    format!("{} in a shapegroup: expected a shape", shape.label()),
                ));
            }
            self.shape(c, to_world, depth + 1)?;
        }
        Ok(())
    }

    /// Counts `count` more primitives (triangles or spheres) against the scene's budget.
    fn place(&mut self, o: &Object, count: usize) -> Result<(), SceneError> {
        self.primitives = self.primitives.saturating_add(count);
        if self.primitives > MAX_SCENE_PRIMITIVES {
            return Err(error(
                o,
                format!("{}: the scene would hold more than {MAX_SCENE_PRIMITIVES} triangles and spheres (instances are copies)", o.label()),
            ));
        }
        Ok(())
    }

    /// Adds material `m`, named `name`, black from behind if `one_sided`; its index.
    pub(super) fn push_material(&mut self, m: Material, name: String, one_sided: bool) -> usize {
        self.scene.materials.push(m);
        self.scene.one_sided.push(one_sided);
        self.scene
            .material_names
            .resize(self.scene.materials.len() - 1, String::new());
        self.scene.material_names.push(name);
        self.scene.materials.len() - 1
    }

    /// A top-level emitter.
    fn emitter(&mut self, o: &Object) -> Result<(), SceneError> {
        self.no_nested_plugins(o)?;
        let light = match o.kind.as_str() {
            "point" => {
                let to_world = o.transform("to_world")?;
                let position = o.point("position")?.unwrap_or(DVec3::ZERO);
                Light::Point {
                    position: to_world.transform_point3(position).as_vec3(),
                    intensity: o.rgb("intensity", [1.0; 3])?,
                }
            }
            "spot" => {
                o.refuse(&["texture"])?;
                let to_world = o.transform("to_world")?;
                let linear = prism_math::glam::DMat3::from_mat4(to_world);
                if linear.determinant() == 0.0 {
                    return Err(error(
                        o,
                        format!("{}: to_world: the light's axes are degenerate", o.label()),
                    ));
                }
                let cutoff = o.float("cutoff_angle", 20.0)?;
                let beam_width = o.float("beam_width", cutoff * 0.75)?;
                if !(cutoff > 0.0 && cutoff <= 180.0 && beam_width >= 0.0 && beam_width < cutoff) {
                    return Err(error(o, format!("{}: expected 0 <= beam_width < cutoff_angle <= 180 degrees, found {beam_width} and {cutoff}", o.label())));
                }
                Light::Spot {
                    position: to_world.transform_point3(DVec3::ZERO).as_vec3(),
                    to_local: linear.inverse().as_mat3(),
                    intensity: o.rgb("intensity", [1.0; 3])?,
                    cutoff: cutoff as f32,
                    beam_width: beam_width as f32,
                }
            }
            "envmap" => {
                let to_world = o.transform("to_world")?;
                let linear = prism_math::glam::DMat3::from_mat4(to_world);
                if !(linear.determinant().is_normal()) {
                    return Err(error(
                        o,
                        format!("{}: to_world: the map's axes are degenerate", o.label()),
                    ));
                }
                let scale = o.float("scale", 1.0)? as f32;
                let (name, image) = self.image_file(o, false)?;
                let map = image.map(|c| *c * scale);
                if let Some(i) = map.pixels().iter().position(|p| {
                    ![p.r, p.g, p.b]
                        .iter()
                        .all(|v| (0.0..prism_math::ExactSum::LIMIT).contains(v))
                }) {
                    return Err(error(o, format!("{}: {name}: texel {} (scaled by {scale}) is not finite, non-negative radiance below 2^55", o.label(), i)));
                }
                if self
                    .scene
                    .lights
                    .iter()
                    .any(|l| matches!(l, Light::EnvironmentMap { .. } | Light::Environment { .. }))
                {
                    return Err(not_supported(
                        o,
                        format!(
                            "{}: a second light at infinity: not supported by prism",
                            o.label()
                        ),
                    ));
                }
                Light::EnvironmentMap {
                    radiance: Arc::new(map),
                    mapping: crate::EnvMapping::Mitsuba {
                        to_local: linear.inverse().as_mat3(),
                    },
                }
            }
            "constant" => Light::Environment {
                radiance: o.rgb("radiance", [1.0; 3])?,
            },
            "directional" => {
                let to_world = o.transform("to_world")?;
                let d = o.point("direction")?.unwrap_or(DVec3::Z);
                let d = to_world.transform_vector3(d);
                if d.length_squared() == 0.0 {
                    return Err(error(
                        o,
                        format!("{}: direction: expected a non-zero vector", o.label()),
                    ));
                }
                Light::Directional {
                    direction: d.normalize().as_vec3(),
                    irradiance: o.rgb("irradiance", [1.0; 3])?,
                }
            }
            "area" => {
                return Err(error(
                    o,
                    format!("{}: an area emitter belongs inside a <shape>", o.label()),
                ))
            }
            _ => return Err(unsupported(o)),
        };
        self.scene.lights.push(light);
        Ok(())
    }
}
