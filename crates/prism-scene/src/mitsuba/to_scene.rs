//! A Mitsuba [`Document`] as a prism [`Scene`] with the render settings it names: shapes
//! placed by their `to_world`, BSDFs and emitters as prism's materials and lights, the
//! sensor as the camera, the film's size, the sampler's count and the integrator's depth.
//! A plugin prism does not render is a located error naming it.

use prism_math::glam::{DMat4, DVec3};
use prism_math::{Loc, Rgb, Vec2, Vec3};

use super::document::{Document, Object, Value};
use super::limits::{DISK_SEGMENTS, MAX_FILM_SIDE, MAX_OBJECT_DEPTH, MAX_SAMPLE_COUNT};
use crate::error::SceneError;
use crate::scene::{Camera, Light, Material, Scene, SceneSphere, Shading, ThinLens, TriangleMesh};

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
}

impl Default for MitsubaSettings {
    fn default() -> MitsubaSettings {
        MitsubaSettings {
            size: (768, 576),
            filter: Filter::Gaussian { stddev: 0.5 },
            spp: 4,
            max_bounces: None,
            rr_bounces: 5,
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
}

/// The scene `doc` describes.
///
/// # Errors
/// [`SceneError::Element`] at the plugin: one prism does not render, a property of the wrong
/// kind or out of range, a mesh file that cannot be read, a reference cycle.
pub fn to_scene(doc: &Document) -> Result<MitsubaScene, SceneError> {
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
        }),
        settings: MitsubaSettings::default(),
        sensor_seen: false,
        bsdfs: std::collections::HashMap::new(),
    };
    let root = &doc.objects[0];
    for &(_, child) in &root.children {
        let o = &doc.objects[child];
        match o.tag.as_str() {
            "shape" => b.shape(child, DMat4::IDENTITY, 0)?,
            "emitter" => b.emitter(o)?,
            "sensor" => b.sensor(o)?,
            "integrator" => b.integrator(o)?,
            // Objects defined at the top level to be referenced are used where referenced.
            "bsdf" | "texture" => {}
            _ => return Err(unsupported(o)),
        }
    }
    if !b.sensor_seen {
        return Err(SceneError::Element {
            at: root.at.clone(),
            element: "scene".into(),
            message: "no <sensor>: the scene has no camera".into(),
        });
    }
    Ok(MitsubaScene {
        scene: b.scene,
        settings: b.settings,
    })
}

/// The scene being built.
struct Builder<'d> {
    doc: &'d Document,
    scene: Scene,
    settings: MitsubaSettings,
    sensor_seen: bool,
    /// Material index of each BSDF object already translated.
    bsdfs: std::collections::HashMap<usize, usize>,
}

/// `<tag type="...">: not supported by prism`.
fn unsupported(o: &Object) -> SceneError {
    error(o, format!("{}: not supported by prism", o.label()))
}

/// A located error at object `o`.
fn error(o: &Object, message: String) -> SceneError {
    SceneError::Element {
        at: o.at.clone(),
        element: o.tag.clone(),
        message,
    }
}

/// Typed property reads, with Mitsuba's defaults.
impl Object {
    fn value(&self, name: &str) -> Option<(&Value, &Loc)> {
        self.prop(name).map(|p| (&p.value, &p.at))
    }

    fn kind_error(&self, name: &str, want: &str, got: &Value) -> SceneError {
        error(
            self,
            format!(
                "{}: {name}: expected {want}, found <{}>",
                self.label(),
                got.kind()
            ),
        )
    }

    fn float(&self, name: &str, default: f64) -> Result<f64, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Float(v), _)) => Ok(*v),
            Some((Value::Integer(v), _)) => Ok(*v as f64),
            Some((v, _)) => Err(self.kind_error(name, "a <float>", v)),
        }
    }

    fn integer(&self, name: &str, default: i64) -> Result<i64, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Integer(v), _)) => Ok(*v),
            Some((v, _)) => Err(self.kind_error(name, "an <integer>", v)),
        }
    }

    fn boolean(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        match self.value(name) {
            None => Ok(default),
            Some((Value::Boolean(v), _)) => Ok(*v),
            Some((v, _)) => Err(self.kind_error(name, "a <boolean>", v)),
        }
    }

    fn string(&self, name: &str) -> Result<Option<&str>, SceneError> {
        match self.value(name) {
            None => Ok(None),
            Some((Value::String(v), _)) => Ok(Some(v)),
            Some((v, _)) => Err(self.kind_error(name, "a <string>", v)),
        }
    }

    fn rgb(&self, name: &str, default: [f64; 3]) -> Result<Rgb, SceneError> {
        let c = match self.value(name) {
            None => default,
            Some((Value::Rgb(c), _)) => *c,
            Some((Value::Float(v), _)) => [*v; 3],
            Some((v, _)) => return Err(self.kind_error(name, "an <rgb> or <float>", v)),
        };
        if c.iter().any(|x| *x < 0.0) {
            return Err(error(
                self,
                format!("{}: {name}: expected values of at least 0", self.label()),
            ));
        }
        Ok(Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32))
    }

    fn point(&self, name: &str) -> Result<Option<DVec3>, SceneError> {
        match self.value(name) {
            None => Ok(None),
            Some((Value::Point(p) | Value::Vector(p), _)) => Ok(Some(*p)),
            Some((v, _)) => Err(self.kind_error(name, "a <point>", v)),
        }
    }

    fn transform(&self, name: &str) -> Result<DMat4, SceneError> {
        match self.value(name) {
            None => Ok(DMat4::IDENTITY),
            Some((Value::Transform(m), _)) => Ok(*m),
            Some((v, _)) => Err(self.kind_error(name, "a <transform>", v)),
        }
    }

    /// Fails on a property prism would ignore but that changes the picture in Mitsuba.
    fn refuse(&self, names: &[&str]) -> Result<(), SceneError> {
        for n in names {
            if self.prop(n).is_some() {
                return Err(error(
                    self,
                    format!("{}: {n}: not supported by prism", self.label()),
                ));
            }
        }
        Ok(())
    }
}

/// A named index of refraction (Mitsuba's table), or a number.
fn ior(o: &Object, name: &str, default: &str) -> Result<f64, SceneError> {
    let named = |n: &str| -> Option<f64> {
        Some(match n {
            "vacuum" => 1.0,
            "helium" => 1.000_036,
            "hydrogen" => 1.000_132,
            "air" => 1.000_277,
            "carbon dioxide" => 1.000_45,
            "water" => 1.3330,
            "acetone" => 1.36,
            "ethanol" => 1.361,
            "carbon tetrachloride" => 1.461,
            "glycerol" => 1.4729,
            "benzene" => 1.501,
            "silicone oil" => 1.520_45,
            "bromine" => 1.661,
            "water ice" => 1.31,
            "fused quartz" => 1.458,
            "pyrex" => 1.470,
            "acrylic glass" => 1.49,
            "polypropylene" => 1.49,
            "bk7" => 1.5046,
            "sodium chloride" => 1.544,
            "amber" => 1.55,
            "pet" => 1.5750,
            "diamond" => 2.419,
            _ => return None,
        })
    };
    match o.value(name) {
        None => Ok(named(default).expect("a known default")),
        Some((Value::Float(v), _)) => Ok(*v),
        Some((Value::String(s), _)) => named(s).ok_or_else(|| {
            error(
                o,
                format!(
                    "{}: {name}: no index of refraction is named {s:?}",
                    o.label()
                ),
            )
        }),
        Some((v, _)) => Err(o.kind_error(name, "a <float> or a named material", v)),
    }
}

impl Builder<'_> {
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
        // Its BSDF and its area emitter.
        let mut material = None;
        let mut emission = None;
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            match c.tag.as_str() {
                "bsdf" => material = Some(self.bsdf(child, depth + 1)?),
                "emitter" if c.kind == "area" => {
                    c.refuse(&["to_world"])?;
                    emission = Some(c.rgb("radiance", [1.0; 3])?);
                }
                _ => return Err(unsupported(c)),
            }
        }
        // Mitsuba's default BSDF: diffuse, reflectance 0.5.
        let default_diffuse = Material::Diffuse {
            reflectance: Rgb::splat(0.5),
            texture: None,
        };
        let material = match (emission, material) {
            // An area emitter keeps a BSDF given to its shape: light meeting it scatters too.
            (Some(radiance), surface) => {
                // Without a BSDF of its own an emitter's surface is black, as Mitsuba makes it.
                let reflectance = match surface.map(|m| &self.scene.materials[m]) {
                    None => Rgb::splat(0.0),
                    Some(Material::Diffuse {
                        reflectance,
                        texture: None,
                    }) => *reflectance,
                    Some(_) => {
                        return Err(error(o, format!("{}: an area emitter on a shape whose BSDF is not a plain diffuse one: not supported by prism yet", o.label())))
                    }
                };
                self.push_material(
                    Material::EmissiveDiffuse {
                        radiance,
                        reflectance,
                    },
                    format!("{} area emitter", o.label()),
                )
            }
            (None, Some(m)) => m,
            (None, None) => self.push_material(default_diffuse, "default diffuse".into()),
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
                let c = m.w_axis.truncate();
                self.scene.spheres.push(SceneSphere {
                    center: c.as_vec3(),
                    radius: r as f32,
                    material,
                });
                return Ok(());
            }
            "rectangle" => unit_mesh(
                vec![
                    DVec3::new(-1.0, -1.0, 0.0),
                    DVec3::new(1.0, -1.0, 0.0),
                    DVec3::new(1.0, 1.0, 0.0),
                    DVec3::new(-1.0, 1.0, 0.0),
                ],
                vec![[0, 1, 2], [2, 3, 0]],
                Some(vec![
                    Vec2::new(0.0, 0.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(0.0, 1.0),
                ]),
            ),
            "cube" => cube(),
            "disk" => disk(),
            "obj" | "ply" => {
                let file = o
                    .string("filename")?
                    .ok_or_else(|| error(o, format!("{}: expected a filename", o.label())))?;
                let path = self.doc.folder.join(file);
                let poly = if o.kind == "obj" {
                    prism_mesh::read_obj(&path)
                } else {
                    prism_mesh::read_ply(&path)
                }
                .map_err(|e| error(o, format!("{}: {e}", o.label())))?;
                from_polymesh(&poly)
            }
            _ => return Err(unsupported(o)),
        };
        let (positions, mut triangles, normals, uvs) = mesh;
        let normal_matrix = to_world.inverse().transpose();
        let world: Vec<Vec3> = positions
            .iter()
            .map(|p| to_world.transform_point3(*p).as_vec3())
            .collect();
        if flip {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        let shading = match normals {
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

    fn push_material(&mut self, m: Material, name: String) -> usize {
        self.scene.materials.push(m);
        self.scene
            .material_names
            .resize(self.scene.materials.len() - 1, String::new());
        self.scene.material_names.push(name);
        self.scene.materials.len() - 1
    }

    /// The material of BSDF object `index` (translated once however often it is used).
    fn bsdf(&mut self, index: usize, depth: usize) -> Result<usize, SceneError> {
        if let Some(&m) = self.bsdfs.get(&index) {
            return Ok(m);
        }
        let mut o = &self.doc.objects[index];
        let mut depth = depth;
        // `twosided` wraps one BSDF; prism's BSDFs scatter alike on both sides.
        while o.kind == "twosided" {
            depth += 1;
            if depth > MAX_OBJECT_DEPTH {
                return Err(error(
                    o,
                    format!("objects nested more than {MAX_OBJECT_DEPTH} deep (a <ref> cycle?)"),
                ));
            }
            let inner: Vec<usize> = o
                .children
                .iter()
                .map(|&(_, c)| c)
                .filter(|&c| self.doc.objects[c].tag == "bsdf")
                .collect();
            match inner[..] {
                [one] => o = &self.doc.objects[one],
                _ => {
                    return Err(error(
                        o,
                        format!(
                            "{}: expected one nested <bsdf> (prism has no two-BSDF twosided)",
                            o.label()
                        ),
                    ))
                }
            }
        }
        if let Some(&(_, c)) = o.children.first() {
            let c = &self.doc.objects[c];
            return Err(error(
                c,
                format!(
                    "{} in {}: textures and nested plugins are not supported by prism yet",
                    c.label(),
                    o.label()
                ),
            ));
        }
        let name = o.id.clone().unwrap_or_else(|| o.label());
        let material = match o.kind.as_str() {
            "diffuse" => Material::Diffuse {
                reflectance: o.rgb("reflectance", [0.5; 3])?,
                texture: None,
            },
            "dielectric" => {
                let int = ior(o, "int_ior", "bk7")?;
                let ext = ior(o, "ext_ior", "air")?;
                Material::Glass {
                    reflectance: o.rgb("specular_reflectance", [1.0; 3])?,
                    transmittance: o.rgb("specular_transmittance", [1.0; 3])?,
                    roughness: 0.0,
                    ior: (int / ext) as f32,
                }
            }
            "conductor" => {
                o.refuse(&["eta", "k"])?;
                match o.string("material")?.unwrap_or("none") {
                    "none" => Material::Mirror {
                        reflectance: o.rgb("specular_reflectance", [1.0; 3])?,
                    },
                    other => {
                        return Err(error(o, format!("{}: material {other:?}: not supported by prism yet (only \"none\", a perfect mirror)", o.label())))
                    }
                }
            }
            "roughconductor" => {
                o.refuse(&["alpha_u", "alpha_v", "specular_reflectance"])?;
                let distribution = o.string("distribution")?.unwrap_or("beckmann");
                if distribution != "beckmann" {
                    return Err(error(o, format!("{}: distribution {distribution:?}: not supported by prism yet (beckmann)", o.label())));
                }
                let alpha = o.float("alpha", 0.1)?;
                if !(alpha > 0.0 && alpha <= 4.0) {
                    return Err(error(
                        o,
                        format!(
                            "{}: alpha: expected a roughness above 0 and at most 4, found {alpha}",
                            o.label()
                        ),
                    ));
                }
                // `eta` and `k` given win; else the named material, "none" (all reflected) by
                // default, as Mitsuba 3.
                let (eta, k) = if o.prop("eta").is_some() || o.prop("k").is_some() {
                    (o.rgb("eta", [0.0; 3])?, o.rgb("k", [1.0; 3])?)
                } else {
                    match o.string("material")?.unwrap_or("none") {
                        "none" => (Rgb::splat(0.0), Rgb::splat(1.0)),
                        name => {
                            let (e, k) = super::conductors::conductor(name).ok_or_else(|| {
                                error(
                                    o,
                                    format!(
                                        "{}: material {name:?}: Mitsuba names no such conductor",
                                        o.label()
                                    ),
                                )
                            })?;
                            (Rgb::new(e[0], e[1], e[2]), Rgb::new(k[0], k[1], k[2]))
                        }
                    }
                };
                Material::Microfacet {
                    alpha: alpha as f32,
                    eta,
                    k,
                }
            }
            _ => return Err(unsupported(o)),
        };
        let m = self.push_material(material, name);
        self.bsdfs.insert(index, m);
        Ok(m)
    }

    /// A top-level emitter.
    fn emitter(&mut self, o: &Object) -> Result<(), SceneError> {
        let light = match o.kind.as_str() {
            "point" => {
                let to_world = o.transform("to_world")?;
                let position = o.point("position")?.unwrap_or(DVec3::ZERO);
                Light::Point {
                    position: to_world.transform_point3(position).as_vec3(),
                    intensity: o.rgb("intensity", [1.0; 3])?,
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

    /// The sensor: the camera, and its film and sampler.
    fn sensor(&mut self, o: &Object) -> Result<(), SceneError> {
        if self.sensor_seen {
            return Err(error(
                o,
                format!("{}: a second sensor: not supported by prism yet", o.label()),
            ));
        }
        self.sensor_seen = true;
        if !matches!(o.kind.as_str(), "perspective" | "thinlens") {
            return Err(unsupported(o));
        }
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            match c.tag.as_str() {
                "film" => self.film(c)?,
                "sampler" => {
                    let n = c.integer("sample_count", 4)?;
                    if !(1..=i64::from(MAX_SAMPLE_COUNT)).contains(&n) {
                        return Err(error(
                            c,
                            format!(
                                "{}: sample_count: expected 1 to {MAX_SAMPLE_COUNT}, found {n}",
                                c.label()
                            ),
                        ));
                    }
                    self.settings.spp = n as u32;
                }
                _ => return Err(unsupported(c)),
            }
        }
        let (w, h) = self.settings.size;
        let aspect = f64::from(w) / f64::from(h);
        let fov = match o.value("fov") {
            Some(_) => o.float("fov", 0.0)?,
            None => {
                // A 35 mm film's width over the focal length (Mitsuba's "50mm" default).
                let f = o.string("focal_length")?.unwrap_or("50mm");
                let mm: f64 = f.trim_end_matches("mm").trim().parse().map_err(|_| {
                    error(
                        o,
                        format!(
                            "{}: focal_length: expected millimetres such as \"50mm\", found {f:?}",
                            o.label()
                        ),
                    )
                })?;
                2.0 * (36.0 / (2.0 * mm)).atan().to_degrees()
            }
        };
        if !(fov > 0.0 && fov < 180.0) {
            return Err(error(
                o,
                format!(
                    "{}: fov: expected degrees strictly between 0 and 180, found {fov}",
                    o.label()
                ),
            ));
        }
        let axis = o.string("fov_axis")?.unwrap_or("x");
        let t = (fov.to_radians() * 0.5).tan();
        // The tangents of the half angles across and up the film.
        let (tx, ty) = match axis {
            "x" => (t, t / aspect),
            "y" => (t * aspect, t),
            "diagonal" => {
                let d = (1.0 + 1.0 / (aspect * aspect)).sqrt();
                (t / d, t / d / aspect)
            }
            "smaller" if aspect > 1.0 => (t * aspect, t),
            "smaller" => (t, t / aspect),
            "larger" if aspect > 1.0 => (t, t / aspect),
            "larger" => (t * aspect, t),
            other => {
                return Err(error(
                    o,
                    format!(
                        "{}: fov_axis: expected x, y, diagonal, smaller or larger, found {other:?}",
                        o.label()
                    ),
                ))
            }
        };
        let to_world = o.transform("to_world")?;
        let eye = to_world.transform_point3(DVec3::ZERO);
        let dir = to_world.transform_vector3(DVec3::Z);
        let up = to_world.transform_vector3(DVec3::Y);
        let left = to_world.transform_vector3(DVec3::X);
        if dir.length_squared() == 0.0 || up.length_squared() == 0.0 {
            return Err(error(
                o,
                format!("{}: to_world: the camera's axes are degenerate", o.label()),
            ));
        }
        // Mitsuba's camera has +x to the left; a to_world that mirrors it flips the picture.
        if up.cross(dir).dot(left) <= 0.0 {
            return Err(error(
                o,
                format!(
                    "{}: to_world mirrors the image: not supported by prism yet",
                    o.label()
                ),
            ));
        }
        let near = o.float("near_clip", 1e-2)?;
        let far = o.float("far_clip", 1e4)?;
        if !(near > 0.0 && far > near) {
            return Err(error(
                o,
                format!(
                    "{}: near_clip and far_clip: expected 0 < near < far, found {near} and {far}",
                    o.label()
                ),
            ));
        }
        let lens = if o.kind == "thinlens" {
            let radius = o.float("aperture_radius", 0.0)?;
            let focus = o.float("focus_distance", 0.0)?;
            if !(radius >= 0.0 && focus > 0.0) {
                return Err(error(
                    o,
                    format!(
                        "{}: expected aperture_radius >= 0 and focus_distance > 0",
                        o.label()
                    ),
                ));
            }
            Some(ThinLens {
                radius: radius as f32,
                focal_distance: focus as f32,
            })
        } else {
            None
        };
        self.scene.camera = Camera {
            eye: eye.as_vec3(),
            target: (eye + dir.normalize()).as_vec3(),
            up: up.normalize().as_vec3(),
            hfov: (2.0 * tx.atan()).to_degrees() as f32,
            vfov: (2.0 * ty.atan()).to_degrees() as f32,
            near: near as f32,
            far: far as f32,
            lens,
        };
        Ok(())
    }

    /// The film: its size and reconstruction filter.
    fn film(&mut self, o: &Object) -> Result<(), SceneError> {
        if o.kind != "hdrfilm" {
            return Err(unsupported(o));
        }
        o.refuse(&[
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ])?;
        let side = |name: &str, default: i64| -> Result<u32, SceneError> {
            let v = o.integer(name, default)?;
            if !(1..=i64::from(MAX_FILM_SIDE)).contains(&v) {
                return Err(error(
                    o,
                    format!(
                        "{}: {name}: expected 1 to {MAX_FILM_SIDE} pixels, found {v}",
                        o.label()
                    ),
                ));
            }
            Ok(v as u32)
        };
        self.settings.size = (side("width", 768)?, side("height", 576)?);
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            if c.tag != "rfilter" {
                return Err(unsupported(c));
            }
            self.settings.filter = match c.kind.as_str() {
                "box" => Filter::Box,
                "gaussian" => Filter::Gaussian {
                    stddev: c.float("stddev", 0.5)?,
                },
                "tent" => Filter::Tent {
                    radius: c.float("radius", 1.0)?,
                },
                _ => return Err(unsupported(c)),
            };
        }
        Ok(())
    }

    /// The integrator's depth settings.
    fn integrator(&mut self, o: &Object) -> Result<(), SceneError> {
        if o.kind != "path" {
            return Err(unsupported(o));
        }
        if o.boolean("hide_emitters", false)? {
            return Err(error(
                o,
                format!("{}: hide_emitters: not supported by prism yet", o.label()),
            ));
        }
        let max_depth = o.integer("max_depth", -1)?;
        self.settings.max_bounces = match max_depth {
            -1 => None,
            d if (1..=1024).contains(&d) => Some(d as u32 - 1),
            d => {
                return Err(error(
                    o,
                    format!(
                        "{}: max_depth: expected -1 or 1 to 1024, found {d}",
                        o.label()
                    ),
                ))
            }
        };
        let rr = o.integer("rr_depth", 5)?;
        if !(1..=1024).contains(&rr) {
            return Err(error(
                o,
                format!("{}: rr_depth: expected 1 to 1024, found {rr}", o.label()),
            ));
        }
        self.settings.rr_bounces = rr as u32;
        Ok(())
    }
}

/// A mesh in object space: positions, triangles, normals, uvs.
type ObjectMesh = (
    Vec<DVec3>,
    Vec<[u32; 3]>,
    Option<Vec<DVec3>>,
    Option<Vec<Vec2>>,
);

fn unit_mesh(
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    uvs: Option<Vec<Vec2>>,
) -> ObjectMesh {
    (positions, triangles, None, uvs)
}

/// Mitsuba's `cube`: [-1, 1]^3, four vertices a face so that each face is flat.
fn cube() -> ObjectMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let n = DVec3::from_array({
                let mut a = [0.0; 3];
                a[axis] = sign;
                a
            });
            let (u, v) = super::transform::coordinate_system(n);
            let base = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push(n + u * a + v * b);
            }
            // Counter-clockwise seen from outside: u x v is n.
            let ccw = u.cross(v).dot(n) > 0.0;
            if ccw {
                triangles.push([base, base + 1, base + 2]);
                triangles.push([base + 2, base + 3, base]);
            } else {
                triangles.push([base, base + 2, base + 1]);
                triangles.push([base + 2, base, base + 3]);
            }
        }
    }
    (positions, triangles, None, None)
}

/// Mitsuba's `disk`: radius 1 in the z = 0 plane, facing +z, as a fan of
/// [`DISK_SEGMENTS`] triangles.
fn disk() -> ObjectMesh {
    let mut positions = vec![DVec3::ZERO];
    let mut uvs = vec![Vec2::new(0.5, 0.5)];
    let n = DISK_SEGMENTS;
    for i in 0..n {
        let phi = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        positions.push(DVec3::new(phi.cos(), phi.sin(), 0.0));
        uvs.push(Vec2::new(
            0.5 + 0.5 * phi.cos() as f32,
            0.5 + 0.5 * phi.sin() as f32,
        ));
    }
    let triangles = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    (positions, triangles, None, Some(uvs))
}

/// A read mesh as triangles (polygons as fans).
fn from_polymesh(p: &prism_mesh::PolyMesh) -> ObjectMesh {
    let mut triangles = Vec::with_capacity(p.face_count());
    for f in 0..p.face_count() {
        let v = p.face(f);
        for i in 1..v.len().saturating_sub(1) {
            triangles.push([v[0], v[i], v[i + 1]]);
        }
    }
    (
        p.positions.clone(),
        triangles,
        p.normals.clone(),
        p.uvs
            .as_ref()
            .map(|u| u.iter().map(|t| t.as_vec2()).collect()),
    )
}
