//! Geometry: `<source>` arrays with their accessors, and `<mesh>` primitives
//! (`<polylist>`, `<triangles>`, `<polygons>`) read into polygons over shared positions
//! with per-corner normals and texture coordinates; the CGL sphere extra.

use prism_math::{Loc, Warning};
use std::collections::HashMap;

use prism_math::glam::{DVec2, DVec3};
use prism_mesh::PolyMesh;
use roxmltree::Node as XmlNode;

use super::document::{MeshData, Part, Shape};
use super::xml::{child, children, count_attr, floats, floats_n, indices, reference, Cx};
use crate::error::SceneError;

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

/// Reads a `<source>` of at least `min_stride` values per element.
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

/// Reads one `<geometry>`: a `<mesh>`, a CGL sphere, or (with a warning) nothing drawable.
pub(super) fn read_geometry(
    cx: &Cx,
    g: XmlNode,
    warn: &mut dyn FnMut(&str, Warning),
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
        Warning::at(
            Loc::line(cx.file, cx.line(g)),
            format!("<geometry> holding <{kind}> is not read; it is skipped"),
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

/// Reads a `<mesh>`: its sources and its `<polylist>`, `<triangles>` and `<polygons>`.
fn read_mesh(
    cx: &Cx,
    mesh: XmlNode,
    warn: &mut dyn FnMut(&str, Warning),
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
                    Warning::at(
                        Loc::line(cx.file, cx.line(prim)),
                        format!("<{kind}> is not read; its primitives are skipped"),
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
                        Warning::at(
                            Loc::line(cx.file, cx.line(ph)),
                            "polygons with holes (<ph>) are not read; they are skipped",
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
