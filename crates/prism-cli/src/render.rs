//! `prism render`: path-trace a CS184 COLLADA scene (or the built-in Cornell box).

use prism_math::Warning;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use anyhow::Result;
use clap::{Args, ValueEnum};
use prism_render::film::{FilmSettings, Share};
use prism_render::integrators::{Integrator, PathSettings};
use prism_render::parts::{PartIdentity, PartWriter};
use prism_render::render::{render, render_tiles, Job, RenderOptions};
use prism_render::render_scene::RenderScene;
use prism_scene::{CameraMode, NormalsMode, SceneOptions};

use crate::error::UserError;

/// The estimator.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum IntegratorArg {
    /// Path tracing with next-event estimation, MIS and Russian roulette (a tile's paths
    /// advance together, stage by stage).
    Path,
    /// The same path tracer one path at a time: the reference `path` equals bit for bit.
    PathScalar,
    /// Emission plus one bounce of direct light.
    Direct,
    /// Shading normals as colours.
    Normals,
}

/// Which lights a light sample reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightChoiceArg {
    /// Every shading point samples every light (the course's estimator).
    Every,
    /// Each light sample picks one light, uniformly (Mitsuba's estimator): one shadow ray
    /// per sample however many lights the scene has.
    One,
}

/// Where shading normals come from.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum NormalsArg {
    /// Area-weighted vertex normals computed from the mesh (the course's).
    Area,
    /// The file's normals.
    File,
    /// Face normals.
    Flat,
}

/// Where the camera comes from.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CameraArg {
    /// The course's placement: looking at the scene's centre along the file camera's
    /// direction from 1.5 scene diagonals away.
    Course,
    /// The file camera's own position and orientation.
    File,
}

/// Arguments of `prism render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// A CS184 COLLADA scene (.dae), a Mitsuba 3 scene (.xml), an OBJ scene or a Delft
    /// config; without one, the built-in Cornell box with two spheres.
    scene: Option<PathBuf>,
    /// Output image; its extension picks the format: .png or .jpg (sRGB, clamped) or .exr
    /// (linear radiance). The folder must exist.
    #[arg(short, long, short_alias = 'f', default_value = "render.png")]
    output: PathBuf,
    /// Also write linear radiance to this OpenEXR file.
    #[arg(long, value_name = "FILE")]
    exr: Option<PathBuf>,
    /// Samples per pixel (the most, with --adaptive) [default: 64, or a Mitsuba scene's
    /// sample_count].
    #[arg(short = 's', long = "spp")]
    spp: Option<u32>,
    /// Samples per area light (and hemisphere light) at each shading point; with
    /// `--light-choice one`, light samples at each shading point.
    #[arg(short = 'l', long = "light-samples", default_value_t = 1)]
    light_samples: u32,
    /// Which lights a light sample reaches [default: one for a Mitsuba scene with a box
    /// filter, else every].
    #[arg(long, value_enum, value_name = "CHOICE")]
    light_choice: Option<LightChoiceArg>,
    /// Most bounces a path takes: 0 shows emitters only, 1 adds direct light [default: 7, or
    /// a Mitsuba scene's max_depth - 1].
    #[arg(short = 'm', long = "max-bounces")]
    max_bounces: Option<u32>,
    /// Image size: WIDTH HEIGHT [default: 512 384, or a Mitsuba scene's film].
    #[arg(short = 'r', long = "resolution", num_args = 2, value_names = ["WIDTH", "HEIGHT"])]
    resolution: Option<Vec<u32>>,
    /// Set a Mitsuba scene's parameter: `-D spp=64` gives `$spp` its value, over the file's
    /// `<default>` (as Mitsuba's command line).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE")]
    define: Vec<String>,
    /// Read past what prism does not render in a Mitsuba scene, with one warning per kind:
    /// a grey diffuse BSDF stands in for an unsupported one, unsupported shapes and
    /// emitters are left out.
    #[arg(long)]
    lenient: bool,
    /// Which of a Mitsuba scene's sensors to render (from 0). Without it, a scene with
    /// several renders each to its own files, `_N` before each output's extension.
    #[arg(long, value_name = "N")]
    sensor: Option<usize>,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    threads: Option<usize>,
    /// The estimator.
    #[arg(long, value_enum, default_value_t = IntegratorArg::Path)]
    integrator: IntegratorArg,
    /// With --integrator direct: sample the hemisphere uniformly instead of the lights (the
    /// course's -H).
    #[arg(short = 'H', long)]
    hemisphere: bool,
    /// Keep only light that took exactly this many bounces (0: emitters seen directly).
    #[arg(long, value_name = "M")]
    bounce: Option<u32>,
    /// Adaptive sampling: stop a pixel once its 95% confidence interval is within TOL of
    /// its mean illuminance (checked every --batch samples).
    #[arg(long, value_name = "TOL")]
    adaptive: Option<f32>,
    /// Samples between adaptive-sampling checks (default 32; only with --adaptive).
    #[arg(long)]
    batch: Option<u32>,
    /// The course's adaptive-sampling flag: --batch BATCH --adaptive TOL in one.
    #[arg(short = 'a', num_args = 2, value_names = ["BATCH", "TOL"], conflicts_with_all = ["adaptive", "batch"])]
    course_adaptive: Option<Vec<String>>,
    /// Environment light from a latitude-longitude OpenEXR or Radiance HDR map of linear
    /// radiance (the course's -e), seen by every ray and importance-sampled; it replaces the
    /// scene's hemisphere or environment light. Orientation: docs/path-tracer.md.
    #[arg(short = 'e', long, value_name = "FILE.exr|FILE.hdr")]
    envmap: Option<PathBuf>,
    /// Thin-lens camera: the lens radius in world units (the course's -b); 0 is a pinhole.
    #[arg(short = 'b', long, value_name = "RADIUS")]
    lens_radius: Option<f32>,
    /// Thin-lens camera: the distance along the view axis to the plane in focus (the
    /// course's -d); by default the distance to the point the camera looks at.
    #[arg(short = 'd', long, value_name = "DISTANCE")]
    focal_distance: Option<f32>,
    /// Write the sample-count heat map (blue: few, red: the most) to this .png or .jpg.
    #[arg(long, value_name = "FILE")]
    heatmap: Option<PathBuf>,
    /// Seed of every random number: the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Shading normals.
    #[arg(long, value_enum, default_value_t = NormalsArg::Area)]
    normals: NormalsArg,
    /// Camera placement.
    #[arg(long, value_enum, default_value_t = CameraArg::Course)]
    camera: CameraArg,
    /// Print BVH statistics, times (`render: 12.3 ms`), samples/s, and the path integrator's
    /// share of time per stage (camera rays, closest hits, hit records, ...) and its time
    /// per stage summed over the threads, on stderr.
    #[arg(long)]
    stats: bool,
    /// Render only share I of N (I from 0) of the image's 32x32 tiles, dealt round-robin,
    /// and write a part file (-o PART.exr) for `prism merge`.
    #[arg(long, value_name = "I/N", value_parser = crate::split::parse_tile)]
    tile: Option<(u32, u32)>,
    /// Render only sample indices FROM.. of each pixel (default 0) and write a part file
    /// (-o PART.exr) for `prism merge`; not with --adaptive.
    #[arg(long, value_name = "FROM")]
    samples_from: Option<u32>,
    /// Render only sample indices ..TO of each pixel, exclusive (default --spp) and write a
    /// part file (-o PART.exr) for `prism merge`; not with --adaptive.
    #[arg(long, value_name = "TO")]
    samples_to: Option<u32>,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
}

/// The share of the render asked for with --tile, --samples-from and --samples-to, checked;
/// `None` for the whole render.
fn share(a: &RenderArgs, adaptive: Option<f32>) -> Result<Option<Share>> {
    if a.tile.is_none() && a.samples_from.is_none() && a.samples_to.is_none() {
        return Ok(None);
    }
    let (from, to) = (a.samples_from.unwrap_or(0), a.samples_to.unwrap_or(a.spp()));
    if a.samples_from.is_some() || a.samples_to.is_some() {
        if adaptive.is_some() {
            return Err(UserError::Refused(
                "--samples-from/--samples-to with --adaptive: adaptive sampling decides per \
                 pixel when to stop, so its samples cannot be split into ranges; split by \
                 --tile instead"
                    .into(),
            )
            .into());
        }
        if !(from < to && to <= a.spp()) {
            return Err(UserError::Refused(format!(
                "--samples-from {from} --samples-to {to}: expected 0 <= FROM < TO <= --spp ({})",
                a.spp()
            ))
            .into());
        }
    }
    let mut pictures = Vec::new();
    if a.exr.is_some() {
        pictures.push("--exr");
    }
    if a.heatmap.is_some() {
        pictures.push("--heatmap");
    }
    crate::split::check_part_output(&a.output, &pictures)?;
    let (part, parts) = a.tile.unwrap_or((0, 1));
    Ok(Some(Share {
        part,
        parts,
        samples: from..to,
    }))
}

/// Samples between adaptive-sampling checks when --batch is not given.
const DEFAULT_BATCH: u32 = 32;

/// The adaptive tolerance and batch, from `--adaptive TOL --batch N` or the course's
/// `-a BATCH TOL`.
fn adaptive_settings(a: &RenderArgs) -> Result<(Option<f32>, Option<u32>)> {
    let Some(v) = &a.course_adaptive else {
        return Ok((a.adaptive, a.batch));
    };
    let batch = v[0].parse::<u32>().ok().filter(|&b| b > 0);
    let tol = v[1].parse::<f32>().ok();
    match (batch, tol) {
        (Some(b), Some(t)) => Ok((Some(t), Some(b))),
        _ => Err(UserError::Refused(format!(
            "-a: expected BATCH (a positive integer) and TOL (a number), found {} {}",
            v[0], v[1]
        ))
        .into()),
    }
}

/// The thin lens from --lens-radius and --focal-distance, checked; `None` for a pinhole.
fn thin_lens(
    a: &RenderArgs,
    camera: &prism_scene::Camera,
) -> Result<Option<prism_scene::ThinLens>> {
    let radius = match a.lens_radius {
        None => {
            if a.focal_distance.is_some() {
                eprintln!(
                    "prism: warning: --focal-distance has no effect: it applies to a lens \
                     (--lens-radius)"
                );
            }
            return Ok(None);
        }
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(r) => {
            return Err(UserError::Refused(format!(
                "--lens-radius: expected a radius of 0 or more, found {r}"
            ))
            .into())
        }
    };
    let focal_distance = match a.focal_distance {
        None => (camera.target - camera.eye).length(),
        Some(d) if d.is_finite() && d > 0.0 => d,
        Some(d) => {
            return Err(UserError::Refused(format!(
                "--focal-distance: expected a positive distance, found {d}"
            ))
            .into())
        }
    };
    Ok(Some(prism_scene::ThinLens {
        radius,
        focal_distance,
    }))
}

/// Refuses impossible flag combinations and warns of ineffective ones, naming the flags.
fn check_flags(a: &RenderArgs, adaptive: Option<f32>, batch: Option<u32>) -> Result<()> {
    if let Some(m) = a.bounce {
        let most = match a.integrator {
            IntegratorArg::Normals => {
                return Err(UserError::Refused(
                    "--bounce: the normals integrator does not bounce; use --integrator path"
                        .into(),
                )
                .into())
            }
            IntegratorArg::Direct => 1,
            IntegratorArg::Path | IntegratorArg::PathScalar => a.max_bounces(),
        };
        if m > most {
            let why = match a.integrator {
                IntegratorArg::Direct => "--integrator direct stops after 1".to_string(),
                _ => format!("--max-bounces is {most}"),
            };
            return Err(UserError::Refused(format!(
                "--bounce {m}: no path gets that far ({why}), so the image would be black"
            ))
            .into());
        }
    }
    let warn = |flag: &str, why: &str| eprintln!("prism: warning: {flag} has no effect: {why}");
    if a.hemisphere && !matches!(a.integrator, IntegratorArg::Direct) {
        warn("--hemisphere", "it applies to --integrator direct only");
    }
    if adaptive.is_none() {
        if a.heatmap.is_some() {
            eprintln!(
                "prism: warning: --heatmap without --adaptive: every pixel takes the same \
                 samples, so the map is one colour"
            );
        }
        if batch.is_some() {
            warn("--batch", "it applies to --adaptive only");
        }
    }
    Ok(())
}

/// Largest image side.
const MAX_SIDE: u32 = 16384;

/// Most samples of each light at a shading point.
const MAX_LIGHT_SAMPLES: u32 = 1 << 16;

/// Samples per pixel when neither `-s` nor the scene says.
const DEFAULT_SPP: u32 = 64;

/// Most bounces when neither `-m` nor the scene says.
const DEFAULT_BOUNCES: u32 = 7;

/// The bounces of a Mitsuba `max_depth = -1` path: Russian roulette ends paths long before.
const UNBOUNDED_BOUNCES: u32 = 1024;

impl RenderArgs {
    /// Samples per pixel.
    fn spp(&self) -> u32 {
        self.spp.unwrap_or(DEFAULT_SPP)
    }

    /// Most bounces.
    fn max_bounces(&self) -> u32 {
        self.max_bounces.unwrap_or(DEFAULT_BOUNCES)
    }

    /// The image's width and height.
    fn size(&self) -> (u32, u32) {
        match self.resolution.as_deref() {
            Some([w, h]) => (*w, *h),
            _ => (512, 384),
        }
    }
}

/// The arguments with what a Mitsuba scene (`.xml`) says filled in where the flags are
/// silent (`-r` from its film, `-s` from its sampler, `-m` from its integrator), and the
/// scene read; other scenes leave them as given.
/// The `-D` settings, parsed.
fn defines(a: &RenderArgs) -> Result<Vec<(String, String)>> {
    let mut defines = Vec::new();
    for d in &a.define {
        match d.split_once('=') {
            Some((name, value)) if !name.is_empty() => {
                defines.push((name.to_string(), value.to_string()));
            }
            _ => {
                return Err(UserError::bad_value("--define", "NAME=VALUE", format!("{d:?}")).into())
            }
        }
    }
    Ok(defines)
}

/// How many sensors the Mitsuba scene `a` renders has (none for other scenes).
fn sensor_count(a: &RenderArgs) -> Result<Option<usize>> {
    let Some(path) = a
        .scene
        .as_ref()
        .filter(|p| crate::output::extension(p) == "xml")
    else {
        return Ok(None);
    };
    crate::error::check_input(path, None)?;
    let doc = prism_scene::read_document(path, &defines(a)?).map_err(UserError::input)?;
    let root = &doc.objects[0];
    Ok(Some(
        root.children
            .iter()
            .filter(|&&(_, c)| doc.objects[c].tag == "sensor")
            .count(),
    ))
}

/// `a` for sensor `i` of several: each output named with `_i` before its extension.
fn for_sensor(a: &RenderArgs, i: usize) -> RenderArgs {
    let suffixed = |p: &std::path::Path| {
        let stem = p.file_stem().unwrap_or_default().to_string_lossy();
        let name = match p.extension() {
            Some(ext) => format!("{stem}_{i}.{}", ext.to_string_lossy()),
            None => format!("{stem}_{i}"),
        };
        p.with_file_name(name)
    };
    let mut r = a.clone();
    r.sensor = Some(i);
    r.output = suffixed(&a.output);
    r.exr = a.exr.as_deref().map(suffixed);
    r.heatmap = a.heatmap.as_deref().map(suffixed);
    r
}

fn resolve(a: &RenderArgs) -> Result<(Option<prism_scene::MitsubaScene>, RenderArgs)> {
    let defines = defines(a)?;
    let mut r = a.clone();
    let Some(path) = a
        .scene
        .as_ref()
        .filter(|p| crate::output::extension(p) == "xml")
    else {
        if !defines.is_empty() && !a.quiet {
            eprintln!("prism: warning: -D has no effect: it sets a Mitsuba scene's parameters");
        }
        if a.sensor.is_some() && !a.quiet {
            eprintln!("prism: warning: --sensor has no effect: it picks a Mitsuba scene's sensor");
        }
        return Ok((None, r));
    };
    let options = prism_scene::MitsubaOptions {
        lenient: a.lenient,
        sensor: a.sensor.unwrap_or(0),
    };
    let m = prism_scene::read_mitsuba_with(path, &defines, options).map_err(UserError::input)?;
    let s = &m.settings;
    r.spp = r.spp.or(Some(s.spp));
    r.max_bounces = r
        .max_bounces
        .or(Some(s.max_bounces.unwrap_or(UNBOUNDED_BOUNCES)));
    r.resolution = r.resolution.or(Some(vec![s.size.0, s.size.1]));
    Ok((Some(m), r))
}

/// Runs `prism render`.
pub fn run(a: &RenderArgs) -> Result<()> {
    use crate::output::ImageFormat;
    if a.sensor.is_none() {
        if let Some(count @ 2..) = sensor_count(a)? {
            return (0..count).try_for_each(|i| run(&for_sensor(a, i)));
        }
    }
    let mut inputs = Vec::new();
    inputs.extend(a.scene.as_deref().map(|p| ("the scene", p)));
    inputs.extend(a.envmap.as_deref().map(|p| ("--envmap", p)));
    let (format, heatmap_format) =
        crate::output::picture_outputs(&a.output, a.exr.as_deref(), a.heatmap.as_deref(), &inputs)?;
    if let Some(map) = &a.envmap {
        if !matches!(crate::output::extension(map).as_str(), "exr" | "hdr") {
            return Err(UserError::WrongKind {
                flag: Some("--envmap".into()),
                path: map.clone(),
                expected: "an OpenEXR (.exr) or Radiance (.hdr) map".into(),
            }
            .into());
        }
    }
    // The inputs are checked once the outputs are known good.
    if let Some(scene) = &a.scene {
        crate::error::check_input(scene, None)?;
    }
    if let Some(map) = &a.envmap {
        crate::error::check_input(map, Some("--envmap"))?;
    }
    let (mitsuba, resolved) = resolve(a)?;
    if let Some(m) = &mitsuba {
        // No output may replace a file the scene reads (a mesh, a texture, an include).
        let read: Vec<(&str, &std::path::Path)> = m
            .inputs
            .iter()
            .map(|p| ("a file the scene reads,", p.as_path()))
            .collect();
        let mut outputs = vec![("--output", a.output.as_path())];
        outputs.extend(a.exr.as_deref().map(|p| ("--exr", p)));
        outputs.extend(a.heatmap.as_deref().map(|p| ("--heatmap", p)));
        crate::output::check_distinct(&read, &outputs)?;
    }
    let rr_bounces = mitsuba.as_ref().map(|m| m.settings.rr_bounces);
    let hide_emitters = mitsuba.as_ref().is_some_and(|m| m.settings.hide_emitters);
    let filter = mitsuba
        .as_ref()
        .map_or(prism_scene::Filter::Box, |m| m.settings.filter);
    // Mitsuba's estimator under a box filter; see `RenderOptions::mitsuba`.
    let one_light = match a.light_choice {
        Some(choice) => choice == LightChoiceArg::One,
        None => mitsuba.is_some() && filter == prism_scene::Filter::Box,
    };
    // A size given on the command line replaces a Mitsuba film's, crop and all.
    let film_replaced = a.resolution.is_some();
    let a = &resolved;
    let (adaptive, batch) = adaptive_settings(a)?;
    check_flags(a, adaptive, batch)?;
    let share = share(a, adaptive)?;
    let (w, h) = a.size();
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(UserError::Refused(format!(
            "--resolution: expected 1 to {MAX_SIDE} pixels a side, found {w} x {h}"
        ))
        .into());
    }
    let film = match share {
        Some(_) => prism_render::film::share_bytes(w, h),
        None => prism_render::film::film_bytes(w, h),
    };
    crate::resources::check_frame("--resolution", w, h, film)?;
    if a.light_samples == 0 || a.light_samples > MAX_LIGHT_SAMPLES {
        return Err(UserError::Refused(format!(
            "--light-samples: expected 1 to {MAX_LIGHT_SAMPLES}, found {}",
            a.light_samples
        ))
        .into());
    }
    if let Some(s) = &share {
        crate::split::check_tile_count(s.parts, w, h)?;
    }
    if a.spp() == 0 || a.spp() > 1 << 20 {
        return Err(UserError::Refused(format!(
            "--spp: expected 1 to {}, found {}",
            1 << 20,
            a.spp()
        ))
        .into());
    }
    if let Some(t) = adaptive {
        if !(t > 0.0 && t.is_finite()) {
            return Err(UserError::Refused(format!(
                "--adaptive: expected a positive tolerance, found {t}"
            ))
            .into());
        }
    }
    let t0 = Instant::now();
    let opts = SceneOptions {
        normals: match a.normals {
            NormalsArg::Area => NormalsMode::Area,
            NormalsArg::File => NormalsMode::File,
            NormalsArg::Flat => NormalsMode::Flat,
        },
        camera: match a.camera {
            CameraArg::Course => CameraMode::Course,
            CameraArg::File => CameraMode::File,
        },
    };
    let scene = match (&a.scene, mitsuba) {
        (_, Some(m)) => {
            let mut scene = m.scene;
            if film_replaced {
                scene.camera.crop = None;
            }
            scene
        }
        (None, None) => prism_scene::cornell_box(),
        (Some(path), None) => prism_scene::load(path, &opts).map_err(UserError::input)?,
    };
    let mut scene = scene;
    let lens = thin_lens(a, &scene.camera)?;
    if a.lens_radius.is_some() {
        scene.camera.lens = lens;
    }
    if let Some(path) = &a.envmap {
        let map = prism_image::read_radiance(path).map_err(UserError::input)?;
        let replaced = scene
            .light_by_environment_map(std::sync::Arc::new(map))
            .map_err(|e| UserError::input(format!("--envmap {}: {e}", path.display())))?;
        if replaced {
            scene.warnings.push(Warning::new(format!(
                "--envmap replaces the scene's hemisphere or environment light with {}",
                path.display()
            )));
        }
    }
    if !scene.is_lit() {
        let name = a
            .scene
            .as_ref()
            .map_or("the scene".to_string(), |p| p.display().to_string());
        scene.warnings.push(Warning::new(format!(
            "{name}: the scene has no light and no emitting surface that gives off light; it \
             renders black (`--envmap FILE.exr` lights it, `--integrator normals` shows its shapes)"
        )));
    }
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let read = t0.elapsed();
    let t1 = Instant::now();
    let prepared = RenderScene::new(&scene);
    let build = t1.elapsed();
    let rr_bounces = rr_bounces.unwrap_or(PathSettings::default().rr_bounces);
    let options = RenderOptions {
        film: FilmSettings {
            width: w,
            height: h,
            spp: a.spp(),
            adaptive,
            batch: batch.unwrap_or(DEFAULT_BATCH).max(1),
            seed: a.seed,
            filter,
        },
        path: PathSettings {
            rr_bounces,
            hide_emitters,
            one_light,
            light_samples: a.light_samples.max(1),
            max_bounces: a.max_bounces(),
            integrator: match a.integrator {
                IntegratorArg::Path => Integrator::Path,
                IntegratorArg::PathScalar => Integrator::PathScalar,
                IntegratorArg::Direct => Integrator::Direct {
                    hemisphere: a.hemisphere,
                },
                IntegratorArg::Normals => Integrator::Normals,
            },
            only_bounce: a.bounce,
        },
    };
    let pool = crate::resources::pool(a.threads)?;
    if let Some(share) = share {
        let tiles = prism_render::film::tiles(w, h);
        let pixels: u64 = tiles
            .iter()
            .enumerate()
            .filter(|&(k, _)| share.has_tile(k))
            .map(|(_, &(x0, y0))| {
                u64::from((w - x0).min(prism_render::film::TILE))
                    * u64::from((h - y0).min(prism_render::film::TILE))
            })
            .sum();
        let bar = crate::progress::samples_bar(pixels * share.samples.len() as u64, a.quiet);
        let t2 = Instant::now();
        let profile = prism_render::profile::Profile::default();
        let fingerprint = Instant::now();
        let identity = PartIdentity::path(scene.fingerprint(), &options);
        let fingerprint = fingerprint.elapsed();
        // Each tile goes into the part file as soon as it is rendered (in tile order): the
        // render holds the tiles in flight, not a picture of sums.
        let samples = std::sync::atomic::AtomicU64::new(0);
        prism_image::write_atomic(&a.output, |out| {
            let writer = Mutex::new(PartWriter::new(
                out,
                identity.to_attributes(),
                share.clone(),
                w,
                h,
            )?);
            let failed = Mutex::new(None);
            let stop = AtomicBool::new(false);
            pool.install(|| {
                let job = Job {
                    share: &share,
                    skip: None,
                    profile: Some(&profile),
                    stop: Some(&stop),
                    camera: None,
                };
                let progress = |done| bar.set_position(done);
                render_tiles(&prepared, &options, &job, &progress, |origin, sums| {
                    let n: u64 = sums.iter().map(|p| u64::from(p.n)).sum();
                    samples.fetch_add(n, Ordering::Relaxed);
                    let mut w = writer.lock().unwrap_or_else(PoisonError::into_inner);
                    if let Err(e) = w.add(origin, sums) {
                        stop.store(true, Ordering::Relaxed);
                        failed
                            .lock()
                            .unwrap_or_else(PoisonError::into_inner)
                            .get_or_insert(e);
                    }
                });
            });
            if let Some(e) = failed.into_inner().unwrap_or_else(PoisonError::into_inner) {
                return Err(e);
            }
            let writer = writer.into_inner().unwrap_or_else(PoisonError::into_inner);
            writer.finish()?;
            Ok(())
        })?;
        let render_time = t2.elapsed();
        bar.finish_and_clear();
        let t3 = Instant::now();
        let samples = samples.into_inner();
        crate::split::part_summary(&share, samples, &a.output, a.quiet, t0);
        if a.stats {
            let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
            eprintln!("read: {:.1} ms", ms(read));
            eprintln!("build: {:.1} ms", ms(build));
            eprintln!("render and write: {:.1} ms", ms(render_time));
            eprintln!("fingerprint: {:.1} ms", ms(fingerprint));
            eprintln!("finish: {:.1} ms", ms(t3.elapsed()));
            eprintln!("samples: {samples}");
            eprintln!(
                "samples/s: {:.0}",
                samples as f64 / render_time.as_secs_f64()
            );
            print_stages(&profile);
        }
        return Ok(());
    }
    let bar =
        crate::progress::samples_bar(u64::from(w) * u64::from(h) * u64::from(a.spp()), a.quiet);
    let t2 = Instant::now();
    let out = pool.install(|| render(&prepared, &options, &|done| bar.set_position(done)));
    let render_time = t2.elapsed();
    bar.finish_and_clear();
    let t3 = Instant::now();
    match format {
        ImageFormat::Exr => prism_image::write_exr(&a.output, &out.image)?,
        _ => crate::output::write_rgb8(&a.output, format, &out.image.linear_to_srgb8())?,
    }
    let mut written = vec![a.output.display().to_string()];
    if let Some(exr) = &a.exr {
        prism_image::write_exr(exr, &out.image)?;
        written.push(exr.display().to_string());
    }
    if let (Some(path), Some(f)) = (&a.heatmap, heatmap_format) {
        crate::output::write_rgb8(path, f, &prism_image::heatmap(&out.samples))?;
        written.push(path.display().to_string());
    }
    let write = t3.elapsed();
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "{}",
            summary(w, h, out.total_samples, t0.elapsed(), render_time, &written)
        );
    }
    if a.stats {
        let s = prepared.bvh_stats();
        eprintln!(
            "bvh: {} primitives, {} nodes, {} leaves, depth {}, largest leaf {}, SAH cost {:.2}, {:.1} bytes/primitive",
            s.primitives,
            s.nodes,
            s.leaves,
            s.depth,
            s.max_leaf_size,
            s.sah_cost,
            s.bytes as f64 / s.primitives.max(1) as f64
        );
        eprintln!("simd: {}", prism_math::Isa::get().name());
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read: {:.1} ms", ms(read));
        eprintln!("build: {:.1} ms", ms(build));
        eprintln!("render: {:.1} ms", ms(render_time));
        eprintln!("write: {:.1} ms", ms(write));
        eprintln!("samples: {}", out.total_samples);
        eprintln!(
            "samples/s: {:.0}",
            out.total_samples as f64 / render_time.as_secs_f64()
        );
        print_stages(&out.profile);
    }
    Ok(())
}

/// Prints the path integrator's share of time per stage (`stages: camera rays 5.9%, ...`)
/// and its time per stage summed over the threads (`stage times: camera rays 61.2 ms,
/// ...`), if it ran.
fn print_stages(profile: &prism_render::profile::Profile) {
    if let Some(shares) = profile.shares() {
        let stages: Vec<String> = shares
            .iter()
            .map(|(stage, share)| format!("{} {:.1}%", stage.name(), 100.0 * share))
            .collect();
        eprintln!("stages: {}", stages.join(", "));
        let times: Vec<String> = shares
            .iter()
            .map(|&(stage, _)| {
                let ms = profile.time(stage).as_secs_f64() * 1e3;
                format!("{} {ms:.1} ms", stage.name())
            })
            .collect();
        eprintln!("stage times: {}", times.join(", "));
    }
}

/// The line printed when a render ends on a terminal: size, samples, times, outputs.
fn summary(
    w: u32,
    h: u32,
    samples: u64,
    total: std::time::Duration,
    render: std::time::Duration,
    written: &[String],
) -> String {
    let rate = samples as f64 / render.as_secs_f64().max(1e-9);
    format!(
        "prism: rendered {w}x{h}, {:.2} M samples ({:.1} per pixel) in {:.1} s ({:.2} M samples/s) -> {}",
        samples as f64 / 1e6,
        samples as f64 / (f64::from(w) * f64::from(h)),
        total.as_secs_f64(),
        rate / 1e6,
        written.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_names_size_samples_rate_and_outputs() {
        let s = summary(
            4,
            2,
            80,
            std::time::Duration::from_secs(2),
            std::time::Duration::from_secs(1),
            &["a.png".into(), "a.exr".into()],
        );
        assert_eq!(
            s,
            "prism: rendered 4x2, 0.00 M samples (10.0 per pixel) in 2.0 s (0.00 M samples/s) -> a.png, a.exr"
        );
    }
}
