//! The scene registry: the one list of scenes the CLI, the app, tests and benchmarks read.
//!
//! Each built-in scene is a TOML file in `assets/scenes/` (embedded in the binary, so `hox`
//! runs from anywhere); [`scene`] documents the format. [`Instance`] builds a scene into a
//! running simulation with its probes, and [`run`] advances it for a time or until it settles.
//! [`bench`] times the bending scene's beam (`hox bench`).

pub mod bench;
pub mod lesson;
pub mod paper;
pub mod params;
pub mod reference;
pub mod run;
pub mod scene;
pub mod study;

pub use params::{Params, SceneOverrides};
pub use run::{
    RestWatch, RunMode, RunReport, SETTLE_CAP_SECS, SETTLE_DAMPING_NAME, SETTLE_EQUILIBRIUM_FRAMES, SETTLE_FRAMES,
    SETTLE_KINETIC_REL, SETTLE_RESIDUAL_REL, SettleState, Settler, driven_until_secs, in_equilibrium, median, run,
    run_observed,
};
pub use scene::{BUILTIN_MESHES, Drive, NodeSelector, Scene, SceneFile, SceneMesh, builtin_mesh};

use hox_sim::measure::probe::Probe;
use hox_sim::solver::Simulation;

/// The built-in scenes: (name, TOML text). Adding a scene: its file plus one line here.
pub const BUILTIN: &[(&str, &str)] = &[
    ("bending", include_str!("../../assets/scenes/bending.toml")),
    ("tension", include_str!("../../assets/scenes/tension.toml")),
    ("torsion", include_str!("../../assets/scenes/torsion.toml")),
    ("drop", include_str!("../../assets/scenes/drop.toml")),
    ("twist", include_str!("../../assets/scenes/twist.toml")),
    ("squash", include_str!("../../assets/scenes/squash.toml")),
    ("tube", include_str!("../../assets/scenes/tube.toml")),
    ("elbow", include_str!("../../assets/scenes/elbow.toml")),
    ("hook", include_str!("../../assets/scenes/hook.toml")),
];

/// The paper's three scenes.
pub const PAPER_SCENES: [&str; 3] = ["bending", "tension", "torsion"];

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("unknown scene '{name}' (available: {available})")]
    Unknown { name: String, available: String },
    #[error("{source_name}: {message}")]
    Parse { source_name: String, message: String },
    #[error("{source_name}: {key} = {value}: {reason}")]
    Invalid { source_name: String, key: String, value: String, reason: String },
    #[error("cannot read scene file {path}: {message}")]
    Io { path: String, message: String },
    #[error("{source_name}: cannot build the mesh: {message}")]
    Mesh { source_name: String, message: String },
    /// A mesh file's own error (it names the file).
    #[error("{0}")]
    MeshFile(String),
    #[error("{source_name}: {message}")]
    Simulation { source_name: String, message: String },
    #[error("{source_name}: {message}")]
    Probe { source_name: String, message: String },
}

/// Names of the built-in scenes, comma-separated.
pub fn names() -> String {
    BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// Every built-in scene, parsed and validated.
pub fn registry() -> Result<Vec<Scene>, SceneError> {
    BUILTIN.iter().map(|(n, text)| Scene::from_toml(text, &format!("builtin:{n}"))).collect()
}

/// A built-in scene by name.
pub fn by_name(name: &str) -> Result<Scene, SceneError> {
    let (n, text) = BUILTIN
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| SceneError::Unknown { name: name.to_string(), available: names() })?;
    Scene::from_toml(text, &format!("builtin:{n}"))
}

/// A scene built into a running simulation.
pub struct Instance {
    pub scene: Scene,
    pub sim: Simulation,
    pub probes: Vec<Probe>,
}

impl Instance {
    /// Builds the mesh, effects, simulation and probes of `scene`.
    pub fn new(scene: Scene) -> Result<Instance, SceneError> {
        let mesh = scene.build_mesh()?;
        let effects = scene.build_effects(&mesh)?;
        let probes = scene
            .file
            .probes
            .iter()
            .map(|p| Probe::locate(&mesh, &p.name, hox_sim::Vec3::from(p.point_m)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| SceneError::Probe { source_name: scene.source.clone(), message: e.to_string() })?;
        let sim = Simulation::new(mesh, scene.material(), scene.settings(), effects)
            .map_err(|e| SceneError::Simulation { source_name: scene.source.clone(), message: e.to_string() })?;
        Ok(Instance { scene, sim, probes })
    }

    /// Mean current displacement of the nodes of every physical group of the mesh file (empty
    /// for a box scene), metres.
    pub fn group_displacements(&self) -> std::collections::BTreeMap<String, [f64; 3]> {
        self.scene.group_displacements(&self.sim.positions)
    }

    /// Writes the current state as the next frame of `series`: current positions,
    /// `displacement_m` per point and the volume-averaged von Mises stress per cell
    /// (`von_mises_stress_pa`); see [`hox_sim::io::vtk`].
    pub fn write_vtk_frame(&self, series: &mut hox_sim::io::vtk::PvdSeries) -> Result<std::path::PathBuf, SceneError> {
        use hox_sim::io::vtk::{DataArray, von_mises_stress_pa};
        let sim = &self.sim;
        let stress = von_mises_stress_pa(sim.mesh(), sim.geometry(), sim.material(), &sim.positions);
        series
            .write_frame(
                sim.time_secs(),
                sim.mesh(),
                &sim.positions,
                &[],
                &[DataArray::scalars("von_mises_stress_pa", stress)],
            )
            .map_err(|e| SceneError::Simulation { source_name: self.scene.source.clone(), message: e.to_string() })
    }

    /// Current displacement of every probe, metres.
    pub fn probe_displacements(&self) -> Vec<(String, [f64; 3])> {
        self.probes
            .iter()
            .map(|p| {
                let u = p.displacement(&self.sim.positions, &self.sim.mesh().rest_positions);
                (p.name.clone(), [u.x, u.y, u.z])
            })
            .collect()
    }
}

/// Solves the static equilibrium of `scene` on `mesh` ([`static_problem`] with
/// [`hox_sim::solver::statics::solve`]); `progress` as there.
pub fn solve_static(
    scene: &Scene,
    mesh: &hox_sim::mesh::Mesh,
    tolerance: f64,
    load_steps: usize,
    progress: hox_sim::solver::statics::Progress<'_>,
) -> Result<hox_sim::solver::statics::StaticSolution, SceneError> {
    let (acceleration_m_s2, dirichlet) = static_problem(scene, mesh)?;
    let problem = hox_sim::solver::statics::StaticProblem {
        mesh,
        material: scene.material(),
        quadrature_degree: scene.settings().quadrature_degree,
        acceleration_m_s2,
        dirichlet,
        tolerance,
        load_steps,
    };
    hox_sim::solver::statics::solve(&problem, progress).map_err(|e| SceneError::Simulation {
        source_name: scene.source.clone(),
        message: format!("static solve: {e}"),
    })
}

/// The static problem of a scene: body acceleration and Dirichlet conditions (clamped nodes at
/// rest, prescribed ones moved to their final, fully ramped positions). Contact has no static
/// counterpart here and is refused; damping does not change the equilibrium.
pub fn static_problem(
    scene: &Scene,
    mesh: &hox_sim::mesh::Mesh,
) -> Result<(hox_sim::Vec3, Vec<hox_sim::effect::Prescribed>), SceneError> {
    use scene::EffectSpec;
    let mut acceleration = hox_sim::Vec3::zeros();
    let mut dirichlet = Vec::new();
    for (k, spec) in scene.file.effects.iter().enumerate() {
        let select = |nodes| scene.selected_nodes(mesh, k, nodes);
        match spec {
            EffectSpec::Gravity { acceleration_m_s2 } => acceleration += hox_sim::Vec3::from(*acceleration_m_s2),
            EffectSpec::Clamp { nodes } => dirichlet.push(hox_sim::solver::statics::clamp(select(nodes)?)),
            EffectSpec::Prescribed { nodes, .. } => {
                let mut p = spec.prescribed(select(nodes)?).expect("a prescribed spec");
                p.ramp_secs = 1.0; // evaluated at "time" = load fraction
                dirichlet.push(p);
            }
            EffectSpec::Damping { .. } => {}
            EffectSpec::Contact { .. } => {
                return Err(SceneError::Invalid {
                    source_name: scene.source.clone(),
                    key: format!("effects[{k}]"),
                    value: "contact".into(),
                    reason: "a static solution with contact is not supported".into(),
                });
            }
        }
    }
    Ok((acceleration, dirichlet))
}

#[cfg(test)]
mod tests;
