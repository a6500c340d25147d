//! The mixed formulation (`crate::fem::energy::mixed`) through the solvers: the static solver,
//! Newton, VBD and XPBD minimise its energy, and it is refused by name where it cannot run.

use super::tests::{G, beam, clamped_at_x0};
use super::*;
use crate::Vec3;
use crate::effect::{Clamp, Damping, Effect, Gravity};
use crate::element::ElementType;
use crate::material::{Material, MaterialModel, VolumeMeasure};
use crate::mesh::Mesh;
use crate::xpbd::constraint::Formulation;

/// Static tip deflection (z, m) of `mesh` clamped at x = 0 under gravity, the material's volume
/// measured as `measure`.
fn static_tip_z(mesh: &Mesh, material: Material, measure: VolumeMeasure) -> f64 {
    let problem = statics::StaticProblem {
        mesh,
        material: material.with_volume_measure(measure).unwrap(),
        quadrature_degree: None,
        acceleration_m_s2: G,
        dirichlet: vec![statics::clamp(clamped_at_x0(mesh))],
        tolerance: 1e-10,
        load_steps: 1,
    };
    let x = statics::solve(&problem, &mut |_, _, _| {}).unwrap().positions;
    tip_z(mesh, &x)
}

/// The mean z displacement of the nodes at x = 1 (the beam's end).
fn tip_z(mesh: &Mesh, x: &[Vec3]) -> f64 {
    let tip = mesh.nodes_where(|p| (p.x - 1.0).abs() < 1e-12);
    tip.iter().map(|&n| x[n as usize].z - mesh.rest_positions[n as usize].z).sum::<f64>() / tip.len() as f64
}

/// A stiff StVK (E = 10⁸ Pa: a sag of a few millimetres, the linear regime) at `nu`.
fn stiff(nu: f64) -> Material {
    Material::new(MaterialModel::StVenantKirchhoff, 1.0e8, nu, 1000.0).unwrap()
}

#[test]
fn the_mixed_formulation_gives_a_locked_p2_beam_its_sag_back() {
    // locking's symptom: the pointwise sag falls as ν → 0.5 (the volume constrained at every
    // point); measured once per element it stays (the body's own sag changes by a few per cent
    // between ν = 0.3 and 0.4999), and it is the sag of the finer mixed beam within
    // the coarse mesh's own error (one element through the thickness; 0.2 % on 8×2×2 at 0.499,
    // docs/study/locking.md)
    let p2 = ElementType::from_name("p2").unwrap();
    let (coarse, fine) = (beam(p2, [4, 1, 1]), beam(p2, [8, 2, 2]));
    let sag = |mesh: &Mesh, nu: f64, m: VolumeMeasure| static_tip_z(mesh, stiff(nu), m);
    let [point, mixed] =
        [VolumeMeasure::Point, VolumeMeasure::Element].map(|m| [sag(&coarse, 0.3, m), sag(&coarse, 0.4999, m)]);
    let reference = sag(&fine, 0.4999, VolumeMeasure::Element);
    let seen = format!("ν = 0.3, 0.4999: point {point:?}, mixed {mixed:?}; fine mixed at 0.4999 {reference}");
    assert!(point[1] / point[0] < 0.8, "the pointwise P2 beam should lock: {seen}");
    assert!((mixed[1] / mixed[0] - 1.0).abs() < 0.03, "the mixed P2 beam should not: {seen}");
    assert!(1.0 - point[1] / reference > 0.25, "{seen}");
    assert!((1.0 - mixed[1] / reference).abs() < 0.15, "{seen}");
}

fn settings(method: Method, formulation: Formulation) -> SolverSettings {
    SolverSettings { method, formulation, frames_per_second: 60.0, ..SolverSettings::default() }
}

fn effects(mesh: &Mesh, damping_per_sec: f64) -> Vec<Box<dyn Effect>> {
    vec![
        Box::new(Gravity::new(G)),
        Box::new(Clamp { nodes: clamped_at_x0(mesh) }),
        Box::new(Damping { rate_per_sec: damping_per_sec }),
    ]
}

#[test]
fn every_solver_runs_the_mixed_formulation_towards_its_static_equilibrium() {
    let mesh = beam(ElementType::from_name("p2").unwrap(), [2, 1, 1]);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 2.0e5, 0.49, 1000.0).unwrap();
    let reference = static_tip_z(&mesh, material, VolumeMeasure::Element);
    let plain = static_tip_z(&mesh, material, VolumeMeasure::Point);
    assert!(reference < plain * 1.02, "mixed {reference} vs plain {plain}: the mixed beam is softer");
    for method in Method::ALL {
        let mut sim =
            Simulation::new(mesh.clone(), material, settings(method, Formulation::Mixed), effects(&mesh, 8.0))
                .unwrap_or_else(|e| panic!("{method}: {e}"));
        assert_eq!(sim.material().volume_measure, VolumeMeasure::Element, "{method}");
        for _ in 0..240 {
            sim.step_frame().unwrap_or_else(|e| panic!("{method}: {e}"));
        }
        let tip = tip_z(&mesh, &sim.positions);
        assert!(
            (tip / reference - 1.0).abs() < 0.02,
            "{method}: settled tip {tip} against the mixed static {reference}"
        );
    }
}

#[test]
fn every_solver_runs_the_p1_patch_pressure_towards_its_static_equilibrium() {
    // Newton: the sparse pattern widened to the patches (nodes two edges apart), the frame's
    // potential with the patch energy; Newton-CG: the patch terms beside the element Hessians;
    // XPBD: a deviatoric constraint per element and per node patch with a hydrostatic one, whose
    // potential is the same energy; VBD: each node's update reading every patch around it. All
    // settle on the static mixed P1 beam, softer than the pointwise one, at ν = 0.4999
    let mesh = beam(ElementType::from_name("p1").unwrap(), [8, 2, 2]);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 2.0e5, 0.4999, 1000.0).unwrap();
    let reference = static_tip_z(&mesh, material, VolumeMeasure::Element);
    let plain = static_tip_z(&mesh, material, VolumeMeasure::Point);
    assert!(reference < plain * 1.05, "patch {reference} vs plain {plain}: the patch beam is softer");
    for (method, tolerance) in
        [(Method::Newton, 0.02), (Method::NewtonCg, 0.02), (Method::Xpbd, 0.05), (Method::Vbd, 0.05)]
    {
        let mut sim =
            Simulation::new(mesh.clone(), material, settings(method, Formulation::Mixed), effects(&mesh, 8.0))
                .unwrap_or_else(|e| panic!("{method}: {e}"));
        assert_eq!(sim.material().volume_measure, VolumeMeasure::Element);
        for _ in 0..240 {
            sim.step_frame().unwrap_or_else(|e| panic!("{method}: {e}"));
        }
        let tip = tip_z(&mesh, &sim.positions);
        assert!(
            (tip / reference - 1.0).abs() < tolerance,
            "{method}: settled tip {tip} against the patch static {reference} (plain {plain})"
        );
    }
}

/// The symptom a split projected one term after the other would show: a P1 beam at rest in the
/// mixed formulation, with no load, stays at rest under XPBD (the deviatoric and hydrostatic
/// terms both vanish at rest with their gradients).
#[test]
fn xpbd_keeps_a_p1_beam_at_rest_in_the_mixed_formulation() {
    let mesh = beam(ElementType::from_name("p1").unwrap(), [4, 1, 1]);
    for model in [MaterialModel::StVenantKirchhoff, MaterialModel::NeoHookean] {
        let material = Material::new(model, 2.0e5, 0.499, 1000.0).unwrap();
        let effects: Vec<Box<dyn Effect>> = vec![Box::new(Clamp { nodes: clamped_at_x0(&mesh) })];
        let mut sim =
            Simulation::new(mesh.clone(), material, settings(Method::Xpbd, Formulation::Mixed), effects).unwrap();
        for _ in 0..10 {
            sim.step_frame().unwrap();
        }
        let moved = sim.positions.iter().zip(&mesh.rest_positions).map(|(x, r)| (x - r).amax()).fold(0.0, f64::max);
        assert!(moved < 1e-12, "{model:?}: a rest beam moved {moved} m");
    }
}

#[test]
fn switching_to_the_mixed_formulation_in_a_run_changes_the_energy_and_back() {
    let mesh = beam(ElementType::from_name("q2").unwrap(), [2, 1, 1]);
    let material = Material::new(MaterialModel::NeoHookean, 2.0e5, 0.45, 1000.0).unwrap();
    let mut sim =
        Simulation::new(mesh.clone(), material, settings(Method::Newton, Formulation::Energy), effects(&mesh, 0.0))
            .unwrap();
    for _ in 0..5 {
        sim.step_frame().unwrap();
    }
    let plain = sim.elastic_energy_j();
    sim.set_settings(settings(Method::Newton, Formulation::Mixed)).unwrap();
    assert_eq!(sim.material().volume_measure, VolumeMeasure::Element);
    let mixed = sim.elastic_energy_j();
    assert!(mixed < plain && mixed > 0.5 * plain, "plain {plain} J, mixed {mixed} J at the same state");
    // a new material keeps the formulation's measure
    sim.set_material(Material::new(MaterialModel::NeoHookean, 3.0e5, 0.45, 1000.0).unwrap()).unwrap();
    assert_eq!(sim.material().volume_measure, VolumeMeasure::Element);
    sim.set_settings(settings(Method::Newton, Formulation::Energy)).unwrap();
    assert_eq!(sim.material().volume_measure, VolumeMeasure::Point);
    sim.step_frame().unwrap();
}

#[test]
fn the_mixed_formulation_is_refused_by_name_where_it_cannot_run() {
    let material = Material::new(MaterialModel::StVenantKirchhoff, 2.0e5, 0.49, 1000.0).unwrap();
    let (p1, q1) = (ElementType::from_name("p1").unwrap(), ElementType::from_name("q1").unwrap());
    let refused = |et: ElementType, method: Method| {
        let mesh = beam(et, [2, 1, 1]);
        Simulation::new(mesh.clone(), material, settings(method, Formulation::Mixed), effects(&mesh, 0.0))
            .err()
            .map(|e| e.to_string())
    };
    let err = refused(q1, Method::Newton).expect("Q1 mixed refused");
    assert!(err.contains("inf–sup") && err.contains("Q1"), "{err}");
    // P1's pressure per node patch runs on every solver
    for method in Method::ALL {
        assert_eq!(refused(p1, method), None, "P1 mixed on {method:?}");
    }
    let mesh = beam(ElementType::from_name("p2").unwrap(), [2, 1, 1]);
    let snh = Material::new(MaterialModel::StableNeoHookean, 2.0e5, 0.49, 1000.0).unwrap();
    let err = Simulation::new(mesh.clone(), snh, settings(Method::Xpbd, Formulation::Mixed), effects(&mesh, 0.0))
        .err()
        .expect("snh refused")
        .to_string();
    assert!(err.contains("snh") && err.contains("use stvk or nh"), "{err}");
    // and a running simulation keeps its formulation when asked for a material it cannot measure so
    let mut sim =
        Simulation::new(mesh.clone(), material, settings(Method::Newton, Formulation::Mixed), effects(&mesh, 0.0))
            .unwrap();
    assert!(sim.set_material(snh).is_err());
    assert_eq!(sim.material().model, MaterialModel::StVenantKirchhoff);
}

/// Issue #62's acceptance, "no pressure checkerboard": the element pressures of the mixed P2 beam
/// at ν = 0.4999 vary smoothly. A checkerboard alternates between neighbours, so the mean jump
/// across a shared face is about twice the pressures' standard deviation; a smooth field (the
/// bending beam's pressure runs linearly through its thickness, tension above, compression
/// below) jumps across faces by a fraction of it. Both figures are stated.
#[test]
fn the_mixed_p2_beam_s_element_pressures_show_no_checkerboard() {
    let p2 = ElementType::from_name("p2").unwrap();
    let mesh = beam(p2, [8, 2, 2]);
    let material = stiff(0.4999).with_volume_measure(VolumeMeasure::Element).unwrap();
    let problem = statics::StaticProblem {
        mesh: &mesh,
        material,
        quadrature_degree: None,
        acceleration_m_s2: G,
        dirichlet: vec![statics::clamp(clamped_at_x0(&mesh))],
        tolerance: 1e-10,
        load_steps: 1,
    };
    let x = statics::solve(&problem, &mut |_, _, _| {}).unwrap().positions;
    let geometry = crate::fem::geometry::precompute(&mesh, None).unwrap();
    let (block, g) = (&mesh.blocks[0], &geometry[0]);
    let n = g.nodes_per_element;
    let pressures: Vec<f64> = (0..g.num_elements())
        .map(|e| {
            let nodes = block.element(e);
            let xs: Vec<Vec3> = nodes.iter().map(|&i| x[i as usize]).collect();
            let rest: Vec<Vec3> = nodes.iter().map(|&i| mesh.rest_positions[i as usize]).collect();
            let grads = &g.grad_in_material[e * g.points_per_element * n..(e + 1) * g.points_per_element * n];
            crate::fem::energy::mixed::element_pressure_pa(&xs, &rest, grads, g.volumes(e), &material)
        })
        .collect();
    // face neighbours: tetrahedra sharing three corners (Gmsh order: the first four nodes)
    let corners = |e: usize| {
        let mut c: Vec<u32> = block.element(e)[..4].to_vec();
        c.sort_unstable();
        c
    };
    let mut faces: std::collections::HashMap<[u32; 3], Vec<usize>> = Default::default();
    for e in 0..pressures.len() {
        let c = corners(e);
        for skip in 0..4 {
            let f: Vec<u32> = c.iter().enumerate().filter(|(k, _)| *k != skip).map(|(_, v)| *v).collect();
            faces.entry([f[0], f[1], f[2]]).or_default().push(e);
        }
    }
    let jumps: Vec<f64> =
        faces.values().filter(|es| es.len() == 2).map(|es| (pressures[es[0]] - pressures[es[1]]).abs()).collect();
    let mean = pressures.iter().sum::<f64>() / pressures.len() as f64;
    let sd = (pressures.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / pressures.len() as f64).sqrt();
    let mean_jump = jumps.iter().sum::<f64>() / jumps.len() as f64;
    let (lo, hi) = pressures.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &p| (a.min(p), b.max(p)));
    let seen = format!(
        "{} elements, {} inner faces: pressures {lo:.3e}..{hi:.3e} Pa, sd {sd:.3e} Pa, mean jump across a face {mean_jump:.3e} Pa ({:.2} sd)",
        pressures.len(),
        jumps.len(),
        mean_jump / sd
    );
    println!("{seen}");
    assert!(sd > 0.0 && lo < 0.0 && hi > 0.0, "tension and compression: {seen}");
    assert!(mean_jump < 0.5 * sd, "a checkerboard jumps by about 2 sd: {seen}");
}

#[test]
fn the_nodal_strain_tetrahedron_cures_a_locked_p1_beam() {
    // P1 has one strain per element: its mixed formulation is one pressure per node
    // (`mixed::patch`, Bonet & Burton's averaged nodal pressure) and, for the deviatoric term,
    // the nodes' averaged deformation gradients with a tenth left on the elements (Gee et al.'s
    // isochoric stabilisation). On the beam of five tetrahedra per cell at ν = 0.4999 (the linear
    // regime) the pointwise P1 locks (16×4×4 misses over 30 % of P2 mixed's sag); the nodal
    // strain gives it back within a few per cent, on the finer mesh too. Were the nodal
    // deviatoric term left out (the averaged pressure alone), 16×4×4 would still miss a quarter
    // of it (25.8 %, 32×8×8 11.0 %: measured before the nodal strain).
    let (p1, p2) = (ElementType::from_name("p1").unwrap(), ElementType::from_name("p2").unwrap());
    let sag = |mesh: &Mesh, nu: f64, m: VolumeMeasure| static_tip_z(mesh, stiff(nu), m);
    let reference = sag(&beam(p2, [16, 4, 4]), 0.4999, VolumeMeasure::Element);
    let missing = |cells: [usize; 3]| {
        let mesh = beam(p1, cells);
        [VolumeMeasure::Point, VolumeMeasure::Element].map(|m| 100.0 * (1.0 - sag(&mesh, 0.4999, m) / reference))
    };
    let ([coarse_point, coarse_patch], [fine_point, fine_patch]) = (missing([16, 4, 4]), missing([32, 8, 8]));
    let seen = format!(
        "% of P2 mixed's sag missed at ν = 0.4999: 16×4×4 {coarse_point:.1} pointwise, {coarse_patch:.1} mixed; \
         32×8×8 {fine_point:.1}, {fine_patch:.1}"
    );
    println!("{seen}");
    assert!(coarse_point > 30.0 && fine_point > 18.0, "the pointwise P1 beam locks: {seen}");
    assert!(coarse_patch.abs() < 5.0, "the nodal-strain tetrahedron cures it: {seen}");
    assert!(fine_patch.abs() < 3.0, "and on the finer mesh: {seen}");
}
