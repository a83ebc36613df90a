//! The gallery's cloth pictures: the course's scenes simulated, the stiffness and density
//! series, and the draped sphere with each shader.

use std::path::Path;

use anyhow::{Context, Result};
use prism_image::montage;

use super::index::Entry;

/// The cloth: the course's five scenes, the ks and density series, and a draped sphere with
/// each shader, drawn by prism-shade, each framed to hold the whole run.
pub fn pictures(output: &Path, assets: Option<&Path>, entries: &mut Vec<Entry>) -> Result<()> {
    use prism_shade::Shader;
    let Some(assets) = assets else {
        return Ok(());
    };
    let scenes = assets.join("clothsim/scene");
    let textures = assets.join("clothsim/textures");
    if !scenes.is_dir() || !textures.is_dir() {
        return Ok(());
    }
    let (w, h) = (240u32, 188u32);
    let user = |e: prism_cloth::ClothError| crate::error::UserError::input(e);
    let run = |name: &str, set: &[String], frames: u32| -> Result<prism_cloth::Cloth> {
        let scene =
            prism_cloth::read_scene(&scenes.join(format!("{name}.json")), set).map_err(user)?;
        let mut c = prism_cloth::Cloth::new(&scene);
        for _ in 0..frames {
            c.frame();
        }
        Ok(c)
    };
    let draw = |c: &prism_cloth::Cloth,
                view: &prism_shade::View,
                shader: &Shader|
     -> Result<prism_image::RgbImage> {
        let mut mesh = prism_cloth::cloth_mesh(c);
        mesh.append(&prism_cloth::obstacles(&c.scene));
        prism_shade::shade(
            &mesh,
            view,
            shader,
            &prism_shade::Uniforms::default(),
            &prism_shade::ShadeOptions::default(),
        )
        .map_err(|e| crate::error::UserError::input(e).into())
    };
    let frames = 90;
    // The gallery's camera: along the course app's view direction, raised a little, far
    // enough that the cloth at the end of the run (with where a hanging cloth started, and
    // the sphere a falling one drapes) fits the narrower side.
    let frame = |start: &prism_cloth::Cloth, end: &prism_cloth::Cloth| -> prism_shade::View {
        // A pinned cloth's pins hold its top where it started; a falling one has left it.
        let mut mesh = prism_cloth::cloth_mesh(end);
        if end.scene.sphere.is_none() && end.scene.plane.is_none() {
            mesh.append(&prism_cloth::cloth_mesh(start));
        }
        if let Some(s) = end.scene.sphere {
            mesh.append(&prism_shade::ShadeMesh::sphere(
                s.origin.as_vec3(),
                s.radius as f32,
                8,
            ));
        }
        let (lo, hi) = mesh.bounds().expect("a cloth has masses");
        prism_shade::View::fit(
            (lo + hi) * 0.5,
            (hi - lo).length() * 0.5,
            prism_math::Vec3::new(0.0, 0.35, 1.0).normalize(),
            prism_math::Vec3::Y,
            35.0,
            w,
            h,
            prism_shade::Framing::NarrowerSide { margin: 1.1 },
        )
    };
    let save = |name: &str,
                panels: &[prism_image::RgbImage],
                cols: usize,
                labels: &[&str]|
     -> Result<()> {
        let mut img = prism_shade::to_bytes(&montage(panels, cols, prism_math::Rgb::BLACK));
        super::labels::label_panels(&mut img, w, h, cols, labels);
        prism_image::write_png(&output.join(name), &img).with_context(|| format!("writing {name}"))
    };
    // The five scenes after one simulated second.
    let names = ["pinned2", "pinned4", "sphere", "plane", "selfCollision"];
    let mut panels = Vec::new();
    for n in names {
        let start = run(n, &[], 0)?;
        let c = run(n, &[], frames)?;
        panels.push(draw(&c, &frame(&start, &c), &Shader::Phong)?);
    }
    save("cloth_scenes.png", &panels, 5, &names)?;
    entries.push(Entry {
        file: "cloth_scenes.png".into(),
        caption: format!(
            "prism cloth: {} after one simulated second",
            names.join(", ")
        ),
    });
    // The report's series on pinned2.
    for (file, key, values) in [
        ("cloth_ks.png", "ks", ["500", "5000", "50000"]),
        ("cloth_density.png", "density", ["15", "150", "1500"]),
    ] {
        let mut panels = Vec::new();
        for v in values {
            let set = vec![format!("{key}={v}")];
            let start = run("pinned2", &set, 0)?;
            let end = run("pinned2", &set, frames)?;
            panels.push(draw(&end, &frame(&start, &end), &Shader::Phong)?);
        }
        let labels: Vec<String> = values.iter().map(|v| format!("{key} = {v}")).collect();
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        save(file, &panels, 3, &labels)?;
        entries.push(Entry {
            file: file.into(),
            caption: format!(
                "pinned2 with {key} = {} (--set {key}=...)",
                values.join(", ")
            ),
        });
    }
    // The draped sphere with each shader.
    let load = |f: &str| -> Result<prism_image::RgbImage> {
        Ok(prism_image::read_image(&textures.join(f))?
            .to_rgb8()
            .to_rgb_f32())
    };
    let tex = prism_shade::course_texture(load("texture_1.png")?);
    let cube = prism_image::CubeMap::read(&textures.join("cube"))?;
    let shaders = [
        Shader::Normal,
        Shader::Diffuse,
        Shader::Phong,
        Shader::Texture(tex.clone()),
        Shader::Bump(tex.clone()),
        Shader::Displacement(tex),
        Shader::Mirror(cube),
    ];
    let start = run("sphere", &[], 0)?;
    let c = run("sphere", &[], frames)?;
    let view = frame(&start, &c);
    let panels: Vec<_> = shaders
        .iter()
        .map(|s| draw(&c, &view, s))
        .collect::<Result<_>>()?;
    let labels = shaders.iter().map(Shader::name).collect::<Vec<_>>();
    save("cloth_shaders.png", &panels, 4, &labels)?;
    entries.push(Entry {
        file: "cloth_shaders.png".into(),
        caption:
            "the draped sphere with each shader: normal, diffuse, Blinn-Phong, texture, bump, \
                  displacement, mirror (texture_1 as texture and height map)"
                .into(),
    });
    Ok(())
}
