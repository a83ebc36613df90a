//! `prism demo`: a gallery of the features, drawn from built-in inputs, one module a system:
//! the rasterizer ([`svg`]), mesh editing ([`mesh`]), the path tracer ([`render`]), the
//! Whitted ray tracer ([`raytrace`]), the cloth with the shaders ([`cloth`]), and the
//! gallery's index ([`index`]).

mod cloth;
mod index;
mod labels;
mod mesh;
mod raytrace;
mod render;
mod svg;

use crate::error::UserError;
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
    /// The course's files (`shared/assets`), for the pictures made from them (the bunnies, the
    /// Delft presets, the cloth). Without it: `PRISM_DATA`, else a `shared/assets` folder above
    /// the executable or the working folder; if none is found, those pictures are left out
    /// and the run says so.
    #[arg(long, alias = "assets", value_name = "DIR")]
    pub data: Option<PathBuf>,
    /// Print each system's time on stderr (`svg: 812.3 ms`, ...).
    #[arg(long)]
    pub stats: bool,
    /// Worker threads (default: one per core; the pictures are the same bytes whatever the
    /// count).
    #[arg(short = 't', long)]
    pub threads: Option<usize>,
}

/// Runs `prism demo`.
pub fn run(a: &DemoArgs) -> Result<()> {
    crate::resources::pool(a.threads)?.install(|| run_in_pool(a))
}

/// Runs `prism demo` on the current worker pool.
fn run_in_pool(a: &DemoArgs) -> Result<()> {
    let assets = match prism_scene::course_assets(a.data.as_deref()) {
        Ok(found) => Some(found),
        Err(e @ prism_scene::AssetsError::NotFound { .. }) => {
            eprintln!(
                "prism: warning: {e}; the demo leaves out the pictures made from them (the \
                 bunnies, the Delft presets prism has no copy of, the cloth)"
            );
            None
        }
        Err(e) => return Err(UserError::input(e).into()),
    };
    // Only once the inputs are known good is anything created.
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("creating {}", a.output.display()))?;
    let assets = assets.as_deref();
    let mut entries = Vec::new();
    let jobs = svg::jobs()?;
    let pb = crate::progress::bar(jobs.len() as u64 + 12, "demo", a.quiet);
    let mut t = std::time::Instant::now();
    let mut stage = |name: &str| {
        if a.stats {
            pb.suspend(|| eprintln!("{name}: {:.1} ms", t.elapsed().as_secs_f64() * 1e3));
        }
        t = std::time::Instant::now();
    };
    svg::draw_jobs(jobs, &a.output, &mut entries, &pb)?;
    stage("svg");
    mesh::subdivision(&a.output, &mut entries, &pb)?;
    stage("mesh");
    render::pictures(&a.output, assets, &mut entries, &pb)?;
    stage("render");
    mesh::teapot(&a.output, &mut entries, &pb)?;
    stage("bezier");
    raytrace::pictures(&a.output, assets, &mut entries)?;
    stage("raytrace");
    cloth::pictures(&a.output, assets, &mut entries)?;
    stage("cloth");
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
