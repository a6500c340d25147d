//! Settled XPBD on the paper's P2 bending beam (160 elements), run with the substeps the study
//! reports as sufficient (70), lands within 1 % of the static solution on the same mesh, with
//! both formulations.

use hox_scenes::{Instance, RunMode, SceneOverrides};

#[test]
fn p2_160_at_70_substeps_settles_within_one_percent_of_the_static_solution() {
    let scene = hox_scenes::by_name("bending").unwrap();
    let mesh = scene.build_mesh().unwrap();
    let (acceleration, dirichlet) = hox_scenes::static_problem(&scene, &mesh).unwrap();
    let problem = hox_sim::solver::statics::StaticProblem {
        mesh: &mesh,
        material: scene.material(),
        quadrature_degree: None,
        acceleration_m_s2: acceleration,
        dirichlet,
        tolerance: 1e-8,
        load_steps: 1,
    };
    let statics = hox_sim::solver::statics::solve(&problem, &mut |_, _, _| {}).unwrap();
    let probe = hox_sim::measure::probe::Probe::locate(&mesh, "tip", hox_sim::Vec3::new(2.0, 0.25, 0.25)).unwrap();
    let u_static = probe.displacement(&statics.positions, &mesh.rest_positions);
    for formulation in ["energy", "split"] {
        let at = |substeps: u32| {
            let s = scene
                .with_overrides(&SceneOverrides {
                    substeps: Some(substeps),
                    formulation: Some(hox_sim::xpbd::constraint::Formulation::from_name(formulation).unwrap()),
                    ..Default::default()
                })
                .unwrap();
            let mut inst = Instance::new(s).unwrap();
            let report = hox_scenes::run(&mut inst, RunMode::SETTLE, &mut |_, _| {}).unwrap();
            assert!(report.at_rest, "{formulation} at {substeps} substeps did not come to rest");
            let u = hox_sim::Vec3::from(report.probes["tip"]);
            (u - u_static).norm() / u_static.norm()
        };
        let (paper, sufficient) = (at(50), at(70));
        assert!(sufficient < 0.01, "{formulation}: {:.3} % off the static solution at 70 substeps", 100.0 * sufficient);
        assert!(paper > sufficient, "{formulation}: more substeps must reduce the bias ({paper} → {sufficient})");
    }
}
