//! Area-weighted vertex normals of a polygon mesh.

use prism_math::glam::DVec3;

use crate::PolyMesh;

/// Area-weighted vertex normals: each vertex gets the normalised sum, over its faces, of the
/// face's area times its unit normal. For a polygon that product is half its Newell vector
/// `sum (p_i x p_{i+1})`, so triangles contribute `(b - a) x (c - a) / 2`. This is libigl's
/// `per_vertex_normals` with area weighting. A vertex with no faces, or whose weighted sum
/// vanishes, gets the zero vector.
#[must_use]
pub fn vertex_normals_area_weighted(mesh: &PolyMesh) -> Vec<DVec3> {
    let mut acc = vec![DVec3::ZERO; mesh.vertex_count()];
    for face in mesh.faces() {
        let mut newell = DVec3::ZERO;
        for k in 0..face.len() {
            let p = mesh.positions[face[k] as usize];
            let q = mesh.positions[face[(k + 1) % face.len()] as usize];
            newell += p.cross(q);
        }
        for &v in face {
            acc[v as usize] += newell;
        }
    }
    acc.into_iter().map(DVec3::normalize_or_zero).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icosahedron;

    /// Closed form: on the icosahedron every vertex normal is the radial direction.
    #[test]
    fn icosahedron_normals_are_radial() {
        let m = icosahedron();
        for (n, p) in vertex_normals_area_weighted(&m).iter().zip(&m.positions) {
            assert!((*n - p.normalize()).length() < 1e-12);
        }
    }

    /// Closed form: a vertex shared by a big and a small face leans to the big one in
    /// proportion to area.
    #[test]
    fn weights_by_area() {
        let p = PolyMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
            ],
            // Triangle in z = 0 (area 2, normal +z) and in y = 0 (area 1, normal +y).
            &[vec![0, 1, 2], vec![0, 3, 1]],
        );
        let n = vertex_normals_area_weighted(&p)[0];
        assert!((n - DVec3::new(0.0, 1.0, 2.0).normalize()).length() < 1e-12);
    }
}
