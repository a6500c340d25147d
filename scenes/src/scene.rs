//! Scene files: a scene is data, a TOML file (`assets/scenes/*.toml`) naming its mesh,
//! material, solver settings, the effects it needs and its probes.
//!
//! ```toml
//! name = "bending"
//! description = "…"
//! [mesh]        # a structured box (see hox_sim::mesh::structured), or a Gmsh file:
//!               # [mesh] file = "beam.msh" (relative to the scene file; see docs/MESHES.md)
//! box_min_m = [0, 0, 0]
//! box_max_m = [2, 0.5, 0.5]
//! element = "p2"          # p1 p2 p3 q1 q2 prism pyramid
//! grid = [8, 2, 2]        # hexahedral cells per direction
//! split = "five"          # five (unbiased) | six (biased): tetrahedra per cell
//! refine = 0              # 1-to-8 refinements of the tetrahedra
//! [material]
//! model = "stvk"          # stvk | snh | snh-log | nh
//! youngs_modulus_pa = 3e6
//! poisson_ratio = 0.35
//! density_kg_m3 = 1000
//! [solver]                # all optional; defaults are the paper's
//! substeps = 50
//! iterations = 1
//! frames_per_second = 60
//! formulation = "energy"  # energy | split
//! quadrature_degree = 2   # omit for each element type's default
//! duration_secs = 3       # default run length
//! settle_damping_per_sec = 10  # velocity damping used by --settle
//! parallel = false        # project elements colour by colour on all threads
//! stability_guard = true   # above h·ω_max = 3, substeps with h·ω_max ≤ 1 (hox_sim::solver::stability)
//! [[effects]]             # only the effects listed are simulated
//! type = "gravity"        # gravity | clamp | prescribed | damping | contact
//! acceleration_m_s2 = [0, 0, -9.81]
//! [[effects]]
//! type = "clamp"
//! nodes = { plane = "x", at_m = 0 }   # or { box_min_m = [...], box_max_m = [...] },
//!                                     # or { group = "clamp" } (a mesh file's physical group)
//! [[effects]]
//! type = "prescribed"     # translation and/or rotation, ramped smoothly then held
//! nodes = { plane = "x", at_m = 1 }
//! translation_m = [0.5, 0, 0]
//! rotation_axis = [1, 0, 0]
//! rotation_origin_m = [1, 0.25, 0.25]
//! rotation_deg = 90
//! ramp_secs = 1
//! [[effects]]
//! type = "damping"
//! rate_per_sec = 1
//! [[effects]]
//! type = "contact"        # half-space contact with a (moving) plane
//! point_m = [0, 0, 0]
//! normal = [0, 0, 1]      # points into the allowed side
//! velocity_m_s = [0, 0, 0]
//! move_secs = 2           # the plane stops after this long (default: never)
//! friction = 0.5
//! [[probes]]
//! name = "tip"
//! point_m = [2, 0.25, 0.25]
//! ```
//!
//! Unknown keys, missing fields, wrong types, negative or non-finite values, probes outside
//! the body and unknown physical groups are errors naming the file, the key and the value.

use hox_sim::Vec3;
use hox_sim::effect::{AxisRotation, Clamp, ContactPlane, Damping, Effect, Gravity, Prescribed};
use hox_sim::element::ElementType;
use hox_sim::io::gmsh::ImportedMesh;
use hox_sim::material::{Material, MaterialModel};
use hox_sim::mesh::Mesh;
use hox_sim::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
use hox_sim::solver::SolverSettings;
use hox_sim::xpbd::constraint::Formulation;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::SceneError;

/// A scene file as written (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub mesh: MeshSpec,
    pub material: MaterialSpec,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub effects: Vec<EffectSpec>,
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
}

/// The `[mesh]` table: either `file` (a Gmsh `.msh` file) or a structured box (`box_min_m`,
/// `box_max_m`, `element`, `grid`, optionally `split` and `refine`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// A Gmsh mesh file, relative to the scene file (or absolute).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_min_m: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_max_m: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<[usize; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refine: Option<usize>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub model: String,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub density_kg_m3: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    pub substeps: u32,
    pub iterations: u32,
    pub frames_per_second: f64,
    pub formulation: String,
    pub quadrature_degree: Option<usize>,
    pub duration_secs: f64,
    pub settle_damping_per_sec: f64,
    /// Project elements in parallel, colour by colour.
    pub parallel: bool,
    /// Take more substeps when the stiffest element needs them (`hox_sim::solver::stability`).
    pub stability_guard: bool,
}

impl Default for SolverSpec {
    fn default() -> Self {
        Self {
            substeps: 50,
            iterations: 1,
            frames_per_second: 60.0,
            formulation: "energy".into(),
            quadrature_degree: None,
            duration_secs: 3.0,
            settle_damping_per_sec: 10.0,
            parallel: false,
            stability_guard: true,
        }
    }
}

/// Which nodes an effect acts on: those on an axis-aligned plane, inside a box, or in a
/// physical group of the mesh file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSelector {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_min_m: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_max_m: Option<[f64; 3]>,
    /// A physical group of the mesh file (`[mesh] file = …`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
}

impl NodeSelector {
    /// The nodes of a mesh file's physical group.
    pub fn group(name: &str) -> Self {
        Self { group: Some(name.to_string()), ..Default::default() }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum EffectSpec {
    Gravity {
        acceleration_m_s2: [f64; 3],
    },
    Clamp {
        nodes: NodeSelector,
    },
    Prescribed {
        nodes: NodeSelector,
        #[serde(default)]
        translation_m: [f64; 3],
        #[serde(default)]
        rotation_axis: Option<[f64; 3]>,
        #[serde(default)]
        rotation_origin_m: Option<[f64; 3]>,
        #[serde(default)]
        rotation_deg: f64,
        #[serde(default)]
        ramp_secs: f64,
    },
    Damping {
        rate_per_sec: f64,
    },
    Contact {
        point_m: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        velocity_m_s: [f64; 3],
        #[serde(default)]
        move_secs: Option<f64>,
        #[serde(default)]
        friction: f64,
    },
}

impl EffectSpec {
    /// The prescribed motion this spec describes, acting on `nodes` (None for other effects).
    pub fn prescribed(&self, nodes: Vec<u32>) -> Option<Prescribed> {
        let EffectSpec::Prescribed { translation_m, rotation_axis, rotation_origin_m, rotation_deg, ramp_secs, .. } =
            self
        else {
            return None;
        };
        let rotation = rotation_axis.map(|axis| AxisRotation {
            axis: Vec3::from(axis).normalize(),
            origin_m: Vec3::from(rotation_origin_m.unwrap_or([0.0; 3])),
            angle_rad: rotation_deg.to_radians(),
        });
        Some(Prescribed { nodes, translation_m: Vec3::from(*translation_m), rotation, ramp_secs: *ramp_secs })
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Self::Gravity { .. } => "gravity",
            Self::Clamp { .. } => "clamp",
            Self::Prescribed { .. } => "prescribed",
            Self::Damping { .. } => "damping",
            Self::Contact { .. } => "contact",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub point_m: [f64; 3],
}

/// Prescribed motion of a mesh file's physical group (see [`Scene::from_mesh_file`]): a
/// translation and/or a rotation, ramped in smoothly over `ramp_secs`, then held.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    pub group: String,
    pub translation_m: [f64; 3],
    pub rotation_axis: Option<[f64; 3]>,
    /// Default: the centre of the group's nodes.
    pub rotation_origin_m: Option<[f64; 3]>,
    pub rotation_deg: f64,
    pub ramp_secs: f64,
}

/// A validated scene: typed settings ready to build a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Where the scene came from (a file path or `builtin:NAME`), for error messages.
    pub source: String,
    /// The folder relative mesh file paths are resolved against (the scene file's folder).
    pub base_dir: Option<PathBuf>,
    pub file: SceneFile,
    pub mesh: SceneMesh,
    pub material: Material,
    pub settings: SolverSettings,
}

/// Where a scene's mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneMesh {
    /// A structured box, built on demand.
    Box(BoxMeshSpec),
    /// A mesh file, read (and checked) when the scene is validated.
    File { path: PathBuf, imported: Arc<ImportedMesh> },
}

impl SceneMesh {
    /// The box spec, for a box scene.
    pub fn as_box(&self) -> Option<&BoxMeshSpec> {
        match self {
            SceneMesh::Box(b) => Some(b),
            SceneMesh::File { .. } => None,
        }
    }
    /// The imported mesh, for a mesh-file scene.
    pub fn imported(&self) -> Option<&ImportedMesh> {
        match self {
            SceneMesh::Box(_) => None,
            SceneMesh::File { imported, .. } => Some(imported),
        }
    }
    /// A short description: "p2" for a box, the element types for a file ("p2" or "q1+pyramid").
    pub fn element_names(&self) -> String {
        match self {
            SceneMesh::Box(b) => b.element_type.name().to_string(),
            SceneMesh::File { imported, .. } => {
                imported.mesh.blocks.iter().map(|b| b.element_type.name()).collect::<Vec<_>>().join("+")
            }
        }
    }
}

impl SceneFile {
    /// A scene around a mesh file: the bending scene's material (StVK, E = 3 MPa, ν = 0.35,
    /// ρ = 1000 kg/m³), the default solver settings, and gravity unless `gravity` is false.
    /// Callers add clamps and drives (`NodeSelector::group`).
    pub fn for_mesh_file(path: &Path, gravity: bool) -> SceneFile {
        SceneFile {
            name: path.file_stem().map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned()),
            description: format!("the mesh {}", path.display()),
            mesh: MeshSpec {
                file: Some(path.display().to_string()),
                box_min_m: None,
                box_max_m: None,
                element: None,
                grid: None,
                split: None,
                refine: None,
            },
            material: MaterialSpec {
                model: "stvk".into(),
                youngs_modulus_pa: 3e6,
                poisson_ratio: 0.35,
                density_kg_m3: 1000.0,
            },
            solver: SolverSpec::default(),
            effects: if gravity {
                vec![EffectSpec::Gravity { acceleration_m_s2: [0.0, 0.0, -9.81] }]
            } else {
                Vec::new()
            },
            probes: Vec::new(),
        }
    }
}

/// Command-line (or app) changes to a scene, applied before validation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneOverrides {
    pub element: Option<String>,
    pub grid: Option<[usize; 3]>,
    pub split: Option<String>,
    pub refine: Option<usize>,
    pub material: Option<String>,
    pub youngs_modulus_pa: Option<f64>,
    pub poisson_ratio: Option<f64>,
    pub density_kg_m3: Option<f64>,
    pub formulation: Option<String>,
    pub quadrature_degree: Option<usize>,
    pub substeps: Option<u32>,
    pub iterations: Option<u32>,
    pub frames_per_second: Option<f64>,
    pub parallel: Option<bool>,
    pub stability_guard: Option<bool>,
}

impl Scene {
    /// Parses and validates a scene file's text. `source` names it in errors; a mesh file is
    /// looked for relative to the working directory.
    pub fn from_toml(text: &str, source: &str) -> Result<Scene, SceneError> {
        Scene::from_toml_in(text, source, None)
    }

    /// Like [`Scene::from_toml`], with relative mesh file paths resolved against `base_dir`.
    pub fn from_toml_in(text: &str, source: &str, base_dir: Option<&Path>) -> Result<Scene, SceneError> {
        let file: SceneFile = toml::from_str(text)
            .map_err(|e| SceneError::Parse { source_name: source.to_string(), message: e.to_string() })?;
        Scene::validate(file, source, base_dir.map(Path::to_path_buf), None)
    }

    /// Reads a scene file from disk (a mesh file it names is relative to its folder).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::Io { path: path.display().to_string(), message: e.to_string() })?;
        Scene::from_toml_in(&text, &path.display().to_string(), path.parent())
    }

    /// Validates a parsed scene file (a relative mesh file path is relative to the working
    /// directory).
    pub fn from_file(file: SceneFile, source: &str) -> Result<Scene, SceneError> {
        Scene::validate(file, source, None, None)
    }

    /// Validates `file`; `cached` is a mesh file already read for the same path.
    fn validate(
        file: SceneFile,
        source: &str,
        base_dir: Option<PathBuf>,
        cached: Option<&SceneMesh>,
    ) -> Result<Scene, SceneError> {
        let invalid = |key: &str, value: String, reason: &str| SceneError::Invalid {
            source_name: source.to_string(),
            key: key.to_string(),
            value,
            reason: reason.to_string(),
        };
        let mesh = mesh_of(&file.mesh, source, base_dir.as_deref(), cached, &invalid)?;
        let mm = &file.material;
        let model = MaterialModel::from_name(&mm.model)
            .ok_or_else(|| invalid("material.model", format!("{:?}", mm.model), "expected stvk, snh, snh-log or nh"))?;
        let material = Material::new(model, mm.youngs_modulus_pa, mm.poisson_ratio, mm.density_kg_m3).map_err(|e| {
            use hox_sim::material::MaterialError as E;
            let (key, value) = match &e {
                E::YoungsModulus { .. } | E::NonFiniteLame { .. } => {
                    ("material.youngs_modulus_pa", mm.youngs_modulus_pa)
                }
                E::PoissonRatio { .. } => ("material.poisson_ratio", mm.poisson_ratio),
                E::Density { .. } => ("material.density_kg_m3", mm.density_kg_m3),
            };
            invalid(key, value.to_string(), &e.to_string())
        })?;
        let s = &file.solver;
        let formulation = Formulation::from_name(&s.formulation).ok_or_else(|| {
            invalid("solver.formulation", format!("{:?}", s.formulation), "expected \"energy\" or \"split\"")
        })?;
        if s.substeps == 0 {
            return Err(invalid("solver.substeps", "0".into(), "must be at least 1"));
        }
        if s.iterations == 0 {
            return Err(invalid("solver.iterations", "0".into(), "must be at least 1"));
        }
        positive("solver.frames_per_second", s.frames_per_second, &invalid)?;
        positive("solver.duration_secs", s.duration_secs, &invalid)?;
        non_negative("solver.settle_damping_per_sec", s.settle_damping_per_sec, &invalid)?;
        if let Some(d) = s.quadrature_degree {
            let types: Vec<ElementType> = match &mesh {
                SceneMesh::Box(b) => vec![b.element_type],
                SceneMesh::File { imported, .. } => imported.mesh.blocks.iter().map(|b| b.element_type).collect(),
            };
            for element_type in types {
                let max = hox_sim::fem::quadrature::max_degree(element_type.shape());
                if d == 0 || d > max {
                    return Err(invalid(
                        "solver.quadrature_degree",
                        d.to_string(),
                        &format!("must lie in 1..={max} for {element_type}"),
                    ));
                }
            }
        }
        if formulation == Formulation::Split && material.split_stiffness_pa().iter().any(|k| !(*k > 0.0)) {
            return Err(invalid(
                "material.poisson_ratio",
                mm.poisson_ratio.to_string(),
                "the split formulation needs positive Lamé parameters (ν ≥ 0); use the energy formulation",
            ));
        }
        let settings = SolverSettings {
            substeps: s.substeps,
            iterations: s.iterations,
            frames_per_second: s.frames_per_second,
            formulation,
            quadrature_degree: s.quadrature_degree,
            parallel: s.parallel,
            stability_guard: s.stability_guard,
        };
        for (k, e) in file.effects.iter().enumerate() {
            validate_effect(k, e, &invalid)?;
            if let EffectSpec::Clamp { nodes } | EffectSpec::Prescribed { nodes, .. } = e {
                validate_group(&format!("effects[{k}].nodes"), nodes, &mesh, &invalid)?;
            }
        }
        let mut names = std::collections::HashSet::new();
        for (k, p) in file.probes.iter().enumerate() {
            finite3(&format!("probes[{k}].point_m"), &p.point_m, &invalid)?;
            if !names.insert(p.name.as_str()) {
                return Err(invalid(&format!("probes[{k}].name"), format!("{:?}", p.name), "is used twice"));
            }
        }
        Ok(Scene { source: source.to_string(), base_dir, file, mesh, material, settings })
    }

    pub fn name(&self) -> &str {
        &self.file.name
    }

    /// A scene around a Gmsh mesh file ([`SceneFile::for_mesh_file`]) with its physical groups
    /// `clamps` held and `drives` moved: what `hox simulate --mesh` and the app's "Open mesh"
    /// build. Unknown groups are errors listing the file's groups.
    pub fn from_mesh_file(
        path: &Path,
        clamps: &[String],
        drives: &[Drive],
        gravity: bool,
    ) -> Result<Scene, SceneError> {
        let source = path.display().to_string();
        let base = Scene::from_file(SceneFile::for_mesh_file(path, gravity), &source)?;
        let imported = base.mesh.imported().expect("a mesh-file scene");
        for (group, role) in clamps.iter().map(|g| (g, "clamp")).chain(drives.iter().map(|d| (&d.group, "drive"))) {
            imported.node_set(group).map_err(|e| SceneError::MeshFile(format!("{e} (the {role} group)")))?;
        }
        let mut file = base.file.clone();
        for group in clamps {
            file.effects.push(EffectSpec::Clamp { nodes: NodeSelector::group(group) });
        }
        for d in drives {
            // rotate about the group's centre unless told otherwise
            let origin = match (d.rotation_axis, d.rotation_origin_m) {
                (Some(_), None) => imported.node_set(&d.group).ok().filter(|n| !n.is_empty()).map(|nodes| {
                    let c: Vec3 = nodes.iter().map(|&n| imported.mesh.rest_positions[n as usize]).sum::<Vec3>()
                        / nodes.len() as f64;
                    [c.x, c.y, c.z]
                }),
                (_, o) => o,
            };
            file.effects.push(EffectSpec::Prescribed {
                nodes: NodeSelector::group(&d.group),
                translation_m: d.translation_m,
                rotation_axis: d.rotation_axis,
                rotation_origin_m: origin,
                rotation_deg: d.rotation_deg,
                ramp_secs: d.ramp_secs,
            });
        }
        Scene::validate(file, &source, None, Some(&base.mesh))
    }

    /// Mean displacement of the nodes of every non-empty physical group of the mesh file, for
    /// `positions` (empty for a box scene), metres.
    pub fn group_displacements(&self, positions: &[Vec3]) -> std::collections::BTreeMap<String, [f64; 3]> {
        let Some(imported) = self.mesh.imported() else { return Default::default() };
        let rest = &imported.mesh.rest_positions;
        imported
            .node_sets
            .iter()
            .filter(|(_, nodes)| !nodes.is_empty())
            .map(|(name, nodes)| {
                let sum: Vec3 = nodes.iter().map(|&n| positions[n as usize] - rest[n as usize]).sum();
                let u = sum / nodes.len() as f64;
                (name.clone(), [u.x, u.y, u.z])
            })
            .collect()
    }

    /// The scene with `overrides` applied, validated again.
    pub fn with_overrides(&self, o: &SceneOverrides) -> Result<Scene, SceneError> {
        let mut f = self.file.clone();
        if o.element.is_some() {
            f.mesh.element.clone_from(&o.element);
        }
        if o.grid.is_some() {
            f.mesh.grid = o.grid;
        }
        if o.split.is_some() {
            f.mesh.split.clone_from(&o.split);
        }
        if o.refine.is_some() {
            f.mesh.refine = o.refine;
        }
        if let Some(v) = &o.material {
            f.material.model = v.clone();
        }
        if let Some(v) = o.youngs_modulus_pa {
            f.material.youngs_modulus_pa = v;
        }
        if let Some(v) = o.poisson_ratio {
            f.material.poisson_ratio = v;
        }
        if let Some(v) = o.density_kg_m3 {
            f.material.density_kg_m3 = v;
        }
        if let Some(v) = &o.formulation {
            f.solver.formulation = v.clone();
        }
        if o.quadrature_degree.is_some() {
            f.solver.quadrature_degree = o.quadrature_degree;
        }
        if let Some(v) = o.substeps {
            f.solver.substeps = v;
        }
        if let Some(v) = o.iterations {
            f.solver.iterations = v;
        }
        if let Some(v) = o.frames_per_second {
            f.solver.frames_per_second = v;
        }
        if let Some(v) = o.parallel {
            f.solver.parallel = v;
        }
        if let Some(v) = o.stability_guard {
            f.solver.stability_guard = v;
        }
        Scene::validate(f, &self.source, self.base_dir.clone(), Some(&self.mesh))
    }

    /// Builds the mesh (a mesh file's was read when the scene was validated).
    pub fn build_mesh(&self) -> Result<Mesh, SceneError> {
        match &self.mesh {
            SceneMesh::Box(b) => {
                b.build().map_err(|e| SceneError::Mesh { source_name: self.source.clone(), message: e.to_string() })
            }
            SceneMesh::File { imported, .. } => Ok(imported.mesh.clone()),
        }
    }

    /// The nodes effect `k`'s selector picks in `mesh`; selecting none is an error.
    pub fn selected_nodes(&self, mesh: &Mesh, k: usize, sel: &NodeSelector) -> Result<Vec<u32>, SceneError> {
        let nodes = match (&sel.group, self.mesh.imported()) {
            (Some(name), Some(imported)) => imported
                .node_set(name)
                .map_err(|e| SceneError::Invalid {
                    source_name: self.source.clone(),
                    key: format!("effects[{k}].nodes.group"),
                    value: format!("{name:?}"),
                    reason: e.to_string(),
                })?
                .to_vec(),
            _ => select_nodes(mesh, sel),
        };
        if nodes.is_empty() {
            return Err(SceneError::Invalid {
                source_name: self.source.clone(),
                key: format!("effects[{k}].nodes"),
                value: format!("{sel:?}"),
                reason: "selects no node of the mesh".into(),
            });
        }
        Ok(nodes)
    }

    /// The effects the scene lists, bound to `mesh`'s nodes.
    pub fn build_effects(&self, mesh: &Mesh) -> Result<Vec<Box<dyn Effect>>, SceneError> {
        let mut effects: Vec<Box<dyn Effect>> = Vec::new();
        for (k, e) in self.file.effects.iter().enumerate() {
            let select = |sel: &NodeSelector| self.selected_nodes(mesh, k, sel);
            effects.push(match e {
                EffectSpec::Gravity { acceleration_m_s2 } => Box::new(Gravity::new(Vec3::from(*acceleration_m_s2))),
                EffectSpec::Clamp { nodes } => Box::new(Clamp { nodes: select(nodes)? }),
                EffectSpec::Prescribed { nodes, .. } => {
                    Box::new(e.prescribed(select(nodes)?).expect("a prescribed spec"))
                }
                EffectSpec::Damping { rate_per_sec } => Box::new(Damping { rate_per_sec: *rate_per_sec }),
                EffectSpec::Contact { point_m, normal, velocity_m_s, move_secs, friction } => {
                    Box::new(ContactPlane::new(
                        Vec3::from(*point_m),
                        Vec3::from(*normal),
                        Vec3::from(*velocity_m_s),
                        move_secs.unwrap_or(f64::INFINITY),
                        *friction,
                    ))
                }
            });
        }
        Ok(effects)
    }
}

/// Nodes picked by a selector. Plane selection uses a tolerance of 1e-9 × the body's size.
pub fn select_nodes(mesh: &Mesh, sel: &NodeSelector) -> Vec<u32> {
    let (lo, hi) = mesh.bounding_box();
    let tol = 1e-9 * (hi - lo).norm().max(1e-300);
    if let (Some(plane), Some(at)) = (&sel.plane, sel.at_m) {
        let d = axis_index(plane).unwrap_or(0);
        return mesh.nodes_where(|p| (p[d] - at).abs() <= tol);
    }
    if let (Some(a), Some(b)) = (sel.box_min_m, sel.box_max_m) {
        return mesh.nodes_where(|p| (0..3).all(|d| p[d] >= a[d] - tol && p[d] <= b[d] + tol));
    }
    Vec::new()
}

fn axis_index(name: &str) -> Option<usize> {
    match name.to_ascii_lowercase().as_str() {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}

type Invalid<'a> = dyn Fn(&str, String, &str) -> SceneError + 'a;

fn finite3(key: &str, v: &[f64; 3], invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if v.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(invalid(key, format!("{v:?}"), "must be finite")) }
}

fn positive(key: &str, v: f64, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 { Ok(()) } else { Err(invalid(key, v.to_string(), "must be a finite positive number")) }
}

fn non_negative(key: &str, v: f64, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 { Ok(()) } else { Err(invalid(key, v.to_string(), "must be finite and not negative")) }
}

fn validate_selector(key: &str, sel: &NodeSelector, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if sel.group.is_some() {
        return if sel.plane.is_none() && sel.at_m.is_none() && sel.box_min_m.is_none() && sel.box_max_m.is_none() {
            Ok(())
        } else {
            Err(invalid(key, format!("{sel:?}"), "give a group alone, not with a plane or box"))
        };
    }
    match (&sel.plane, sel.at_m, sel.box_min_m, sel.box_max_m) {
        (Some(p), Some(at), None, None) => {
            if axis_index(p).is_none() {
                return Err(invalid(&format!("{key}.plane"), format!("{p:?}"), "expected \"x\", \"y\" or \"z\""));
            }
            if !at.is_finite() {
                return Err(invalid(&format!("{key}.at_m"), at.to_string(), "must be finite"));
            }
            Ok(())
        }
        (None, None, Some(a), Some(b)) => {
            finite3(&format!("{key}.box_min_m"), &a, invalid)?;
            finite3(&format!("{key}.box_max_m"), &b, invalid)
        }
        _ => Err(invalid(key, format!("{sel:?}"), "give either plane and at_m, box_min_m and box_max_m, or group")),
    }
}

/// A group selector needs a mesh file that has the group.
fn validate_group(key: &str, sel: &NodeSelector, mesh: &SceneMesh, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    let Some(name) = &sel.group else { return Ok(()) };
    match mesh.imported() {
        None => Err(invalid(
            &format!("{key}.group"),
            format!("{name:?}"),
            "physical groups need a mesh file ([mesh] file = \"….msh\")",
        )),
        Some(imported) => imported
            .node_set(name)
            .map(|_| ())
            .map_err(|e| invalid(&format!("{key}.group"), format!("{name:?}"), &e.to_string())),
    }
}

/// The scene's mesh: a box from its fields, or the file (read now, or reused from `cached`).
fn mesh_of(
    m: &MeshSpec,
    source: &str,
    base_dir: Option<&Path>,
    cached: Option<&SceneMesh>,
    invalid: &Invalid<'_>,
) -> Result<SceneMesh, SceneError> {
    if let Some(file) = &m.file {
        let box_keys = [
            ("mesh.box_min_m", m.box_min_m.is_some()),
            ("mesh.box_max_m", m.box_max_m.is_some()),
            ("mesh.element", m.element.is_some()),
            ("mesh.grid", m.grid.is_some()),
            ("mesh.split", m.split.is_some()),
            ("mesh.refine", m.refine.is_some()),
        ];
        if let Some((key, _)) = box_keys.iter().find(|(_, given)| *given) {
            return Err(invalid(
                key,
                "given".into(),
                &format!(
                    "the mesh is read from {file}; box_min_m, box_max_m, element, grid, split and refine describe box meshes"
                ),
            ));
        }
        let path = match base_dir {
            Some(dir) if Path::new(file).is_relative() => dir.join(file),
            _ => PathBuf::from(file),
        };
        if let Some(SceneMesh::File { path: p, imported }) = cached
            && *p == path
        {
            return Ok(SceneMesh::File { path, imported: imported.clone() });
        }
        let imported = hox_sim::io::gmsh::read_msh(&path).map_err(|e| {
            // a scene built from the mesh file alone (`--mesh`) is named by the file already
            if source == path.display().to_string() {
                SceneError::MeshFile(e.to_string())
            } else {
                SceneError::Mesh { source_name: source.to_string(), message: e.to_string() }
            }
        })?;
        return Ok(SceneMesh::File { path, imported: Arc::new(imported) });
    }
    let missing = |key: &str| {
        invalid(
            key,
            "missing".into(),
            "a box mesh needs box_min_m, box_max_m, element and grid (or give file = \"….msh\")",
        )
    };
    let box_min_m = m.box_min_m.ok_or_else(|| missing("mesh.box_min_m"))?;
    let box_max_m = m.box_max_m.ok_or_else(|| missing("mesh.box_max_m"))?;
    let element = m.element.as_deref().ok_or_else(|| missing("mesh.element"))?;
    let grid = m.grid.ok_or_else(|| missing("mesh.grid"))?;
    let split = m.split.as_deref().unwrap_or("five");
    let element_type = ElementType::from_name(element).ok_or_else(|| {
        invalid("mesh.element", format!("{element:?}"), &format!("expected one of {}", ElementType::names()))
    })?;
    let split = TetSplit::from_name(split)
        .ok_or_else(|| invalid("mesh.split", format!("{split:?}"), "expected \"five\" or \"six\""))?;
    finite3("mesh.box_min_m", &box_min_m, invalid)?;
    finite3("mesh.box_max_m", &box_max_m, invalid)?;
    for d in 0..3 {
        if box_max_m[d] <= box_min_m[d] {
            return Err(invalid(
                "mesh.box_max_m",
                format!("{box_max_m:?}"),
                "must exceed box_min_m in every direction",
            ));
        }
        if grid[d] == 0 {
            return Err(invalid("mesh.grid", format!("{grid:?}"), "needs at least one cell per direction"));
        }
    }
    Ok(SceneMesh::Box(BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::from(box_min_m), max_m: Vec3::from(box_max_m), cells: grid },
        element_type,
        split,
        refine: m.refine.unwrap_or(0),
    }))
}

fn validate_effect(k: usize, e: &EffectSpec, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    let key = |f: &str| format!("effects[{k}].{f}");
    match e {
        EffectSpec::Gravity { acceleration_m_s2 } => finite3(&key("acceleration_m_s2"), acceleration_m_s2, invalid),
        EffectSpec::Clamp { nodes } => validate_selector(&key("nodes"), nodes, invalid),
        EffectSpec::Prescribed { nodes, translation_m, rotation_axis, rotation_origin_m, rotation_deg, ramp_secs } => {
            validate_selector(&key("nodes"), nodes, invalid)?;
            finite3(&key("translation_m"), translation_m, invalid)?;
            if let Some(a) = rotation_axis {
                finite3(&key("rotation_axis"), a, invalid)?;
                if Vec3::from(*a).norm() == 0.0 {
                    return Err(invalid(&key("rotation_axis"), format!("{a:?}"), "must not be zero"));
                }
            }
            if let Some(o) = rotation_origin_m {
                finite3(&key("rotation_origin_m"), o, invalid)?;
            }
            if !rotation_deg.is_finite() {
                return Err(invalid(&key("rotation_deg"), rotation_deg.to_string(), "must be finite"));
            }
            if *rotation_deg != 0.0 && rotation_axis.is_none() {
                return Err(invalid(&key("rotation_axis"), "missing".into(), "a rotation needs an axis"));
            }
            non_negative(&key("ramp_secs"), *ramp_secs, invalid)
        }
        EffectSpec::Damping { rate_per_sec } => non_negative(&key("rate_per_sec"), *rate_per_sec, invalid),
        EffectSpec::Contact { point_m, normal, velocity_m_s, move_secs, friction } => {
            finite3(&key("point_m"), point_m, invalid)?;
            finite3(&key("normal"), normal, invalid)?;
            if Vec3::from(*normal).norm() == 0.0 {
                return Err(invalid(&key("normal"), format!("{normal:?}"), "must not be zero"));
            }
            finite3(&key("velocity_m_s"), velocity_m_s, invalid)?;
            if let Some(t) = move_secs {
                non_negative(&key("move_secs"), *t, invalid)?;
            }
            non_negative(&key("friction"), *friction, invalid)
        }
    }
}
