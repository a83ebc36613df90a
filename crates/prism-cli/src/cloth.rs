//! `prism cloth`: the course's ClothSim scenes simulated exactly, written as OBJ and drawn
//! through prism-shade with the course app's camera.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::Args;
use prism_cloth::{
    cloth_mesh, course_view, obstacles, read_scene, Cloth, FRAMES_PER_SECOND, STEPS_PER_FRAME,
};
use prism_mesh::obj::{Corner, NumberStyle, ObjWriter};
use prism_shade::{shade_rgb8, ShadeMesh, ShadeOptions, Uniforms};

use crate::error::UserError;
use crate::output::write_text;
use crate::shade::{ShaderArg, ShaderFiles};

/// Arguments of `prism cloth`.
#[derive(Args, Debug)]
pub struct ClothArgs {
    /// The course's scene JSON (cloth, and optionally sphere and plane).
    scene: PathBuf,
    /// Draw the run: a folder (one PNG per frame, `frame_0001.png`, ...), a .png (an
    /// animated PNG of every frame, playing at 90 frames a second, in real time) or a .gif
    /// (every frame in 256 colours, playing at 50 frames a second, GIF's fastest).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Frames to simulate (30 steps each, 90 frames a simulated second).
    #[arg(long, default_value_t = 90)]
    frames: u32,
    /// The cloth's shader when drawing (the sphere and plane take the same); `wireframe`
    /// draws every triangle's edges in white over black, hidden lines removed.
    #[arg(long, value_enum, default_value_t = ShaderArg::Phong)]
    shader: ShaderArg,
    #[command(flatten)]
    files: ShaderFiles,
    /// Samples per pixel when drawing: a square number (1, 4, 9, 16, ...).
    #[arg(
        short = 's',
        long = "spp",
        visible_alias = "samples",
        default_value_t = 1
    )]
    samples: u32,
    /// Picture size: WIDTH HEIGHT (the course app's window by default).
    #[arg(short = 'r', long = "resolution", num_args = 2, value_names = ["WIDTH", "HEIGHT"], default_values_t = [1024, 800])]
    resolution: Vec<u32>,
    /// Write the state after the last frame as OBJ: the first nw*nh `v` lines are the
    /// masses in row-major order (index y*nw + x), then uvs, normals and faces.
    #[arg(long, value_name = "OUT.obj")]
    obj: Option<PathBuf>,
    /// Write one such OBJ per frame into this folder (`frame_0001.obj`, ...).
    #[arg(long, value_name = "DIR")]
    obj_sequence: Option<PathBuf>,
    /// Override a scene value: `--set ks=500`, `--set cloth.density=15`,
    /// `--set sphere.radius=0.3` (the value is JSON).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print per-stage times and `particle-updates/s` on stderr.
    #[arg(long)]
    stats: bool,
    /// No progress bar, warnings or summary line.
    #[arg(short, long)]
    quiet: bool,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    threads: Option<usize>,
}

/// Most frames one run may ask for.
const MAX_FRAMES: u32 = 1_000_000;

/// The OBJ of the cloth's state: masses, uvs, normals, faces (numbers as Rust shows them).
fn cloth_obj(c: &Cloth) -> String {
    let mut out = Vec::new();
    write_cloth_obj(c, &mut ObjWriter::new(&mut out, NumberStyle::Plain))
        .expect("writing to memory");
    String::from_utf8(out).expect("OBJ text is ASCII")
}

/// Writes [`cloth_obj`]'s statements.
fn write_cloth_obj(c: &Cloth, w: &mut ObjWriter<impl std::io::Write>) -> std::io::Result<()> {
    let m = cloth_mesh(c);
    for p in &c.positions {
        w.vector("v", &p.to_array())?;
    }
    for uv in &m.uvs {
        w.vector("vt", &uv.to_array())?;
    }
    for n in &m.normals {
        w.vector("vn", &n.to_array())?;
    }
    for t in &m.triangles {
        w.face(t.map(|v| Corner::new(v, Some(v), Some(v))))?;
    }
    Ok(())
}

/// Runs `prism cloth`.
pub fn run(a: &ClothArgs) -> Result<()> {
    crate::resources::pool(a.threads)?.install(|| run_in_pool(a))
}

/// Runs `prism cloth` on the current worker pool.
fn run_in_pool(a: &ClothArgs) -> Result<()> {
    if a.frames == 0 || a.frames > MAX_FRAMES {
        return Err(UserError::Refused(format!(
            "--frames: expected 1 to {MAX_FRAMES}, found {}",
            a.frames
        ))
        .into());
    }
    let (w, h) = (a.resolution[0], a.resolution[1]);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(UserError::Refused(format!(
            "--resolution: expected 1 to 16384 pixels a side, found {w} x {h}"
        ))
        .into());
    }
    // A frame is drawn while the one before it is written: two in flight.
    let bytes = 2 * prism_shade::frame_bytes(w, h, a.samples.clamp(1, 256));
    crate::resources::check_frame("--resolution", w, h, bytes)?;
    // Where the pictures go: a folder (one per frame) or one animation (.png or .gif).
    let mut gif = false;
    let frames_dir = match &a.output {
        Some(o) if o.is_dir() || o.to_string_lossy().ends_with('/') => {
            crate::error::check_folder_input(o, "--output")?;
            Some(o.clone())
        }
        Some(o) => {
            use crate::output::ImageFormat;
            let format =
                crate::output::image_output(o, "--output", &[ImageFormat::Png, ImageFormat::Gif])?;
            gif = format == ImageFormat::Gif;
            None
        }
        None => None,
    };
    if let Some(o) = &a.obj {
        if crate::output::extension(o) != "obj" {
            return Err(UserError::WrongKind {
                flag: Some("--obj".into()),
                path: o.clone(),
                expected: "an .obj file".into(),
            }
            .into());
        }
        crate::output::check_folder(o, "--obj")?;
    }
    if let Some(d) = &a.obj_sequence {
        crate::error::check_folder_input(d, "--obj-sequence")?;
    }
    let mut outputs = Vec::new();
    outputs.extend(
        a.output
            .as_deref()
            .filter(|_| frames_dir.is_none())
            .map(|p| ("--output", p)),
    );
    outputs.extend(a.obj.as_deref().map(|p| ("--obj", p)));
    let mut inputs = vec![("the scene", a.scene.as_path())];
    inputs.extend(a.files.inputs());
    crate::output::check_distinct(&inputs, &outputs)?;
    crate::error::check_input(&a.scene, None)?;
    let shader = a.files.shader(a.shader, a.quiet)?;
    if !(1..=16u32).any(|k| k * k == a.samples) {
        return Err(UserError::Refused(format!(
            "--spp: expected a square number from 1 to 256, found {}",
            a.samples
        ))
        .into());
    }
    // Wireframe: every edge in white, depth-tested against faces filled with the
    // background, so that hidden lines are removed.
    let (uniforms, shade_options) = if a.shader == ShaderArg::Wireframe {
        (
            Uniforms {
                color: prism_math::Rgb::BLACK,
                ..Uniforms::default()
            },
            ShadeOptions {
                samples: a.samples,
                wireframe: Some(prism_math::Rgb::WHITE),
                ..ShadeOptions::default()
            },
        )
    } else {
        (
            Uniforms::default(),
            ShadeOptions {
                samples: a.samples,
                ..ShadeOptions::default()
            },
        )
    };
    if a.output.is_none() && a.obj.is_none() && a.obj_sequence.is_none() && !a.stats && !a.quiet {
        eprintln!(
            "prism: warning: nothing will be written: give -o (pictures), --obj or \
             --obj-sequence (the state), or --stats to time the run"
        );
    }
    let t0 = Instant::now();
    let scene = read_scene(&a.scene, &a.set).map_err(UserError::input)?;
    let read = t0.elapsed();
    let mut cloth = Cloth::new(&scene);
    let view = course_view(&cloth, w, h);
    let obstacles = obstacles(&scene);
    let bar = crate::progress::bar(u64::from(a.frames), "cloth", a.quiet);
    let mut simulate = Duration::ZERO;
    let mut render = Duration::ZERO;
    let mut write = Duration::ZERO;
    let draws = a.output.is_some();
    let mut frames_wall = Duration::ZERO;
    // Simulates every frame and, when drawing, draws frame f while simulating frame f + 1
    // (on rayon: the picture of a frame depends only on that frame's positions, so the
    // bytes are the same as drawing after each frame); `each` takes the pictures in order.
    // Stops at a diverged frame.
    let mut run_frames = |each: &mut dyn FnMut(
        u32,
        prism_image::Rgb8Image,
        &mut Duration,
    ) -> Result<()>|
     -> Result<()> {
        let wall = Instant::now();
        let mut pending: Option<(u32, ShadeMesh)> = None;
        for f in 1..=a.frames + 1 {
            let drawing = pending.take();
            let simulating = f <= a.frames;
            let (picture, sim_time) = rayon::join(
                || {
                    drawing.map(|(g, mesh)| {
                        let t = Instant::now();
                        let img = shade_rgb8(&mesh, &view, &shader, &uniforms, &shade_options);
                        (g, img, t.elapsed())
                    })
                },
                || {
                    simulating.then(|| {
                        let t = Instant::now();
                        cloth.frame();
                        t.elapsed()
                    })
                },
            );
            if let Some(t) = sim_time {
                simulate += t;
            }
            if let Some((g, img, t)) = picture {
                render += t;
                each(g, img.map_err(UserError::input)?, &mut write)?;
            }
            if !simulating {
                break;
            }
            if !cloth.is_finite() {
                bar.finish_and_clear();
                return Err(UserError::Refused(format!(
                    "{}: the simulation diverged in frame {f} (positions left the finite numbers): \
                     ks is too stiff for the masses at this time step",
                    a.scene.display()
                ))
                .into());
            }
            if let Some(dir) = &a.obj_sequence {
                let t = Instant::now();
                write_text(&dir.join(format!("frame_{f:04}.obj")), &cloth_obj(&cloth))?;
                write += t.elapsed();
            }
            if draws {
                let mut mesh = cloth_mesh(&cloth);
                mesh.append(&obstacles);
                pending = Some((f, mesh));
            }
            bar.set_position(u64::from(f));
        }
        bar.finish_and_clear();
        frames_wall = wall.elapsed();
        Ok(())
    };
    match (&a.output, &frames_dir) {
        (_, Some(dir)) => run_frames(&mut |f, img, write| {
            let t = Instant::now();
            let path = dir.join(format!("frame_{f:04}.png"));
            prism_image::write_png(&path, &img)
                .with_context(|| format!("writing {}", path.display()))?;
            *write += t.elapsed();
            Ok(())
        })?,
        (Some(path), None) => {
            // The animation streams into a temporary file, renamed into place at the end.
            prism_image::write_atomic_with(
                path,
                |out| -> Result<()> {
                    let fps = FRAMES_PER_SECOND as u16;
                    // The encoders' failures (a full disk, say) name the file.
                    let named = || format!("writing {}", path.display());
                    let mut enc = if gif {
                        Animation::Gif(
                            prism_image::GifEncoder::new(out, w, h, fps).with_context(named)?,
                        )
                    } else {
                        Animation::Png(
                            prism_image::ApngEncoder::new(out, w, h, a.frames, fps)
                                .with_context(named)?,
                        )
                    };
                    run_frames(&mut |_, img, write| {
                        let t = Instant::now();
                        enc.push(&img).with_context(named)?;
                        *write += t.elapsed();
                        Ok(())
                    })?;
                    enc.finish().with_context(named)
                },
                |p, e| anyhow::anyhow!("writing {}: {e}", p.display()),
            )?;
        }
        (None, None) => run_frames(&mut |_, _, _| Ok(()))?,
    }
    // A folder holds this run's frames alone: frames of a longer earlier run go.
    if let Some(dir) = &frames_dir {
        remove_stale_frames(dir, "png", a.frames)?;
    }
    if let Some(dir) = &a.obj_sequence {
        remove_stale_frames(dir, "obj", a.frames)?;
    }
    let cloth = &cloth;
    if let Some(o) = &a.obj {
        let t = Instant::now();
        write_text(o, &cloth_obj(cloth))?;
        write += t.elapsed();
    }
    let updates = cloth.positions.len() as f64 * f64::from(a.frames) * STEPS_PER_FRAME as f64;
    if a.stats {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        eprintln!("read: {:.1} ms", ms(read));
        eprintln!("simulate: {:.1} ms", ms(simulate));
        for (name, t) in prism_cloth::StepTimes::NAMES.iter().zip(cloth.times.steps) {
            eprintln!("  {name}: {:.1} ms", ms(t));
        }
        eprintln!("render: {:.1} ms", ms(render));
        eprintln!("write: {:.1} ms", ms(write));
        if draws {
            // Simulated and drawn (not written) frames per second of wall time, drawing
            // overlapped with simulating.
            let drawn = frames_wall.saturating_sub(write).as_secs_f64().max(1e-9);
            eprintln!("frames/s: {:.1}", f64::from(a.frames) / drawn);
        }
        eprintln!(
            "particle-updates/s: {:.0}",
            updates / simulate.as_secs_f64().max(1e-9)
        );
    }
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "prism: simulated {} masses for {} frames ({:.1} s simulated) in {:.1} s ({:.2} M particle-updates/s)",
            cloth.positions.len(),
            a.frames,
            f64::from(a.frames) / prism_cloth::FRAMES_PER_SECOND,
            t0.elapsed().as_secs_f64(),
            updates / simulate.as_secs_f64().max(1e-9) / 1e6
        );
    }
    Ok(())
}

/// The animation `-o OUT.png` or `-o OUT.gif` writes.
enum Animation<W: std::io::Write> {
    Png(prism_image::ApngEncoder<W>),
    Gif(prism_image::GifEncoder<W>),
}

impl<W: std::io::Write> Animation<W> {
    fn push(&mut self, frame: &prism_image::Rgb8Image) -> Result<()> {
        match self {
            Animation::Png(e) => e.push(frame)?,
            Animation::Gif(e) => e.push(frame)?,
        }
        Ok(())
    }

    fn finish(self) -> Result<()> {
        match self {
            Animation::Png(e) => e.finish()?,
            Animation::Gif(e) => e.finish()?,
        }
        Ok(())
    }
}

/// Removes the `frame_NNNN.EXT` files in `dir` that this run did not write (it wrote
/// `frame_0001` to `frame_{frames}`), so that the folder shows this run alone.
fn remove_stale_frames(dir: &Path, ext: &str, frames: u32) -> Result<()> {
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let number = name
            .strip_prefix("frame_")
            .and_then(|n| n.strip_suffix(ext))
            .and_then(|n| n.strip_suffix('.'))
            .filter(|n| n.len() >= 4 && n.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|n| n.parse::<u64>().ok());
        if number.is_some_and(|n| n == 0 || n > u64::from(frames)) {
            let path = entry.path();
            std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
        }
    }
    Ok(())
}
