//! The gallery's mesh pictures: a de Casteljau construction, the icosahedron through Loop
//! subdivision, and the Utah teapot's Bezier patches, shaded with their edges on top.

use std::path::Path;

use anyhow::{Context, Result};
use indicatif::ProgressBar;

use super::index::Entry;

/// Draws a mesh Blinn-Phong shaded with its edges on top, framed from the front and a
/// little above, and writes it to a PNG.
fn write_shaded(mesh: &prism_mesh::PolyMesh, size: u32, out: &Path) -> Result<()> {
    let mut m = prism_shade::ShadeMesh::from_polymesh(mesh);
    let (lo, hi) = m.bounds().context("the mesh has vertices")?;
    let centre = (lo + hi) * 0.5;
    // A mesh wound inside out (the teapot's patches) is lit from outside all the same.
    let outward: f32 = m
        .positions
        .iter()
        .zip(&m.normals)
        .map(|(p, n)| n.dot(*p - centre))
        .sum();
    if outward < 0.0 {
        m.normals.iter_mut().for_each(|n| *n = -*n);
    }
    let r = (hi - lo).length() * 0.5;
    let dir = prism_math::Vec3::new(0.35, 0.45, 1.0).normalize();
    let view = prism_shade::View::fit(
        centre,
        r,
        dir,
        prism_math::Vec3::Y,
        45.0,
        size,
        size,
        prism_shade::Framing::Vertical { margin: 1.05 },
    );
    let u = prism_shade::Uniforms {
        light_pos: centre + prism_math::Vec3::new(2.0, 3.0, 4.0) * r,
        light_intensity: prism_math::Rgb::splat((29.0f32 * r * r).max(1e-6)),
        ..prism_shade::Uniforms::default()
    };
    let opts = prism_shade::ShadeOptions {
        samples: 4,
        background: prism_math::Rgb::WHITE,
        wireframe: Some(prism_math::Rgb::splat(0.15)),
        // Thinner edges on dense meshes.
        wire_width: if m.triangles.len() > 1000 { 0.3 } else { 0.75 },
    };
    let img = prism_shade::shade(&m, &view, &prism_shade::Shader::Phong, &u, &opts)
        .map_err(crate::error::UserError::input)?;
    prism_image::write_png(out, &prism_shade::to_bytes(&img))
        .with_context(|| format!("writing {}", out.display()))
}

/// The de Casteljau construction and three levels of Loop subdivision, each one step of
/// `pb`.
pub fn subdivision(output: &Path, entries: &mut Vec<Entry>, pb: &ProgressBar) -> Result<()> {
    // Mesh editing: a de Casteljau construction, and Loop subdivision, shaded with edges.
    let curve = [
        prism_math::DVec2::new(0.2, 0.35),
        prism_math::DVec2::new(0.3, 0.6),
        prism_math::DVec2::new(0.5, 0.75),
        prism_math::DVec2::new(0.7, 0.45),
        prism_math::DVec2::new(1.0, 0.9),
    ];
    crate::bezier::write_curve(
        &curve,
        0.5,
        300,
        &output.join("bezier_decasteljau.png"),
        crate::output::ImageFormat::Png,
    )?;
    entries.push(Entry {
        file: "bezier_decasteljau.png".into(),
        caption: "Bezier curve with its de Casteljau levels at t = 0.5".into(),
    });
    pb.inc(1);
    let mut mesh = prism_mesh::icosahedron();
    for level in 0..=2 {
        if level > 0 {
            let he = prism_mesh::HalfedgeMesh::from_polymesh(&mesh)?;
            mesh = prism_mesh::loop_subdivide(&he, prism_mesh::LoopWeights::Warren)?;
        }
        let file = format!("loop_level_{level}.png");
        write_shaded(&mesh, 300, &output.join(&file))?;
        entries.push(Entry {
            file,
            caption: format!(
                "Icosahedron after {level} level(s) of Loop subdivision ({} faces)",
                mesh.face_count()
            ),
        });
        pb.inc(1);
    }
    Ok(())
}

/// The Utah teapot, one step of `pb`.
pub fn teapot(output: &Path, entries: &mut Vec<Entry>, pb: &ProgressBar) -> Result<()> {
    // The Utah teapot's 32 bicubic patches (Newell, 1975), tessellated and welded; Z up.
    let patches = prism_mesh::parse_bez(include_str!("../../data/teapot.bez"), "teapot.bez")?;
    let mut teapot = prism_mesh::tessellate(&patches, 8);
    for p in &mut teapot.positions {
        *p = prism_math::glam::DVec3::new(p.x, p.z, -p.y);
    }
    write_shaded(&teapot, 300, &output.join("bezier_teapot.png"))?;
    entries.push(Entry {
        file: "bezier_teapot.png".into(),
        caption: format!(
            "Utah teapot: 32 bicubic patches tessellated at 8x8 and welded ({} vertices, {} triangles)",
            teapot.vertex_count(),
            teapot.face_count()
        ),
    });
    pb.inc(1);
    Ok(())
}
