//! The cloth drawn as the course app draws it: the cloth and its obstacles as shading meshes
//! for prism-shade, and the app's camera.

use prism_math::Vec3;
use prism_shade::{ShadeMesh, View};

use crate::{Cloth, ClothScene};

/// The cloth as a shading mesh: its grid at the masses' positions.
pub fn cloth_mesh(c: &Cloth) -> ShadeMesh {
    let p = &c.scene.cloth;
    let positions: Vec<Vec3> = c.positions.iter().map(|q| q.as_vec3()).collect();
    ShadeMesh::grid(&positions, p.num_width_points, p.num_height_points)
}

/// The course app's view: looking at `(avg.x, avg.y / 2, avg.z)` of the starting masses
/// from +z at `2 0.9 max(width, height)`, vertical field of view 35 degrees.
pub fn course_view(c: &Cloth, w: u32, h: u32) -> View {
    let n = c.positions.len() as f64;
    let avg = c
        .positions
        .iter()
        .fold(prism_math::glam::DVec3::ZERO, |a, p| a + *p)
        / n;
    let p = &c.scene.cloth;
    let target = Vec3::new(avg.x as f32, (avg.y / 2.0) as f32, avg.z as f32);
    let dist = (2.0 * 0.9 * p.width.max(p.height)) as f32;
    View {
        eye: target + Vec3::new(0.0, 0.0, dist),
        target,
        up: Vec3::Y,
        fov_y: 35.0,
        width: w,
        height: h,
    }
}

/// The sphere (at 0.92 of its radius, as the course app draws it) and the plane (a 2 m
/// square around its point) as one shading mesh.
pub fn obstacles(scene: &ClothScene) -> ShadeMesh {
    let mut obstacles = ShadeMesh::default();
    if let Some(s) = scene.sphere {
        obstacles.append(&ShadeMesh::sphere(
            s.origin.as_vec3(),
            0.92 * s.radius as f32,
            40,
        ));
    }
    if let Some(p) = scene.plane {
        // A 2 m square around the plane's point.
        let n = p.normal.as_vec3();
        let t = n.any_orthonormal_vector();
        let b = n.cross(t);
        let c = p.point.as_vec3();
        let corners = [c - t - b, c + t - b, c - t + b, c + t + b];
        let mut quad = ShadeMesh::grid(&corners, 2, 2);
        quad.normals = vec![n; 4];
        obstacles.append(&quad);
    }
    obstacles
}
