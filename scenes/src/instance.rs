//! A scene built: into a running simulation with its probes ([`Instance`]), or into its static
//! problem and solved ([`solve_static`]).

use hox_sim::measure::probe::Probe;
use hox_sim::solver::Simulation;

use crate::error::SceneError;
use crate::scene::{EffectSpec, Scene};

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
    // the formulation's material: the mixed one measures its hydrostatic term per element (per
    // node patch on P1), which the static solver assembles as Newton does whatever the scene's
    // solver
    let settings = hox_sim::solver::SolverSettings { method: hox_sim::solver::Method::Newton, ..scene.settings() };
    let material = settings.formulated(&scene.material(), mesh).map_err(|e| SceneError::Simulation {
        source_name: scene.source.clone(),
        message: format!("static solve: {e}"),
    })?;
    let problem = hox_sim::solver::statics::StaticProblem {
        mesh,
        material,
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
