//! `hox.Scene`: a scene — its mesh, material, effects, solver settings and probes — from the
//! registry, a scene file, a Gmsh file or numpy arrays, changed by the parameter table's keys.

use crate::{from_json, value_error};
use hox_scenes::{Scene, SceneOverrides};
use hox_sim::element::ElementType;
use hox_sim::io::gmsh::ImportedMesh;
use hox_sim::mesh::{ElementBlock, Mesh};
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

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

/// A prescribed motion of a group, from `{"group": …, "translation_m": (x, y, z), …}`.
fn drive_from(d: &Bound<'_, PyAny>) -> PyResult<hox_scenes::Drive> {
    let get = |key: &str| -> PyResult<Option<Bound<'_, PyAny>>> {
        match d.get_item(key) {
            Ok(v) if !v.is_none() => Ok(Some(v)),
            _ => Ok(None),
        }
    };
    let group: String = get("group")?.ok_or_else(|| value_error("a drive needs its \"group\""))?.extract()?;
    let known = ["group", "translation_m", "rotation_axis", "rotation_origin_m", "rotation_deg", "ramp_secs"];
    for key in d.try_iter()? {
        let key: String = key?.extract()?;
        if !known.contains(&key.as_str()) {
            return Err(value_error(format!(
                "drive of \"{group}\": unknown key {key:?} (known: {})",
                known.join(", ")
            )));
        }
    }
    Ok(hox_scenes::Drive {
        group,
        translation_m: get("translation_m")?.map(|v| v.extract()).transpose()?.unwrap_or([0.0; 3]),
        rotation_axis: get("rotation_axis")?.map(|v| v.extract()).transpose()?,
        rotation_origin_m: get("rotation_origin_m")?.map(|v| v.extract()).transpose()?,
        rotation_deg: get("rotation_deg")?.map(|v| v.extract()).transpose()?.unwrap_or(0.0),
        ramp_secs: get("ramp_secs")?.map(|v| v.extract()).transpose()?.unwrap_or(1.0),
    })
}

/// A scene: its mesh, material, effects, solver settings and probes.
#[pyclass(name = "Scene", module = "hox", frozen)]
pub struct PyScene {
    inner: Mutex<Scene>,
}

impl PyScene {
    pub fn wrap(scene: Scene) -> PyScene {
        PyScene { inner: Mutex::new(scene) }
    }

    pub fn scene(&self) -> Scene {
        self.inner.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

/// A content name for a mesh given as arrays: the same arrays give the same name (the key its
/// computed references are cached under), other arrays another.
fn arrays_name(mesh: &Mesh) -> String {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in &mesh.rest_positions {
        [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()].hash(&mut h);
    }
    for b in &mesh.blocks {
        b.element_type.name().hash(&mut h);
        b.connectivity.hash(&mut h);
    }
    format!("arrays-{:016x}", h.finish())
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

    /// A scene around a Gmsh mesh file (MSH 4.1 or 2.2): its physical groups `clamp` held,
    /// `drives` moved (`[{"group": "end", "translation_m": (0, 0, -0.1), "ramp_secs": 1}]`),
    /// under gravity unless `gravity=False`.
    #[staticmethod]
    #[pyo3(signature = (path, clamp = vec!["clamp".to_string()], drives = Vec::new(), gravity = true))]
    fn from_mesh_file(
        path: std::path::PathBuf,
        clamp: Vec<String>,
        drives: Vec<Bound<'_, PyAny>>,
        gravity: bool,
    ) -> PyResult<PyScene> {
        let drives = drives.iter().map(drive_from).collect::<PyResult<Vec<_>>>()?;
        Scene::from_mesh_file(&path, &clamp, &drives, gravity).map(PyScene::wrap).map_err(value_error)
    }

    /// A scene around a mesh given as arrays: `nodes` `(n, 3)` metres; `elements` a dict from
    /// element type (`hox.elements()`: "p1", "p2", …) to its `(m, k)` node indices from 0, in
    /// Gmsh's node order; `groups` a dict from name to node indices; `clamp` and `drives` as in
    /// `from_mesh_file`. The mesh is checked as a Gmsh file is (indices, inverted or flat
    /// elements: `ValueError` naming the element by its row).
    #[staticmethod]
    #[pyo3(signature = (nodes, elements, groups = None, clamp = Vec::new(), drives = Vec::new(), gravity = true))]
    fn from_arrays(
        nodes: PyReadonlyArray2<'_, f64>,
        elements: &Bound<'_, PyDict>,
        groups: Option<&Bound<'_, PyDict>>,
        clamp: Vec<String>,
        drives: Vec<Bound<'_, PyAny>>,
        gravity: bool,
    ) -> PyResult<PyScene> {
        if nodes.shape().len() != 2 || nodes.shape()[1] != 3 {
            return Err(value_error(format!("nodes: expected an (n, 3) array, got shape {:?}", nodes.shape())));
        }
        let coords = nodes.as_array();
        let rest_positions: Vec<hox_sim::Vec3> =
            coords.rows().into_iter().map(|r| hox_sim::Vec3::new(r[0], r[1], r[2])).collect();
        let mut blocks = Vec::new();
        for (name, conn) in elements.iter() {
            let name: String = name.extract()?;
            let et = ElementType::from_name(&name).ok_or_else(|| {
                value_error(format!("elements: unknown element type {name:?} (known: {})", ElementType::names()))
            })?;
            let expected = || {
                value_error(format!("elements[{name:?}]: expected an (m, {}) array of node indices", et.num_nodes()))
            };
            // an int64 array is read in place; any other sequence of rows element by element
            let conn: Vec<Vec<i64>> = match conn.extract::<PyReadonlyArray2<'_, i64>>() {
                Ok(a) => a.as_array().rows().into_iter().map(|r| r.to_vec()).collect(),
                Err(_) => conn.extract().map_err(|_| expected())?,
            };
            let mut flat = Vec::with_capacity(conn.len() * et.num_nodes());
            for (row, element) in conn.iter().enumerate() {
                if element.len() != et.num_nodes() {
                    return Err(value_error(format!(
                        "elements[{name:?}] row {row}: {} node indices, a {name} element has {}",
                        element.len(),
                        et.num_nodes()
                    )));
                }
                for &n in element {
                    flat.push(u32::try_from(n).map_err(|_| {
                        value_error(format!("elements[{name:?}] row {row}: node index {n} is not a valid index"))
                    })?);
                }
            }
            blocks.push(ElementBlock::new(et, flat));
        }
        let mut node_sets = BTreeMap::new();
        for (name, set) in groups.into_iter().flatten() {
            let name: String = name.extract()?;
            let set: Vec<i64> = set
                .extract()
                .map_err(|_| value_error(format!("groups[{name:?}]: expected a sequence of node indices")))?;
            let set = set
                .iter()
                .map(|&n| {
                    u32::try_from(n).map_err(|_| value_error(format!("groups[{name:?}]: node index {n} is not valid")))
                })
                .collect::<PyResult<Vec<u32>>>()?;
            node_sets.insert(name, set);
        }
        let mesh = Mesh { rest_positions, blocks };
        let name = arrays_name(&mesh);
        let imported = ImportedMesh::from_arrays("the arrays (rows and nodes counted from 0)", mesh, node_sets)
            .map_err(value_error)?;
        let drives = drives.iter().map(drive_from).collect::<PyResult<Vec<_>>>()?;
        Scene::from_imported(&name, Arc::new(imported), &clamp, &drives, gravity)
            .map(PyScene::wrap)
            .map_err(value_error)
    }

    /// This scene with parameters set by their keys (`hox.parameters()`): `element="p2"`,
    /// `poisson=0.45`, `grid=(16, 4, 4)`, `solver="newton"`, … A bad key or value raises
    /// ValueError naming it and what it expects.
    #[pyo3(signature = (**params))]
    fn with_params(&self, params: Option<&Bound<'_, PyDict>>) -> PyResult<PyScene> {
        let mut overrides = SceneOverrides::default();
        for (key, value) in params.into_iter().flatten() {
            // `vbd_iterations=` for the table's `vbd-iterations` (a Python keyword has no dash)
            let key: String = key.extract::<String>()?.replace('_', "-");
            overrides.set_text(&key, &value_text(&value)?).map_err(value_error)?;
        }
        self.scene().with_overrides(&overrides).map(PyScene::wrap).map_err(value_error)
    }

    /// This scene with probes added by name: `with_probes(tip=(1.0, 0.1, 0.1))`, metres, rest
    /// coordinates (a point outside the mesh is a ValueError when the simulation is built).
    #[pyo3(signature = (**probes))]
    fn with_probes(&self, probes: Option<&Bound<'_, PyDict>>) -> PyResult<PyScene> {
        let mut specs = Vec::new();
        for (name, point) in probes.into_iter().flatten() {
            let name: String = name.extract()?;
            let point_m: [f64; 3] = point
                .extract()
                .map_err(|_| value_error(format!("probe {name:?}: expected a point (x, y, z) in metres")))?;
            if point_m.iter().any(|c| !c.is_finite()) {
                return Err(value_error(format!("probe {name:?}: the point {point_m:?} must be finite")));
            }
            specs.push(hox_scenes::scene::ProbeSpec { name, point_m });
        }
        self.scene().with_probes(&specs).map(PyScene::wrap).map_err(value_error)
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

    /// The probes: `{name: (x, y, z)}`, rest coordinates in metres.
    #[getter]
    fn probes(&self) -> BTreeMap<String, [f64; 3]> {
        self.scene().file.probes.iter().map(|p| (p.name.clone(), p.point_m)).collect()
    }

    /// The mesh file's physical groups (or the arrays' groups) with their node counts; empty
    /// for a box scene.
    #[getter]
    fn groups(&self) -> BTreeMap<String, usize> {
        let scene = self.scene();
        scene
            .mesh
            .imported()
            .map(|m| m.node_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect())
            .unwrap_or_default()
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
