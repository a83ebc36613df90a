//! COLLADA 1.4.1 reading: geometry, the node hierarchy and the up axis.
//!
//! The reading follows the specification, which is also what the course's files need
//! (`FORMATS.md` section 2):
//! - Geometry comes from `<polylist>`, `<triangles>` and `<polygons>`. Faces are built from
//!   the `VERTEX` indices, so positions are shared exactly as the file shares them; normals and
//!   texture coordinates, which COLLADA indexes separately, are kept per face corner.
//! - A `<geometry>` with no `<mesh>` but a CGL `<sphere><radius>` extra is a sphere.
//! - A node's transform is the product of its transform elements in document order
//!   (`T·R_Y·R_X·R_Z` for the usual modo `translate, rotate ×3`), with `<matrix>` read row by
//!   row and `<rotate>` as axis and angle in degrees. World matrices compose parent first.
//! - `<up_axis>` is reported, not applied; [`UpAxis::to_y_up`] gives the conversion.
//!
//! Malformed values are read past, not refused: each library entry, node or binding that
//! cannot be read carries its error as a `defect` (with a warning naming file, line and
//! element), and whoever uses it ([`Collada::world_mesh`], [`crate::Scene::from_collada`])
//! returns that error. A defect in something nothing uses stays a warning, as in the
//! course's own renderer. Malformed XML, a wrong root, a reference to a missing geometry
//! and the limits ([`MAX_COLLADA_BYTES`], [`MAX_NODE_DEPTH`], [`MAX_NODES`],
//! [`MAX_PLACED_FACES`]) are errors at once.

mod library;
mod to_scene;
mod writer;

use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::Path;

use prism_math::glam::{DMat3, DMat4, DVec2, DVec3, DVec4};
use prism_mesh::PolyMesh;
use roxmltree::{Document, Node as XmlNode};

use crate::error::SceneError;

pub use library::{CameraDef, EffectDef, LightDef, LightKind};
pub use writer::write_collada;

/// Largest COLLADA file read, in bytes.
pub const MAX_COLLADA_BYTES: u64 = 1 << 30;

/// Deepest node nesting followed, `instance_node` references included.
pub const MAX_NODE_DEPTH: usize = 64;

/// Most nodes the visual scene may expand to, each `instance_node` copying its target's
/// whole subtree.
pub const MAX_NODES: usize = 1_000_000;

/// Most polygons the instanced geometries may place in the world, counted over every
/// instance.
pub const MAX_PLACED_FACES: usize = 50_000_000;

/// The document's up axis (`<asset><up_axis>`), `Y` when absent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpAxis {
    /// `X_UP`.
    X,
    /// `Y_UP`, the default.
    #[default]
    Y,
    /// `Z_UP` (Blender exports).
    Z,
}

impl UpAxis {
    /// The rotation that takes this document's world to a Y-up world.
    ///
    /// - `Z_UP`: `(x, y, z) -> (-x, z, y)`, the course's conversion (a half turn about
    ///   `(0, 1, 1)`), which keeps Blender's front view facing the default camera.
    /// - `X_UP`: `(x, y, z) -> (y, x, -z)`, the course's conversion.
    /// - `Y_UP`: the identity.
    #[must_use]
    pub fn to_y_up(self) -> DMat4 {
        match self {
            UpAxis::Y => DMat4::IDENTITY,
            UpAxis::Z => DMat4::from_mat3(DMat3::from_cols(
                DVec3::new(-1.0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(0.0, 1.0, 0.0),
            )),
            UpAxis::X => DMat4::from_mat3(DMat3::from_cols(
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, -1.0),
            )),
        }
    }
}

/// A read COLLADA document: its geometries and the flattened nodes of its visual scene.
#[derive(Clone, Debug, Default)]
pub struct Collada {
    /// `<asset><up_axis>`.
    pub up_axis: UpAxis,
    /// Every `<geometry>` in `<library_geometries>`, in file order.
    pub geometries: Vec<Geometry>,
    /// The instanced visual scene's nodes, depth first, each with its world matrix (the up
    /// axis not applied). Empty when the file instances no visual scene.
    pub nodes: Vec<Node>,
    /// Every `<camera>`, in file order.
    pub cameras: Vec<CameraDef>,
    /// Every `<light>` of a known kind, in file order.
    pub lights: Vec<LightDef>,
    /// Every `<effect>`, read as a material.
    pub effects: Vec<EffectDef>,
    /// Every `<material>`: its id and the index of its effect in [`Collada::effects`], or
    /// why it has none (a user of the material refuses it with that error).
    pub materials: Vec<(String, Result<usize, SceneError>)>,
    /// Features read past without being understood, one message each.
    pub warnings: Vec<String>,
}

/// One `<geometry>`.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Its `id` attribute.
    pub id: String,
    /// Its `name` attribute (the id when absent).
    pub name: String,
    /// Line of its start tag.
    pub line: u32,
    /// What it holds ([`Shape::Empty`] when it is malformed).
    pub shape: Shape,
    /// Why it cannot be read, if it cannot; placing it is then an error.
    pub defect: Option<SceneError>,
}

/// What a geometry holds.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A polygon mesh.
    Mesh(MeshData),
    /// The course's CGL sphere extra: centred at the node's origin.
    Sphere {
        /// Radius in local units.
        radius: f64,
    },
    /// Nothing drawable (splines, or primitives prism does not read; a warning names them).
    Empty,
}

/// A mesh geometry: polygons over shared positions, with per-corner attributes.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    /// Positions and faces (faces index positions, as the `VERTEX` input does). `normals` and
    /// `uvs` are set only when every corner of each vertex agrees, so they are per-vertex.
    pub mesh: PolyMesh,
    /// One normal per face corner, in face order, if the file gives normals.
    pub corner_normals: Option<Vec<DVec3>>,
    /// One texture coordinate per face corner (the first `TEXCOORD` set), if given.
    pub corner_uvs: Option<Vec<DVec2>>,
    /// The primitive elements, each a range of faces with its material symbol.
    pub parts: Vec<Part>,
}

/// One `<polylist>`, `<triangles>` or `<polygons>` element of a mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Part {
    /// Its `material` symbol, bound to a material by the instancing node.
    pub material: Option<String>,
    /// Its faces in [`MeshData::mesh`].
    pub faces: Range<usize>,
}

/// A node of the visual scene.
#[derive(Clone, Debug)]
pub struct Node {
    /// Its `id` attribute (may be empty).
    pub id: String,
    /// Its `name` attribute (the id when absent).
    pub name: String,
    /// Line of its start tag.
    pub line: u32,
    /// Local-to-world matrix: the parents' transforms, then its own. When the node has a
    /// defect, this is the lenient reading: a `<matrix>` with fewer than 16 numbers takes
    /// them in order over the identity (as the course's renderer reads it), and any other
    /// malformed transform element is left out.
    pub world: DMat4,
    /// The first malformed transform element of this node or an ancestor, if any: a user of
    /// [`Node::world`] that needs it exactly refuses the node with this error.
    pub defect: Option<SceneError>,
    /// What it instances.
    pub instances: Vec<Instance>,
}

/// Something a node instances.
#[derive(Clone, Debug, PartialEq)]
pub enum Instance {
    /// `<instance_geometry>`: an index into [`Collada::geometries`] and the material bindings
    /// as `(symbol, target id)` pairs.
    Geometry {
        /// Index into [`Collada::geometries`].
        geometry: usize,
        /// `bind_material` pairs: the part's symbol and the `<material>` id (no `#`).
        materials: Vec<(String, String)>,
        /// The first binding whose target is missing, if any: a user of that binding
        /// refuses it with this error.
        defect: Option<SceneError>,
    },
    /// `<instance_camera>`, by camera id.
    Camera(String),
    /// `<instance_light>`, by light id.
    Light(String),
    /// An `<instance_camera>` or `<instance_light>` whose target does not exist: a user of
    /// cameras and lights refuses it with this error.
    Missing(SceneError),
}

impl Collada {
    /// Every instanced mesh in world space merged into one polygon mesh, converted to a Y-up
    /// world when `y_up` is set. Per-vertex normals (transformed by the inverse transpose) and
    /// texture coordinates are kept when every merged mesh has them. A document that
    /// instances no visual scene contributes each mesh geometry once, untransformed.
    ///
    /// # Errors
    /// The defect of a placed geometry, or of the node that places it.
    pub fn world_mesh(&self, y_up: bool) -> Result<PolyMesh, SceneError> {
        let up = if y_up {
            self.up_axis.to_y_up()
        } else {
            DMat4::IDENTITY
        };
        let mut placed: Vec<(&MeshData, DMat4)> = Vec::new();
        if self.nodes.is_empty() {
            for g in &self.geometries {
                if let Some(e) = &g.defect {
                    return Err(e.clone());
                }
                if let Shape::Mesh(m) = &g.shape {
                    placed.push((m, up));
                }
            }
        } else {
            for n in &self.nodes {
                for i in &n.instances {
                    if let Instance::Geometry { geometry, .. } = i {
                        let g = &self.geometries[*geometry];
                        if let Some(e) = g.defect.as_ref().or(n.defect.as_ref()) {
                            return Err(e.clone());
                        }
                        if let Shape::Mesh(m) = &g.shape {
                            placed.push((m, up * n.world));
                        }
                    }
                }
            }
        }
        let mut out = PolyMesh::default();
        let mut normals = Some(Vec::new());
        let mut uvs = Some(Vec::new());
        for (m, matrix) in placed {
            let base = out.positions.len() as u32;
            out.positions
                .extend(m.mesh.positions.iter().map(|&p| matrix.transform_point3(p)));
            let nm = DMat3::from_mat4(matrix).inverse().transpose();
            match (&mut normals, &m.mesh.normals) {
                (Some(acc), Some(ns)) => {
                    acc.extend(ns.iter().map(|&n| (nm * n).normalize_or_zero()));
                }
                _ => normals = None,
            }
            match (&mut uvs, &m.mesh.uvs) {
                (Some(acc), Some(ts)) => acc.extend_from_slice(ts),
                _ => uvs = None,
            }
            let mut face = Vec::new();
            for f in m.mesh.faces() {
                face.clear();
                face.extend(f.iter().map(|&i| i + base));
                out.push_face(&face);
            }
        }
        out.normals = normals.filter(|n| !n.is_empty());
        out.uvs = uvs.filter(|t| !t.is_empty());
        Ok(out)
    }
}

/// Reads a COLLADA file.
///
/// # Errors
/// [`SceneError::Io`] for a file that cannot be read, is not a regular file or is over
/// [`MAX_COLLADA_BYTES`]; otherwise as
/// [`parse_collada`].
pub fn read_collada(path: &Path) -> Result<Collada, SceneError> {
    let name = path.display().to_string();
    let io = |e: std::io::Error| SceneError::Io {
        path: name.clone(),
        source: std::sync::Arc::new(e),
    };
    let text = prism_math::limits::read_input_text(path, MAX_COLLADA_BYTES).map_err(io)?;
    parse_collada(&text, &name)
}

/// Parses COLLADA text; `file` names it in errors.
///
/// # Errors
/// [`SceneError::Xml`] for malformed XML; [`SceneError::Element`], naming the line and element,
/// for a missing or malformed required element, a number that does not parse or is not finite,
/// an index out of range, or a reference (`#id`) to nothing.
pub fn parse_collada(text: &str, file: &str) -> Result<Collada, SceneError> {
    let xml = Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| SceneError::Xml {
        file: file.to_string(),
        source: e,
    })?;
    let root = xml.root_element();
    let cx = Cx {
        lines: prism_math::LineIndex::new(text),
        file,
    };
    if root.tag_name().name() != "COLLADA" {
        return Err(cx.err(root, "expected a <COLLADA> root element"));
    }
    let mut out = Collada::default();
    let mut warned = std::collections::BTreeSet::new();
    let mut warn = |out: &mut Collada, key: &str, message: String| {
        if warned.insert(key.to_string()) {
            out.warnings.push(message);
        }
    };
    // A malformed entry is kept with its error, which is an error only for its users.
    let defect = |out: &mut Collada, e: SceneError| {
        out.warnings
            .push(format!("{e}; read past: an error only where it is used"));
        Some(e)
    };

    if let Some(up) = child(root, "asset").and_then(|a| child(a, "up_axis")) {
        out.up_axis = match up.text().unwrap_or("").trim() {
            "X_UP" => UpAxis::X,
            "Y_UP" => UpAxis::Y,
            "Z_UP" => UpAxis::Z,
            other => {
                return Err(cx.err(up, format!("expected X_UP, Y_UP or Z_UP, found {other:?}")))
            }
        };
    }

    let mut geometry_index = HashMap::new();
    for lib in children(root, "library_geometries") {
        for g in children(lib, "geometry") {
            let id = g.attribute("id").unwrap_or("").to_string();
            let (shape, fault) =
                match read_geometry(&cx, g, &mut |key, msg| warn(&mut out, key, msg)) {
                    Ok(shape) => (shape, None),
                    Err(e) => (Shape::Empty, defect(&mut out, e)),
                };
            if !id.is_empty() {
                geometry_index.insert(id.clone(), out.geometries.len());
            }
            out.geometries.push(Geometry {
                name: g.attribute("name").unwrap_or(&id).to_string(),
                id,
                line: cx.line(g),
                shape,
                defect: fault,
            });
        }
    }
    for lib in children(root, "library_cameras") {
        for c in children(lib, "camera") {
            let camera = library::camera(&cx, c).unwrap_or_else(|e| CameraDef {
                defect: defect(&mut out, e),
                ..CameraDef::unread(&cx, c)
            });
            out.cameras.push(camera);
        }
    }
    let mut all_light_ids = Vec::new();
    for lib in children(root, "library_lights") {
        for l in children(lib, "light") {
            all_light_ids.push(l.attribute("id").unwrap_or("").to_string());
            match library::light(&cx, l, &mut |k, m| warn(&mut out, k, m)) {
                Ok(Some(light)) => out.lights.push(light),
                Ok(None) => {}
                Err(e) => {
                    let light = LightDef {
                        defect: defect(&mut out, e),
                        ..LightDef::unread(&cx, l)
                    };
                    out.lights.push(light);
                }
            }
        }
    }
    // Image ids and their files (`file://` dropped), the first of each id.
    let mut images: HashMap<String, String> = HashMap::new();
    for lib in children(root, "library_images") {
        for i in children(lib, "image") {
            let file = child(i, "init_from").and_then(|f| {
                // 1.4.1 holds the path as text; 1.5 in a <ref>.
                child(f, "ref").and_then(|r| r.text()).or_else(|| f.text())
            });
            if let (Some(id), Some(file)) = (i.attribute("id"), file) {
                let file = file.trim();
                let file = file.strip_prefix("file://").unwrap_or(file);
                images
                    .entry(id.to_string())
                    .or_insert_with(|| file.to_string());
            }
        }
    }
    for lib in children(root, "library_effects") {
        for e in children(lib, "effect") {
            let effect = match library::effect(&cx, e, &images, &mut |k, m| warn(&mut out, k, m)) {
                Ok(effect) => effect,
                Err(err) => EffectDef {
                    defect: defect(&mut out, err),
                    ..EffectDef::unread(&cx, e)
                },
            };
            out.effects.push(effect);
        }
    }
    // The first effect of each id, as a search in file order finds it.
    let mut effect_index: HashMap<String, usize> = HashMap::new();
    for (i, e) in out.effects.iter().enumerate() {
        effect_index.entry(e.id.clone()).or_insert(i);
    }
    for lib in children(root, "library_materials") {
        for m in children(lib, "material") {
            let effect = child(m, "instance_effect")
                .ok_or_else(|| cx.err(m, "expected an <instance_effect>"))
                .and_then(|inst| {
                    let url = reference(&cx, inst, "url")?;
                    effect_index
                        .get(url)
                        .copied()
                        .ok_or_else(|| cx.err(inst, format!("no <effect> with id {url:?}")))
                });
            if let Err(e) = &effect {
                defect(&mut out, e.clone());
            }
            out.materials
                .push((m.attribute("id").unwrap_or("").to_string(), effect));
        }
    }

    let mut library_nodes = HashMap::new();
    for lib in children(root, "library_nodes") {
        for n in lib.descendants().filter(|n| n.has_tag_name("node")) {
            if let Some(id) = n.attribute("id") {
                library_nodes.insert(id.to_string(), n);
            }
        }
    }
    let scenes: Vec<XmlNode> = children(root, "library_visual_scenes")
        .flat_map(|l| children(l, "visual_scene"))
        .collect();
    let instanced = child(root, "scene").and_then(|s| child(s, "instance_visual_scene"));
    let scene = match instanced {
        Some(inst) => {
            let url = reference(&cx, inst, "url")?;
            Some(
                *scenes
                    .iter()
                    .find(|s| s.attribute("id") == Some(url))
                    .ok_or_else(|| cx.err(inst, format!("no <visual_scene> with id {url:?}")))?,
            )
        }
        None => scenes.first().copied(),
    };
    if let Some(scene) = scene {
        let walker = Walker {
            cx: &cx,
            geometry_index: &geometry_index,
            library_nodes: &library_nodes,
            camera_ids: out.cameras.iter().map(|c| c.id.as_str()).collect(),
            light_ids: out.lights.iter().map(|l| l.id.as_str()).collect(),
            material_ids: out.materials.iter().map(|(id, _)| id.as_str()).collect(),
            all_light_ids: all_light_ids.iter().map(String::as_str).collect(),
        };
        count_nodes(&cx, scene, &library_nodes)?;
        let mut nodes = Vec::new();
        let mut warnings = Vec::new();
        for n in children(scene, "node") {
            walker.node(n, DMat4::IDENTITY, None, 0, &mut nodes, &mut warnings)?;
        }
        for (key, msg) in warnings {
            warn(&mut out, &key, msg);
        }
        out.nodes = nodes;
    }
    // Instances copy their geometry's faces: bound the total before anyone places them.
    let mut placed = 0usize;
    for n in &out.nodes {
        for i in &n.instances {
            if let Instance::Geometry { geometry, .. } = i {
                if let Shape::Mesh(m) = &out.geometries[*geometry].shape {
                    placed = placed.saturating_add(m.mesh.face_count());
                }
            }
        }
        if placed > MAX_PLACED_FACES {
            return Err(SceneError::Element {
                file: file.to_string(),
                line: n.line,
                element: "node".into(),
                message: format!(
                    "the instances place more than {MAX_PLACED_FACES} polygons in the world"
                ),
            });
        }
    }
    Ok(out)
}

/// Counts the nodes the visual scene expands to, without expanding it, and refuses more
/// than [`MAX_NODES`] or an `instance_node` that leads back to a node containing it. Each
/// node is visited once, with an explicit stack.
fn count_nodes<'b, 'i>(
    cx: &Cx<'_, 'i>,
    scene: XmlNode<'b, 'i>,
    library_nodes: &HashMap<String, XmlNode<'b, 'i>>,
) -> Result<(), SceneError> {
    #[derive(Clone, Copy)]
    enum Mark {
        Open,
        Done(u64),
    }
    // A node's parts: its child nodes and the targets of its instance_node references.
    let parts = |n: XmlNode<'b, 'i>| -> Vec<(XmlNode<'b, 'i>, Option<XmlNode<'b, 'i>>)> {
        n.children()
            .filter_map(|c| match c.tag_name().name() {
                "node" => Some((c, None)),
                "instance_node" => c
                    .attribute("url")
                    .and_then(|u| u.strip_prefix('#'))
                    .and_then(|u| library_nodes.get(u))
                    .map(|&t| (t, Some(c))),
                _ => None,
            })
            .collect()
    };
    let mut marks: HashMap<roxmltree::NodeId, Mark> = HashMap::new();
    let mut stack: Vec<(XmlNode, Option<XmlNode>, bool)> =
        children(scene, "node").map(|n| (n, None, false)).collect();
    let mut total = 0u64;
    while let Some((n, via, finished)) = stack.pop() {
        match (marks.get(&n.id()).copied(), finished) {
            (Some(Mark::Done(_)), false) => {}
            (Some(Mark::Open), false) => {
                let at = via.unwrap_or(n);
                return Err(cx.err(
                    at,
                    "the node instances a node that contains it (its own ancestor)",
                ));
            }
            (None, _) => {
                marks.insert(n.id(), Mark::Open);
                stack.push((n, via, true));
                stack.extend(parts(n).into_iter().map(|(c, via)| (c, via, false)));
            }
            (Some(_), true) => {
                let mut size = 1u64;
                for (c, _) in parts(n) {
                    if let Some(Mark::Done(k)) = marks.get(&c.id()) {
                        size = size.saturating_add(*k);
                    }
                }
                if size > MAX_NODES as u64 {
                    return Err(cx.err(
                        n,
                        format!("the node expands to more than {MAX_NODES} nodes"),
                    ));
                }
                marks.insert(n.id(), Mark::Done(size));
            }
        }
    }
    for n in children(scene, "node") {
        if let Some(Mark::Done(k)) = marks.get(&n.id()) {
            total = total.saturating_add(*k);
        }
    }
    if total > MAX_NODES as u64 {
        return Err(cx.err(
            scene,
            format!("the scene expands to more than {MAX_NODES} nodes"),
        ));
    }
    Ok(())
}

struct Cx<'a, 'input> {
    /// Line numbers of the text's byte offsets, for locating elements.
    lines: prism_math::LineIndex<'input>,
    file: &'a str,
}

impl Cx<'_, '_> {
    fn line(&self, n: XmlNode) -> u32 {
        self.lines.line(n.range().start)
    }

    fn err(&self, n: XmlNode, message: impl Into<String>) -> SceneError {
        SceneError::Element {
            file: self.file.to_string(),
            line: self.line(n),
            element: n.tag_name().name().to_string(),
            message: message.into(),
        }
    }
}

fn child<'a, 'i>(n: XmlNode<'a, 'i>, name: &str) -> Option<XmlNode<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(name))
}

fn children<'a, 'i: 'a>(
    n: XmlNode<'a, 'i>,
    name: &'a str,
) -> impl Iterator<Item = XmlNode<'a, 'i>> + 'a {
    n.children().filter(move |c| c.has_tag_name(name))
}

/// A `#id` attribute, without the `#`.
fn reference<'a>(cx: &Cx, n: XmlNode<'a, '_>, attr: &str) -> Result<&'a str, SceneError> {
    let v = n
        .attribute(attr)
        .ok_or_else(|| cx.err(n, format!("expected a {attr} attribute")))?;
    v.strip_prefix('#').ok_or_else(|| {
        cx.err(
            n,
            format!("{attr}: expected a local reference \"#id\", found {v:?}"),
        )
    })
}

/// The finite numbers in an element's text.
fn floats(cx: &Cx, n: XmlNode) -> Result<Vec<f64>, SceneError> {
    let text = n.text().unwrap_or("");
    let mut out = Vec::with_capacity(text.len() / 8);
    for (i, t) in text.split_ascii_whitespace().enumerate() {
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            Ok(_) => {
                return Err(cx.err(n, format!("number {i}: expected a finite value, found {t}")))
            }
            Err(_) => return Err(cx.err(n, format!("number {i}: expected a number, found {t:?}"))),
        }
    }
    Ok(out)
}

/// Exactly `count` finite numbers from an element's text.
fn floats_n(cx: &Cx, n: XmlNode, count: usize) -> Result<Vec<f64>, SceneError> {
    let v = floats(cx, n)?;
    if v.len() != count {
        return Err(cx.err(n, format!("expected {count} numbers, found {}", v.len())));
    }
    Ok(v)
}

/// The non-negative integers in an element's text.
fn indices(cx: &Cx, n: XmlNode) -> Result<Vec<u32>, SceneError> {
    let text = n.text().unwrap_or("");
    let mut out = Vec::with_capacity(text.len() / 3);
    for (i, t) in text.split_ascii_whitespace().enumerate() {
        out.push(t.parse::<u32>().map_err(|_| {
            cx.err(
                n,
                format!("index {i}: expected a non-negative integer, found {t:?}"),
            )
        })?);
    }
    Ok(out)
}

fn count_attr(cx: &Cx, n: XmlNode, attr: &str) -> Result<Option<usize>, SceneError> {
    n.attribute(attr)
        .map(|v| {
            v.trim().parse::<usize>().map_err(|_| {
                cx.err(
                    n,
                    format!("{attr}: expected a non-negative integer, found {v:?}"),
                )
            })
        })
        .transpose()
}

/// A `<source>`: its numbers grouped by the accessor's stride.
struct Source {
    values: Vec<f64>,
    stride: usize,
    count: usize,
    offset: usize,
}

impl Source {
    fn get(&self, i: usize, k: usize) -> f64 {
        self.values[self.offset + i * self.stride + k]
    }
}

fn read_source(cx: &Cx, s: XmlNode, min_stride: usize) -> Result<Source, SceneError> {
    let array = child(s, "float_array").ok_or_else(|| {
        cx.err(
            s,
            "expected a <float_array> (other array types are not geometry)",
        )
    })?;
    let values = floats(cx, array)?;
    if let Some(c) = count_attr(cx, array, "count")? {
        if c != values.len() {
            return Err(cx.err(
                array,
                format!("count says {c} numbers but {} are given", values.len()),
            ));
        }
    }
    let accessor = child(s, "technique_common").and_then(|t| child(t, "accessor"));
    let (stride, offset, count) = match accessor {
        Some(a) => {
            let stride = count_attr(cx, a, "stride")?.unwrap_or(1);
            let offset = count_attr(cx, a, "offset")?.unwrap_or(0);
            let count = match count_attr(cx, a, "count")? {
                Some(c) => c,
                None => values.len().saturating_sub(offset) / stride.max(1),
            };
            if stride < min_stride {
                return Err(cx.err(
                    a,
                    format!("stride {stride}: expected at least {min_stride} values per element"),
                ));
            }
            let needed = count
                .checked_mul(stride)
                .and_then(|v| v.checked_add(offset))
                .filter(|&n| n <= values.len());
            if needed.is_none() {
                return Err(cx.err(
                    a,
                    format!(
                        "{count} elements of stride {stride} need more than the {} numbers given",
                        values.len()
                    ),
                ));
            }
            (stride, offset, count)
        }
        None => (min_stride, 0, values.len() / min_stride),
    };
    Ok(Source {
        values,
        stride,
        count,
        offset,
    })
}

fn read_geometry(
    cx: &Cx,
    g: XmlNode,
    warn: &mut dyn FnMut(&str, String),
) -> Result<Shape, SceneError> {
    if let Some(mesh) = child(g, "mesh") {
        return read_mesh(cx, mesh, warn).map(Shape::Mesh);
    }
    let sphere = g
        .descendants()
        .find(|n| n.has_tag_name("technique") && n.attribute("profile") == Some("CGL"))
        .and_then(|t| child(t, "sphere"));
    if let Some(s) = sphere {
        let r = child(s, "radius").ok_or_else(|| cx.err(s, "expected a <radius>"))?;
        let radius = floats_n(cx, r, 1)?[0];
        if radius <= 0.0 {
            return Err(cx.err(r, format!("expected a positive radius, found {radius}")));
        }
        return Ok(Shape::Sphere { radius });
    }
    let kind = g
        .children()
        .find(|c| c.is_element())
        .map_or("nothing", |c| c.tag_name().name());
    warn(
        &format!("geometry:{kind}"),
        format!(
            "{}:{}: <geometry> holding <{kind}> is not read; it is skipped",
            cx.file,
            cx.line(g)
        ),
    );
    Ok(Shape::Empty)
}

/// One primitive element's inputs, resolved to sources.
struct Inputs<'s> {
    stride: usize,
    vertex: usize,
    normal: Option<(usize, &'s Source)>,
    uv: Option<(usize, &'s Source)>,
}

fn read_mesh(
    cx: &Cx,
    mesh: XmlNode,
    warn: &mut dyn FnMut(&str, String),
) -> Result<MeshData, SceneError> {
    let mut sources = HashMap::new();
    for s in children(mesh, "source") {
        let id = s
            .attribute("id")
            .ok_or_else(|| cx.err(s, "expected an id attribute"))?;
        if child(s, "float_array").is_some() {
            sources.insert(id, (s, read_source(cx, s, 1)?));
        }
    }
    let lookup = |n: XmlNode, min_stride: usize| -> Result<&Source, SceneError> {
        let id = reference(cx, n, "source")?;
        let (_, src) = sources
            .get(id)
            .ok_or_else(|| cx.err(n, format!("no <source> with id {id:?} in this mesh")))?;
        if src.stride < min_stride {
            return Err(cx.err(
                n,
                format!(
                    "source {id:?} has stride {}, expected at least {min_stride}",
                    src.stride
                ),
            ));
        }
        Ok(src)
    };

    let vertices = child(mesh, "vertices").ok_or_else(|| cx.err(mesh, "expected <vertices>"))?;
    let vertices_id = vertices
        .attribute("id")
        .ok_or_else(|| cx.err(vertices, "expected an id attribute"))?;
    let mut positions_src = None;
    let mut vertex_normals = None;
    let mut vertex_uvs = None;
    for input in children(vertices, "input") {
        match input.attribute("semantic") {
            Some("POSITION") => positions_src = Some(lookup(input, 3)?),
            Some("NORMAL") => vertex_normals = Some(lookup(input, 3)?),
            Some("TEXCOORD") => vertex_uvs = Some(lookup(input, 2)?),
            _ => {}
        }
    }
    let positions_src =
        positions_src.ok_or_else(|| cx.err(vertices, "expected a POSITION input"))?;
    let positions: Vec<DVec3> = (0..positions_src.count)
        .map(|i| {
            DVec3::new(
                positions_src.get(i, 0),
                positions_src.get(i, 1),
                positions_src.get(i, 2),
            )
        })
        .collect();
    let vertex_count = positions.len();
    for (what, src) in [("NORMAL", vertex_normals), ("TEXCOORD", vertex_uvs)] {
        if let Some(s) = src {
            if s.count < vertex_count {
                return Err(cx.err(
                    vertices,
                    format!(
                        "{what} has {} entries for {vertex_count} positions",
                        s.count
                    ),
                ));
            }
        }
    }

    let mut out = MeshData {
        mesh: PolyMesh::new(positions, &[]),
        ..MeshData::default()
    };
    let mut corner_normals: Vec<DVec3> = Vec::new();
    let mut corner_uvs: Vec<DVec2> = Vec::new();
    let mut all_normals = true;
    let mut all_uvs = true;
    let mut face = Vec::new();

    for prim in mesh.children().filter(|c| c.is_element()) {
        let kind = prim.tag_name().name();
        if !matches!(kind, "polylist" | "triangles" | "polygons") {
            if matches!(
                kind,
                "lines" | "linestrips" | "tristrips" | "trifans" | "spline"
            ) {
                warn(
                    &format!("primitive:{kind}"),
                    format!(
                        "{}:{}: <{kind}> is not read; its primitives are skipped",
                        cx.file,
                        cx.line(prim)
                    ),
                );
            }
            continue;
        }
        // Inputs: offsets, and the sources of VERTEX, NORMAL and the first TEXCOORD.
        let mut inputs = Inputs {
            stride: 0,
            vertex: usize::MAX,
            normal: vertex_normals.map(|s| (usize::MAX, s)),
            uv: vertex_uvs.map(|s| (usize::MAX, s)),
        };
        for input in children(prim, "input") {
            let offset = count_attr(cx, input, "offset")?
                .ok_or_else(|| cx.err(input, "expected an offset attribute"))?;
            if offset > 64 {
                return Err(cx.err(input, format!("offset {offset} is implausibly large")));
            }
            inputs.stride = inputs.stride.max(offset + 1);
            match input.attribute("semantic") {
                Some("VERTEX") => {
                    let id = reference(cx, input, "source")?;
                    if id != vertices_id {
                        return Err(cx.err(
                            input,
                            format!("VERTEX source {id:?} is not this mesh's <vertices> {vertices_id:?}"),
                        ));
                    }
                    inputs.vertex = offset;
                }
                Some("NORMAL") => inputs.normal = Some((offset, lookup(input, 3)?)),
                Some("TEXCOORD") => {
                    let first = !matches!(inputs.uv, Some((o, _)) if o != usize::MAX);
                    if first {
                        inputs.uv = Some((offset, lookup(input, 2)?));
                    }
                }
                _ => {}
            }
        }
        if inputs.vertex == usize::MAX {
            return Err(cx.err(prim, "expected a VERTEX input"));
        }
        // Polygon sizes and the index runs they use.
        let mut runs: Vec<(XmlNode, Vec<u32>, Vec<usize>)> = Vec::new();
        let declared = count_attr(cx, prim, "count")?;
        match kind {
            "polylist" => {
                let p = child(prim, "p");
                let vc = child(prim, "vcount");
                let (p, vc) = match (p, vc, declared) {
                    (None, _, Some(0)) | (_, None, Some(0)) => continue,
                    (Some(p), Some(vc), _) => (p, vc),
                    (None, _, _) => return Err(cx.err(prim, "expected a <p>")),
                    (_, None, _) => return Err(cx.err(prim, "expected a <vcount>")),
                };
                let sizes: Vec<usize> = indices(cx, vc)?.into_iter().map(|v| v as usize).collect();
                if let Some(c) = declared {
                    if c != sizes.len() {
                        return Err(cx.err(
                            vc,
                            format!(
                                "count says {c} polygons but {} sizes are given",
                                sizes.len()
                            ),
                        ));
                    }
                }
                runs.push((p, indices(cx, p)?, sizes));
            }
            "triangles" => {
                let Some(p) = child(prim, "p") else {
                    if declared.unwrap_or(0) == 0 {
                        continue;
                    }
                    return Err(cx.err(prim, "expected a <p>"));
                };
                let idx = indices(cx, p)?;
                let n = idx.len() / (3 * inputs.stride);
                if let Some(c) = declared {
                    if c != n {
                        return Err(
                            cx.err(p, format!("count says {c} triangles but {n} are given"))
                        );
                    }
                }
                runs.push((p, idx, vec![3; n]));
            }
            _ => {
                for p in children(prim, "p") {
                    let idx = indices(cx, p)?;
                    let n = idx.len() / inputs.stride;
                    runs.push((p, idx, vec![n]));
                }
                if let Some(ph) = child(prim, "ph") {
                    warn(
                        "polygons:ph",
                        format!(
                            "{}:{}: polygons with holes (<ph>) are not read; they are skipped",
                            cx.file,
                            cx.line(ph)
                        ),
                    );
                }
            }
        }

        let first_face = out.mesh.face_count();
        for (p, idx, sizes) in runs {
            let corners: usize = sizes.iter().sum();
            if corners.checked_mul(inputs.stride) != Some(idx.len()) {
                return Err(cx.err(
                    p,
                    format!(
                        "expected {} indices ({corners} corners × {} inputs), found {}",
                        corners.saturating_mul(inputs.stride),
                        inputs.stride,
                        idx.len()
                    ),
                ));
            }
            let mut at = 0;
            for (poly, &n) in sizes.iter().enumerate() {
                if n < 3 {
                    return Err(cx.err(
                        p,
                        format!("polygon {poly}: expected at least 3 vertices, found {n}"),
                    ));
                }
                face.clear();
                for c in 0..n {
                    let corner = &idx[(at + c) * inputs.stride..(at + c + 1) * inputs.stride];
                    let v = corner[inputs.vertex] as usize;
                    if v >= vertex_count {
                        return Err(cx.err(
                            p,
                            format!("polygon {poly}: vertex index {v} is out of range (there are {vertex_count} positions)"),
                        ));
                    }
                    face.push(v as u32);
                    // The attribute index of this corner: its own input, or the vertex's.
                    let index = |(o, src): (usize, &Source), what: &str| {
                        let i = if o == usize::MAX {
                            v
                        } else {
                            corner[o] as usize
                        };
                        if i < src.count {
                            Ok(i)
                        } else {
                            Err(cx.err(
                                p,
                                format!("polygon {poly}: {what} index {i} is out of range (there are {})", src.count),
                            ))
                        }
                    };
                    match inputs.normal {
                        Some(input) => {
                            let (i, s) = (index(input, "normal")?, input.1);
                            corner_normals.push(DVec3::new(s.get(i, 0), s.get(i, 1), s.get(i, 2)));
                        }
                        None => all_normals = false,
                    }
                    match inputs.uv {
                        Some(input) => {
                            let (i, s) = (index(input, "texture coordinate")?, input.1);
                            corner_uvs.push(DVec2::new(s.get(i, 0), s.get(i, 1)));
                        }
                        None => all_uvs = false,
                    }
                }
                out.mesh.push_face(&face);
                at += n;
            }
        }
        out.parts.push(Part {
            material: prim.attribute("material").map(str::to_string),
            faces: first_face..out.mesh.face_count(),
        });
    }

    if all_normals && !corner_normals.is_empty() {
        out.mesh.normals = per_vertex(&out.mesh, &corner_normals);
        out.corner_normals = Some(corner_normals);
    }
    if all_uvs && !corner_uvs.is_empty() {
        out.mesh.uvs = per_vertex(&out.mesh, &corner_uvs);
        out.corner_uvs = Some(corner_uvs);
    }
    Ok(out)
}

/// Per-corner values as per-vertex ones, if every corner of each vertex carries the same value
/// (and every vertex is used).
fn per_vertex<T: Copy + PartialEq>(mesh: &PolyMesh, corners: &[T]) -> Option<Vec<T>> {
    let mut out: Vec<Option<T>> = vec![None; mesh.vertex_count()];
    let mut k = 0;
    for f in mesh.faces() {
        for &v in f {
            let c = corners[k];
            k += 1;
            match out[v as usize] {
                None => out[v as usize] = Some(c),
                Some(prev) if prev == c => {}
                Some(_) => return None,
            }
        }
    }
    out.into_iter().collect()
}

struct Walker<'a, 'b, 'i> {
    cx: &'a Cx<'a, 'i>,
    geometry_index: &'a HashMap<String, usize>,
    library_nodes: &'a HashMap<String, XmlNode<'b, 'i>>,
    camera_ids: HashSet<&'a str>,
    light_ids: HashSet<&'a str>,
    material_ids: HashSet<&'a str>,
    /// Every light id, including lights of unknown kinds (skipped with a warning).
    all_light_ids: HashSet<&'a str>,
}

impl<'b, 'i> Walker<'_, 'b, 'i> {
    /// Reads node `n` under a parent with world matrix `parent` (and the parent's defect),
    /// then its children, depth first. The depth is checked before going deeper.
    fn node(
        &self,
        n: XmlNode<'b, 'i>,
        parent: DMat4,
        parent_defect: Option<&SceneError>,
        depth: usize,
        out: &mut Vec<Node>,
        warnings: &mut Vec<(String, String)>,
    ) -> Result<(), SceneError> {
        let cx = self.cx;
        if depth >= MAX_NODE_DEPTH {
            return Err(cx.err(n, format!("nodes nest deeper than {MAX_NODE_DEPTH}")));
        }
        let mut local = DMat4::IDENTITY;
        let mut defect = parent_defect.cloned();
        let mut instances = Vec::new();
        let mut kids = Vec::new();
        let note = |e: SceneError, warnings: &mut Vec<(String, String)>| {
            let message = format!("{e}; read past: an error only where it is used");
            warnings.push((message.clone(), message));
            e
        };
        for c in n.children().filter(|c| c.is_element()) {
            let name = c.tag_name().name();
            if matches!(name, "matrix" | "translate" | "scale" | "rotate" | "lookat") {
                match transform(cx, c) {
                    Ok(m) => local *= m,
                    Err(e) => {
                        if name == "matrix" {
                            local *= lenient_matrix(c);
                        }
                        let e = note(e, warnings);
                        defect.get_or_insert(e);
                    }
                }
                continue;
            }
            match name {
                "skew" => warnings.push((
                    "transform:skew".into(),
                    format!(
                        "{}:{}: <skew> is not read; the node is placed without it",
                        cx.file,
                        cx.line(c)
                    ),
                )),
                "instance_geometry" => {
                    let url = reference(cx, c, "url")?;
                    let geometry = *self
                        .geometry_index
                        .get(url)
                        .ok_or_else(|| cx.err(c, format!("no <geometry> with id {url:?}")))?;
                    let mut materials = Vec::new();
                    let mut binding_defect = None;
                    for im in c
                        .descendants()
                        .filter(|d| d.has_tag_name("instance_material"))
                    {
                        let binding = im
                            .attribute("symbol")
                            .ok_or_else(|| cx.err(im, "expected a symbol attribute"))
                            .and_then(|symbol| {
                                let target = reference(cx, im, "target")?;
                                if !self.material_ids.contains(target) {
                                    return Err(
                                        cx.err(im, format!("no <material> with id {target:?}"))
                                    );
                                }
                                Ok((symbol.to_string(), target.to_string()))
                            });
                        match binding {
                            Ok(b) => materials.push(b),
                            Err(e) => {
                                // Kept in place, so that "the first binding" still means it.
                                let symbol = im.attribute("symbol").unwrap_or("").to_string();
                                let target = im.attribute("target").unwrap_or("").to_string();
                                materials.push((symbol, target));
                                let e = note(e, warnings);
                                binding_defect.get_or_insert(e);
                            }
                        }
                    }
                    instances.push(Instance::Geometry {
                        geometry,
                        materials,
                        defect: binding_defect,
                    });
                }
                "instance_camera" => {
                    let camera = reference(cx, c, "url").and_then(|url| {
                        if self.camera_ids.contains(url) {
                            Ok(url)
                        } else {
                            Err(cx.err(c, format!("no <camera> with id {url:?}")))
                        }
                    });
                    instances.push(match camera {
                        Ok(url) => Instance::Camera(url.to_string()),
                        Err(e) => Instance::Missing(note(e, warnings)),
                    });
                }
                "instance_light" => {
                    let light = reference(cx, c, "url").and_then(|url| {
                        if self.all_light_ids.contains(url) {
                            Ok(url)
                        } else {
                            Err(cx.err(c, format!("no <light> with id {url:?}")))
                        }
                    });
                    match light {
                        Ok(url) if self.light_ids.contains(url) => {
                            instances.push(Instance::Light(url.to_string()));
                        }
                        // A light of an unknown kind was skipped with a warning.
                        Ok(_) => {}
                        Err(e) => instances.push(Instance::Missing(note(e, warnings))),
                    }
                }
                "instance_node" => {
                    let url = reference(cx, c, "url")?;
                    let target = *self.library_nodes.get(url).ok_or_else(|| {
                        cx.err(c, format!("no <node> with id {url:?} in <library_nodes>"))
                    })?;
                    kids.push(target);
                }
                "node" => kids.push(c),
                _ => {}
            }
        }
        let mut world = parent * local;
        if !world.is_finite() {
            let e = note(cx.err(n, "the node's world matrix is not finite"), warnings);
            defect.get_or_insert(e);
            world = DMat4::IDENTITY;
        }
        let id = n.attribute("id").unwrap_or("").to_string();
        out.push(Node {
            name: n.attribute("name").unwrap_or(&id).to_string(),
            id,
            line: cx.line(n),
            world,
            defect: defect.clone(),
            instances,
        });
        for k in kids {
            self.node(k, world, defect.as_ref(), depth + 1, out, warnings)?;
        }
        Ok(())
    }
}

/// One transform element (`matrix`, `translate`, `scale`, `rotate`, `lookat`) as a matrix.
fn transform(cx: &Cx, c: XmlNode) -> Result<DMat4, SceneError> {
    Ok(match c.tag_name().name() {
        "matrix" => {
            let v = floats_n(cx, c, 16)?;
            let mut cols = [0.0; 16];
            cols.copy_from_slice(&v);
            DMat4::from_cols_array(&cols).transpose()
        }
        "translate" => {
            let v = floats_n(cx, c, 3)?;
            DMat4::from_translation(DVec3::new(v[0], v[1], v[2]))
        }
        "scale" => {
            let v = floats_n(cx, c, 3)?;
            DMat4::from_scale(DVec3::new(v[0], v[1], v[2]))
        }
        "rotate" => {
            let v = floats_n(cx, c, 4)?;
            if v[3] == 0.0 {
                return Ok(DMat4::IDENTITY);
            }
            let axis = DVec3::new(v[0], v[1], v[2])
                .try_normalize()
                .ok_or_else(|| cx.err(c, "expected a non-zero rotation axis"))?;
            DMat4::from_axis_angle(axis, v[3].to_radians())
        }
        _ => {
            let v = floats_n(cx, c, 9)?;
            let eye = DVec3::new(v[0], v[1], v[2]);
            let target = DVec3::new(v[3], v[4], v[5]);
            let up = DVec3::new(v[6], v[7], v[8]);
            let forward = (target - eye).try_normalize();
            let right = forward.and_then(|f| f.cross(up).try_normalize());
            let (Some(f), Some(r)) = (forward, right) else {
                return Err(cx.err(
                    c,
                    "expected distinct eye and target and an up not along the view",
                ));
            };
            let u = r.cross(f);
            DMat4::from_cols(
                r.extend(0.0),
                u.extend(0.0),
                (-f).extend(0.0),
                DVec4::new(eye.x, eye.y, eye.z, 1.0),
            )
        }
    })
}

/// A malformed `<matrix>` as the course's renderer reads it: the finite numbers it holds,
/// in row-major order, over the identity (a short matrix keeps the identity's last entries;
/// numbers past 16 are dropped).
fn lenient_matrix(c: XmlNode) -> DMat4 {
    let mut rows = DMat4::IDENTITY.transpose().to_cols_array();
    let numbers = c
        .text()
        .unwrap_or("")
        .split_ascii_whitespace()
        .map_while(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()));
    for (slot, v) in rows.iter_mut().zip(numbers) {
        *slot = v;
    }
    DMat4::from_cols_array(&rows).transpose()
}

#[cfg(test)]
mod tests;
