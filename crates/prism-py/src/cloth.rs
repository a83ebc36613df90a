//! `prism.Cloth`: the course's mass-spring cloth, stepped exactly as its algorithm, with
//! the masses' positions a NumPy view of the simulation's own buffer.

use std::path::PathBuf;

use numpy::ndarray::ArrayView2;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::rows;
use crate::errors::{argument, from_error, raise, Kind};

/// Most steps one call may take.
const MAX_STEPS: u64 = 1 << 40;

/// A cloth scene (the course's JSON) being simulated: 90 frames a simulated second, 30
/// time steps a frame, the same bytes as `prism cloth` on any number of threads.
#[pyclass(module = "prism", name = "Cloth")]
pub struct Cloth {
    cloth: prism_cloth::Cloth,
    /// Time steps taken.
    steps: u64,
    name: String,
}

impl Cloth {
    /// Takes `n` steps on the calling thread's behalf (GIL released), stopping early on
    /// Ctrl-C; checks the positions stay finite.
    fn advance(
        &mut self,
        py: Python<'_>,
        n: u64,
        threads: Option<usize>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        if n > MAX_STEPS {
            return Err(argument(format!(
                "expected at most {MAX_STEPS} steps, found {n}"
            )));
        }
        let cloth = &mut self.cloth;
        // Steps taken before an interruption still count.
        let taken = std::sync::atomic::AtomicU64::new(0);
        let work = |control: &crate::work::Control| {
            let mut k = 0;
            while k < n && !control.stopped() {
                cloth.step();
                k += 1;
                taken.store(k, std::sync::atomic::Ordering::Relaxed);
                if k % prism_cloth::STEPS_PER_FRAME as u64 == 0 || k == n {
                    control.set_done(k);
                }
            }
        };
        // A frame or less runs on this thread: a step in a Python loop costs a step.
        let result = if n <= prism_cloth::STEPS_PER_FRAME as u64 && progress.is_none() {
            crate::work::run_short(py, threads, work)
        } else {
            crate::work::run(py, threads, progress, n, work)
        };
        self.steps += taken.into_inner();
        result?;
        if !self.cloth.is_finite() {
            return Err(raise(
                Kind::Input,
                format!(
                    "{}: the simulation diverged by step {} (positions left the finite \
                     numbers): ks is too stiff for the masses at this time step",
                    self.name, self.steps
                ),
                Some(&self.name),
            ));
        }
        Ok(())
    }
}

#[pymethods]
impl Cloth {
    /// Reads the course's scene JSON (cloth, and optionally sphere and plane); `overrides`
    /// sets scene values as `prism cloth --set` does: `{"ks": 500, "cloth.density": 15,
    /// "sphere.radius": 0.3}`.
    #[new]
    #[pyo3(signature = (scene_json_path, overrides=None))]
    fn py_new(
        py: Python<'_>,
        scene_json_path: PathBuf,
        overrides: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Cloth> {
        let mut sets = Vec::new();
        if let Some(d) = overrides {
            let json = py.import("json")?;
            for (k, v) in d.iter() {
                let key: String = k
                    .extract()
                    .map_err(|_| argument("overrides: expected string keys"))?;
                let value: String = json.call_method1("dumps", (v,))?.extract()?;
                sets.push(format!("{key}={value}"));
            }
        }
        let name = scene_json_path.display().to_string();
        let cloth = py.detach(|| {
            prism_cloth::read_scene(&scene_json_path, &sets).map(|s| prism_cloth::Cloth::new(&s))
        });
        let cloth = cloth.map_err(|e| from_error(&e, Some(&name)))?;
        Ok(Cloth {
            cloth,
            steps: 0,
            name,
        })
    }

    /// Takes `n` time steps (1/2700 s each).
    #[pyo3(signature = (n=1, *, threads=None, progress=None))]
    fn step(
        &mut self,
        py: Python<'_>,
        n: u64,
        threads: Option<usize>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        self.advance(py, n, threads, progress)
    }

    /// Takes `n` frames (30 time steps each), as `prism cloth --frames n`.
    #[pyo3(signature = (n=1, *, threads=None, progress=None))]
    fn frame(
        &mut self,
        py: Python<'_>,
        n: u64,
        threads: Option<usize>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let steps = n.saturating_mul(prism_cloth::STEPS_PER_FRAME as u64);
        self.advance(py, steps, threads, progress)
    }

    /// The masses' positions, `float64[N, 3]` in row-major grid order (index `y*nw + x`):
    /// a view of the simulation's own buffer (no copy), so it follows every step.
    #[getter]
    fn positions<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArray2<f64>> {
        let this = slf.borrow();
        let p = &this.cloth.positions;
        // SAFETY: `DVec3` is `repr(C)` of three `f64`, so `len` of them are `3 * len` floats.
        let floats = unsafe { std::slice::from_raw_parts(p.as_ptr().cast::<f64>(), p.len() * 3) };
        let view = ArrayView2::from_shape((p.len(), 3), floats).expect("3 floats a mass");
        drop(this);
        // SAFETY: the buffer is allocated once, when the cloth is made, and never moved or
        // freed while the cloth lives; the array keeps the cloth alive through its base.
        unsafe { PyArray2::borrow_from_array(&view, slf.into_any()) }
    }

    /// The cloth's triangles, `int64[T, 3]`, two a grid square, as `prism cloth --obj`
    /// writes them (numbered from 0).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let m = prism_cloth::cloth_mesh(&self.cloth);
        rows(py, m.triangles.iter().map(|t| t.map(i64::from)).collect())
    }

    /// Time steps taken so far.
    #[getter]
    fn steps(&self) -> u64 {
        self.steps
    }

    /// Grid size: (masses across, masses down).
    #[getter]
    fn grid(&self) -> (usize, usize) {
        let c = &self.cloth.scene.cloth;
        (c.num_width_points, c.num_height_points)
    }

    /// Kinetic energy, from the last two steps' positions.
    fn kinetic_energy(&self) -> f64 {
        self.cloth.kinetic_energy()
    }

    /// Potential energy: the springs' and gravity's.
    fn potential_energy(&self) -> f64 {
        self.cloth.potential_energy()
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.grid();
        format!("<prism.Cloth {} {w}x{h}, {} steps>", self.name, self.steps)
    }
}
