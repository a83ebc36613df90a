//! The read COLLADA document as plain data: the up axis, geometries (meshes with parts,
//! spheres), the flattened nodes with their world matrices and instances, and
//! [`Collada::world_mesh`], every instanced mesh merged in world space.

use std::ops::Range;

use prism_math::glam::{DMat3, DMat4, DVec2, DVec3};
use prism_mesh::PolyMesh;

use super::library::{CameraDef, EffectDef, LightDef};
use crate::error::SceneError;

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
    pub warnings: Vec<prism_math::Warning>,
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
