//! Fuzz the shading pipeline's OBJ reader and the pipeline: any input must give a mesh or a
//! located error, never a panic; a small mesh is drawn at 16 x 12 with every untextured
//! shader and a wireframe, from a camera framing it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_math::{Rgb, Vec3};
use prism_shade::{shade, to_bytes, ShadeMesh, ShadeOptions, Shader, Uniforms, View};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match ShadeMesh::from_obj(text, "fuzz.obj") {
        Ok(mesh) => {
            if mesh.triangles.len() > 2000 {
                return;
            }
            let Some((lo, hi)) = mesh.bounds() else { return };
            let c = (lo + hi) * 0.5;
            let r = (hi - lo).length().max(1e-3);
            if !c.is_finite() || !r.is_finite() {
                return;
            }
            let view = View {
                eye: c + Vec3::new(0.3, 0.2, 2.0) * r,
                target: c,
                up: Vec3::Y,
                fov_y: 45.0,
                width: 16,
                height: 12,
            };
            let opts = ShadeOptions {
                samples: 4,
                wireframe: Some(Rgb::new(1.0, 0.0, 0.0)),
                ..ShadeOptions::default()
            };
            for shader in [Shader::Normal, Shader::Wireframe, Shader::Diffuse, Shader::Phong] {
                if let Ok(img) = shade(&mesh, &view, &shader, &Uniforms::default(), &opts) {
                    let _ = to_bytes(&img);
                }
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.obj:"), "{e}"),
    }
});
