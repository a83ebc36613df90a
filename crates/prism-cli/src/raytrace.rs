//! `prism raytrace`: the Delft Whitted ray tracer on a preset, an OBJ scene or a TOML render
//! config, with its feature switches, bloom, BVH views and the ray tree of one pixel.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use prism_image::Bloom;
use prism_render::film::Share;
use prism_render::parts::{Part, PartIdentity};
use prism_render::whitted::camera::OrbitView;
use prism_render::whitted::film::{
    rays_per_pixel, raytrace, raytrace_share, trace_pixel, RaytraceOptions,
};
use prism_render::whitted::overlay::Overlay;
use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
use prism_render::whitted::tracer::WhittedSettings;
use prism_scene::{Features, OrbitCamera};

use crate::error::UserError;
use crate::output::write_text;
use crate::output::{image_output, ImageFormat};

/// Arguments of `prism raytrace`.
#[derive(Args, Debug)]
pub struct RaytraceArgs {
    /// A preset (single-triangle, cube, cube-textured, cornell-box,
    /// cornell-box-parallelogram-light, monkey, teapot, dragon, spheres, custom), an OBJ
    /// scene (lit by a point light at (-1, 1, -1)) or a TOML render config.
    #[arg(default_value = "cornell-box")]
    scene: String,
    /// Output image: .png, .bmp or .jpg (clamped, byte = trunc(255 v), no gamma) or .exr
    /// (linear). With several config cameras, NAME-0.png, NAME-1.png, ...
    #[arg(short, long, default_value = "raytrace.png")]
    output: PathBuf,
    /// Also write the linear image to this OpenEXR file.
    #[arg(long, value_name = "FILE")]
    exr: Option<PathBuf>,
    /// Image size: WIDTH HEIGHT (default: the config's window_size, else 800 800).
    #[arg(short = 'r', long = "resolution", num_args = 2, value_names = ["WIDTH", "HEIGHT"])]
    resolution: Option<Vec<u32>>,
    /// The course's files (`shared/assets`, whose `delft-raytracer/data` holds the presets'
    /// OBJ files), or that data folder itself (default: the config's data_path, else
    /// PRISM_DATA or a `shared/assets` folder above the executable or the working folder,
    /// else the copies built into prism).
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Turn features on, comma-separated: shading, recursive, hard-shadow, soft-shadow,
    /// normal-interp, texture, bilinear, bvh, bloom, transparency, multi-rays, and the
    /// extras dof, motion-blur, glossy, env-map, mipmap, sah. Without a config the first
    /// eight and sah start on; a config's [features] start as it says (off when absent).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    enable: Vec<String>,
    /// Turn features off (names as --enable).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    disable: Vec<String>,
    /// Brute force: test every ray against every primitive (same as --disable bvh).
    #[arg(long)]
    no_bvh: bool,
    /// Rays per pixel, jittered over the pixel (more than 1 turns multi-rays on; with
    /// multi-rays on and no --spp, 16).
    #[arg(short = 's', long = "spp")]
    spp: Option<u32>,
    /// Samples per segment light; a parallelogram takes a k x k grid, k = ceil(sqrt(N)).
    #[arg(long = "light-samples", default_value_t = 16)]
    light_samples: u32,
    /// Most reflection bounces after the camera ray.
    #[arg(long = "max-depth", default_value_t = 3)]
    max_depth: u32,
    /// Depth of field: the lens radius (turns dof on; default: the config's, else 0.05).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    dof_aperture: Option<f32>,
    /// Depth of field: distance along the view axis of the plane in focus (turns dof on;
    /// default: the config's, else the camera's distance from its look-at point).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    dof_focal_distance: Option<f32>,
    /// Depth of field: lens samples per pixel (default: the config's, else 16).
    #[arg(long, value_name = "N")]
    dof_samples: Option<u32>,
    /// Motion blur: mesh MESH (its index, or its material's name) moves by VX,VY,VZ over the
    /// shutter; repeatable, replaces the config's [[motion]] (turns motion-blur on).
    #[arg(long, value_name = "MESH=VX,VY,VZ", allow_hyphen_values = true)]
    motion: Vec<String>,
    /// Motion blur: shutter times per pixel (default: the config's, else 16).
    #[arg(long, value_name = "N")]
    motion_samples: Option<u32>,
    /// Glossy reflection: rays per reflection (default: the config's, else 16).
    #[arg(long, value_name = "N")]
    glossy_samples: Option<u32>,
    /// Environment mapping: a latitude-longitude PNG, JPEG, EXR or HDR image seen by rays
    /// that miss (turns env-map on; replaces the config's).
    #[arg(long, value_name = "FILE")]
    environment_map: Option<PathBuf>,
    /// Environment mapping: the map's radiance scale (default: the config's, else 1).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    environment_strength: Option<f32>,
    /// Bloom: only pixels whose luminance is above this count as bright.
    #[arg(long, default_value_t = 0.0)]
    bloom_threshold: f32,
    /// Bloom: blur passes (each horizontal then vertical).
    #[arg(long, default_value_t = 1)]
    bloom_passes: u32,
    /// Write only the bloom layer (turns bloom on).
    #[arg(long)]
    bloom_debug: bool,
    /// Record the ray tree of pixel X,Y (X from the left, Y from the top of the written
    /// image): writes OUT.rays.json and OUT.debug.png, the rays drawn over the render.
    #[arg(long, value_name = "X,Y", value_delimiter = ',')]
    debug_pixel: Option<Vec<u32>>,
    /// Draw the debug overlay from this orbit around the render camera's look-at point:
    /// rotation in degrees and distance, like a config camera.
    #[arg(
        long,
        value_name = "RX,RY,RZ,DIST",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    debug_camera: Option<Vec<f32>>,
    /// Also write the ray tree as a PLY of coloured line segments (for Blender).
    #[arg(long, value_name = "FILE.ply")]
    debug_ply: Option<PathBuf>,
    /// Draw the boxes of this level of the BVH over the render (0: the root box).
    #[arg(long, value_name = "N")]
    bvh_level: Option<usize>,
    /// Draw leaf K of the BVH (its box and its triangles) over the render.
    #[arg(long, value_name = "K")]
    bvh_leaf: Option<usize>,
    /// Render only share I of N (I from 0) of the image's 32x32 tiles, dealt round-robin,
    /// and write a part file (-o PART.exr; NAME-0.exr, ... with several cameras) for
    /// `prism merge`, which adds bloom.
    #[arg(long, value_name = "I/N", value_parser = crate::split::parse_tile)]
    tile: Option<(u32, u32)>,
    /// Seed of the jitter: the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    threads: Option<usize>,
    /// Print BVH statistics, rays by kind, times and rays/s on stderr.
    #[arg(long)]
    stats: bool,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
}

/// Largest image side.
const MAX_SIDE: u32 = 16384;
/// Rays per pixel with multi-rays on and no --spp.
const DEFAULT_SPP: u32 = 16;
/// Default image side.
const DEFAULT_SIDE: u32 = 800;

/// Sets feature `name` in `f`.
fn set_feature(f: &mut Features, name: &str, on: bool, flag: &str) -> Result<()> {
    let Some(slot) = f.switch(name.trim()) else {
        return Err(UserError::Refused(format!(
            "{flag} {}: expected one of {}",
            name.trim(),
            Features::NAMES.join(", ")
        ))
        .into());
    };
    *slot = on;
    Ok(())
}

/// The output path for camera `i` of `n`: the path itself for one camera, else
/// `STEM-i.EXT`.
fn numbered(path: &Path, i: usize, n: usize) -> PathBuf {
    if n <= 1 {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = match path.extension() {
        Some(e) => format!("{stem}-{i}.{}", e.to_string_lossy()),
        None => format!("{stem}-{i}"),
    };
    path.with_file_name(name)
}

/// `OUT` with its extension replaced by `suffix` (`OUT.rays.json`).
fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}{suffix}"))
}

/// Checks, before any rendering, every file the run will write (each camera's picture,
/// linear copy, ray tree, PLY and debug picture): none may name the scene, the environment
/// map or another.
fn check_every_output(
    a: &RaytraceArgs,
    n: usize,
    debug: bool,
    environment: Option<&Path>,
) -> Result<()> {
    let mut outputs: Vec<(&str, PathBuf)> = Vec::new();
    for ci in 0..n {
        let path = numbered(&a.output, ci, n);
        outputs.push(("--output", path.clone()));
        if a.tile.is_none() {
            outputs.extend(a.exr.as_deref().map(|e| ("--exr", numbered(e, ci, n))));
            if debug {
                outputs.push(("--debug-pixel's ray tree", sibling(&path, ".rays.json")));
                outputs.push(("--debug-pixel's picture", sibling(&path, ".debug.png")));
                outputs.extend(
                    a.debug_ply
                        .as_deref()
                        .map(|p| ("--debug-ply", numbered(p, ci, n))),
                );
            }
        }
    }
    let outputs: Vec<(&str, &Path)> = outputs.iter().map(|(f, p)| (*f, p.as_path())).collect();
    let scene = Path::new(&a.scene);
    let mut inputs: Vec<(&str, &Path)> = if scene.is_file() {
        vec![("the scene", scene)]
    } else {
        Vec::new()
    };
    inputs.extend(environment.map(|e| ("the environment map", e)));
    crate::output::check_distinct(&inputs, &outputs)
}

/// The extras' settings and scene additions a run uses.
struct RunExtras {
    settings: prism_scene::Extras,
    motion: Vec<(usize, prism_math::Vec3)>,
    environment: Option<std::sync::Arc<prism_image::RgbImage>>,
    /// The environment map's file (read even when environment mapping is off).
    environment_file: Option<PathBuf>,
}

impl RunExtras {
    /// `scene`'s fingerprint with what the extras add to the scene (moving meshes, the
    /// environment map's texels) folded in, so that parts of different runs do not merge.
    fn fingerprint(&self, scene: u64) -> u64 {
        let mut h = scene;
        let mut add = |bits: u32| h = (h ^ u64::from(bits)).wrapping_mul(0x0100_0000_01b3);
        for &(i, v) in &self.motion {
            add(i as u32);
            v.to_array().iter().for_each(|x| add(x.to_bits()));
        }
        if let Some(im) = &self.environment {
            add(im.width());
            add(im.height());
            for p in im.pixels() {
                [p.r, p.g, p.b].iter().for_each(|x| add(x.to_bits()));
            }
        }
        h
    }
}

/// Checks one extras flag's number: finite, at least `lo` (above it if `open`), at most
/// [`prism_scene::MAX_EXTENT`].
fn extent_flag(flag: &str, v: Option<f32>, lo: f32, open: bool) -> Result<Option<f32>> {
    let Some(x) = v else { return Ok(None) };
    let ok = x.is_finite() && (if open { x > lo } else { x >= lo }) && x <= prism_scene::MAX_EXTENT;
    if !ok {
        let from = if open { "above" } else { "from" };
        return Err(UserError::Refused(format!(
            "{flag}: expected a number {from} {lo} up to {}, found {x}",
            prism_scene::MAX_EXTENT
        ))
        .into());
    }
    Ok(Some(x))
}

/// Checks one extras sample-count flag.
fn samples_flag(flag: &str, v: Option<u32>) -> Result<Option<u32>> {
    match v {
        Some(n) if n == 0 || n > prism_scene::MAX_EXTRA_SAMPLES => {
            Err(UserError::Refused(format!(
                "{flag}: expected 1 to {} samples, found {n}",
                prism_scene::MAX_EXTRA_SAMPLES
            ))
            .into())
        }
        _ => Ok(v),
    }
}

/// The extras of a run: the config's settings with the flags' in their place, the moving
/// meshes and the environment map; flags that set an extra turn it on. Refuses an
/// environment map switched on without a map.
fn extras(
    a: &RaytraceArgs,
    loaded: &prism_scene::DelftScene,
    features: &mut Features,
) -> Result<RunExtras> {
    let mut e = loaded.extras;
    if let Some(r) = extent_flag("--dof-aperture", a.dof_aperture, 0.0, false)? {
        e.dof_aperture = r;
        features.depth_of_field = true;
    }
    if let Some(d) = extent_flag("--dof-focal-distance", a.dof_focal_distance, 0.0, true)? {
        e.dof_focal_distance = Some(d);
        features.depth_of_field = true;
    }
    e.dof_samples = samples_flag("--dof-samples", a.dof_samples)?.unwrap_or(e.dof_samples);
    e.motion_samples =
        samples_flag("--motion-samples", a.motion_samples)?.unwrap_or(e.motion_samples);
    e.glossy_samples =
        samples_flag("--glossy-samples", a.glossy_samples)?.unwrap_or(e.glossy_samples);
    if let Some(s) = extent_flag("--environment-strength", a.environment_strength, 0.0, false)? {
        e.environment_strength = s;
    }
    let mut motion = loaded.motion.clone();
    if !a.motion.is_empty() {
        motion.clear();
        features.motion_blur = true;
        for m in &a.motion {
            motion.extend(motion_flag(m, &loaded.scene)?);
        }
    }
    let environment_file = a
        .environment_map
        .clone()
        .or_else(|| loaded.environment_file.clone());
    let image = match &a.environment_map {
        Some(path) => {
            features.environment_mapping = true;
            Some(std::sync::Arc::new(
                prism_scene::read_environment_map(path).map_err(UserError::input)?,
            ))
        }
        None => loaded.environment.clone(),
    };
    if features.environment_mapping && image.is_none() {
        return Err(UserError::Refused(
            "env-map is on, but no environment map is given: set [extras] environment_map in \
             the config or --environment-map FILE"
                .into(),
        )
        .into());
    }
    if !a.quiet && features.motion_blur && motion.is_empty() {
        eprintln!(
            "prism: warning: motion-blur is on, but nothing moves: give [[motion]] entries or \
             --motion MESH=VX,VY,VZ"
        );
    }
    Ok(RunExtras {
        settings: e,
        motion: if features.motion_blur {
            motion
        } else {
            Vec::new()
        },
        environment: if features.environment_mapping {
            image
        } else {
            None
        },
        environment_file,
    })
}

/// One `--motion MESH=VX,VY,VZ`: the meshes it names and their velocity.
fn motion_flag(m: &str, scene: &prism_scene::Scene) -> Result<Vec<(usize, prism_math::Vec3)>> {
    let bad = || {
        UserError::Refused(format!(
            "--motion {m}: expected MESH=VX,VY,VZ (a mesh index or name, three finite numbers \
             up to {} in size)",
            prism_scene::MAX_EXTENT
        ))
    };
    let (name, v) = m.rsplit_once('=').ok_or_else(bad)?;
    let v: Vec<f32> = v
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if v.len() != 3
        || v.iter()
            .any(|x| !x.is_finite() || x.abs() > prism_scene::MAX_EXTENT)
    {
        return Err(bad().into());
    }
    let mesh = match name.trim().parse::<usize>() {
        Ok(i) => prism_scene::MeshRef::Index(i),
        Err(_) => prism_scene::MeshRef::Name(name.trim().to_string()),
    };
    let found = mesh.resolve(scene);
    if found.is_empty() {
        return Err(UserError::Refused(format!(
            "--motion {m}: no such mesh (the scene's meshes: {})",
            prism_scene::mesh_names(scene)
        ))
        .into());
    }
    let v = prism_math::Vec3::new(v[0], v[1], v[2]);
    Ok(found.into_iter().map(|i| (i, v)).collect())
}

/// Runs `prism raytrace`.
pub fn run(a: &RaytraceArgs) -> Result<()> {
    let allowed = [
        ImageFormat::Png,
        ImageFormat::Bmp,
        ImageFormat::Jpeg,
        ImageFormat::Exr,
    ];
    let format = image_output(&a.output, "--output", &allowed)?;
    if let Some(exr) = &a.exr {
        image_output(exr, "--exr", &[ImageFormat::Exr])?;
    }
    if let Some(ply) = &a.debug_ply {
        if crate::output::extension(ply) != "ply" {
            return Err(UserError::WrongKind {
                flag: Some("--debug-ply".into()),
                path: ply.clone(),
                expected: "a .ply file".into(),
            }
            .into());
        }
        crate::output::check_folder(ply, "--debug-ply")?;
        if a.debug_pixel.is_none() {
            return Err(
                UserError::Refused("--debug-ply: it needs --debug-pixel X,Y".into()).into(),
            );
        }
    }
    if a.debug_camera.is_some() && a.debug_pixel.is_none() {
        eprintln!("prism: warning: --debug-camera has no effect: it applies to --debug-pixel");
    }
    if let Some(spp) = a.spp.filter(|&s| s == 0 || s > 1 << 16) {
        return Err(
            UserError::Refused(format!("--spp: expected 1 to {}, found {spp}", 1 << 16)).into(),
        );
    }
    if a.light_samples == 0 || a.light_samples > 1 << 16 {
        return Err(UserError::Refused(format!(
            "--light-samples: expected 1 to {}, found {}",
            1 << 16,
            a.light_samples
        ))
        .into());
    }
    if a.max_depth > 64 {
        return Err(UserError::Refused(format!(
            "--max-depth: expected 0 to 64, found {}",
            a.max_depth
        ))
        .into());
    }
    if !(a.bloom_threshold.is_finite() && a.bloom_threshold >= 0.0) {
        return Err(UserError::Refused(format!(
            "--bloom-threshold: expected a number of at least 0, found {}",
            a.bloom_threshold
        ))
        .into());
    }
    if a.bloom_passes > 64 {
        return Err(UserError::Refused(format!(
            "--bloom-passes: expected 0 to 64, found {}",
            a.bloom_passes
        ))
        .into());
    }
    if a.tile.is_some() {
        let mut pictures = Vec::new();
        for (given, flag) in [
            (a.exr.is_some(), "--exr"),
            (a.bloom_debug, "--bloom-debug"),
            (a.debug_pixel.is_some(), "--debug-pixel"),
            (a.bvh_level.is_some(), "--bvh-level"),
            (a.bvh_leaf.is_some(), "--bvh-leaf"),
        ] {
            if given {
                pictures.push(flag);
            }
        }
        crate::split::check_part_output(&a.output, &pictures)?;
    }
    crate::error::check_scene_name(&a.scene)?;
    let t0 = Instant::now();
    let loaded = prism_scene::load_delft(&a.scene, a.data.as_deref(), &mut |w| {
        eprintln!("prism: warning: {w}");
    })
    .map_err(UserError::input)?;
    let mut features = loaded.features;
    for n in &a.enable {
        set_feature(&mut features, n, true, "--enable")?;
    }
    for n in &a.disable {
        set_feature(&mut features, n, false, "--disable")?;
    }
    if a.no_bvh {
        features.accel_structure = false;
    }
    if a.spp.is_some_and(|s| s > 1) {
        features.multiple_rays_per_pixel = true;
    }
    if a.bloom_debug {
        features.bloom = true;
    }
    // The template samples segment and parallelogram lights only for soft shadows.
    let area = |l: &prism_scene::Light| {
        matches!(
            l,
            prism_scene::Light::Segment { .. } | prism_scene::Light::Parallelogram { .. }
        )
    };
    let lights = &loaded.scene.lights;
    if !a.quiet && !features.soft_shadow && lights.iter().any(area) {
        let all = lights.iter().all(area);
        eprintln!(
            "prism: warning: soft-shadow is off, so the scene's segment and parallelogram \
             lights give no light (the template samples them only for soft shadows){}",
            if all {
                "; it has no other light, so the picture is black"
            } else {
                ""
            }
        );
    }
    let (w, h) = match (&a.resolution, loaded.window) {
        (Some(r), _) => (r[0], r[1]),
        (None, Some([w, h])) => (w, h),
        (None, None) => (DEFAULT_SIDE, DEFAULT_SIDE),
    };
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(UserError::Refused(format!(
            "--resolution: expected 1 to {MAX_SIDE} pixels a side, found {w} x {h}"
        ))
        .into());
    }
    crate::resources::check_frame(
        "--resolution",
        w,
        h,
        prism_render::whitted::film::raytrace_bytes(w, h),
    )?;
    if let Some((_, parts)) = a.tile {
        crate::split::check_tile_count(parts, w, h)?;
    }
    if a.debug_pixel.as_ref().is_some_and(|p| p.len() != 2) {
        return Err(
            UserError::Refused("--debug-pixel: expected X,Y (two whole numbers)".into()).into(),
        );
    }
    if a.debug_camera.as_ref().is_some_and(|c| c.len() != 4) {
        return Err(UserError::Refused(
            "--debug-camera: expected RX,RY,RZ,DIST (four numbers)".into(),
        )
        .into());
    }
    let debug_pixel = match &a.debug_pixel {
        Some(p) if p[0] >= w || p[1] >= h => {
            return Err(UserError::Refused(format!(
                "--debug-pixel {},{}: outside the {w} x {h} image",
                p[0], p[1]
            ))
            .into())
        }
        Some(p) => Some((p[0], p[1])),
        None => None,
    };
    if let Some(c) = &a.debug_camera {
        if c.iter().any(|v| !v.is_finite()) || c[3] < 0.0 {
            return Err(UserError::Refused(
                "--debug-camera: expected finite RX,RY,RZ degrees and a distance of at least 0"
                    .into(),
            )
            .into());
        }
    }
    let extras = extras(a, &loaded, &mut features)?;
    let read = t0.elapsed();
    let t1 = Instant::now();
    let split = if features.sah_binning {
        Split::Sah
    } else {
        Split::Median
    };
    let scene = WhittedScene::prepare(
        &loaded.scene,
        SceneSetup {
            bvh: features.accel_structure.then_some(split),
            motion: extras.motion.clone(),
            environment: (extras.environment.as_ref())
                .map(|im| Environment::new((**im).clone(), extras.settings.environment_strength)),
        },
    );
    let build = t1.elapsed();
    if (a.bvh_level.is_some() || a.bvh_leaf.is_some()) && scene.bvh().is_none() {
        return Err(UserError::Refused(
            "--bvh-level and --bvh-leaf draw the BVH; it is off (--no-bvh or --disable bvh)".into(),
        )
        .into());
    }
    if let (Some(bvh), Some(level)) = (scene.bvh(), a.bvh_level) {
        if level >= bvh.levels() {
            return Err(UserError::Refused(format!(
                "--bvh-level {level}: the BVH has levels 0 to {}",
                bvh.levels().saturating_sub(1)
            ))
            .into());
        }
    }
    if let (Some(bvh), Some(leaf)) = (scene.bvh(), a.bvh_leaf) {
        let n = bvh.leaf_views().len();
        if leaf >= n {
            return Err(UserError::Refused(format!(
                "--bvh-leaf {leaf}: the BVH has leaves 0 to {}",
                n.saturating_sub(1)
            ))
            .into());
        }
    }
    let opts = RaytraceOptions {
        width: w,
        height: h,
        settings: WhittedSettings {
            features,
            light_samples: a.light_samples,
            max_depth: a.max_depth,
            extras: extras.settings,
        },
        spp: a.spp.unwrap_or(DEFAULT_SPP),
        bloom: Bloom {
            threshold: a.bloom_threshold,
            passes: a.bloom_passes,
        },
        seed: a.seed,
    };
    let pool = crate::resources::pool(a.threads)?;
    let n = loaded.cameras.len();
    check_every_output(
        a,
        n,
        debug_pixel.is_some(),
        extras.environment_file.as_deref(),
    )?;
    let mut written = Vec::new();
    let mut counts = prism_render::whitted::tracer::RayCounts::default();
    let mut render_time = std::time::Duration::ZERO;
    let mut write_time = std::time::Duration::ZERO;
    if let Some((part, parts)) = a.tile {
        let fingerprint = extras.fingerprint(loaded.scene.fingerprint());
        for (ci, camera) in loaded.cameras.iter().enumerate() {
            let share = Share {
                part,
                parts,
                samples: 0..rays_per_pixel(&opts),
            };
            let bar = crate::progress::bar(u64::from(h), "raytrace", a.quiet);
            let (sums, _) = pool.install(|| {
                raytrace_share(&scene, camera, &opts, &share, &|done| {
                    bar.set_position(done);
                })
            });
            bar.finish_and_clear();
            let identity = PartIdentity::whitted(fingerprint, camera, &opts);
            let part = Part::new(identity.to_attributes(), share, sums);
            crate::split::write_part(&part, &numbered(&a.output, ci, n), a.quiet, t0)?;
        }
        return Ok(());
    }
    for (ci, camera) in loaded.cameras.iter().enumerate() {
        let bar = crate::progress::bar(u64::from(h), "raytrace", a.quiet);
        let t2 = Instant::now();
        let out = pool.install(|| raytrace(&scene, camera, &opts, &|done| bar.set_position(done)));
        render_time += t2.elapsed();
        bar.finish_and_clear();
        counts.add(&out.counts);
        let t3 = Instant::now();
        let path = numbered(&a.output, ci, n);
        let picture = if a.bloom_debug {
            out.bloom_layer.clone().unwrap_or_else(|| out.image.clone())
        } else {
            out.image.clone()
        };
        // BVH views are drawn on the picture (never on the EXR's linear values).
        let mut shown = picture.clone();
        if a.bvh_level.is_some() || a.bvh_leaf.is_some() {
            let view = OrbitView::new(camera, w, h);
            let mut ov = Overlay::new(shown, view, &scene);
            ov.bvh(&scene, a.bvh_level, a.bvh_leaf);
            shown = ov.image;
        }
        match format {
            ImageFormat::Exr => prism_image::write_exr(&path, &picture)?,
            _ => crate::output::write_rgb8(&path, format, &shown.to_rgb8_truncated())?,
        }
        written.push(path.display().to_string());
        if let Some(exr) = &a.exr {
            let p = numbered(exr, ci, n);
            prism_image::write_exr(&p, &picture)?;
            written.push(p.display().to_string());
        }
        if let Some((x, row)) = debug_pixel {
            let tr = trace_pixel(&scene, camera, &opts, x, row);
            let json = sibling(&path, ".rays.json");
            write_text(&json, &tr.to_json())?;
            written.push(json.display().to_string());
            if let Some(ply) = &a.debug_ply {
                let p = numbered(ply, ci, n);
                write_text(&p, &tr.to_ply())?;
                written.push(p.display().to_string());
            }
            let (debug_cam, base) = match &a.debug_camera {
                None => (*camera, out.image.clone()),
                Some(c) => {
                    let cam = OrbitCamera {
                        rotation: prism_math::Vec3::new(c[0], c[1], c[2]),
                        distance: c[3],
                        ..*camera
                    };
                    let img = pool
                        .install(|| raytrace(&scene, &cam, &opts, &|_| {}))
                        .image;
                    (cam, img)
                }
            };
            let view = OrbitView::new(&debug_cam, w, h);
            // The picture is dimmed so that the rays stand out.
            let dim = base.map(|p| *p * 0.5);
            let mut ov = Overlay::new(dim, view, &scene);
            ov.ray_tree(&tr.rays);
            let png = sibling(&path, ".debug.png");
            crate::output::write_rgb8(&png, ImageFormat::Png, &ov.image.to_rgb8_truncated())?;
            written.push(png.display().to_string());
        }
        write_time += t3.elapsed();
    }
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "prism: ray traced {w}x{h} x {n} camera(s), {:.2} M rays in {:.1} s ({:.2} M rays/s) -> {}",
            counts.total() as f64 / 1e6,
            t0.elapsed().as_secs_f64(),
            counts.total() as f64 / render_time.as_secs_f64().max(1e-9) / 1e6,
            written.join(", ")
        );
    }
    if a.stats {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("triangles: {}", scene.triangle_count());
        match scene.bvh() {
            Some(bvh) => {
                let s = bvh.stats();
                eprintln!(
                    "bvh: {} levels (8-wide), binary depth {}, {} leaves, largest leaf {}, SAH cost {:.2} ({})",
                    bvh.levels(),
                    s.depth,
                    s.leaves,
                    s.max_leaf_size,
                    s.sah_cost,
                    if features.sah_binning { "binned SAH" } else { "median split" }
                );
            }
            None => eprintln!("bvh: off (brute force)"),
        }
        for (name, rule) in [("binned SAH", Split::Sah), ("median split", Split::Median)] {
            let t = Instant::now();
            let s = scene.bvh_stats(rule);
            eprintln!(
                "tree by {name}: SAH cost {:.2}, binary depth {}, {} leaves, largest leaf {}, {} nodes, built in {:.1} ms",
                s.sah_cost,
                s.depth,
                s.leaves,
                s.max_leaf_size,
                s.nodes,
                ms(t.elapsed())
            );
        }
        eprintln!(
            "rays: camera {}, reflection {}, transmission {}, shadow {}, area-sample {}, total {}",
            counts.camera,
            counts.reflection,
            counts.transmission,
            counts.shadow,
            counts.area_sample,
            counts.total()
        );
        eprintln!("read: {:.1} ms", ms(read));
        eprintln!("build: {:.1} ms", ms(build));
        eprintln!("render: {:.1} ms", ms(render_time));
        eprintln!("write: {:.1} ms", ms(write_time));
        eprintln!(
            "rays/s: {:.0}",
            counts.total() as f64 / render_time.as_secs_f64().max(1e-9)
        );
    }
    Ok(())
}
