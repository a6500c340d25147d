//! hox from Python (issue #60): the `hox._hox` extension module over hox-sim and hox-scenes (not
//! over the command line). Scenes from the registry, a scene file or a Gmsh file, with any
//! parameter of the parameter table set by its key (`Scene.with_params(poisson=0.45)`; a bad
//! value raises `ValueError` naming the key and its range, as `hox --compare` refuses it);
//! `Simulation`: frames stepped with the interpreter released, settling (Ctrl-C stops it),
//! positions, velocities and displacements as numpy arrays, probes, the static solution.
//! The Python package `hox` (python/hox/) re-exports this module and adds what is plain Python.

use hox_scenes::instance::Instance;
use hox_scenes::{Scene, SceneOverrides};
use numpy::{PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A JSON value as the Python object `json.loads` makes of it.
fn from_json<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (value.to_string(),))
}

/// `n × 3` coordinates as a new `(n, 3)` float64 array.
fn points_array<'py>(py: Python<'py>, points: &[hox_sim::Vec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    numpy::PyArray1::from_vec(py, flat).reshape([points.len(), 3])
}

/// A parameter's value from Python as the text the parameter table parses (`--compare KEY=TEXT`).
fn value_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(b) = value.extract::<bool>() {
        return Ok(if b { "true" } else { "false" }.into());
    }
    if let Ok(seq) = value.extract::<Vec<i64>>() {
        return Ok(seq.iter().map(|v| v.to_string()).collect::<Vec<_>>().join("x"));
    }
    Ok(value.str()?.to_string())
}

/// A scene: its mesh, material, effects, solver settings and probes.
#[pyclass(name = "Scene", module = "hox", frozen)]
struct PyScene {
    inner: Mutex<Scene>,
}

impl PyScene {
    fn wrap(scene: Scene) -> PyScene {
        PyScene { inner: Mutex::new(scene) }
    }

    fn scene(&self) -> Scene {
        self.inner.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

#[pymethods]
impl PyScene {
    /// A built-in scene by name (`hox.scenes()` lists them).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<PyScene> {
        hox_scenes::by_name(name).map(PyScene::wrap).map_err(value_error)
    }

    /// A scene from the text of a scene file (TOML, docs/SCENES.md).
    #[staticmethod]
    #[pyo3(signature = (text, source = "python"))]
    fn from_toml(text: &str, source: &str) -> PyResult<PyScene> {
        Scene::from_toml(text, source).map(PyScene::wrap).map_err(value_error)
    }

    /// A scene file read from `path` (a mesh file it names is relative to its folder).
    #[staticmethod]
    fn load(path: std::path::PathBuf) -> PyResult<PyScene> {
        Scene::load(&path).map(PyScene::wrap).map_err(value_error)
    }

    /// A scene around a Gmsh mesh file: its physical groups `clamp` held, under gravity.
    #[staticmethod]
    #[pyo3(signature = (path, clamp = vec!["clamp".to_string()], gravity = true))]
    fn from_mesh_file(path: std::path::PathBuf, clamp: Vec<String>, gravity: bool) -> PyResult<PyScene> {
        Scene::from_mesh_file(&path, &clamp, &[], gravity).map(PyScene::wrap).map_err(value_error)
    }

    /// This scene with parameters set by their keys (`hox.parameters()`): `element="p2"`,
    /// `poisson=0.45`, `grid=(16, 4, 4)`, … A bad key or value raises ValueError naming it.
    #[pyo3(signature = (**params))]
    fn with_params(&self, params: Option<&Bound<'_, PyDict>>) -> PyResult<PyScene> {
        let mut overrides = SceneOverrides::default();
        for (key, value) in params.into_iter().flatten() {
            let key: String = key.extract()?;
            overrides.set_text(&key, &value_text(&value)?).map_err(value_error)?;
        }
        self.scene().with_overrides(&overrides).map(PyScene::wrap).map_err(value_error)
    }

    #[getter]
    fn name(&self) -> String {
        self.scene().name().to_string()
    }

    #[getter]
    fn description(&self) -> String {
        self.scene().file.description.clone()
    }

    /// Every parameter's value, by its scene-file path (`material.poisson_ratio`).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let scene = self.scene();
        from_json(py, &scene.params().to_json(scene.mesh_kind()))
    }

    /// The scene file's text (TOML).
    fn to_toml(&self) -> String {
        self.scene().file.to_toml()
    }

    fn __repr__(&self) -> String {
        let scene = self.scene();
        format!("hox.Scene({:?}: {})", scene.name(), scene.params().box_label())
    }
}

/// A scene built and running: step it, settle it, read its state as numpy arrays.
#[pyclass(name = "Simulation", module = "hox", frozen)]
struct PySimulation {
    inner: Mutex<Running>,
}

struct Running {
    instance: Instance,
    /// Wall-clock time of each frame stepped, milliseconds.
    frame_ms: Vec<f64>,
}

impl PySimulation {
    fn running(&self) -> std::sync::MutexGuard<'_, Running> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Frames stepped between two checks for Ctrl-C while settling.
const FRAMES_PER_SIGNAL_CHECK: usize = 15;

#[pymethods]
impl PySimulation {
    #[new]
    fn new(scene: &PyScene) -> PyResult<PySimulation> {
        let instance = Instance::new(scene.scene()).map_err(value_error)?;
        Ok(PySimulation { inner: Mutex::new(Running { instance, frame_ms: Vec::new() }) })
    }

    /// Steps `frames` frames (each `1 / frames_per_second` simulated seconds), the interpreter
    /// released meanwhile; Ctrl-C stops between two frames.
    #[pyo3(signature = (frames = 1))]
    fn step(&self, py: Python<'_>, frames: usize) -> PyResult<()> {
        for _ in 0..frames {
            py.detach(|| {
                let mut r = self.running();
                let clock = std::time::Instant::now();
                let stepped = r.instance.sim.step_frame();
                r.frame_ms.push(clock.elapsed().as_secs_f64() * 1e3);
                stepped
            })
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            if frames > 1 {
                py.check_signals()?;
            }
        }
        Ok(())
    }

    /// Runs until the body settles in equilibrium (or `cap_secs` simulated seconds) and returns
    /// the run's report (`hox simulate --settle --json`'s fields); Ctrl-C stops it.
    #[pyo3(signature = (cap_secs = None))]
    fn settle<'py>(&self, py: Python<'py>, cap_secs: Option<f64>) -> PyResult<Bound<'py, PyAny>> {
        let mode = match cap_secs {
            Some(c) if !(c.is_finite() && c > 0.0) => {
                return Err(value_error(format!("cap_secs must be a positive number of seconds, got {c}")));
            }
            Some(cap_secs) => hox_scenes::RunMode::Settle { cap_secs },
            None => hox_scenes::RunMode::SETTLE,
        };
        let mut interrupted: Option<PyErr> = None;
        let report = py.detach(|| {
            let mut r = self.running();
            let mut frames = 0usize;
            hox_scenes::run::run_observed(&mut r.instance, mode, &mut |_, _| {}, &mut |instance| {
                frames += 1;
                if frames.is_multiple_of(FRAMES_PER_SIGNAL_CHECK)
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    interrupted = Some(e);
                    return Err(hox_scenes::SceneError::Simulation {
                        source_name: instance.scene.source.clone(),
                        message: "interrupted".into(),
                    });
                }
                Ok(())
            })
        });
        if let Some(e) = interrupted {
            return Err(e);
        }
        let report = report.map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        from_json(py, &serde_json::to_value(&report).map_err(value_error)?)
    }

    /// The static equilibrium of the same mesh and material (Newton's method, load stepping):
    /// its node positions, `(n, 3)`.
    #[pyo3(signature = (tolerance = 1e-9, load_steps = 10))]
    fn static_solve<'py>(
        &self,
        py: Python<'py>,
        tolerance: f64,
        load_steps: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let solved = py.detach(|| {
            let r = self.running();
            let (scene, mesh) = (&r.instance.scene, r.instance.sim.mesh());
            hox_scenes::solve_static(scene, mesh, tolerance, load_steps, &mut |_, _, _| {})
        });
        let solved = solved.map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        points_array(py, &solved.positions)
    }

    /// The nodes' current positions, metres, `(n, 3)`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_array(py, &self.running().instance.sim.positions)
    }

    /// The nodes' velocities, m/s, `(n, 3)`.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_array(py, &self.running().instance.sim.velocities)
    }

    /// The nodes' rest positions, metres, `(n, 3)`.
    #[getter]
    fn rest_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_array(py, &self.running().instance.sim.mesh().rest_positions)
    }

    /// Current minus rest positions, metres, `(n, 3)`.
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = self.running();
        let sim = &r.instance.sim;
        let u: Vec<hox_sim::Vec3> =
            sim.positions.iter().zip(&sim.mesh().rest_positions).map(|(x, x0)| x - x0).collect();
        points_array(py, &u)
    }

    /// Each probe's displacement, metres: `{name: (ux, uy, uz)}`.
    #[getter]
    fn probes(&self) -> std::collections::BTreeMap<String, [f64; 3]> {
        self.running().instance.probe_displacements().into_iter().collect()
    }

    /// Simulated time, seconds.
    #[getter]
    fn time_secs(&self) -> f64 {
        self.running().instance.sim.time_secs()
    }

    /// The median wall-clock time of the frames stepped by `step`, milliseconds (NaN before any).
    #[getter]
    fn ms_per_frame(&self) -> f64 {
        let mut ms = self.running().frame_ms.clone();
        if ms.is_empty() { f64::NAN } else { hox_sim::measure::median(&mut ms) }
    }

    #[getter]
    fn num_nodes(&self) -> usize {
        self.running().instance.sim.mesh().num_nodes()
    }

    #[getter]
    fn num_elements(&self) -> usize {
        self.running().instance.sim.mesh().num_elements()
    }

    fn __repr__(&self) -> String {
        let r = self.running();
        format!(
            "hox.Simulation({:?}: {} nodes, {} elements, t = {:.3} s)",
            r.instance.scene.name(),
            r.instance.sim.mesh().num_nodes(),
            r.instance.sim.mesh().num_elements(),
            r.instance.sim.time_secs()
        )
    }
}

/// The built-in scenes' names.
#[pyfunction]
fn scenes() -> Vec<String> {
    hox_scenes::BUILTIN.iter().map(|(n, _)| n.to_string()).collect()
}

/// The parameter table: each parameter's key, scene-file path, label, unit, what it expects.
#[pyfunction]
fn parameters(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let table: Vec<serde_json::Value> = hox_scenes::params::PARAMS
        .iter()
        .filter(|p| p.surfaces.cli)
        .map(|p| {
            serde_json::json!({
                "key": p.key,
                "path": p.file_path(),
                "label": p.label,
                "unit": p.unit,
                "expected": p.kind.expected(),
                "help": p.help,
            })
        })
        .collect();
    from_json(py, &serde_json::Value::Array(table))
}

#[pymodule]
fn _hox(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_class::<PySimulation>()?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(parameters, m)?)?;
    Ok(())
}
