//! `prism shade`: a mesh drawn by the software pipeline with one of the course's shaders,
//! as the course app's OpenGL would draw it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use prism_math::{Rgb, Vec3};
use prism_shade::{
    course_texture, shade_rgb8, Framing, ShadeMesh, ShadeOptions, Shader, Uniforms, View,
};

use crate::error::UserError;
use crate::output::{image_output, ImageFormat};

/// The shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ShaderArg {
    /// The normal as a colour, (n + 1) / 2.
    Normal,
    /// The flat colour (white).
    Wireframe,
    /// I / r^2 max(n.l, 0).
    Diffuse,
    /// Blinn-Phong: ambient 0.1, diffuse 0.8, specular 0.5 with exponent 32.
    Phong,
    /// The texture's colour (--texture).
    Texture,
    /// Blinn-Phong with the normal bent by a height map (--height-map).
    Bump,
    /// Vertices moved along their normals by the height map, then bump shading.
    Displacement,
    /// The cube map (--cubemap) along the mirror direction.
    Mirror,
}

/// Arguments of `prism shade`.
#[derive(Args, Debug)]
pub struct ShadeArgs {
    /// The mesh: .obj (with its uvs and normals), .ply or .dae.
    mesh: PathBuf,
    /// Output image: .png, .bmp or .jpg (round(255 clamp(c)), no gamma, as OpenGL writes).
    #[arg(short, long, default_value = "shade.png")]
    output: PathBuf,
    /// The shader.
    #[arg(long, value_enum, default_value_t = ShaderArg::Phong)]
    shader: ShaderArg,
    /// Eye position X,Y,Z (default: in front of the mesh along +z, framing its bounds).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    eye: Option<Vec<f32>>,
    /// The point looked at (default: the centre of the mesh's bounds).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    target: Option<Vec<f32>>,
    /// Up direction.
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true,
        default_value = "0,1,0"
    )]
    up: Vec<f32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 45.0)]
    fov_y: f32,
    /// Image size: WIDTH HEIGHT.
    #[arg(short = 'r', long = "resolution", num_args = 2, value_names = ["WIDTH", "HEIGHT"], default_values_t = [800, 600])]
    resolution: Vec<u32>,
    /// Samples per pixel: a square number (1, 4, 9, 16, ...).
    #[arg(
        short = 's',
        long = "spp",
        visible_alias = "samples",
        default_value_t = 1
    )]
    samples: u32,
    #[command(flatten)]
    files: ShaderFiles,
    /// Light position (default: the course's (0.5, 2, 2) when the mesh lies within a unit
    /// of the origin, as the course's meshes do; else that point scaled by the mesh's
    /// size and moved with its centre, so that the light stands where it stands for the
    /// course's meshes).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    light: Option<Vec<f32>>,
    /// Light intensity (default: the course's 3,3,3, times the square of the scale when
    /// the light is placed by the mesh's size, so that the mesh is lit as the course's are).
    #[arg(long, value_name = "R,G,B", value_delimiter = ',')]
    light_intensity: Option<Vec<f32>>,
    /// Background colour.
    #[arg(
        long,
        value_name = "R,G,B",
        value_delimiter = ',',
        default_value = "0,0,0"
    )]
    background: Vec<f32>,
    /// Draw every triangle's edges on top (depth-tested), in this colour.
    #[arg(long, value_name = "R,G,B", value_delimiter = ',')]
    wireframe: Option<Vec<f32>>,
    /// Print per-stage times on stderr: read, render (vertex stage to final image), write.
    #[arg(long)]
    stats: bool,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    threads: Option<usize>,
}

/// The files the course's image-reading shaders take, shared by `prism shade` and
/// `prism cloth`.
#[derive(Args, Debug)]
pub struct ShaderFiles {
    /// Texture for --shader texture (default: the course's texture_1.png).
    #[arg(long, value_name = "PNG")]
    texture: Option<PathBuf>,
    /// Height map for --shader bump and displacement (its red channel; default: the
    /// course's texture_2.png).
    #[arg(long, value_name = "PNG")]
    height_map: Option<PathBuf>,
    /// Folder with the cube map's faces posx, negx, posy, negy, posz, negz (.png or .jpg)
    /// for --shader mirror (default: the course's textures/cube).
    #[arg(long, value_name = "DIR")]
    cubemap: Option<PathBuf>,
    /// The course's files (`shared/assets`), where the default texture, height map and cube
    /// map are found (default: PRISM_DATA, else a `shared/assets` folder above the
    /// executable or the working folder).
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
}

impl ShaderFiles {
    /// The files given, named by their flags, for the check that no output replaces them.
    pub fn inputs(&self) -> Vec<(&'static str, &Path)> {
        let mut v = Vec::new();
        v.extend(self.texture.as_deref().map(|p| ("--texture", p)));
        v.extend(self.height_map.as_deref().map(|p| ("--height-map", p)));
        v.extend(self.cubemap.as_deref().map(|p| ("--cubemap", p)));
        v
    }

    /// The shader `arg` names with the images it reads: the files given, else the course's
    /// (`clothsim/textures`: texture_1.png, texture_2.png, cube). Warns of a file given to a
    /// shader that does not read it unless `quiet`.
    pub fn shader(&self, arg: ShaderArg, quiet: bool) -> Result<Shader> {
        if let Some(p) = &self.texture {
            crate::error::check_input(p, Some("--texture"))?;
        }
        if let Some(p) = &self.height_map {
            crate::error::check_input(p, Some("--height-map"))?;
        }
        if let Some(p) = &self.cubemap {
            crate::error::check_folder_input(p, "--cubemap")?;
        }
        let file = |given: &Option<PathBuf>, rel: &str, flag: &str| match given {
            Some(p) => Ok(p.clone()),
            None => staged(self.data.as_deref(), rel, flag),
        };
        let shader = match arg {
            ShaderArg::Normal => Shader::Normal,
            ShaderArg::Wireframe => Shader::Wireframe,
            ShaderArg::Diffuse => Shader::Diffuse,
            ShaderArg::Phong => Shader::Phong,
            ShaderArg::Texture => {
                let path = file(&self.texture, "texture_1.png", "--texture")?;
                Shader::Texture(course_texture(load_rgb(&path, "--texture")?))
            }
            ShaderArg::Bump | ShaderArg::Displacement => {
                let path = file(&self.height_map, "texture_2.png", "--height-map")?;
                let map = course_texture(load_rgb(&path, "--height-map")?);
                if arg == ShaderArg::Bump {
                    Shader::Bump(map)
                } else {
                    Shader::Displacement(map)
                }
            }
            ShaderArg::Mirror => {
                let dir = file(&self.cubemap, "cube", "--cubemap")?;
                Shader::Mirror(
                    prism_image::CubeMap::read(&dir)
                        .map_err(|e| UserError::Refused(format!("--cubemap: {e}")))?,
                )
            }
        };
        if !quiet {
            if self.texture.is_some() && arg != ShaderArg::Texture {
                eprintln!(
                    "prism: warning: --texture has no effect: it applies to --shader texture"
                );
            }
            if self.height_map.is_some()
                && !matches!(arg, ShaderArg::Bump | ShaderArg::Displacement)
            {
                eprintln!("prism: warning: --height-map has no effect: it applies to --shader bump and displacement");
            }
            if self.cubemap.is_some() && arg != ShaderArg::Mirror {
                eprintln!("prism: warning: --cubemap has no effect: it applies to --shader mirror");
            }
        }
        Ok(shader)
    }
}

fn three(v: &[f32], flag: &str) -> Result<Vec3> {
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        return Err(UserError::Refused(format!(
            "{flag}: expected three finite numbers separated by commas, found {v:?}"
        ))
        .into());
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn colour(v: &[f32], flag: &str) -> Result<Rgb> {
    let c = three(v, flag)?;
    if c.min_element() < 0.0 {
        return Err(UserError::Refused(format!(
            "{flag}: expected values of at least 0, found {v:?}"
        ))
        .into());
    }
    Ok(Rgb::new(c.x, c.y, c.z))
}

/// A file of the course's cloth textures (`clothsim/textures/REL` in the course's files,
/// found as [`prism_scene::course_assets`] finds them), for a shader given no file of its own.
fn staged(data: Option<&Path>, rel: &str, flag: &str) -> Result<PathBuf> {
    let assets = prism_scene::course_assets(data)
        .map_err(|e| UserError::Refused(format!("{flag} not given, and {e}")))?;
    Ok(assets.join("clothsim/textures").join(rel))
}

fn load_rgb(path: &Path, flag: &str) -> Result<prism_image::RgbImage> {
    let img =
        prism_image::read_image(path).map_err(|e| UserError::Refused(format!("{flag}: {e}")))?;
    Ok(img.to_rgb8().to_rgb_f32())
}

/// Reads the mesh by its extension.
pub fn read_shade_mesh(path: &Path) -> Result<ShadeMesh> {
    let user = |m: String| anyhow::Error::from(UserError::Refused(m));
    if crate::output::extension(path) == "obj" {
        let text = prism_math::limits::read_input_text(path, prism_mesh::MAX_MESH_FILE_BYTES)
            .map_err(|e| user(format!("{}: {e}", path.display())))?;
        ShadeMesh::from_obj(&text, &path.display().to_string()).map_err(|e| user(e.to_string()))
    } else {
        let (mesh, warnings) = prism_scene::read_mesh(path).map_err(|e| user(e.to_string()))?;
        for w in warnings {
            eprintln!("prism: warning: {w}");
        }
        Ok(ShadeMesh::from_polymesh(&mesh))
    }
}

/// Runs `prism shade`.
pub fn run(a: &ShadeArgs) -> Result<()> {
    crate::resources::pool(a.threads)?.install(|| run_in_pool(a))
}

/// Runs `prism shade` on the current worker pool.
fn run_in_pool(a: &ShadeArgs) -> Result<()> {
    let format = image_output(
        &a.output,
        "--output",
        &[ImageFormat::Png, ImageFormat::Bmp, ImageFormat::Jpeg],
    )?;
    let mut inputs = vec![("the mesh", a.mesh.as_path())];
    inputs.extend(a.files.inputs());
    crate::output::check_distinct(&inputs, &[("--output", &a.output)])?;
    crate::error::check_input(&a.mesh, None)?;
    let (w, h) = (a.resolution[0], a.resolution[1]);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(UserError::Refused(format!(
            "--resolution: expected 1 to 16384 pixels a side, found {w} x {h}"
        ))
        .into());
    }
    if !(a.fov_y > 0.0 && a.fov_y < 180.0) {
        return Err(UserError::Refused(format!(
            "--fov-y: expected a field of view strictly between 0 and 180 degrees, found {}",
            a.fov_y
        ))
        .into());
    }
    if a.samples == 0 || a.samples > 256 {
        return Err(
            UserError::Refused(format!("--spp: expected 1 to 256, found {}", a.samples)).into(),
        );
    }
    let bytes = prism_shade::frame_bytes(w, h, a.samples);
    crate::resources::check_frame("--resolution", w, h, bytes)?;
    // Sample buffers hold 32 bytes a sample: at most 2^28 samples in all, 2^20 a row.
    let (per_row, all) = (
        u64::from(w) * u64::from(a.samples),
        u64::from(w) * u64::from(h) * u64::from(a.samples),
    );
    if per_row > 1 << 20 || all > 1 << 28 {
        return Err(UserError::Refused(format!(
            "--resolution {w} {h} with --spp {}: {all} samples is over the limit of 2^28 (and 2^20 a row)",
            a.samples
        ))
        .into());
    }
    let up = three(&a.up, "--up")?;
    let light = a
        .light
        .as_deref()
        .map(|l| three(l, "--light"))
        .transpose()?;
    let intensity = a
        .light_intensity
        .as_deref()
        .map(|c| colour(c, "--light-intensity"))
        .transpose()?;
    let background = colour(&a.background, "--background")?;
    let wire = a
        .wireframe
        .as_deref()
        .map(|c| colour(c, "--wireframe"))
        .transpose()?;
    let t0 = Instant::now();
    let mesh = read_shade_mesh(&a.mesh)?;
    let shader = a.files.shader(a.shader, a.quiet)?;
    let (lo, hi) = mesh.bounds().ok_or_else(|| {
        UserError::Refused(format!(
            "{}: the mesh has no faces to draw",
            a.mesh.display()
        ))
    })?;
    let centre = (lo + hi) * 0.5;
    let target = match &a.target {
        Some(t) => three(t, "--target")?,
        None => centre,
    };
    let view = match &a.eye {
        Some(e) => View {
            eye: three(e, "--eye")?,
            target,
            up,
            fov_y: a.fov_y,
            width: w,
            height: h,
        },
        // In front of the mesh along +z, far enough that its bounding sphere fits the
        // narrower field of view.
        None => View::fit(
            target,
            (hi - lo).length() * 0.5,
            Vec3::Z,
            up,
            a.fov_y,
            w,
            h,
            Framing::NarrowerSide { margin: 1.1 },
        ),
    };
    let uniforms = Uniforms::lit_for(lo, hi, light, intensity);
    let opts = ShadeOptions {
        samples: a.samples,
        background,
        wireframe: wire,
        ..ShadeOptions::default()
    };
    let read = t0.elapsed();
    let t1 = Instant::now();
    let bytes = shade_rgb8(&mesh, &view, &shader, &uniforms, &opts).map_err(UserError::input)?;
    let render = t1.elapsed();
    let t2 = Instant::now();
    crate::output::write_rgb8(&a.output, format, &bytes).context("writing the picture")?;
    let write = t2.elapsed();
    if a.stats {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read: {:.1} ms", ms(read));
        eprintln!("render: {:.1} ms", ms(render));
        eprintln!("write: {:.1} ms", ms(write));
    }
    if !a.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "prism: shaded {} triangles at {w}x{h} with {} in {:.1} ms -> {}",
            mesh.triangles.len(),
            shader.name(),
            render.as_secs_f64() * 1e3,
            a.output.display()
        );
    }
    Ok(())
}
