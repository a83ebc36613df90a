//! `prism.shade`: a mesh drawn by the software pipeline with one of the course's shaders,
//! as `prism shade` draws it, to `uint8[H, W, 3]`.

use std::path::{Path, PathBuf};

use numpy::PyArray3;
use prism_math::{Rgb, Vec3};
use prism_shade::{course_texture, Framing, ShadeMesh, ShadeOptions, Shader, Uniforms, View};
use pyo3::prelude::*;

use crate::arrays::{picture, Picture};
use crate::errors::{argument, from_error, from_io, raise, Kind};
use crate::mesh::Mesh;

/// Largest picture side.
const MAX_SIDE: u32 = 16384;

/// Reads a mesh for shading: OBJ with its uvs and normals, else any mesh format.
fn read_shade_mesh(py: Python<'_>, path: &Path) -> PyResult<ShadeMesh> {
    let name = path.display().to_string();
    let is_obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if is_obj {
        let text = py
            .detach(|| prism_math::limits::read_input_text(path, prism_mesh::MAX_MESH_FILE_BYTES))
            .map_err(|e| from_io(&e, &name))?;
        return py
            .detach(|| ShadeMesh::from_obj(&text, &name))
            .map_err(|e| from_error(&e, Some(&name)));
    }
    let (mesh, warnings) = py
        .detach(|| prism_scene::read_mesh(path))
        .map_err(|e| from_error(&e, Some(&name)))?;
    crate::mesh::warn_all(py, &warnings)?;
    Ok(ShadeMesh::from_polymesh(&mesh))
}

/// An image a shader reads: a file path or an array (`uint8[H, W, 3 or 4]`), else the
/// course's file `rel` under `clothsim/textures` in the course's data.
fn shader_image(
    py: Python<'_>,
    given: Option<&Bound<'_, PyAny>>,
    rel: &str,
    what: &str,
    data: Option<&Path>,
) -> PyResult<prism_image::RgbImage> {
    let path = match given {
        Some(g) => match g.extract::<PathBuf>() {
            Ok(p) => p,
            Err(_) => {
                return match picture(g)? {
                    Picture::Rgb8(i) => Ok(i.to_rgb_f32()),
                    Picture::Rgba8(i) => Ok(i.to_rgb8().to_rgb_f32()),
                    Picture::Linear(_) => Err(argument(format!(
                        "{what}: expected an 8-bit image (uint8[H, W, 3 or 4]) or a file"
                    ))),
                }
            }
        },
        None => course_file(data, rel, what)?,
    };
    let name = path.display().to_string();
    let img = py
        .detach(|| prism_image::read_image(&path))
        .map_err(|e| from_error(&e, Some(&name)))?;
    Ok(img.to_rgb8().to_rgb_f32())
}

/// The course's cloth texture `rel` (`clothsim/textures/REL`).
fn course_file(data: Option<&Path>, rel: &str, what: &str) -> PyResult<PathBuf> {
    let assets = prism_scene::course_assets(data)
        .map_err(|e| raise(Kind::File, format!("{what} not given, and {e}"), None))?;
    Ok(assets.join("clothsim/textures").join(rel))
}

/// Three finite numbers.
fn three(v: Option<(f32, f32, f32)>, what: &str) -> PyResult<Option<Vec3>> {
    match v {
        Some((x, y, z)) if x.is_finite() && y.is_finite() && z.is_finite() => {
            Ok(Some(Vec3::new(x, y, z)))
        }
        Some(t) => Err(argument(format!(
            "{what}: expected three finite numbers, found {t:?}"
        ))),
        None => Ok(None),
    }
}

/// A colour of three numbers of at least 0.
fn colour(v: Option<(f32, f32, f32)>, what: &str) -> PyResult<Option<Rgb>> {
    match three(v, what)? {
        Some(c) if c.min_element() < 0.0 => Err(argument(format!(
            "{what}: expected values of at least 0, found {v:?}"
        ))),
        c => Ok(c.map(|c| Rgb::new(c.x, c.y, c.z))),
    }
}

/// Draws a mesh (a path, or a `prism.Mesh`) with one of the course's shaders: "normal",
/// "wireframe", "diffuse", "phong", "texture", "bump", "displacement" or "mirror". Without
/// `eye` the camera stands in front of the mesh along +z, framing its bounds; without
/// `target` it looks at their centre; without `light` the light stands where the course's
/// stands for its meshes. `texture` and `height_map` are image files or arrays; `cubemap` a
/// folder of posx, negx, posy, negy, posz, negz images; each defaults to the course's file
/// (found under `data`, else `PRISM_DATA`, else a `shared/assets` folder above the working
/// folder). Returns the bytes `prism shade` writes: round(255 clamp(c)), no gamma.
#[pyfunction]
#[pyo3(signature = (mesh_or_path, *, shader="phong", eye=None, target=None, up=(0.0, 1.0, 0.0),
    fov_y=45.0, resolution=(800, 600), samples=1, light=None, light_intensity=None,
    background=(0.0, 0.0, 0.0), wireframe=None, texture=None, height_map=None, cubemap=None,
    data=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn shade<'py>(
    py: Python<'py>,
    mesh_or_path: &Bound<'py, PyAny>,
    shader: &str,
    eye: Option<(f32, f32, f32)>,
    target: Option<(f32, f32, f32)>,
    up: (f32, f32, f32),
    fov_y: f32,
    resolution: (u32, u32),
    samples: u32,
    light: Option<(f32, f32, f32)>,
    light_intensity: Option<(f32, f32, f32)>,
    background: (f32, f32, f32),
    wireframe: Option<(f32, f32, f32)>,
    texture: Option<&Bound<'py, PyAny>>,
    height_map: Option<&Bound<'py, PyAny>>,
    cubemap: Option<PathBuf>,
    data: Option<PathBuf>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let (w, h) = resolution;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(argument(format!(
            "resolution: expected 1 to {MAX_SIDE} pixels a side, found {w} x {h}"
        )));
    }
    if !(fov_y > 0.0 && fov_y < 180.0) {
        return Err(argument(format!(
            "fov_y: expected a field of view strictly between 0 and 180 degrees, found {fov_y}"
        )));
    }
    if !(1..=16u32).any(|k| k * k == samples) {
        return Err(argument(format!(
            "samples: expected a square number from 1 to 256, found {samples}"
        )));
    }
    prism_math::limits::check_memory(prism_shade::frame_bytes(w, h, samples)).map_err(|e| {
        raise(
            Kind::Limit,
            format!("resolution {w} x {h}: the image {e}"),
            None,
        )
    })?;
    let (per_row, all) = (
        u64::from(w) * u64::from(samples),
        u64::from(w) * u64::from(h) * u64::from(samples),
    );
    if per_row > 1 << 20 || all > 1 << 28 {
        return Err(raise(
            Kind::Limit,
            format!(
                "resolution {w} x {h} with {samples} samples: {all} samples is over the limit of 2^28 (and 2^20 a row)"
            ),
            None,
        ));
    }
    let up = three(Some(up), "up")?.expect("given");
    let light = three(light, "light")?;
    let intensity = colour(light_intensity, "light_intensity")?;
    let background = colour(Some(background), "background")?.expect("given");
    let wire = colour(wireframe, "wireframe")?;
    let (mesh, name) = match mesh_or_path.cast::<Mesh>() {
        Ok(m) => (
            ShadeMesh::from_polymesh(&m.borrow().current()),
            "the mesh".to_string(),
        ),
        Err(_) => {
            let path: PathBuf = mesh_or_path
                .extract()
                .map_err(|_| argument("mesh_or_path: expected a path or a prism.Mesh"))?;
            (read_shade_mesh(py, &path)?, path.display().to_string())
        }
    };
    let data = data.as_deref();
    let shader = match shader {
        "normal" => Shader::Normal,
        "wireframe" => Shader::Wireframe,
        "diffuse" => Shader::Diffuse,
        "phong" => Shader::Phong,
        "texture" => Shader::Texture(course_texture(shader_image(
            py,
            texture,
            "texture_1.png",
            "texture",
            data,
        )?)),
        "bump" | "displacement" => {
            let map = course_texture(shader_image(
                py,
                height_map,
                "texture_2.png",
                "height_map",
                data,
            )?);
            if shader == "bump" {
                Shader::Bump(map)
            } else {
                Shader::Displacement(map)
            }
        }
        "mirror" => {
            let dir = match cubemap {
                Some(d) => d,
                None => course_file(data, "cube", "cubemap")?,
            };
            let dir_name = dir.display().to_string();
            Shader::Mirror(
                prism_image::CubeMap::read(&dir).map_err(|e| from_error(&e, Some(&dir_name)))?,
            )
        }
        _ => {
            return Err(argument(format!(
                "shader: expected 'normal', 'wireframe', 'diffuse', 'phong', 'texture', 'bump', \
                 'displacement' or 'mirror', found {shader:?}"
            )))
        }
    };
    let (lo, hi) = mesh.bounds().ok_or_else(|| {
        raise(
            Kind::Input,
            format!("{name}: the mesh has no faces to draw"),
            None,
        )
    })?;
    let target = three(target, "target")?.unwrap_or((lo + hi) * 0.5);
    let view = match three(eye, "eye")? {
        Some(eye) => View {
            eye,
            target,
            up,
            fov_y,
            width: w,
            height: h,
        },
        None => View::fit(
            target,
            (hi - lo).length() * 0.5,
            Vec3::Z,
            up,
            fov_y,
            w,
            h,
            Framing::NarrowerSide { margin: 1.1 },
        ),
    };
    let uniforms = Uniforms::lit_for(lo, hi, light, intensity);
    let opts = ShadeOptions {
        samples,
        background,
        wireframe: wire,
        ..ShadeOptions::default()
    };
    let image = crate::work::run(py, threads, None, 1, |_| {
        prism_shade::shade_rgb8(&mesh, &view, &shader, &uniforms, &opts)
    })?
    .map_err(|e| from_error(&e, Some(&name)))?;
    Ok(crate::arrays::rgb8(py, image))
}
