//! The gallery's cloth pictures: the course's scenes simulated, the stiffness and density
//! series, and the draped sphere with each shader.

use std::path::Path;

use anyhow::{Context, Result};
use prism_image::montage;

use super::index::Entry;

/// The cloth: the course's five scenes, the ks and density series, and a draped sphere with
/// each shader, drawn by prism-shade with the course app's camera.
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
    let save = |name: &str, panels: &[prism_image::RgbImage], cols: usize| -> Result<()> {
        let img = montage(panels, cols, prism_math::Rgb::BLACK);
        prism_image::write_png(&output.join(name), &prism_shade::to_bytes(&img))
            .with_context(|| format!("writing {name}"))
    };
    // The five scenes after one simulated second.
    let names = ["pinned2", "pinned4", "sphere", "plane", "selfCollision"];
    let mut panels = Vec::new();
    for n in names {
        let start = run(n, &[], 0)?;
        let view = prism_cloth::course_view(&start, w, h);
        let c = run(n, &[], frames)?;
        panels.push(draw(&c, &view, &Shader::Phong)?);
    }
    save("cloth_scenes.png", &panels, 5)?;
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
            let view = prism_cloth::course_view(&start, w, h);
            panels.push(draw(&run("pinned2", &set, frames)?, &view, &Shader::Phong)?);
        }
        save(file, &panels, 3)?;
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
    let view = prism_cloth::course_view(&start, w, h);
    let c = run("sphere", &[], frames)?;
    let panels: Vec<_> = shaders
        .iter()
        .map(|s| draw(&c, &view, s))
        .collect::<Result<_>>()?;
    save("cloth_shaders.png", &panels, 4)?;
    entries.push(Entry {
        file: "cloth_shaders.png".into(),
        caption:
            "the draped sphere with each shader: normal, diffuse, Blinn-Phong, texture, bump, \
                  displacement, mirror (texture_1 as texture and height map)"
                .into(),
    });
    Ok(())
}
