//! Established tool's output: each picture here was drawn by OpenGL (Mesa llvmpipe, through
//! `shared/bench/shade/gl_ref.py` with the same mesh, camera, shader and options as the
//! case's arguments below). prism must draw the same pixels, up to rasterization ties along
//! triangle edges and last-bit differences in JPEG decoding (the cube map).

use std::path::PathBuf;

use prism_image::{CubeMap, RgbImage, CUBE_FACES};
use prism_math::{Rgb, Vec3};
use prism_shade::{
    course_texture, shade, to_bytes, ShadeMesh, ShadeOptions, Shader, Uniforms, View,
};
use prism_testkit::{compare_images, shared_asset};

fn rgb(path: &std::path::Path) -> RgbImage {
    prism_image::read_image(path)
        .unwrap()
        .to_rgb8()
        .to_rgb_f32()
}

fn textures() -> PathBuf {
    shared_asset("clothsim/textures")
}

struct Case {
    eye: Vec3,
    target: Vec3,
    fov_y: f32,
    size: (u32, u32),
    light: Vec3,
    intensity: Rgb,
    background: Rgb,
}

impl Default for Case {
    fn default() -> Case {
        Case {
            eye: Vec3::new(0.6, 0.8, 3.2),
            target: Vec3::ZERO,
            fov_y: 45.0,
            size: (160, 120),
            light: Vec3::new(0.5, 2.0, 2.0),
            intensity: Rgb::splat(3.0),
            background: Rgb::BLACK,
        }
    }
}

fn check(name: &str, shader: Shader, case: Case, min_identical: f64) {
    let text = std::fs::read_to_string(shared_asset("delft-raytracer/data/monkey.obj")).unwrap();
    let mesh = ShadeMesh::from_obj(&text, "monkey.obj").unwrap();
    let view = View {
        eye: case.eye,
        target: case.target,
        up: Vec3::Y,
        fov_y: case.fov_y,
        width: case.size.0,
        height: case.size.1,
    };
    let u = Uniforms {
        light_pos: case.light,
        light_intensity: case.intensity,
        ..Uniforms::default()
    };
    let opts = ShadeOptions {
        background: case.background,
        ..ShadeOptions::default()
    };
    let ours = to_bytes(&shade(&mesh, &view, &shader, &u, &opts).unwrap());
    let path = prism_testkit::workspace_root()
        .join("crates/prism-shade/tests/golden/gl")
        .join(format!("{name}.png"));
    let gl = prism_image::read_png(&path).unwrap().to_rgb8();
    compare_images(name, &gl, &ours, |s| {
        s.identical_fraction >= min_identical && s.over_24_fraction <= 0.002
    });
}

macro_rules! opengl_cases {
    ($($test:ident: $shader:expr, $case:expr, $min:expr;)*) => {$(
        /// The same pixels as OpenGL's picture of the case.
        #[test]
        fn $test() {
            check(stringify!($test), $shader, $case, $min);
        }
    )*};
}

opengl_cases! {
    monkey_normal: Shader::Normal, Case::default(), 0.995;
    monkey_wireframe: Shader::Wireframe, Case::default(), 0.995;
    monkey_diffuse: Shader::Diffuse, Case::default(), 0.995;
    monkey_phong: Shader::Phong, Case::default(), 0.995;
    monkey_texture: Shader::Texture(course_texture(rgb(&textures().join("texture_1.png")))), Case::default(), 0.995;
    monkey_bump: Shader::Bump(course_texture(rgb(&textures().join("texture_1.png")))), Case::default(), 0.995;
    monkey_displacement: Shader::Displacement(course_texture(rgb(&textures().join("texture_1.png")))), Case::default(), 0.995;
    monkey_mirror: Shader::Mirror(cube()), Case::default(), 0.97;
    monkey_phong_near_clip: Shader::Phong, Case {
        eye: Vec3::new(0.1, 0.1, 0.3),
        target: Vec3::new(0.0, 0.0, -1.0),
        fov_y: 70.0,
        ..Case::default()
    }, 0.995;
    monkey_phong_lit_from_below: Shader::Phong, Case {
        eye: Vec3::new(-1.5, -2.0, -2.5),
        fov_y: 30.0,
        size: (120, 160),
        light: Vec3::new(-1.0, -3.0, -1.0),
        intensity: Rgb::new(5.0, 4.0, 3.0),
        background: Rgb::new(0.1, 0.2, 0.3),
        ..Case::default()
    }, 0.995;
}

fn cube() -> CubeMap {
    let dir = textures().join("cube");
    let faces: [RgbImage; 6] = std::array::from_fn(|i| {
        let name = CUBE_FACES[i];
        let path = ["png", "jpg"]
            .iter()
            .map(|e| dir.join(format!("{name}.{e}")))
            .find(|p| p.is_file())
            .unwrap();
        rgb(&path)
    });
    CubeMap::new(faces).unwrap()
}
