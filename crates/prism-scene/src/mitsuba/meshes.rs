//! The meshes of Mitsuba's shapes in object space: the built-in rectangle, cube and disk laid
//! out as Mitsuba lays them out (texture coordinates included), OBJ files read by corners
//! as Mitsuba reads them (a vertex per distinct position, uv and normal) and PLY meshes, and
//! the vertex normals Mitsuba computes for meshes that have none.

use prism_math::glam::DVec3;
use prism_math::{Vec2, Vec3};

use super::limits::{CYLINDER_SEGMENTS, DISK_SEGMENTS};

/// A mesh in object space: positions, triangles, normals, uvs.
pub(super) type ObjectMesh = (
    Vec<DVec3>,
    Vec<[u32; 3]>,
    Option<Vec<DVec3>>,
    Option<Vec<Vec2>>,
);

pub(super) fn unit_mesh(
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    uvs: Option<Vec<Vec2>>,
) -> ObjectMesh {
    (positions, triangles, None, uvs)
}

/// Mitsuba's `cube`: [-1, 1]^3, four vertices a face so that each face is flat, laid out as
/// Mitsuba lays it out (faces -y, +y, +x, +z, -x, -z; each face's texture coordinates cover
/// the unit square; corner `c` at the signs of its bits), so that textures and anisotropic
/// tangents agree.
pub(super) fn cube() -> ObjectMesh {
    const CORNERS: [u32; 24] = [
        1, 5, 4, 0, 3, 2, 6, 7, 1, 3, 7, 5, 5, 7, 6, 4, 4, 6, 2, 0, 3, 1, 0, 2,
    ];
    // Mitsuba's (u, v) per face corner are (0,1) (1,1) (1,0) (0,0), v running down the
    // image; prism's v runs up it.
    const UV: [(f32, f32); 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let corner = |c: u32| {
        let sign = |bit: u32| if c & bit != 0 { 1.0 } else { -1.0 };
        DVec3::new(sign(1), sign(2), sign(4))
    };
    let positions = CORNERS.iter().map(|&c| corner(c)).collect();
    let uvs = (0..24)
        .map(|i| Vec2::new(UV[i % 4].0, UV[i % 4].1))
        .collect();
    let triangles = (0..6u32)
        .flat_map(|f| {
            let v = 4 * f;
            [[v, v + 1, v + 2], [v + 3, v, v + 2]]
        })
        .collect();
    (positions, triangles, None, Some(uvs))
}

/// Mitsuba's `disk`: radius 1 in the z = 0 plane, facing +z, as [`DISK_SEGMENTS`]
/// triangles, each with its own corners so that the texture coordinates are Mitsuba's polar
/// ones: `u` the radius, `v` the azimuth over 2 pi (running down the image; prism's v runs
/// up it).
pub(super) fn disk() -> ObjectMesh {
    let n = DISK_SEGMENTS;
    let mut positions = Vec::with_capacity(3 * n as usize);
    let mut uvs = Vec::with_capacity(3 * n as usize);
    let mut triangles = Vec::with_capacity(n as usize);
    for i in 0..n {
        let azimuth = |k: u32| std::f64::consts::TAU * f64::from(k) / f64::from(n);
        let (a, b) = (azimuth(i), azimuth(i + 1));
        let base = positions.len() as u32;
        positions.push(DVec3::ZERO);
        positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
        positions.push(DVec3::new(b.cos(), b.sin(), 0.0));
        let v = |k: f64| 1.0 - (k / f64::from(n)) as f32;
        uvs.push(Vec2::new(0.0, v(f64::from(i) + 0.5)));
        uvs.push(Vec2::new(1.0, v(f64::from(i))));
        uvs.push(Vec2::new(1.0, v(f64::from(i + 1))));
        triangles.push([base, base + 1, base + 2]);
    }
    (positions, triangles, None, Some(uvs))
}

/// Mitsuba's `cylinder` from `p0` to `p1` of `radius` (open at both ends), as
/// [`CYLINDER_SEGMENTS`] quads with the exact outward normal at each vertex; the azimuth
/// starts along the first tangent Mitsuba's frame of the axis has, and the texture
/// coordinates are Mitsuba's: `u` the azimuth over 2 pi, `v` along the axis from `p0`
/// (running down the image; prism's v runs up it).
pub(super) fn cylinder(p0: DVec3, p1: DVec3, radius: f64) -> ObjectMesh {
    let axis = p1 - p0;
    let frame = prism_math::Frame::from_normal(axis.normalize().as_vec3());
    let (s, t) = (frame.s.as_dvec3(), frame.t.as_dvec3());
    let n = CYLINDER_SEGMENTS;
    let mut positions = Vec::with_capacity(2 * (n as usize + 1));
    let mut normals = Vec::with_capacity(positions.capacity());
    let mut uvs = Vec::with_capacity(positions.capacity());
    for i in 0..=n {
        let phi = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        let radial = s * phi.cos() + t * phi.sin();
        for z in [0.0, 1.0] {
            positions.push(p0 + radial * radius + axis * z);
            normals.push(radial);
            uvs.push(Vec2::new(i as f32 / n as f32, 1.0 - z as f32));
        }
    }
    let triangles = (0..n)
        .flat_map(|i| {
            let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            // Counter-clockwise seen from outside: the normal points away from the axis.
            [[a, c, d], [a, d, b]]
        })
        .collect();
    (positions, triangles, Some(normals), Some(uvs))
}

/// A PLY file's mesh (its polygons as fans from their first vertex, as Mitsuba splits them).
pub(super) fn from_polymesh(p: &prism_mesh::PolyMesh) -> ObjectMesh {
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

/// An OBJ document as Mitsuba's `obj` shape reads it: one vertex per distinct (position,
/// uv, normal) triple of the corners, polygons as fans from their first corner; uvs kept as
/// the file writes them (prism's v runs up the image, as the file's does), normals only if
/// the corners name some. Fails if the vertices would outnumber `u32`.
pub(super) fn from_obj(doc: &prism_mesh::obj::ObjDocument<f64>) -> Result<ObjectMesh, String> {
    let has_uvs = doc.corners.iter().any(|c| c.vt().is_some());
    let has_normals = doc.corners.iter().any(|c| c.vn().is_some());
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut normals = Vec::new();
    let mut triangles = Vec::with_capacity(doc.corners.len());
    let mut face = Vec::new();
    for f in &doc.faces {
        face.clear();
        for c in doc.face_corners(f) {
            let key = (c.v, c.vt(), c.vn());
            let next = positions.len();
            let v = *index.entry(key).or_insert(next);
            if v == next {
                positions.push(DVec3::from_array(doc.positions[c.v as usize]));
                if has_uvs {
                    let t = c.vt().map_or([0.0; 2], |t| doc.uvs[t as usize]);
                    uvs.push(Vec2::new(t[0] as f32, t[1] as f32));
                }
                if has_normals {
                    normals.push(
                        c.vn()
                            .map_or(DVec3::ZERO, |n| DVec3::from_array(doc.normals[n as usize])),
                    );
                }
            }
            face.push(
                u32::try_from(v).map_err(|_| "more vertices than prism indexes".to_string())?,
            );
        }
        for i in 1..face.len().saturating_sub(1) {
            triangles.push([face[0], face[i], face[i + 1]]);
        }
    }
    Ok((
        positions,
        triangles,
        has_normals.then_some(normals),
        has_uvs.then_some(uvs),
    ))
}

/// Vertex normals as Mitsuba computes them for a file mesh without any (world space, after
/// the winding is final): each triangle's unit normal added to its corners weighted by the
/// corner's interior angle (Thürmer and Wüthrich 1998), normalised, vertex by vertex (two
/// vertices at one position but with different uvs keep their own). Degenerate triangles
/// add nothing; a vertex no triangle reaches gets +z.
pub(super) fn angle_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize].as_dvec3());
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.length_squared() <= 0.0 {
            continue;
        }
        let n = n.normalize();
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            acc[t[k] as usize] += n * a.dot(b).clamp(-1.0, 1.0).acos();
        }
    }
    acc.iter()
        .map(|n| {
            if n.length_squared() > 0.0 {
                n.normalize().as_vec3()
            } else {
                Vec3::Z
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: at a corner of a cube whose vertices are shared, three faces meet at
    /// right angles, so the computed normal is the diagonal (±1, ±1, ±1) / √3; and Mitsuba's
    /// OBJ reading makes one vertex per distinct (position, uv, normal) corner and fans
    /// polygons from their first corner.
    #[test]
    fn obj_corners_and_computed_normals_are_mitsubas() {
        let text =
            "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
                    vt 0 0\nvt 1 0\n\
                    f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
        let options = prism_mesh::obj::ObjOptions {
            attributes: true,
            ..Default::default()
        };
        let doc = prism_mesh::obj::ObjDocument::<f64>::parse(text, "cube.obj", options).unwrap();
        let (positions, triangles, normals, uvs) = from_obj(&doc).unwrap();
        assert_eq!((positions.len(), triangles.len()), (8, 12));
        assert!(normals.is_none() && uvs.is_none());
        assert_eq!(triangles[0], [0, 1, 2]);
        assert_eq!(triangles[1], [0, 2, 3]);
        let world: Vec<Vec3> = positions.iter().map(|p| p.as_vec3()).collect();
        let n = angle_weighted_normals(&world, &triangles);
        for (p, n) in world.iter().zip(&n) {
            assert!((*n - p.normalize()).length() < 1e-6, "{p} {n}");
        }
        // Corners that differ in their uv are separate vertices.
        let split = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 1\nf 1/1 2/1 3/1\nf 1/2 3/1 2/1\n";
        let doc = prism_mesh::obj::ObjDocument::<f64>::parse(split, "s.obj", options).unwrap();
        let (positions, triangles, _, uvs) = from_obj(&doc).unwrap();
        assert_eq!(positions.len(), 4);
        assert_eq!(triangles, vec![[0, 1, 2], [3, 2, 1]]);
        assert_eq!(uvs.unwrap()[3], Vec2::new(1.0, 1.0));
    }

    /// Closed form: every vertex of a cylinder lies at its radius from the axis, between
    /// its ends, with a unit normal square to the axis pointing away from it; each
    /// triangle's winding agrees with the normals (it faces outwards).
    #[test]
    fn cylinders_are_round_and_face_out() {
        let (p0, p1, r) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 0.0, 5.0), 0.5);
        let (positions, triangles, normals, uvs) = cylinder(p0, p1, r);
        let normals = normals.unwrap();
        let axis = (p1 - p0).normalize();
        for (p, n) in positions.iter().zip(&normals) {
            let along = (*p - p0).dot(axis);
            let off = (*p - p0) - axis * along;
            assert!((off.length() - r).abs() < 1e-6);
            assert!(along > -1e-6 && along < (p1 - p0).length() + 1e-6);
            assert!((off.normalize() - *n).length() < 1e-6);
        }
        for t in &triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.dot(normals[t[0] as usize]) > 0.0);
        }
        assert_eq!(uvs.unwrap().len(), positions.len());
    }
}
