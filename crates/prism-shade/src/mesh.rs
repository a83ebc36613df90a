//! [`ShadeMesh`], a mesh as OpenGL draws it: one vertex per distinct corner (position, uv,
//! normal and tangent), triangles over them; built from OBJ text (the course app's rules) or
//! from any polygon mesh prism reads.

use std::collections::HashMap;

use prism_math::glam::DVec3;
use prism_math::{Vec2, Vec3};

use prism_mesh::obj::{Corner, ObjDocument, ObjOptions};

use crate::error::ShadeError;

/// Vertex attributes and triangles, ready for the vertex stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadeMesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates ((0, 0) where the file gives none).
    pub uvs: Vec<Vec2>,
    /// Unit tangents (see [`ShadeMesh::compute_tangents`]).
    pub tangents: Vec<Vec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// A unit vector, or `fallback` for one too short to normalise.
fn unit_or(v: DVec3, fallback: DVec3) -> DVec3 {
    let l = v.length();
    if l > 1e-30 {
        v / l
    } else {
        fallback
    }
}

impl ShadeMesh {
    /// The mesh of OBJ text: each distinct `v/vt/vn` index triple is one vertex; polygons are
    /// fan-triangulated `(0, i, i + 1)`; a missing `vt` is (0, 0); file normals are
    /// normalised; corners without `vn` take the normalised sum of the cross products of
    /// the faces around their position (area-weighted); tangents as
    /// [`ShadeMesh::compute_tangents`]. `file` names the text in errors.
    ///
    /// # Errors
    /// [`ShadeError::Obj`] at the first malformed statement (the rules of
    /// [`ObjDocument::parse`]).
    pub fn from_obj(text: &str, file: &str) -> Result<ShadeMesh, ShadeError> {
        let options = ObjOptions {
            attributes: true,
            markers: false,
        };
        let doc = ObjDocument::<f64>::parse(text, file, options)?;
        let v: Vec<DVec3> = doc
            .positions
            .iter()
            .map(|p| DVec3::from_array(*p))
            .collect();
        let vn: Vec<DVec3> = doc.normals.iter().map(|n| DVec3::from_array(*n)).collect();
        let vt = &doc.uvs;
        let mut corner_of: HashMap<Corner, u32> = HashMap::new();
        let mut corners: Vec<(usize, Option<usize>, Option<usize>)> = Vec::new();
        let mut triangles = Vec::new();
        let mut face = Vec::new();
        for f in &doc.faces {
            face.clear();
            for &c in doc.face_corners(f) {
                let index = *corner_of.entry(c).or_insert_with(|| {
                    corners.push((
                        c.v as usize,
                        c.vt().map(|t| t as usize),
                        c.vn().map(|n| n as usize),
                    ));
                    (corners.len() - 1) as u32
                });
                face.push(index);
            }
            for i in 1..face.len() - 1 {
                triangles.push([face[0], face[i], face[i + 1]]);
            }
        }
        let position_of: Vec<usize> = corners.iter().map(|c| c.0).collect();
        let needs_generated = corners.iter().any(|c| c.2.is_none());
        let generated = if needs_generated {
            generated_normals(&v, &position_of, &triangles)
        } else {
            Vec::new()
        };
        let z = DVec3::Z;
        let mut mesh = ShadeMesh {
            positions: corners.iter().map(|c| v[c.0].as_vec3()).collect(),
            normals: corners
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let n = match c.2 {
                        Some(ni) => vn[ni],
                        None => generated[i],
                    };
                    unit_or(n, z).as_vec3()
                })
                .collect(),
            uvs: corners
                .iter()
                .map(|c| {
                    c.1.map_or(Vec2::ZERO, |t| Vec2::new(vt[t][0] as f32, vt[t][1] as f32))
                })
                .collect(),
            tangents: Vec::new(),
            triangles,
        };
        mesh.compute_tangents();
        Ok(mesh)
    }

    /// The mesh of a polygon mesh (PLY, COLLADA): one vertex per position, fans of its
    /// faces, area-weighted vertex normals, uvs (0, 0).
    #[must_use]
    pub fn from_polymesh(p: &prism_mesh::PolyMesh) -> ShadeMesh {
        let mut triangles = Vec::new();
        for f in p.faces() {
            for i in 1..f.len() - 1 {
                triangles.push([f[0], f[i], f[i + 1]]);
            }
        }
        let ids: Vec<usize> = (0..p.positions.len()).collect();
        let normals = generated_normals(&p.positions, &ids, &triangles);
        let mut mesh = ShadeMesh {
            positions: p.positions.iter().map(|q| q.as_vec3()).collect(),
            normals: normals
                .iter()
                .map(|&n| unit_or(n, DVec3::Z).as_vec3())
                .collect(),
            uvs: vec![Vec2::ZERO; p.positions.len()],
            tangents: Vec::new(),
            triangles,
        };
        mesh.compute_tangents();
        mesh
    }

    /// Tangents as the course app computes them: per triangle `T = (dv2 e1 - dv1 e2) / det`
    /// (`e1`, `e2` its edges, `du`, `dv` their uv steps, `det = du1 dv2 - du2 dv1`, triangles
    /// with `|det| <= 1e-20` giving none), summed per vertex, made orthogonal to the normal
    /// (Gram-Schmidt) and normalised; where that leaves nothing, `normalize(n x (0, 1, 0))`,
    /// else (1, 0, 0).
    pub fn compute_tangents(&mut self) {
        let mut acc = vec![DVec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let p0 = self.positions[a].as_dvec3();
            let e1 = self.positions[b].as_dvec3() - p0;
            let e2 = self.positions[c].as_dvec3() - p0;
            let (t0, t1, t2) = (
                self.uvs[a].as_dvec2(),
                self.uvs[b].as_dvec2(),
                self.uvs[c].as_dvec2(),
            );
            let (du1, dv1) = (t1.x - t0.x, t1.y - t0.y);
            let (du2, dv2) = (t2.x - t0.x, t2.y - t0.y);
            let det = du1 * dv2 - du2 * dv1;
            if det.abs() > 1e-20 {
                let tan = (dv2 * e1 - dv1 * e2) / det;
                for i in [a, b, c] {
                    acc[i] += tan;
                }
            }
        }
        self.tangents = acc
            .iter()
            .zip(&self.normals)
            .map(|(&t, n)| {
                let n = n.as_dvec3();
                let t = t - n * n.dot(t);
                let l = t.length();
                if l >= 1e-12 {
                    (t / l).as_vec3()
                } else {
                    let alt = n.cross(DVec3::Y);
                    let la = alt.length();
                    if la > 1e-6 {
                        (alt / la).as_vec3()
                    } else {
                        Vec3::X
                    }
                }
            })
            .collect();
    }

    /// A grid of `nw x nh` vertices in row-major order (index `y nw + x`), two triangles a
    /// cell, uvs `(x / (nw - 1), y / (nh - 1))`, area-weighted vertex normals and the
    /// constant tangent (1, 0, 0), as the course app uploads its cloth.
    ///
    /// # Panics
    /// If `positions` does not hold `nw nh` points or a side is below 2.
    #[must_use]
    pub fn grid(positions: &[Vec3], nw: usize, nh: usize) -> ShadeMesh {
        assert!(
            nw >= 2 && nh >= 2 && positions.len() == nw * nh,
            "a grid of nw x nh"
        );
        let mut triangles = Vec::with_capacity(2 * (nw - 1) * (nh - 1));
        for y in 0..nh - 1 {
            for x in 0..nw - 1 {
                let i = (y * nw + x) as u32;
                let (r, d, rd) = (i + 1, i + nw as u32, i + nw as u32 + 1);
                triangles.push([i, d, r]);
                triangles.push([r, d, rd]);
            }
        }
        let p64: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
        let ids: Vec<usize> = (0..positions.len()).collect();
        let normals = generated_normals(&p64, &ids, &triangles);
        ShadeMesh {
            positions: positions.to_vec(),
            normals: normals
                .iter()
                .map(|&n| unit_or(n, DVec3::Y).as_vec3())
                .collect(),
            uvs: (0..nh)
                .flat_map(|y| {
                    (0..nw).map(move |x| {
                        Vec2::new(x as f32 / (nw - 1) as f32, y as f32 / (nh - 1) as f32)
                    })
                })
                .collect(),
            tangents: vec![Vec3::X; positions.len()],
            triangles,
        }
    }

    /// A sphere of `n x n` latitude-longitude cells around `center`, outward normals.
    #[must_use]
    pub fn sphere(center: Vec3, radius: f32, n: usize) -> ShadeMesh {
        let n = n.max(3);
        let mut positions = Vec::new();
        for i in 0..=n {
            let theta = std::f32::consts::PI * i as f32 / n as f32;
            for j in 0..=n {
                let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                positions.push(d);
            }
        }
        let mut mesh = ShadeMesh::grid(&positions, n + 1, n + 1);
        mesh.normals.clone_from(&mesh.positions);
        for p in &mut mesh.positions {
            *p = center + radius * *p;
        }
        mesh.compute_tangents();
        mesh
    }

    /// Appends another mesh's vertices and triangles.
    pub fn append(&mut self, other: &ShadeMesh) {
        let off = self.positions.len() as u32;
        self.positions.extend(&other.positions);
        self.normals.extend(&other.normals);
        self.uvs.extend(&other.uvs);
        self.tangents.extend(&other.tangents);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + off)));
    }

    /// The bounds of the positions: `(min, max)`, or `None` for an empty mesh.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for &p in &self.positions {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }
}

/// Per corner, the sum of the (area-weighted) cross products of the triangles around its
/// position index.
fn generated_normals(v: &[DVec3], position_of: &[usize], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut acc = vec![DVec3::ZERO; v.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| v[position_of[i as usize]]);
        let n = (b - a).cross(c - a);
        for &i in t {
            acc[position_of[i as usize]] += n;
        }
    }
    position_of.iter().map(|&p| acc[p]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: a quad fans into two triangles; distinct v/vt/vn triples are distinct
    /// vertices; a missing vn gives the normalised sum of the face normals around the
    /// position; the tangent of a quad with u along x is +x.
    #[test]
    fn corners_normals_tangents() {
        let m = ShadeMesh::from_obj(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             f 1/1 2/2 3/3 4/4\n",
            "q.obj",
        )
        .unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.iter().all(|&n| n == Vec3::Z));
        for t in &m.tangents {
            assert!((*t - Vec3::X).length() < 1e-6, "{t}");
        }
        // Two faces around a shared edge at 90 degrees: the shared corners' normal is the
        // normalised sum.
        let m = ShadeMesh::from_obj(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\n",
            "e.obj",
        )
        .unwrap();
        let s = std::f32::consts::FRAC_1_SQRT_2;
        assert!(
            (m.normals[0] - Vec3::new(0.0, s, s)).length() < 1e-6,
            "{}",
            m.normals[0]
        );
        let e = ShadeMesh::from_obj("v 0 0 0\nf 1 2 3\n", "bad.obj").unwrap_err();
        assert_eq!(
            e.to_string(),
            "bad.obj:2: f: vertex index 2 is out of range (1 defined so far)"
        );
    }
}
