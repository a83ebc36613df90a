//! `prism.Mesh`, a halfedge mesh with edge flip, split and collapse, Loop subdivision and
//! normals, read and written as OBJ, PLY or COLLADA; `prism.bezier_patch`.

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::PyArray2;
use prism_mesh::{loop_subdivide, EdgeId, HalfedgeMesh, LoopWeights, PolyMesh, VertexId};
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::arrays::{points, rows};
use crate::errors::{argument, from_error};

/// A polygon mesh; edits work on its halfedge form (built when first needed), whose edge
/// numbers are those of `prism mesh info --edges`.
#[pyclass(module = "prism", name = "Mesh")]
pub struct Mesh {
    /// The mesh as read or made, with the file's normals and uvs.
    poly: PolyMesh,
    /// The halfedge form, once built.
    halfedge: Option<HalfedgeMesh>,
    /// True once an edit has changed the halfedge form, which is then the mesh.
    edited: bool,
    /// The file the mesh came from, for messages.
    name: String,
}

impl Mesh {
    fn new_from(poly: PolyMesh, name: String) -> Mesh {
        Mesh {
            poly,
            halfedge: None,
            edited: false,
            name,
        }
    }

    /// The mesh as polygons (after any edits).
    pub(crate) fn current(&self) -> Cow<'_, PolyMesh> {
        match (&self.halfedge, self.edited) {
            (Some(h), true) => Cow::Owned(h.to_polymesh()),
            _ => Cow::Borrowed(&self.poly),
        }
    }

    /// The halfedge form, built from the polygons if needed.
    fn halfedge(&mut self) -> PyResult<&mut HalfedgeMesh> {
        if self.halfedge.is_none() {
            let built = HalfedgeMesh::from_polymesh(&self.poly)
                .map_err(|e| from_error(&e, Some(&self.name)))?;
            self.halfedge = Some(built);
        }
        Ok(self.halfedge.as_mut().expect("built above"))
    }

    /// The edge `edge` names: an edge number, or `(a, b)`, two vertices it joins.
    fn edge_id(&mut self, edge: &Bound<'_, PyAny>) -> PyResult<EdgeId> {
        let m = self.halfedge()?;
        if let Ok(e) = edge.extract::<u32>() {
            return Ok(EdgeId(e));
        }
        let (a, b) = edge.extract::<(u32, u32)>().map_err(|_| {
            argument("edge: expected an edge number or a pair of vertex numbers (a, b)")
        })?;
        let n = m.vertex_count();
        if a as usize >= n || b as usize >= n {
            return Err(argument(format!(
                "edge ({a}, {b}): expected vertex numbers below {n}"
            )));
        }
        m.find_edge(VertexId(a), VertexId(b))
            .ok_or_else(|| argument(format!("edge ({a}, {b}): no edge joins these vertices")))
    }
}

/// Python warnings for a reader's warnings.
pub(crate) fn warn_all(py: Python<'_>, warnings: &[prism_math::Warning]) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for w in warnings {
        PyErr::warn(py, &category, &std::ffi::CString::new(w.to_string())?, 1)?;
    }
    Ok(())
}

/// The faces as `int64[F, k]` when they all have `k` corners, else a list of lists.
fn faces_of<'py>(py: Python<'py>, p: &PolyMesh) -> PyResult<Bound<'py, PyAny>> {
    let mut sides = p.faces().map(<[u32]>::len);
    let first = sides.next();
    if first.is_none_or(|k| sides.all(|s| s == k)) {
        let k = first.unwrap_or(3);
        let flat: Vec<i64> = p.faces().flatten().map(|&v| i64::from(v)).collect();
        let array = numpy::ndarray::Array2::from_shape_vec((p.face_count(), k), flat)
            .expect("k corners a face");
        return Ok(PyArray2::from_owned_array(py, array).into_any());
    }
    let list = PyList::empty(py);
    for f in p.faces() {
        list.append(f.to_vec())?;
    }
    Ok(list.into_any())
}

#[pymethods]
impl Mesh {
    /// A mesh from `vertices` (`float64[N, 3]`) and `faces` (an integer array `[F, k]`, or
    /// a list of lists for polygons of several sizes), vertices numbered from 0.
    #[new]
    fn py_new(vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<Mesh> {
        let positions = points(vertices, "vertices")?;
        let np = faces.py().import("numpy")?;
        let faces: Vec<Vec<i64>> = match faces.extract::<Vec<Vec<i64>>>() {
            Ok(f) => f,
            Err(_) => np
                .call_method1("asarray", (faces,))?
                .call_method0("tolist")?
                .extract()
                .map_err(|_| argument("faces: expected rows of vertex numbers"))?,
        };
        let n = positions.len();
        let mut checked = Vec::with_capacity(faces.len());
        for (i, f) in faces.iter().enumerate() {
            if f.len() < 3 {
                return Err(argument(format!(
                    "faces[{i}]: expected 3 or more corners, found {}",
                    f.len()
                )));
            }
            let face: Option<Vec<u32>> = f
                .iter()
                .map(|&v| u32::try_from(v).ok().filter(|&v| (v as usize) < n))
                .collect();
            checked.push(face.ok_or_else(|| {
                argument(format!(
                    "faces[{i}]: expected vertex numbers from 0 to {}, found {f:?}",
                    n.saturating_sub(1)
                ))
            })?);
        }
        Ok(Mesh::new_from(
            PolyMesh::new(positions, &checked),
            "<mesh>".into(),
        ))
    }

    /// Reads an .obj, .ply or .dae mesh. Unless `strict`, a non-manifold mesh is repaired
    /// as OpenMesh repairs it on load, with a warning per repair (as `prism mesh` does).
    #[staticmethod]
    #[pyo3(signature = (path, *, strict=false))]
    fn read(py: Python<'_>, path: PathBuf, strict: bool) -> PyResult<Mesh> {
        let name = path.display().to_string();
        let (poly, warnings) = py
            .detach(|| prism_scene::read_mesh_repaired(&path, strict))
            .map_err(|e| from_error(&e, Some(&name)))?;
        warn_all(py, &warnings)?;
        Ok(Mesh::new_from(poly, name))
    }

    /// Vertex positions, `float64[N, 3]` (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let positions = match (&self.halfedge, self.edited) {
            (Some(h), true) => h.positions(),
            _ => &self.poly.positions,
        };
        rows(py, positions.iter().map(|p| p.to_array()).collect())
    }

    /// Faces: `int64[F, k]` when every face has `k` corners, else a list of lists.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        faces_of(py, &self.current())
    }

    /// Edges as `int64[E, 2]`, the two vertices of each, numbered as the edits take them.
    #[getter]
    fn edges<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let m = self.halfedge()?;
        let edges = (0..m.edge_count())
            .map(|e| {
                let h = m.edge_halfedge(EdgeId(e as u32));
                [i64::from(m.origin(h).0), i64::from(m.dest(h).0)]
            })
            .collect();
        Ok(rows(py, edges))
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.current().vertex_count()
    }

    /// Number of faces.
    #[getter]
    fn face_count(&self) -> usize {
        self.current().face_count()
    }

    /// Area-weighted vertex normals, `float64[N, 3]`.
    fn normals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let normals = prism_mesh::vertex_normals_area_weighted(&self.current());
        rows(py, normals.iter().map(|n| n.to_array()).collect())
    }

    /// A new mesh: `levels` levels of Loop subdivision, with Warren's weights (the
    /// course's, `"warren"`) or Loop's (`"loop"`), as `prism mesh subdivide`.
    #[pyo3(signature = (levels=1, weights="warren", *, progress=None))]
    fn subdivide(
        &self,
        py: Python<'_>,
        levels: u32,
        weights: &str,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Mesh> {
        let w = match weights {
            "warren" => LoopWeights::Warren,
            "loop" => LoopWeights::Loop,
            _ => {
                return Err(argument(format!(
                    "weights: expected 'warren' or 'loop', found {weights:?}"
                )))
            }
        };
        let start = self.current().into_owned();
        let name = self.name.clone();
        prism_mesh::check_subdivision(start.face_count(), levels)
            .map_err(|e| from_error(&e, Some(&name)))?;
        let result = crate::work::run(py, None, progress, u64::from(levels), |control| {
            let mut p = start;
            for level in 0..levels {
                if control.stopped() {
                    break;
                }
                let m = HalfedgeMesh::from_polymesh(&p)?;
                p = loop_subdivide(&m, w)?;
                control.set_done(u64::from(level + 1));
            }
            Ok::<_, prism_mesh::MeshError>(p)
        })?
        .map_err(|e| from_error(&e, Some(&name)))?;
        Ok(Mesh::new_from(result, name))
    }

    /// Flips `edge` (an edge number, or `(a, b)`, the vertices it joins) in place.
    fn flip(&mut self, edge: &Bound<'_, PyAny>) -> PyResult<()> {
        let e = self.edge_id(edge)?;
        self.halfedge()?
            .flip(e)
            .map_err(|err| from_error(&err, None))?;
        self.edited = true;
        Ok(())
    }

    /// Splits `edge` at its midpoint in place; returns the new vertex's number.
    fn split(&mut self, edge: &Bound<'_, PyAny>) -> PyResult<u32> {
        let e = self.edge_id(edge)?;
        let v = self
            .halfedge()?
            .split(e)
            .map_err(|err| from_error(&err, None))?;
        self.edited = true;
        Ok(v.0)
    }

    /// Collapses `edge` to its midpoint in place; returns the kept vertex's number
    /// (vertices above it may be renumbered).
    fn collapse(&mut self, edge: &Bound<'_, PyAny>) -> PyResult<u32> {
        let e = self.edge_id(edge)?;
        let v = self
            .halfedge()?
            .collapse(e)
            .map_err(|err| from_error(&err, None))?;
        self.edited = true;
        Ok(v.0)
    }

    /// Writes the mesh as .obj, .ply (binary) or .dae, by the extension, whole or not at
    /// all.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let name = path.display().to_string();
        let Some(format) = prism_scene::MeshFormat::from_path(&path) else {
            return Err(argument(format!(
                "{name}: expected an .obj, .ply or .dae file name"
            )));
        };
        let mesh = self.current();
        let io = |p: &std::path::Path, source| prism_mesh::MeshError::Io {
            path: p.display().to_string(),
            source,
        };
        let mesh: &PolyMesh = &mesh;
        py.detach(|| {
            prism_image::write_atomic_with(
                &path,
                |w| prism_scene::write_mesh(mesh, format, w).map_err(|e| io(&path, e)),
                io,
            )
        })
        .map_err(|e| from_error(&e, Some(&name)))
    }

    fn __repr__(&self) -> String {
        let p = self.current();
        format!(
            "<prism.Mesh {} vertices, {} faces>",
            p.vertex_count(),
            p.face_count()
        )
    }
}

/// Reads a Bezier patch file (`.bez`, the course's) and tessellates every patch into a
/// `resolution x resolution` grid of quads split into triangles, welded, as `prism bezier`.
#[pyfunction]
#[pyo3(signature = (path, resolution=8))]
pub fn bezier_patch(py: Python<'_>, path: PathBuf, resolution: usize) -> PyResult<Mesh> {
    if resolution == 0 || resolution > 1024 {
        return Err(argument(format!(
            "resolution: expected 1..=1024, found {resolution}"
        )));
    }
    let name = path.display().to_string();
    let text = py
        .detach(|| prism_math::limits::read_input_text(&path, prism_mesh::MAX_MESH_FILE_BYTES))
        .map_err(|e| crate::errors::from_io(&e, &name))?;
    let patches = prism_mesh::parse_bez(&text, &name).map_err(|e| from_error(&e, Some(&name)))?;
    let mesh = py.detach(|| prism_mesh::tessellate(&patches, resolution));
    Ok(Mesh::new_from(mesh, name))
}
