//! The visual scene's node hierarchy: counting what `instance_node` references expand to
//! (and refusing cycles) before expanding, the depth-first walk that composes world
//! matrices and reads instances, and the transform elements.

use prism_math::{Loc, Warning};
use std::collections::{HashMap, HashSet};

use prism_math::glam::{DMat4, DVec3, DVec4};
use roxmltree::Node as XmlNode;

use super::document::{Instance, Node};
use super::limits::{MAX_NODES, MAX_NODE_DEPTH};
use super::xml::{children, floats_n, reference, Cx};
use crate::error::SceneError;

/// Counts the nodes the visual scene expands to, without expanding it, and refuses more
/// than [`MAX_NODES`] or an `instance_node` that leads back to a node containing it. Each
/// node is visited once, with an explicit stack.
pub(super) fn count_nodes<'b, 'i>(
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

/// The visual scene's walk: the ids references may name, and the nodes to instance.
pub(super) struct Walker<'a, 'b, 'i> {
    pub(super) cx: &'a Cx<'a, 'i>,
    pub(super) geometry_index: &'a HashMap<String, usize>,
    pub(super) library_nodes: &'a HashMap<String, XmlNode<'b, 'i>>,
    pub(super) camera_ids: HashSet<&'a str>,
    pub(super) light_ids: HashSet<&'a str>,
    pub(super) material_ids: HashSet<&'a str>,
    /// Every light id, including lights of unknown kinds (skipped with a warning).
    pub(super) all_light_ids: HashSet<&'a str>,
}

impl<'b, 'i> Walker<'_, 'b, 'i> {
    /// Reads node `n` under a parent with world matrix `parent` (and the parent's defect),
    /// then its children, depth first. The depth is checked before going deeper.
    pub(super) fn node(
        &self,
        n: XmlNode<'b, 'i>,
        parent: DMat4,
        parent_defect: Option<&SceneError>,
        depth: usize,
        out: &mut Vec<Node>,
        warnings: &mut Vec<(String, Warning)>,
    ) -> Result<(), SceneError> {
        let cx = self.cx;
        if depth >= MAX_NODE_DEPTH {
            return Err(cx.err(n, format!("nodes nest deeper than {MAX_NODE_DEPTH}")));
        }
        let mut local = DMat4::IDENTITY;
        let mut defect = parent_defect.cloned();
        let mut instances = Vec::new();
        let mut kids = Vec::new();
        let note = |e: SceneError, warnings: &mut Vec<(String, Warning)>| {
            let message = format!("{e}; read past: an error only where it is used");
            warnings.push((message.clone(), Warning::new(message)));
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
                    Warning::at(
                        Loc::line(cx.file, cx.line(c)),
                        "<skew> is not read; the node is placed without it",
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
