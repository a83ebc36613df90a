//! `prism`: one command for the prism graphics toolkit.

mod bezier;
mod cloth;
mod deferred;
mod demo;
mod error;
mod interrupt;
mod mesh;
mod output;
mod present;
mod progress;
mod raytrace;
mod render;
mod resources;
mod shade;
mod split;
mod svg;
mod view;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::deferred::Deferred;
use crate::error::{error_chain, UserError};

/// A computer-graphics toolkit on the CPU: SVG rasterization, mesh editing, path tracing.
#[derive(Parser)]
#[command(name = "prism", version, about, long_about = None)]
struct Cli {
    /// The memory budget: the most one film, frame or buffer sized by an input may take (a
    /// quarter of it for each decoded image), such as 4G or 512M; larger requests are
    /// refused before they are allocated.
    #[arg(long, global = true, value_name = "SIZE", default_value = "2G", value_parser = resources::parse_bytes)]
    max_memory: u64,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Rasterize SVG files to PNG (standard SVG, or the CS184 course dialect).
    Svg(Deferred<svg::SvgArgs>),
    /// Draw a Bezier curve's de Casteljau construction, or tessellate Bezier patches.
    Bezier(Deferred<bezier::BezierArgs>),
    /// Inspect, convert, edit and Loop-subdivide meshes (OBJ, PLY, COLLADA).
    Mesh(Deferred<mesh::MeshArgs>),
    /// Path-trace a CS184 COLLADA scene, or the built-in Cornell box.
    Render(Deferred<render::RenderArgs>),
    /// Whitted-ray-trace a Delft scene (preset, OBJ or TOML config), with visual debugging.
    Raytrace(Deferred<raytrace::RaytraceArgs>),
    /// Draw a mesh with one of the course's shaders, as its OpenGL app would, on the CPU.
    Shade(Deferred<shade::ShadeArgs>),
    /// Simulate the course's ClothSim scenes exactly; write OBJ and draw the run.
    Cloth(Deferred<cloth::ClothArgs>),
    /// Check the part files of a split render and assemble its picture, a row of tiles at a time.
    Merge(Deferred<split::MergeArgs>),
    /// Open an SVG drawing, a lit COLLADA scene (path-traced) or a cloth scene in an
    /// interactive window drawn on the CPU (X11 or Xvfb).
    View(Deferred<view::ViewArgs>),
    /// Write a gallery (index.html and one PNG per feature) from built-in inputs.
    Demo(Deferred<demo::DemoArgs>),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            match error::clap_error_line(&e) {
                Some(line) => eprintln!("prism: error: {line}"),
                None => {
                    let _ = e.print();
                }
            }
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    prism_math::limits::set_memory_budget(cli.max_memory);
    interrupt::clean_up_on_signals();
    let result = match cli.command {
        Command::Svg(a) => svg::run(&a),
        Command::Bezier(a) => bezier::run(&a),
        Command::Mesh(a) => mesh::run(&a),
        Command::Render(a) => render::run(&a),
        Command::Raytrace(a) => raytrace::run(&a),
        Command::Shade(a) => shade::run(&a),
        Command::Cloth(a) => cloth::run(&a),
        Command::Merge(a) => split::run(&a),
        Command::View(a) => view::run(&a),
        Command::Demo(a) => demo::run(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("prism: error: {}", error_chain(e.as_ref()));
            if e.downcast_ref::<UserError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Property: the names the typo suggestion offers are exactly the subcommands.
    #[test]
    fn suggested_subcommands_are_the_subcommands() {
        let names: Vec<String> = super::Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect();
        assert_eq!(names, super::error::SUBCOMMANDS);
    }

    /// clap's own consistency checks over every subcommand's options, once the deferred
    /// options are built.
    #[test]
    fn the_command_line_is_consistent() {
        super::Cli::command().debug_assert();
    }
}
