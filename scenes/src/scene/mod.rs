//! Scenes: a scene is data — a TOML file ([`file`] documents the format) naming its mesh,
//! material and solver parameters (the parameter table, [`crate::params`]), the effects it needs
//! and its probes. This room reads it ([`file`]), checks it ([`validate`]), applies overrides
//! (here) and builds the mesh and effects ([`build`]).

pub mod build;
pub mod builtin;
pub mod file;
pub mod validate;

pub use build::select_nodes;
pub use builtin::{BUILTIN_MESHES, OPENED_PREFIX, builtin_mesh, open_mesh_bytes};
pub use file::{EffectSpec, NodeSelector, ProbeSpec, SceneFile};
pub(crate) use validate::invalid_in;

use hox_sim::Vec3;
use hox_sim::io::gmsh::ImportedMesh;
use hox_sim::material::Material;
use hox_sim::mesh::structured::BoxMeshSpec;
use hox_sim::solver::{NewtonSettings, SolverSettings, VbdSettings};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::SceneError;
use crate::params::{Params, SceneOverrides};

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

/// A validated scene: its file (every parameter once, in `file.params`) and its mesh source.
/// The material is built from the parameters once, when the scene is validated
/// ([`Scene::material`]); the solver settings are derived from them ([`Scene::settings`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Where the scene came from (a file path or `builtin:NAME`), for error messages.
    pub source: String,
    /// The folder relative mesh file paths are resolved against (the scene file's folder).
    pub base_dir: Option<PathBuf>,
    pub file: SceneFile,
    pub mesh: SceneMesh,
    /// The material `file.params` describe, built (and so checked by [`Material::new`]) once by
    /// [`Scene::validate`].
    material: Material,
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

impl Scene {
    /// Parses and validates a scene file's text. `source` names it in errors; a mesh file is
    /// looked for relative to the working directory.
    pub fn from_toml(text: &str, source: &str) -> Result<Scene, SceneError> {
        Scene::from_toml_in(text, source, None)
    }

    /// Like [`Scene::from_toml`], with relative mesh file paths resolved against `base_dir`.
    pub fn from_toml_in(text: &str, source: &str, base_dir: Option<&Path>) -> Result<Scene, SceneError> {
        let file = SceneFile::parse(text, source)?;
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

    /// Every parameter of the scene.
    pub fn params(&self) -> &Params {
        &self.file.params
    }

    /// Whether the mesh is a structured box (element, split, grid and refinement apply).
    pub fn is_box(&self) -> bool {
        self.mesh.as_box().is_some()
    }

    /// What the mesh is: a box, one mesh file, or one file per element type (which mesh
    /// parameters apply: [`crate::params::Param::used_with`]).
    pub fn mesh_kind(&self) -> crate::params::MeshKind {
        self.file.mesh_kind()
    }

    /// The material the parameters describe (built when the scene was validated).
    pub fn material(&self) -> Material {
        self.material
    }

    /// The solver settings the parameters describe.
    pub fn settings(&self) -> SolverSettings {
        let p = &self.file.params;
        SolverSettings {
            substeps: p.substeps,
            iterations: p.iterations,
            frames_per_second: p.frames_per_second,
            formulation: p.formulation,
            quadrature_degree: p.quadrature_degree,
            sweep: p.sweep,
            stability_guard: p.stability_guard,
            method: p.method,
            steps_per_frame: p.steps_per_frame,
            integrator: p.integrator,
            vbd: VbdSettings {
                iterations: p.vbd_iterations,
                chebyshev_rho: p.chebyshev_rho,
                coarse_cells: p.vbd_coarse_cells,
                init: p.vbd_init,
                ..VbdSettings::default()
            },
            newton: NewtonSettings {
                tolerance: p.newton_tolerance,
                max_iterations: u32::try_from(p.newton_iterations).unwrap_or(u32::MAX),
                policy: p.newton_policy,
                ..Default::default()
            },
        }
    }

    /// The scene with `overrides` applied, validated again. An override's bad value is named by
    /// its command-line flag too (`mesh.refine (--refine) = 5: …`).
    pub fn with_overrides(&self, o: &SceneOverrides) -> Result<Scene, SceneError> {
        let mut f = self.file.clone();
        for (p, v) in o.iter() {
            (p.set)(&mut f.params, v);
            f.given.insert(p.key);
        }
        Scene::validate(f, &self.source, self.base_dir.clone(), Some(&self.mesh)).map_err(|e| match e {
            SceneError::Invalid { source_name, key, value, reason } => {
                // an override's key as the user gave it, too
                let key = match o.iter().find(|(p, _)| p.file_path() == key) {
                    Some((p, _)) => format!("{key} ({})", p.flag()),
                    None => key,
                };
                SceneError::Invalid { source_name, key, value, reason }
            }
            e => e,
        })
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
        base.with_groups(clamps, drives)
    }

    /// [`Scene::from_mesh_file`] for a mesh already in memory ([`ImportedMesh::from_arrays`]:
    /// the Python package's numpy and meshio meshes), named `name` (its scene file names it as
    /// its mesh file; nothing is read from disk, and [`Scene::with_overrides`] keeps the mesh).
    pub fn from_imported(
        name: &str,
        imported: Arc<ImportedMesh>,
        clamps: &[String],
        drives: &[Drive],
        gravity: bool,
    ) -> Result<Scene, SceneError> {
        let path = PathBuf::from(name);
        let cached = SceneMesh::File { path: path.clone(), imported };
        let base = Scene::validate(SceneFile::for_mesh_file(&path, gravity), name, None, Some(&cached))?;
        base.with_groups(clamps, drives)
    }

    /// The scene with `probes` added (a probe of the same name replaced), validated again: a
    /// point outside the mesh is an error naming the probe when the scene is built.
    pub fn with_probes(&self, probes: &[ProbeSpec]) -> Result<Scene, SceneError> {
        let mut file = self.file.clone();
        for probe in probes {
            file.probes.retain(|p| p.name != probe.name);
            file.probes.push(probe.clone());
        }
        Scene::validate(file, &self.source, self.base_dir.clone(), Some(&self.mesh))
    }

    /// A mesh-file scene with its groups `clamps` held and `drives` moved.
    fn with_groups(self, clamps: &[String], drives: &[Drive]) -> Result<Scene, SceneError> {
        let (base, source) = (&self, self.source.clone());
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
}
