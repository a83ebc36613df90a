//! `prism.load_scene`, `prism.Scene` and `prism.render`: the path tracer on a scene read
//! once and rendered as often as asked, to linear radiance `float32[H, W, 3]`.

use std::collections::HashMap;
use std::path::PathBuf;

use numpy::PyArray3;
use prism_render::film::FilmSettings;
use prism_render::integrators::{Integrator, PathSettings};
use prism_render::render::{render_until, Controls, RenderOptions};
use prism_render::render_scene::RenderScene;
use prism_scene::{CameraMode, Filter, NormalsMode, SceneOptions};
use pyo3::prelude::*;

use crate::errors::{argument, from_error, raise, Kind};

/// Samples per pixel when neither the call nor the scene says (as `prism render`).
const DEFAULT_SPP: u32 = 64;
/// Most bounces when neither the call nor the scene says.
const DEFAULT_BOUNCES: u32 = 7;
/// The bounces of a Mitsuba `max_depth = -1` path.
const UNBOUNDED_BOUNCES: u32 = 1024;
/// Picture size when neither the call nor the scene says.
const DEFAULT_SIZE: (u32, u32) = (512, 384);
/// Largest picture side.
const MAX_SIDE: u32 = 16384;
/// Most samples per pixel.
const MAX_SPP: u32 = 1 << 20;
/// Samples between adaptive-sampling checks when `batch` is not given.
const DEFAULT_BATCH: u32 = 32;

/// A scene read and prepared (its BVH built) for the path tracer; render it with
/// [`Scene::render`] or `prism.render(scene)` as often as needed.
#[pyclass(module = "prism", name = "Scene")]
pub struct Scene {
    prepared: RenderScene,
    /// The scene's camera without its crop window, for a render given its own size (which
    /// replaces a Mitsuba film's, crop and all, as on the command line).
    uncropped: prism_scene::Camera,
    size: (u32, u32),
    spp: u32,
    max_bounces: u32,
    rr_bounces: u32,
    hide_emitters: bool,
    filter: Filter,
    mitsuba: bool,
    warnings: Vec<String>,
    name: String,
}

/// The `defines` dictionary as `NAME=VALUE` pairs, in name order.
fn defines_of(defines: Option<HashMap<String, String>>) -> Vec<(String, String)> {
    let mut d: Vec<(String, String)> = defines.unwrap_or_default().into_iter().collect();
    d.sort();
    d
}

/// Reads a scene for the path tracer: a CS184 COLLADA scene (.dae), a Mitsuba 3 scene
/// (.xml, with `defines` for its `$name` parameters, `sensor` picking one of several and
/// `lenient` reading past unsupported plugins), an OBJ scene or a Delft config (.toml);
/// `None` for the built-in Cornell box. `normals` ("area", "file", "flat") and `camera`
/// ("course", "file") are `prism render`'s `--normals` and `--camera`; `envmap` lights the
/// scene with a latitude-longitude .exr or .hdr map; `lens_radius` and `focal_distance`
/// make a thin-lens camera.
#[pyfunction]
#[pyo3(signature = (path=None, *, normals="area", camera="course", defines=None, lenient=false,
    sensor=0, envmap=None, lens_radius=None, focal_distance=None))]
#[allow(clippy::too_many_arguments)]
pub fn load_scene(
    py: Python<'_>,
    path: Option<PathBuf>,
    normals: &str,
    camera: &str,
    defines: Option<HashMap<String, String>>,
    lenient: bool,
    sensor: usize,
    envmap: Option<PathBuf>,
    lens_radius: Option<f32>,
    focal_distance: Option<f32>,
) -> PyResult<Scene> {
    let opts = SceneOptions {
        normals: match normals {
            "area" => NormalsMode::Area,
            "file" => NormalsMode::File,
            "flat" => NormalsMode::Flat,
            _ => {
                return Err(argument(format!(
                    "normals: expected 'area', 'file' or 'flat', found {normals:?}"
                )))
            }
        },
        camera: match camera {
            "course" => CameraMode::Course,
            "file" => CameraMode::File,
            _ => {
                return Err(argument(format!(
                    "camera: expected 'course' or 'file', found {camera:?}"
                )))
            }
        },
    };
    let defines = defines_of(defines);
    let name = path.as_ref().map_or_else(
        || "the Cornell box".to_string(),
        |p| p.display().to_string(),
    );
    let is_xml = path
        .as_ref()
        .is_some_and(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml")));
    if let Some(r) = lens_radius {
        if !(r.is_finite() && r >= 0.0) {
            return Err(argument(format!(
                "lens_radius: expected a radius of 0 or more, found {r}"
            )));
        }
    }
    if let Some(d) = focal_distance {
        if !(d.is_finite() && d > 0.0) {
            return Err(argument(format!(
                "focal_distance: expected a positive distance, found {d}"
            )));
        }
    }
    let loaded = py.detach(|| -> Result<Scene, PyErr> {
        let located = |e: &(dyn std::error::Error + 'static)| from_error(e, Some(&name));
        let (mut scene, settings) = match &path {
            Some(p) if is_xml => {
                let options = prism_scene::MitsubaOptions { lenient, sensor };
                let m = prism_scene::read_mitsuba_with(p, &defines, options)
                    .map_err(|e| located(&e))?;
                (m.scene, Some(m.settings))
            }
            Some(p) => (prism_scene::load(p, &opts).map_err(|e| located(&e))?, None),
            None => (prism_scene::cornell_box(), None),
        };
        if let Some(radius) = lens_radius {
            let focal_distance =
                focal_distance.unwrap_or_else(|| (scene.camera.target - scene.camera.eye).length());
            scene.camera.lens = Some(prism_scene::ThinLens {
                radius,
                focal_distance,
            });
        }
        if let Some(map_path) = &envmap {
            let map_name = map_path.display().to_string();
            let map = prism_image::read_radiance(map_path)
                .map_err(|e| from_error(&e, Some(&map_name)))?;
            scene
                .light_by_environment_map(std::sync::Arc::new(map))
                .map_err(|e| raise(Kind::Input, format!("{map_name}: {e}"), Some(&map_name)))?;
        }
        let warnings = scene.warnings.iter().map(ToString::to_string).collect();
        let uncropped = prism_scene::Camera {
            crop: None,
            ..scene.camera
        };
        let prepared = RenderScene::new(&scene);
        let s = settings.as_ref();
        Ok(Scene {
            prepared,
            uncropped,
            size: s.map_or(DEFAULT_SIZE, |s| s.size),
            spp: s.map_or(DEFAULT_SPP, |s| s.spp),
            max_bounces: s.map_or(DEFAULT_BOUNCES, |s| {
                s.max_bounces.unwrap_or(UNBOUNDED_BOUNCES)
            }),
            rr_bounces: s.map_or(PathSettings::default().rr_bounces, |s| s.rr_bounces),
            hide_emitters: s.is_some_and(|s| s.hide_emitters),
            filter: s.map_or(Filter::Box, |s| s.filter),
            mitsuba: s.is_some(),
            warnings,
            name: name.clone(),
        })
    })?;
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for w in &loaded.warnings {
        PyErr::warn(py, &category, &std::ffi::CString::new(w.as_str())?, 1)?;
    }
    Ok(loaded)
}

#[pymethods]
impl Scene {
    /// Renders the scene: `spp` samples per pixel, `resolution` (width, height), at most
    /// `max_bounces` bounces (each defaults to the scene's, as a Mitsuba file gives them, else
    /// 64, 512x384 and 7), with `prism render`'s integrators ("path", "path-scalar",
    /// "direct", "normals"). Returns linear radiance, the numbers `prism render` writes to
    /// EXR for the same settings and seed, whatever the thread count.
    #[pyo3(signature = (*, spp=None, resolution=None, max_bounces=None, seed=0, integrator="path",
        light_samples=1, adaptive=None, batch=None, threads=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        spp: Option<u32>,
        resolution: Option<(u32, u32)>,
        max_bounces: Option<u32>,
        seed: u64,
        integrator: &str,
        light_samples: u32,
        adaptive: Option<f32>,
        batch: Option<u32>,
        threads: Option<usize>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let integrator = match integrator {
            "path" => Integrator::Path,
            "path-scalar" => Integrator::PathScalar,
            "direct" => Integrator::Direct { hemisphere: false },
            "normals" => Integrator::Normals,
            _ => {
                return Err(argument(format!(
                    "integrator: expected 'path', 'path-scalar', 'direct' or 'normals', found {integrator:?}"
                )))
            }
        };
        let (w, h) = resolution.unwrap_or(self.size);
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(argument(format!(
                "resolution: expected 1 to {MAX_SIDE} pixels a side, found {w} x {h}"
            )));
        }
        prism_math::limits::check_memory(prism_render::film::film_bytes(w, h)).map_err(|e| {
            raise(
                Kind::Limit,
                format!("resolution {w} x {h}: the image {e}"),
                None,
            )
        })?;
        let spp = spp.unwrap_or(self.spp);
        if spp == 0 || spp > MAX_SPP {
            return Err(argument(format!(
                "spp: expected 1 to {MAX_SPP}, found {spp}"
            )));
        }
        if light_samples == 0 || light_samples > 1 << 16 {
            return Err(argument(format!(
                "light_samples: expected 1 to 65536, found {light_samples}"
            )));
        }
        if let Some(t) = adaptive {
            if !(t > 0.0 && t.is_finite()) {
                return Err(argument(format!(
                    "adaptive: expected a positive tolerance, found {t}"
                )));
            }
        }
        let options = RenderOptions {
            film: FilmSettings {
                width: w,
                height: h,
                spp,
                adaptive,
                batch: batch.unwrap_or(DEFAULT_BATCH).max(1),
                seed,
                filter: self.filter,
            },
            path: PathSettings {
                rr_bounces: self.rr_bounces,
                hide_emitters: self.hide_emitters,
                // Mitsuba's estimator under a box filter, as `prism render` picks it.
                one_light: self.mitsuba && self.filter == Filter::Box,
                light_samples,
                max_bounces: max_bounces.unwrap_or(self.max_bounces),
                integrator,
                only_bounce: None,
            },
        };
        // A size given here replaces a Mitsuba film's, crop and all.
        let camera = resolution.map(|_| &self.uncropped);
        let prepared = &self.prepared;
        let total = u64::from(w) * u64::from(h) * u64::from(spp);
        let out = crate::work::run(py, threads, progress, total, |control| {
            let controls = Controls {
                stop: Some(control.flag()),
                camera,
            };
            render_until(prepared, &options, controls, &|done| {
                control.set_done(done);
            })
        })?;
        Ok(crate::arrays::rgb_f32(py, out.image))
    }

    /// The picture size the scene asks for, (width, height).
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        self.size
    }

    /// Samples per pixel the scene asks for.
    #[getter]
    fn spp(&self) -> u32 {
        self.spp
    }

    /// Most bounces the scene asks for.
    #[getter]
    fn max_bounces(&self) -> u32 {
        self.max_bounces
    }

    /// What the reader read past, one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn __repr__(&self) -> String {
        format!("<prism.Scene {}>", self.name)
    }
}

/// Path-traces a scene (a path, or a [`Scene`] from `load_scene`) to linear radiance
/// `float32[H, W, 3]`: `prism.load_scene(path).render(...)` in one call.
#[pyfunction]
#[pyo3(signature = (scene, *, spp=None, resolution=None, max_bounces=None, seed=0,
    integrator="path", light_samples=1, adaptive=None, batch=None, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: Option<u32>,
    resolution: Option<(u32, u32)>,
    max_bounces: Option<u32>,
    seed: u64,
    integrator: &str,
    light_samples: u32,
    adaptive: Option<f32>,
    batch: Option<u32>,
    threads: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let owned;
    let target: &Bound<'py, Scene> = match scene.cast::<Scene>() {
        Ok(s) => s,
        Err(_) => {
            let path: PathBuf = scene
                .extract()
                .map_err(|_| argument("scene: expected a path or a prism.Scene"))?;
            let loaded = load_scene(
                py,
                Some(path),
                "area",
                "course",
                None,
                false,
                0,
                None,
                None,
                None,
            )?;
            owned = Bound::new(py, loaded)?;
            &owned
        }
    };
    let scene = target.try_borrow()?;
    scene.render(
        py,
        spp,
        resolution,
        max_bounces,
        seed,
        integrator,
        light_samples,
        adaptive,
        batch,
        threads,
        progress,
    )
}
