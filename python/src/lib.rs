//! hox from Python (issue #60): the `hox._hox` extension module over hox-sim and hox-scenes (not
//! over the command line). The Python package `hox` (python/hox/) re-exports it and adds what
//! is plain Python (meshio meshes, sweeps and the study through an executor, tables).
//!
//! - [`scene`]: `Scene` — the registry, a scene file, a Gmsh file, numpy arrays; every parameter
//!   of the parameter table by its key, with the command line's ranges and errors (`ValueError`
//!   naming the key); groups held or driven; probes;
//! - [`simulation`]: `Simulation` — frames stepped with the interpreter released, settling
//!   (Ctrl-C stops it), positions, velocities and rest positions as read-only numpy views of the
//!   simulation's own memory, fields per element or on the display surface, energies, probes,
//!   the static solution, the reference and the error against it;
//! - [`study`]: the study's cells one at a time (`hox.study` sends them through an executor).

mod scene;
mod simulation;
mod study;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pub(crate) fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

pub(crate) fn runtime_error(e: impl std::fmt::Display) -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(e.to_string())
}

/// Set in a process forked from one where hox had run (`os.register_at_fork`, hox/__init__.py):
/// the process pool of `concurrent.futures` forks its workers on Linux before Python 3.14.
static FORKED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Called in a forked child: its work goes to a thread pool of its own from now on.
#[pyfunction]
fn _after_fork_in_child() {
    FORKED.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// Runs hox's work `f`: here, with rayon's global pool, or in a process forked from one whose
/// global pool had started, in a pool made in this process. A fork copies only the forking
/// thread: the global pool's threads are gone in the child, and work sent to them would wait
/// for ever (`a_process_pool_forked_after_a_run_does_not_hang`, python/tests/test_study.py).
pub(crate) fn work<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if !FORKED.load(std::sync::atomic::Ordering::SeqCst) {
        return f();
    }
    type Pools = std::sync::Mutex<Option<(u32, &'static rayon::ThreadPool)>>;
    static POOL: Pools = std::sync::Mutex::new(None);
    let pid = std::process::id();
    let pool = {
        let mut mine = POOL.lock().unwrap_or_else(|e| e.into_inner());
        match *mine {
            Some((p, pool)) if p == pid => pool,
            _ => {
                // a pool of a parent process is never dropped here: its threads are not ours
                let built = rayon::ThreadPoolBuilder::new().build();
                let pool: &'static rayon::ThreadPool = match built {
                    Ok(pool) => Box::leak(Box::new(pool)),
                    Err(_) => return f(),
                };
                *mine = Some((pid, pool));
                pool
            }
        }
    };
    pool.install(f)
}

/// A JSON value as the Python object `json.loads` makes of it.
pub(crate) fn from_json<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (value.to_string(),))
}

/// The built-in scenes' names.
#[pyfunction]
fn scenes() -> Vec<String> {
    hox_scenes::BUILTIN.iter().map(|(n, _)| n.to_string()).collect()
}

/// The registered element types: name, Gmsh type, node count, description.
#[pyfunction]
fn elements(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    let table: Vec<serde_json::Value> = hox_sim::element::ElementType::all()
        .map(|e| {
            serde_json::json!({
                "name": e.name(),
                "gmsh_type": e.gmsh_type(),
                "nodes": e.num_nodes(),
                "description": e.description(),
            })
        })
        .collect();
    from_json(py, &serde_json::Value::Array(table))
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

/// The machine this runs on, as the study and `hox bench` name it.
#[pyfunction]
fn machine() -> String {
    hox_scenes::bench::machine()
}

#[pymodule]
fn _hox(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::PyScene>()?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(elements, m)?)?;
    m.add_function(wrap_pyfunction!(parameters, m)?)?;
    m.add_function(wrap_pyfunction!(machine, m)?)?;
    m.add_function(wrap_pyfunction!(_after_fork_in_child, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_cells, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_cell, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
