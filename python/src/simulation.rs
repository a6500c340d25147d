//! `hox.Simulation`: a scene built and running — stepped with the interpreter released, its state
//! read as numpy arrays, its fields, energies, probes, static solution, reference and error.

use crate::scene::PyScene;
use crate::{from_json, runtime_error, value_error};
use hox_scenes::instance::Instance;
use hox_sim::measure::field::{Field, SurfaceGradients, element_means, element_volumes_m3};
use hox_sim::measure::surface::Surface;
use numpy::ndarray::ArrayView2;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use std::sync::{Mutex, MutexGuard};

/// `n × 3` coordinates as a new `(n, 3)` float64 array.
pub fn points_array<'py>(py: Python<'py>, points: &[hox_sim::Vec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    PyArray1::from_vec(py, flat).reshape([points.len(), 3])
}

/// A scene built and running: step it, settle it, read its state as numpy arrays.
#[pyclass(name = "Simulation", module = "hox", frozen)]
pub struct PySimulation {
    inner: Mutex<Running>,
}

struct Running {
    instance: Instance,
    /// Wall-clock time of each frame stepped, milliseconds.
    frame_ms: Vec<f64>,
    /// The display surface and its gradients, by the segments it was cut with (made on demand).
    surface: Option<(usize, Surface, SurfaceGradients)>,
}

impl Running {
    /// The simulation and its display surface cut with `segments`, made on the first call.
    fn with_surface(&mut self, segments: usize) -> (&Instance, &Surface, &SurfaceGradients) {
        if self.surface.as_ref().is_none_or(|(s, _, _)| *s != segments) {
            let mesh = self.instance.sim.mesh();
            let surface = Surface::new(mesh, segments);
            let gradients = SurfaceGradients::new(mesh, &surface);
            self.surface = Some((segments, surface, gradients));
        }
        let (_, surface, gradients) = self.surface.as_ref().expect("made above");
        (&self.instance, surface, gradients)
    }
}

impl PySimulation {
    fn running(&self) -> MutexGuard<'_, Running> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Which of the simulation's own node arrays a view shows.
#[derive(Clone, Copy)]
enum NodeArray {
    Positions,
    Velocities,
    Rest,
}

/// A read-only `(n, 3)` numpy view of one of the simulation's node arrays, no copy: its base is
/// the simulation, kept alive as long as the view.
fn node_view<'py>(slf: &Bound<'py, PySimulation>, which: NodeArray) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (ptr, n) = {
        let r = slf.get().running();
        let sim = &r.instance.sim;
        let v = match which {
            NodeArray::Positions => &sim.positions,
            NodeArray::Velocities => &sim.velocities,
            NodeArray::Rest => &sim.mesh().rest_positions,
        };
        (v.as_ptr() as *const f64, v.len())
    };
    // SAFETY: `Vec3` is nalgebra's `Vector3<f64>`, three contiguous f64s, so the node array is
    // an `n × 3` row-major block. The simulation is the view's base object, so the memory lives
    // as long as the view; nothing in this module replaces or resizes these vectors (a stepped
    // frame writes them in place: `a_view_follows_the_simulation_in_place` in the tests), so the
    // pointer stays valid. Stepping while another Python thread reads the view is the caller's
    // race, as with any array shared between threads.
    let array = unsafe {
        let view = ArrayView2::from_shape_ptr((n, 3), ptr);
        PyArray2::borrow_from_array(&view, slf.clone().into_any())
    };
    array.readwrite().make_nonwriteable();
    Ok(array)
}

/// Frames stepped between two checks for Ctrl-C while settling.
const FRAMES_PER_SIGNAL_CHECK: usize = 15;

/// A field by name, with the names listed when it is unknown.
fn field_named(name: &str) -> PyResult<Field> {
    Field::from_name(name).filter(|f| *f != Field::Error).ok_or_else(|| {
        let names: Vec<&str> = Field::ALL.iter().filter(|f| **f != Field::Error).map(|f| f.name()).collect();
        value_error(format!("unknown field {name:?} (known: {})", names.join(", ")))
    })
}

#[pymethods]
impl PySimulation {
    #[new]
    fn new(py: Python<'_>, scene: &PyScene) -> PyResult<PySimulation> {
        let scene = scene.scene();
        let instance = py.detach(|| crate::work(|| Instance::new(scene))).map_err(value_error)?;
        Ok(PySimulation { inner: Mutex::new(Running { instance, frame_ms: Vec::new(), surface: None }) })
    }

    /// Steps `frames` frames (each `1 / frames_per_second` simulated seconds), the interpreter
    /// released meanwhile; Ctrl-C stops between two frames.
    #[pyo3(signature = (frames = 1))]
    fn step(&self, py: Python<'_>, frames: usize) -> PyResult<()> {
        for _ in 0..frames {
            py.detach(|| {
                crate::work(|| {
                    let mut r = self.running();
                    let clock = std::time::Instant::now();
                    let stepped = r.instance.sim.step_frame();
                    r.frame_ms.push(clock.elapsed().as_secs_f64() * 1e3);
                    stepped
                })
            })
            .map_err(runtime_error)?;
            if frames > 1 {
                py.check_signals()?;
            }
        }
        Ok(())
    }

    /// Steps `frames` frames in one loop in Rust, the interpreter released once, and returns each
    /// frame's wall time in ms: the baseline `python/bench/overhead.py` measures the cost of
    /// stepping from Python one call per frame against (`step` takes the same frames).
    fn step_in_rust<'py>(&self, py: Python<'py>, frames: usize) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let ms = py.detach(|| {
            crate::work(|| {
                let mut r = self.running();
                let mut ms = Vec::with_capacity(frames);
                for _ in 0..frames {
                    let clock = std::time::Instant::now();
                    r.instance.sim.step_frame()?;
                    ms.push(clock.elapsed().as_secs_f64() * 1e3);
                }
                r.frame_ms.extend_from_slice(&ms);
                Ok::<_, hox_sim::solver::SimError>(ms)
            })
        });
        Ok(PyArray1::from_vec(py, ms.map_err(runtime_error)?))
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
            crate::work(|| {
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
            })
        });
        if let Some(e) = interrupted {
            return Err(e);
        }
        let report = report.map_err(runtime_error)?;
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
        if !(tolerance.is_finite() && tolerance > 0.0) || load_steps == 0 {
            return Err(value_error(format!(
                "static_solve: tolerance must be positive ({tolerance}) and load_steps at least 1 ({load_steps})"
            )));
        }
        let solved = py.detach(|| {
            crate::work(|| {
                let r = self.running();
                let (scene, mesh) = (&r.instance.scene, r.instance.sim.mesh());
                hox_scenes::solve_static(scene, mesh, tolerance, load_steps, &mut |_, _, _| {})
            })
        });
        points_array(py, &solved.map_err(runtime_error)?.positions)
    }

    /// The reference the error is measured against (`hox simulate --reference`'s): committed
    /// for a paper scene, else computed (the static solver on refined Q2 meshes, cached on
    /// disk, minutes the first time) or, for a mesh file, its own static solution. A dict:
    /// origin, label, mesh, probes, estimated error.
    fn reference<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let scene = self.running().instance.scene.clone();
        let reference = py.detach(|| crate::work(|| hox_scenes::reference::for_scene(&scene, &mut |_, _| {})));
        from_json(py, &reference.map_err(runtime_error)?.to_json())
    }

    /// The probes' error against [`reference`](Self::reference) now: `{"error_m", "error_pct",
    /// "reference"}` (the largest probe distance, metres and % of the reference displacement).
    fn error<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (scene, probes) = {
            let r = self.running();
            (r.instance.scene.clone(), r.instance.probe_displacements())
        };
        if probes.is_empty() {
            return Err(value_error("the scene has no probes to measure an error at (Scene.with_probes)"));
        }
        let reference = py
            .detach(|| crate::work(|| hox_scenes::reference::for_scene(&scene, &mut |_, _| {})))
            .map_err(runtime_error)?;
        from_json(
            py,
            &serde_json::json!({
                "error_m": reference.error_m(&probes),
                "error_pct": reference.error_pct(&probes),
                "reference": reference.label(),
            }),
        )
    }

    /// The nodes' current positions, metres, `(n, 3)`: a read-only view of the simulation's own
    /// array (no copy), which follows the simulation as it steps; `positions.copy()` keeps one.
    #[getter]
    fn positions<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        node_view(slf, NodeArray::Positions)
    }

    /// The nodes' velocities, m/s, `(n, 3)`: a read-only view, as `positions`.
    #[getter]
    fn velocities<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        node_view(slf, NodeArray::Velocities)
    }

    /// The nodes' rest positions, metres, `(n, 3)`: a read-only view.
    #[getter]
    fn rest_positions<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        node_view(slf, NodeArray::Rest)
    }

    /// Current minus rest positions, metres, `(n, 3)` (a new array).
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = self.running();
        let sim = &r.instance.sim;
        let u: Vec<hox_sim::Vec3> =
            sim.positions.iter().zip(&sim.mesh().rest_positions).map(|(x, x0)| x - x0).collect();
        points_array(py, &u)
    }

    /// The elements as `{type: (m, k) node indices}` (Gmsh's node order), block by block: the
    /// order of per-element fields.
    #[getter]
    fn elements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let r = self.running();
        let d = pyo3::types::PyDict::new(py);
        for b in &r.instance.sim.mesh().blocks {
            let conn = PyArray1::from_vec(py, b.connectivity.iter().map(|&n| i64::from(n)).collect());
            d.set_item(b.element_type.name(), conn.reshape([b.len(), b.nodes_per_element()])?)?;
        }
        Ok(d)
    }

    /// A field per element, volume-averaged over its quadrature points: "von-mises" (Pa),
    /// "strain" (equivalent Green–Lagrange), "det-f", "energy-density" (J/m³); `(m,)`, elements
    /// block by block as `elements` lists them.
    fn element_field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let field = field_named(name)?;
        if !field.needs_gradient() {
            return Err(value_error(format!("{name} is a field of the nodes (displacements), not of the elements")));
        }
        let r = self.running();
        let sim = &r.instance.sim;
        Ok(PyArray1::from_vec(py, element_means(field, sim.mesh(), sim.geometry(), sim.material(), &sim.positions)))
    }

    /// The rest volume of each element, m³, `(m,)` (its sum: `volume_m3`).
    #[getter]
    fn element_volumes_m3<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let r = self.running();
        PyArray1::from_vec(py, element_volumes_m3(r.instance.sim.mesh(), r.instance.sim.geometry()))
    }

    /// The body's rest volume, m³ (the quadrature the solver integrates with).
    #[getter]
    fn volume_m3(&self) -> f64 {
        let r = self.running();
        element_volumes_m3(r.instance.sim.mesh(), r.instance.sim.geometry()).iter().sum()
    }

    /// The display surface the app draws (curved faces cut into `segments` pieces per edge):
    /// `{"points": (v, 3) current positions, "rest_points": (v, 3), "triangles": (t, 3)}`.
    #[pyo3(signature = (segments = 4))]
    fn surface<'py>(&self, py: Python<'py>, segments: usize) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let mut r = self.running();
        let (instance, surface, _) = r.with_surface(segments);
        let (mut points, mut rest_points) = (Vec::new(), Vec::new());
        surface.vertices.eval_into(&instance.sim.positions, &mut points);
        surface.vertices.eval_into(&instance.sim.mesh().rest_positions, &mut rest_points);
        let triangles: Vec<u32> = surface.triangles.iter().flatten().copied().collect();
        let n = surface.triangles.len();
        let d = pyo3::types::PyDict::new(py);
        d.set_item("points", points_array(py, &points)?)?;
        d.set_item("rest_points", points_array(py, &rest_points)?)?;
        d.set_item("triangles", PyArray1::from_vec(py, triangles).reshape([n, 3])?)?;
        Ok(d)
    }

    /// A field at the display surface's points (`surface(segments)`'s order), as the app colours
    /// it: "displacement" (|u|, m) or a field of F at each point, the mean over the elements
    /// meeting there.
    #[pyo3(signature = (name, segments = 4))]
    fn surface_field<'py>(&self, py: Python<'py>, name: &str, segments: usize) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let field = field_named(name)?;
        let mut r = self.running();
        let (instance, surface, gradients) = r.with_surface(segments);
        let (positions, rest, material) =
            (&instance.sim.positions, &instance.sim.mesh().rest_positions, instance.sim.material());
        let mut values = Vec::new();
        if field.needs_gradient() {
            gradients.values_into(field, material, positions, rest, &mut values);
        } else {
            let mut u = Vec::new();
            surface.vertices.displacements_into(positions, rest, &mut u);
            values = u.iter().map(|u| u.norm()).collect();
        }
        Ok(PyArray1::from_vec(py, values))
    }

    /// Energies now, joules: kinetic, elastic, gravity's potential (from the rest positions),
    /// and their sum.
    #[getter]
    fn energies(&self) -> std::collections::BTreeMap<&'static str, f64> {
        let r = self.running();
        let sim = &r.instance.sim;
        let g = sim.body_acceleration_m_s2();
        let gravity: f64 = -sim
            .masses_kg()
            .iter()
            .zip(sim.positions.iter().zip(&sim.mesh().rest_positions))
            .map(|(m, (x, x0))| m * g.dot(&(x - x0)))
            .sum::<f64>();
        let (kinetic, elastic) = (sim.kinetic_energy_j(), sim.elastic_energy_j());
        [
            ("kinetic_j", kinetic),
            ("elastic_j", elastic),
            ("gravity_j", gravity),
            ("total_j", kinetic + elastic + gravity),
        ]
        .into_iter()
        .collect()
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

    /// The policy Newton's last step ran ("interactive" or "careful") and why, as `hox simulate
    /// --json`'s `newton_policy` and `newton_policy_why`; None for XPBD, VBD and before a step.
    #[getter]
    fn newton_policy(&self) -> Option<(String, String)> {
        self.running().instance.sim.newton_policy().map(|p| (p.ran.name().to_string(), p.why.clone()))
    }

    /// What the app and `hox simulate` say when the solver is not the one for this body (VBD on
    /// a curved or hollow part), naming the one that is; None otherwise.
    #[getter]
    fn solver_advice(&self) -> Option<String> {
        hox_scenes::run::solver_advice(&self.running().instance)
    }

    /// The wall-clock time of every frame stepped by `step`, milliseconds.
    #[getter]
    fn frame_ms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.running().frame_ms.clone())
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
