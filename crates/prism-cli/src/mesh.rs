//! `prism mesh`: inspect, convert, edit and subdivide meshes (OBJ, PLY, COLLADA; PLY is
//! written as binary little-endian; COLLADA input is flattened to one Y-up world-space mesh).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::{Args, Subcommand, ValueEnum};
use prism_mesh::{loop_subdivide, HalfedgeMesh, LoopWeights, PolyMesh, TopologyError};

use crate::error::UserError;

/// Arguments of `prism mesh`.
#[derive(Args, Debug)]
pub struct MeshArgs {
    #[command(subcommand)]
    command: MeshCommand,
    /// Refuse a non-manifold mesh instead of repairing it with a warning, as OpenMesh and
    /// pmp do on load (a vertex where fans of faces touch becomes one vertex per fan; a
    /// face on an edge already used in its direction gets vertices of its own).
    #[arg(long, global = true)]
    strict: bool,
    /// No progress bar, warnings or summary lines (errors and the listings asked for still
    /// print).
    #[arg(short, long, global = true)]
    quiet: bool,
    /// Print times on stderr: per stage for subdivide (`subdivide: 12.3 ms`), the whole
    /// command's for the others (`total: 1.2 ms`).
    #[arg(long, global = true)]
    stats: bool,
}

/// Neighbour weights for Loop subdivision.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Weights {
    /// Warren's beta (3/16 for valence 3, else 3/(8n)), as the CS184 course uses.
    Warren,
    /// Loop's original beta.
    Loop,
}

/// A mesh, an output, and one edge of it.
#[derive(Args, Debug)]
struct EdgeArgs {
    /// Input mesh (.obj, .ply or .dae).
    input: PathBuf,
    /// Output mesh (.obj, .ply or .dae).
    #[arg(short, long)]
    output: PathBuf,
    /// The edge by index (as `prism mesh info` numbers edges: in order of first use).
    #[arg(long, conflicts_with = "vertices")]
    edge: Option<u32>,
    /// The edge by its two vertex indices, counted from 1 as in the OBJ file: A,B.
    #[arg(long, value_name = "A,B")]
    vertices: Option<String>,
}

#[derive(Subcommand, Debug)]
enum MeshCommand {
    /// Print vertex, edge and face counts, boundary edges and the Euler characteristic;
    /// with --vertices, --edges or --faces, also list them (vertices numbered from 1 as in
    /// OBJ files, edges and faces from 0, as the edge operations take them).
    Info {
        /// Input mesh (.obj, .ply or .dae).
        input: PathBuf,
        /// List vertices with their positions.
        #[arg(long)]
        vertices: bool,
        /// List edges with their end vertices and positions (the numbers --edge takes).
        #[arg(long)]
        edges: bool,
        /// List faces with their vertices.
        #[arg(long)]
        faces: bool,
        /// Most items listed per kind (0: all).
        #[arg(long, default_value_t = 20)]
        limit: usize,
    },
    /// Area-weighted vertex normals (written as `vn` in OBJ output).
    Normals {
        /// Input mesh (.obj, .ply or .dae).
        input: PathBuf,
        /// Output mesh (.obj and .dae carry the normals; .ply carries positions and faces only).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Read and write a mesh (checks that it builds a valid halfedge mesh).
    Convert {
        /// Input mesh (.obj, .ply or .dae).
        input: PathBuf,
        /// Output mesh (.obj, .ply or .dae).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Split an edge at its midpoint (interior or boundary edge of triangles).
    Split(EdgeArgs),
    /// Flip an interior edge between two triangles.
    Flip(EdgeArgs),
    /// Collapse an edge (interior or boundary) to its midpoint, if the link condition holds.
    Collapse(EdgeArgs),
    /// Loop subdivision of a triangle mesh.
    Subdivide {
        /// Input mesh (.obj, .ply or .dae).
        input: PathBuf,
        /// Output mesh (.obj, .ply or .dae).
        #[arg(short, long)]
        output: PathBuf,
        /// Number of levels.
        #[arg(short = 'n', long, default_value_t = 1)]
        levels: u32,
        /// Neighbour weights.
        #[arg(long, value_enum, default_value_t = Weights::Warren)]
        weights: Weights,
    },
}

fn build(path: &Path, mesh: &PolyMesh) -> Result<HalfedgeMesh> {
    HalfedgeMesh::from_polymesh(mesh)
        .map_err(|e| UserError::input(format!("{}: {e}", path.display())).into())
}

/// Reads a mesh and, unless `strict`, repairs it as OpenMesh does on load, printing the
/// reader's warnings and one per repair (prism-scene's [`prism_scene::read_mesh_repaired`]).
fn load(path: &Path, (strict, quiet): (bool, bool)) -> Result<PolyMesh> {
    let (mesh, warnings) =
        prism_scene::read_mesh_repaired(path, strict).map_err(UserError::input)?;
    for w in warnings.iter().filter(|_| !quiet) {
        eprintln!("warning: {w}");
    }
    Ok(mesh)
}

/// Writes a mesh as .obj, .ply (binary little-endian) or .dae, chosen by extension,
/// atomically. The extension and folder are checked (by [`crate::output::mesh_output`])
/// before any work.
pub(crate) fn write(path: &Path, mesh: &PolyMesh) -> Result<()> {
    let format = crate::output::mesh_output(path, "--output")?;
    let io = |p: &Path, source| prism_mesh::MeshError::Io {
        path: p.display().to_string(),
        source,
    };
    prism_image::write_atomic_with(
        path,
        |w| prism_scene::write_mesh(mesh, format, w).map_err(|e| io(path, e)),
        io,
    )?;
    Ok(())
}

fn ms(d: std::time::Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}

/// A position as three numbers.
fn xyz(p: prism_math::glam::DVec3) -> String {
    format!("{} {} {}", number(p.x), number(p.y), number(p.z))
}

/// A coordinate as a person reads it: the shortest text that gives back its single-precision
/// value (the precision mesh files hold; double-precision noise such as 1.9999984000003002
/// from a file's transforms is not shown), in exponent form when very small or large.
fn number(x: f64) -> String {
    let f = x as f32;
    let a = f.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-4..1e7).contains(&a) {
        format!("{f}")
    } else {
        format!("{f:e}")
    }
}

/// An edge as `vertices A,B` (numbered from 1), with " (boundary)" when it is one.
fn edge_words(m: &HalfedgeMesh, e: prism_mesh::EdgeId) -> String {
    let h = m.edge_halfedge(e);
    let (a, b) = (m.origin(h), m.dest(h));
    let boundary = if m.is_boundary_edge(e) {
        " (boundary)"
    } else {
        ""
    };
    format!("vertices {},{}{boundary}", a.0 + 1, b.0 + 1)
}

/// Prints up to `limit` lines (all with 0), then how many were left out.
fn list(kind: &str, count: usize, limit: usize, line: impl Fn(usize) -> String) {
    let shown = if limit == 0 { count } else { count.min(limit) };
    for i in 0..shown {
        println!("{}", line(i));
    }
    if shown < count {
        println!(
            "... {} more {kind} (--limit {count} lists them all)",
            count - shown
        );
    }
}

/// Reads a mesh, applies `op` to the chosen edge, prints what changed and writes the result.
/// `op` says what it did, in words.
fn edge_op(
    args: &EdgeArgs,
    (strict, quiet): (bool, bool),
    what: &str,
    op: impl FnOnce(&mut HalfedgeMesh, prism_mesh::EdgeId) -> Result<String, TopologyError>,
) -> Result<()> {
    let (input, output) = (&args.input, &args.output);
    let (edge, vertices) = (args.edge, args.vertices.as_deref());
    let p = load(input, (strict, quiet))?;
    let mut m = build(input, &p)?;
    let e = match (edge, vertices) {
        (Some(e), _) => prism_mesh::EdgeId(e),
        (None, Some(v)) => {
            let n = m.vertex_count();
            let ids: Vec<u32> = v
                .split(',')
                .map(|x| x.trim().parse::<u32>())
                .collect::<Result<Vec<u32>, _>>()
                .ok()
                .filter(|ids| ids.len() == 2 && ids.iter().all(|&i| i >= 1 && i as usize <= n))
                .ok_or_else(|| {
                    UserError::Refused(format!(
                        "--vertices: expected A,B with 1 <= A, B <= {n}, found {v:?}"
                    ))
                })?;
            m.find_edge(
                prism_mesh::VertexId(ids[0] - 1),
                prism_mesh::VertexId(ids[1] - 1),
            )
            .ok_or_else(|| {
                UserError::Refused(format!("--vertices {v}: no edge joins these vertices"))
            })?
        }
        (None, None) => {
            return Err(UserError::Refused("give --edge E or --vertices A,B".into()).into())
        }
    };
    let before = if (e.0 as usize) < m.edge_count() {
        format!("edge {} ({})", e.0, edge_words(&m, e))
    } else {
        format!("edge {}", e.0)
    };
    let done = op(&mut m, e)
        .map_err(|err| UserError::Refused(format!("{}: cannot {what}: {err}", input.display())))?;
    write(output, &m.to_polymesh())?;
    if !quiet {
        println!("{before}: {done}");
        println!(
            "now {} vertices, {} edges, {} faces",
            m.vertex_count(),
            m.edge_count(),
            m.face_count()
        );
    }
    Ok(())
}

/// Runs `prism mesh`.
pub fn run(a: &MeshArgs) -> Result<()> {
    let t = Instant::now();
    run_command(a)?;
    if a.stats && !matches!(a.command, MeshCommand::Subdivide { .. }) {
        eprintln!("total: {}", ms(t.elapsed()));
    }
    Ok(())
}

/// Runs the `prism mesh` subcommand `a` names.
fn run_command(a: &MeshArgs) -> Result<()> {
    // The output's format and folder are checked before any work.
    let output = match &a.command {
        MeshCommand::Info { .. } => None,
        MeshCommand::Normals { output, .. }
        | MeshCommand::Convert { output, .. }
        | MeshCommand::Subdivide { output, .. } => Some(output),
        MeshCommand::Split(e) | MeshCommand::Flip(e) | MeshCommand::Collapse(e) => Some(&e.output),
    };
    if let Some(output) = output {
        crate::output::mesh_output(output, "--output")?;
        let input = match &a.command {
            MeshCommand::Info { input, .. }
            | MeshCommand::Normals { input, .. }
            | MeshCommand::Convert { input, .. }
            | MeshCommand::Subdivide { input, .. } => input,
            MeshCommand::Split(e) | MeshCommand::Flip(e) | MeshCommand::Collapse(e) => &e.input,
        };
        crate::output::check_distinct(&[("the mesh", input)], &[("--output", output)])?;
    }
    let input_path = match &a.command {
        MeshCommand::Info { input, .. }
        | MeshCommand::Normals { input, .. }
        | MeshCommand::Convert { input, .. }
        | MeshCommand::Subdivide { input, .. } => input,
        MeshCommand::Split(e) | MeshCommand::Flip(e) | MeshCommand::Collapse(e) => &e.input,
    };
    crate::error::check_input(input_path, None)?;
    let reading = (a.strict, a.quiet);
    match &a.command {
        MeshCommand::Info {
            input,
            vertices,
            edges,
            faces,
            limit,
        } => {
            let p = load(input, reading)?;
            let m = build(input, &p)?;
            let boundary_edges = (0..m.edge_count())
                .filter(|&e| m.is_boundary_edge(prism_mesh::EdgeId(e as u32)))
                .count();
            println!("vertices: {}", m.vertex_count());
            println!("edges: {}", m.edge_count());
            println!("faces: {}", m.face_count());
            println!("boundary edges: {boundary_edges}");
            println!("euler characteristic: {}", m.euler_characteristic());
            println!("triangles only: {}", p.is_triangle_mesh());
            if *vertices {
                list("vertices", m.vertex_count(), *limit, |i| {
                    let v = prism_mesh::VertexId(i as u32);
                    let boundary = if m.is_boundary_vertex(v) {
                        " (boundary)"
                    } else {
                        ""
                    };
                    format!("vertex {}: {}{boundary}", i + 1, xyz(m.position(v)))
                });
            }
            if *edges {
                list("edges", m.edge_count(), *limit, |i| {
                    let e = prism_mesh::EdgeId(i as u32);
                    let h = m.edge_halfedge(e);
                    format!(
                        "edge {i}: {}, from {} to {}",
                        edge_words(&m, e),
                        xyz(m.position(m.origin(h))),
                        xyz(m.position(m.dest(h)))
                    )
                });
            }
            if *faces {
                list("faces", m.face_count(), *limit, |i| {
                    let ids: Vec<String> = m
                        .face_halfedges(prism_mesh::FaceId(i as u32))
                        .map(|h| (m.origin(h).0 + 1).to_string())
                        .collect();
                    format!("face {i}: vertices {}", ids.join(","))
                });
            }
            Ok(())
        }
        MeshCommand::Normals { input, output } => {
            let mut p = load(input, reading)?;
            p.normals = Some(prism_mesh::vertex_normals_area_weighted(&p));
            write(output, &p)
        }
        MeshCommand::Convert { input, output } => {
            let p = load(input, reading)?;
            build(input, &p)?;
            write(output, &p)
        }
        MeshCommand::Flip(e) => edge_op(e, reading, "flip", |m, id| {
            m.flip(id)?;
            Ok(format!("flipped; it now joins {}", edge_words(m, id)))
        }),
        MeshCommand::Split(e) => edge_op(e, reading, "split", |m, id| {
            let v = m.split(id)?;
            Ok(format!(
                "split at new vertex {} ({})",
                v.0 + 1,
                xyz(m.position(v))
            ))
        }),
        MeshCommand::Collapse(e) => edge_op(e, reading, "collapse", |m, id| {
            let v = m.collapse(id)?;
            Ok(format!(
                "collapsed to vertex {} ({}); vertices above may be renumbered",
                v.0 + 1,
                xyz(m.position(v))
            ))
        }),
        MeshCommand::Subdivide {
            input,
            output,
            levels,
            weights,
        } => {
            let w = match weights {
                Weights::Warren => LoopWeights::Warren,
                Weights::Loop => LoopWeights::Loop,
            };
            let t = Instant::now();
            let mut p = load(input, reading)?;
            let read_time = t.elapsed();
            // Refuse before allocating what cannot fit: every level makes 4 faces of one.
            prism_mesh::check_subdivision(p.face_count(), *levels).map_err(|e| {
                UserError::Refused(format!(
                    "{}: {levels} levels of {} faces: {e}",
                    input.display(),
                    p.face_count()
                ))
            })?;
            // Progress in output faces, so the ETA weighs each level by its work.
            let bar = crate::progress::bar(
                (1..=*levels)
                    .map(|l| (p.face_count() as u64) << (2 * l))
                    .sum(),
                "subdivide",
                a.quiet,
            );
            let (mut build_time, mut sub_time) =
                (std::time::Duration::ZERO, std::time::Duration::ZERO);
            for _ in 0..*levels {
                let t = Instant::now();
                let m = build(input, &p)?;
                build_time += t.elapsed();
                let t = Instant::now();
                p = loop_subdivide(&m, w)
                    .map_err(|e| UserError::input(format!("{}: {e}", input.display())))?;
                sub_time += t.elapsed();
                bar.inc(p.face_count() as u64);
            }
            bar.finish_and_clear();
            let t = Instant::now();
            write(output, &p)?;
            if a.stats {
                eprintln!("read: {}", ms(read_time));
                eprintln!("build: {}", ms(build_time));
                eprintln!("subdivide: {}", ms(sub_time));
                eprintln!("write: {}", ms(t.elapsed()));
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::number;

    /// Closed forms: single-precision shortest text, exponent form for tiny and huge values.
    #[test]
    fn coordinates_print_as_people_read_them() {
        assert_eq!(number(1.999_998_400_000_300_2), "1.9999985");
        assert_eq!(number(1.644_04e-16), "1.64404e-16");
        assert_eq!(number(f64::from(2e-7_f32)), "2e-7");
        assert_eq!(number(-0.0), "0");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-2.0), "-2");
    }
}
