//! `prism demo`: a gallery of the features, drawn from built-in inputs, one module a system:
//! the rasterizer ([`svg`]), mesh editing ([`mesh`]), the path tracer ([`render`]), the
//! Whitted ray tracer ([`raytrace`]), the cloth with the shaders ([`cloth`]), and the
//! gallery's index ([`index`]).

mod cloth;
mod index;
mod mesh;
mod raytrace;
mod render;
mod svg;

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

/// Arguments of `prism demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder to write the gallery into (created if missing).
    #[arg(short, long, default_value = "gallery")]
    pub output: PathBuf,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// The course's staged assets, for the pictures that need their files (the bunny); those
    /// pictures are left out when the folder is missing.
    #[arg(long, default_value = "../shared/assets")]
    pub assets: PathBuf,
}

/// Runs `prism demo`.
pub fn run(a: &DemoArgs) -> Result<()> {
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("creating {}", a.output.display()))?;
    let mut entries = Vec::new();
    let jobs = svg::jobs()?;
    let pb = crate::progress::bar(jobs.len() as u64 + 11, "demo", a.quiet);
    svg::draw_jobs(jobs, &a.output, &mut entries, &pb)?;
    mesh::subdivision(&a.output, &mut entries, &pb)?;
    render::pictures(&a.output, &a.assets, &mut entries, &pb)?;
    mesh::teapot(&a.output, &mut entries, &pb)?;
    raytrace::pictures(&a.output, &a.assets, &mut entries)?;
    cloth::pictures(&a.output, &a.assets, &mut entries)?;
    pb.finish_and_clear();
    index::write_index(&a.output, &entries)?;
    if !a.quiet {
        eprintln!(
            "wrote {} images and index.html to {}",
            entries.len(),
            a.output.display()
        );
    }
    Ok(())
}
