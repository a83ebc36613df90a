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
//!
//! Where things live: `document` (the plain data read), `limits`, `xml` (located errors,
//! numbers), `geometry` (sources and mesh primitives), `nodes` (the node hierarchy and
//! transforms), `library` (effects, lights, cameras); `to_scene` builds a [`crate::Scene`]
//! and `writer` writes a mesh back. This file reads the libraries in order.

mod document;
mod geometry;
mod library;
mod limits;
mod nodes;
mod to_scene;
mod writer;
mod xml;

use prism_math::Loc;
use prism_math::Warning;
use std::collections::HashMap;
use std::path::Path;

use prism_math::glam::DMat4;
use roxmltree::{Document, Node as XmlNode};

use crate::error::SceneError;
use geometry::read_geometry;
use nodes::{count_nodes, Walker};
use xml::{child, children, reference, Cx};

pub use document::{Collada, Geometry, Instance, MeshData, Node, Part, Shape, UpAxis};
pub use library::{CameraDef, EffectDef, LightDef, LightKind};
pub use limits::{MAX_COLLADA_BYTES, MAX_NODES, MAX_NODE_DEPTH, MAX_PLACED_FACES};
pub use writer::write_collada;

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
    let mut warn = |out: &mut Collada, key: &str, warning: Warning| {
        if warned.insert(key.to_string()) {
            out.warnings.push(warning);
        }
    };
    // A malformed entry is kept with its error, which is an error only for its users.
    let defect = |out: &mut Collada, e: SceneError| {
        out.warnings.push(Warning::new(format!(
            "{e}; read past: an error only where it is used"
        )));
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
                at: Loc::line(file, n.line),
                element: "node".into(),
                message: format!(
                    "the instances place more than {MAX_PLACED_FACES} polygons in the world"
                ),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
