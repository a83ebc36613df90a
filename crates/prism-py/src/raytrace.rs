//! `prism.raytrace` and `prism.trace_pixel`: the Delft Whitted ray tracer on a preset, an
//! OBJ scene or a TOML config, to linear `float32[H, W, 3]`, and the ray tree of one pixel.

use std::path::PathBuf;

use numpy::PyArray3;
use prism_image::Bloom;
use prism_render::whitted::film::{raytrace_until, trace_pixel as trace_one, RaytraceOptions};
use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
use prism_render::whitted::tracer::WhittedSettings;
use prism_scene::{Features, OrbitCamera};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{argument, from_error, raise, Kind};

/// Largest picture side.
const MAX_SIDE: u32 = 16384;
/// Rays per pixel with multi-rays on and no `spp`.
const DEFAULT_SPP: u32 = 16;
/// Picture side when neither the call nor the config says.
const DEFAULT_SIDE: u32 = 800;

/// What both calls take, as `prism raytrace`'s flags.
struct Request {
    scene: String,
    resolution: Option<(u32, u32)>,
    features: Option<Py<PyAny>>,
    camera: usize,
    spp: Option<u32>,
    light_samples: u32,
    max_depth: u32,
    seed: u64,
    bloom: Bloom,
    data: Option<PathBuf>,
}

/// A scene prepared for one camera, with the options to trace it.
struct Prepared {
    scene: WhittedScene,
    camera: OrbitCamera,
    opts: RaytraceOptions,
}

/// Sets the features `given` names: a dict of name to bool, or names to turn on.
fn set_features(py: Python<'_>, f: &mut Features, given: Option<&Py<PyAny>>) -> PyResult<()> {
    let Some(given) = given else { return Ok(()) };
    let given = given.bind(py);
    let mut set = |name: &str, on: bool| -> PyResult<()> {
        let slot = f.switch(name.trim()).ok_or_else(|| {
            argument(format!(
                "features: {name:?} is not a feature; expected one of {}",
                Features::NAMES.join(", ")
            ))
        })?;
        *slot = on;
        Ok(())
    };
    if let Ok(d) = given.cast::<PyDict>() {
        for (k, v) in d.iter() {
            set(&k.extract::<String>()?, v.is_truthy()?)?;
        }
        return Ok(());
    }
    let names: Vec<String> = given.extract().map_err(|_| {
        argument("features: expected a dict of name to bool, or a list of names to turn on")
    })?;
    for n in names {
        set(&n, true)?;
    }
    Ok(())
}

impl Request {
    /// Reads the scene and prepares it as `prism raytrace` does.
    fn prepare(&self, py: Python<'_>) -> PyResult<Prepared> {
        if self.spp.is_some_and(|s| s == 0 || s > 1 << 16) {
            return Err(argument(format!("spp: expected 1 to {}", 1 << 16)));
        }
        if self.light_samples == 0 || self.light_samples > 1 << 16 {
            return Err(argument(format!(
                "light_samples: expected 1 to {}, found {}",
                1 << 16,
                self.light_samples
            )));
        }
        if self.max_depth > 64 {
            return Err(argument(format!(
                "max_depth: expected 0 to 64, found {}",
                self.max_depth
            )));
        }
        if !(self.bloom.threshold.is_finite() && self.bloom.threshold >= 0.0)
            || self.bloom.passes > 64
        {
            return Err(argument(
                "bloom_threshold, bloom_passes: expected a threshold of at least 0 and 0 to 64 passes",
            ));
        }
        let mut warnings = Vec::new();
        let name = self.scene.clone();
        let loaded = py
            .detach(|| {
                prism_scene::load_delft(&self.scene, self.data.as_deref(), &mut |w| {
                    warnings.push(w.to_string());
                })
            })
            .map_err(|e| from_error(&e, Some(&name)))?;
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        for w in &warnings {
            PyErr::warn(py, &category, &std::ffi::CString::new(w.as_str())?, 1)?;
        }
        let mut features = loaded.features;
        set_features(py, &mut features, self.features.as_ref())?;
        if self.spp.is_some_and(|s| s > 1) {
            features.multiple_rays_per_pixel = true;
        }
        let (w, h) = match (self.resolution, loaded.window) {
            (Some(r), _) => r,
            (None, Some([w, h])) => (w, h),
            (None, None) => (DEFAULT_SIDE, DEFAULT_SIDE),
        };
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(argument(format!(
                "resolution: expected 1 to {MAX_SIDE} pixels a side, found {w} x {h}"
            )));
        }
        prism_math::limits::check_memory(prism_render::whitted::film::raytrace_bytes(w, h))
            .map_err(|e| {
                raise(
                    Kind::Limit,
                    format!("resolution {w} x {h}: the image {e}"),
                    None,
                )
            })?;
        let camera = *loaded.cameras.get(self.camera).ok_or_else(|| {
            argument(format!(
                "camera: {name} has cameras 0 to {}, found {}",
                loaded.cameras.len().saturating_sub(1),
                self.camera
            ))
        })?;
        if features.environment_mapping && loaded.environment.is_none() {
            return Err(argument(
                "env-map is on, but no environment map is given: set [extras] environment_map in the config",
            ));
        }
        let split = if features.sah_binning {
            Split::Sah
        } else {
            Split::Median
        };
        let extras = loaded.extras;
        let scene = py.detach(|| {
            WhittedScene::prepare(
                &loaded.scene,
                SceneSetup {
                    bvh: features.accel_structure.then_some(split),
                    motion: if features.motion_blur {
                        loaded.motion.clone()
                    } else {
                        Vec::new()
                    },
                    environment: loaded
                        .environment
                        .as_ref()
                        .filter(|_| features.environment_mapping)
                        .map(|im| Environment::new((**im).clone(), extras.environment_strength)),
                },
            )
        });
        let opts = RaytraceOptions {
            width: w,
            height: h,
            settings: WhittedSettings {
                features,
                light_samples: self.light_samples,
                max_depth: self.max_depth,
                extras,
            },
            spp: self.spp.unwrap_or(DEFAULT_SPP),
            bloom: self.bloom,
            seed: self.seed,
        };
        Ok(Prepared {
            scene,
            camera,
            opts,
        })
    }
}

/// Whitted-ray-traces a Delft scene: a preset ("cornell-box", "teapot", ...), an OBJ scene
/// or a TOML render config, seen from config camera `camera`. `features` turns features on
/// or off (a dict of name to bool, or a list of names to turn on; without a config the
/// first eight and sah start on). Returns linear radiance with bloom, the numbers
/// `prism raytrace` writes to EXR for the same settings.
#[pyfunction]
#[pyo3(signature = (config_or_preset=PathBuf::from("cornell-box"), *, resolution=None, features=None, camera=0,
    spp=None, light_samples=16, max_depth=3, seed=0, bloom_threshold=0.0, bloom_passes=1,
    data=None, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn raytrace<'py>(
    py: Python<'py>,
    config_or_preset: PathBuf,
    resolution: Option<(u32, u32)>,
    features: Option<Py<PyAny>>,
    camera: usize,
    spp: Option<u32>,
    light_samples: u32,
    max_depth: u32,
    seed: u64,
    bloom_threshold: f32,
    bloom_passes: u32,
    data: Option<PathBuf>,
    threads: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let request = Request {
        scene: config_or_preset.to_string_lossy().into_owned(),
        resolution,
        features,
        camera,
        spp,
        light_samples,
        max_depth,
        seed,
        bloom: Bloom {
            threshold: bloom_threshold,
            passes: bloom_passes,
        },
        data,
    };
    let p = request.prepare(py)?;
    let rows = u64::from(p.opts.height);
    let out = crate::work::run(py, threads, progress, rows, |control| {
        raytrace_until(
            &p.scene,
            &p.camera,
            &p.opts,
            Some(control.flag()),
            &|done| {
                control.set_done(done);
            },
        )
    })?;
    Ok(crate::arrays::rgb_f32(py, out.image))
}

/// The ray tree of pixel (x, y) (x from the left, y from the top), as `prism raytrace
/// --debug-pixel X,Y` writes it to OUT.rays.json, as a dict. Takes `raytrace`'s options.
#[pyfunction]
#[pyo3(signature = (config_or_preset, x, y, *, resolution=None, features=None, camera=0,
    spp=None, light_samples=16, max_depth=3, seed=0, data=None))]
#[allow(clippy::too_many_arguments)]
pub fn trace_pixel<'py>(
    py: Python<'py>,
    config_or_preset: PathBuf,
    x: u32,
    y: u32,
    resolution: Option<(u32, u32)>,
    features: Option<Py<PyAny>>,
    camera: usize,
    spp: Option<u32>,
    light_samples: u32,
    max_depth: u32,
    seed: u64,
    data: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let request = Request {
        scene: config_or_preset.to_string_lossy().into_owned(),
        resolution,
        features,
        camera,
        spp,
        light_samples,
        max_depth,
        seed,
        bloom: Bloom {
            threshold: 0.0,
            passes: 1,
        },
        data,
    };
    let p = request.prepare(py)?;
    let (w, h) = (p.opts.width, p.opts.height);
    if x >= w || y >= h {
        return Err(argument(format!(
            "pixel {x},{y}: outside the {w} x {h} image"
        )));
    }
    let json = py.detach(|| trace_one(&p.scene, &p.camera, &p.opts, x, y).to_json());
    py.import("json")?.call_method1("loads", (json,))
}
