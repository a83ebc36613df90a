//! Scenes built into prism, so that commands have something meaningful to show without input.

use prism_math::{Rgb, Vec3};

use crate::scene::{Camera, Light, Material, Scene, SceneSphere, Shading, TriangleMesh};

/// The course's Cornell box with two diffuse spheres (the geometry and materials of
/// `CBspheres_lambertian.dae`, in its Y-up world): a 2 x 1.5 x 2 box open towards the camera,
/// red wall on the left, blue on the right, two white spheres of radius 0.3, and a
/// 0.6 x 0.8 area light of radiance 10 just under the ceiling. The camera is where the
/// course's placement rule puts it for that file.
#[must_use]
pub fn cornell_box() -> Scene {
    let grey = |v: f32| Material::Diffuse {
        reflectance: Rgb::splat(v),
        texture: None,
    };
    let materials = vec![
        grey(0.8),
        grey(0.6),
        Material::Diffuse {
            reflectance: Rgb::new(0.6, 0.2, 0.2),
            texture: None,
        },
        Material::Diffuse {
            reflectance: Rgb::new(0.2, 0.2, 0.6),
            texture: None,
        },
    ];
    let back = -0.995_684;
    let quad = |name: &str, corners: [[f32; 3]; 4], material: usize| TriangleMesh {
        name: name.to_string(),
        positions: corners.iter().map(|&c| Vec3::from_array(c)).collect(),
        triangles: vec![[0, 1, 2], [3, 0, 2]],
        shading: Shading::Flat,
        material,
        uvs: None,
    };
    let meshes = vec![
        quad(
            "ceiling",
            [
                [1.0, 1.5, -1.0],
                [-1.0, 1.5, -1.0],
                [-1.0, 1.5, 1.0],
                [1.0, 1.5, 1.0],
            ],
            1,
        ),
        quad(
            "floor",
            [
                [1.0, 0.0, -1.0],
                [1.0, 0.0, 1.0],
                [-1.0, 0.0, 1.0],
                [-1.0, 0.0, -1.0],
            ],
            1,
        ),
        quad(
            "leftWall",
            [
                [-1.0, 1.5, -1.0],
                [-1.0, 0.0, -1.0],
                [-1.0, 0.0, 1.0],
                [-1.0, 1.5, 1.0],
            ],
            2,
        ),
        quad(
            "rightWall",
            [
                [1.0, 1.5, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, 0.0, -1.0],
                [1.0, 1.5, -1.0],
            ],
            3,
        ),
        quad(
            "backWall",
            [
                [1.0, 1.5, back],
                [1.0, 0.0, back],
                [-1.0, 0.0, back],
                [-1.0, 1.5, back],
            ],
            1,
        ),
    ];
    let spheres = vec![
        SceneSphere {
            center: Vec3::new(0.4, 0.3, 0.3),
            radius: 0.3,
            material: 0,
            inward: false,
            to_local: None,
        },
        SceneSphere {
            center: Vec3::new(-0.4, 0.3, -0.3),
            radius: 0.3,
            material: 0,
            inward: false,
            to_local: None,
        },
    ];
    // The ceiling light: 0.6 x 0.8 around (0, 1.49, 0), facing down.
    let (center, dim_x, dim_y) = (
        Vec3::new(0.0, 1.49, 0.0),
        Vec3::new(0.6, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.8),
    );
    let lights = vec![Light::Parallelogram {
        corner: center - 0.5 * dim_x - 0.5 * dim_y,
        edges: [dim_x, dim_y],
        colors: [Rgb::splat(10.0); 4],
        facing: Some(Vec3::NEG_Y),
    }];
    let hfov: f32 = 49.134_34;
    let vfov = (2.0 * ((hfov.to_radians() / 2.0).tan() / 1.333_333).atan()).to_degrees();
    // The course's rule: 1.5 times the box diagonal from its centre, along +z.
    let r = 1.5 * Vec3::new(2.0, 1.5, 2.0).length();
    Scene {
        meshes,
        spheres,
        materials,
        material_names: Vec::new(),
        one_sided: Vec::new(),
        lights,
        camera: Camera {
            eye: Vec3::new(0.0, 0.75, r),
            target: Vec3::new(0.0, 0.75, 0.0),
            up: Vec3::Y,
            hfov,
            vfov,
            near: 0.1,
            far: 100.0,
            lens: None,
            orthographic: None,
            crop: None,
        },
        warnings: Vec::new(),
    }
}
