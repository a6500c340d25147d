//! Tests of the implicit solvers' time integrators ([`super::integrator`]): their order of
//! accuracy and energy behaviour on a linear oscillator, the energy of an undamped beam over many
//! periods, and the reference motion's Newmark steps on the shared path.

use super::tests::{G, clamped_at_x0, one_cell_cantilever};
use super::*;
use crate::Vec3;
use crate::effect::{Attachment, Clamp, Effect, Gravity};
use crate::element::ElementType;
use crate::material::{Material, MaterialModel};
use std::sync::atomic::Ordering::Relaxed;

fn et(name: &str) -> ElementType {
    ElementType::from_name(name).unwrap()
}

/// Kinetic + elastic + springs − gravity's work, joules.
fn total_energy_j(sim: &Simulation) -> f64 {
    let g = sim.body_acceleration_m_s2();
    let gravity: f64 = sim
        .positions
        .iter()
        .zip(&sim.mesh().rest_positions)
        .zip(sim.masses_kg())
        .enumerate()
        .filter(|(i, _)| sim.inv_mass()[*i] > 0.0)
        .map(|(_, ((x, x0), m))| -m * g.dot(&(x - x0)))
        .sum();
    let springs: f64 = sim
        .effects()
        .iter()
        .filter_map(|e| e.spring())
        .map(|s| 0.5 * s.stiffness_n_per_m * (sim.positions[s.node as usize] - s.target_m).norm_squared())
        .sum();
    sim.kinetic_energy_j() + sim.elastic_energy_j() + springs + gravity
}

/// A linear oscillator: one free node of a one-cell P1 body (every other node clamped, the
/// material 10⁸ times softer than the spring) on a spring to its rest position, under gravity,
/// released 1 cm above where gravity and the spring balance.
struct Oscillator {
    sim: Simulation,
    node: usize,
    omega_rad_s: f64,
    equilibrium_m: Vec3,
}

const SPRING_N_PER_M: f64 = 100.0;
const AMPLITUDE_M: f64 = 0.01;

fn oscillator(method: Method, integrator: Integrator, steps_per_period: u32) -> Oscillator {
    let mesh = one_cell_cantilever(et("p1"));
    let node = mesh.num_nodes() - 1;
    let rest = mesh.rest_positions[node];
    let clamped: Vec<u32> = (0..mesh.num_nodes() as u32).filter(|&i| i as usize != node).collect();
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1e-6, 0.3, 1000.0).unwrap();
    let effects: Vec<Box<dyn Effect>> = vec![
        Box::new(Gravity::new(G)),
        Box::new(Clamp { nodes: clamped }),
        Box::new(Attachment::new(node as u32, rest, 1.0 / SPRING_N_PER_M)),
    ];
    let mut sim = Simulation::new(mesh, material, SolverSettings::default(), effects).unwrap();
    let mass_kg = sim.masses_kg()[node];
    let omega_rad_s = (SPRING_N_PER_M / mass_kg).sqrt();
    let period_secs = std::f64::consts::TAU / omega_rad_s;
    let mut settings = SolverSettings {
        method,
        integrator,
        frames_per_second: f64::from(steps_per_period) / period_secs,
        ..SolverSettings::default()
    };
    settings.newton.tolerance = 1e-12;
    settings.newton.refactor_every_iteration = true;
    settings.vbd.iterations = 4;
    sim.set_settings(settings).unwrap();
    let equilibrium_m = rest + G * (mass_kg / SPRING_N_PER_M);
    sim.positions[node] = equilibrium_m + Vec3::new(0.0, 0.0, AMPLITUDE_M);
    Oscillator { sim, node, omega_rad_s, equilibrium_m }
}

/// Over `periods` periods: the period the scheme gives, relative to the exact one, minus one,
/// from the angle the state `(u, v/ω)` turns through; and the rate at which the oscillation's
/// energy decays, `−ln(E_end/E_0)` per period (`E` measured from the equilibrium's).
fn period_and_energy_error(method: Method, integrator: Integrator, steps_per_period: u32, periods: u32) -> (f64, f64) {
    let mut o = oscillator(method, integrator, steps_per_period);
    let start = o.sim.positions[o.node];
    o.sim.positions[o.node] = o.equilibrium_m;
    let e_eq = total_energy_j(&o.sim);
    o.sim.positions[o.node] = start;
    let e0 = total_energy_j(&o.sim) - e_eq;
    let phase = |o: &Oscillator| {
        let u = o.sim.positions[o.node].z - o.equilibrium_m.z;
        let v = o.sim.velocities[o.node].z;
        (-v / o.omega_rad_s).atan2(u)
    };
    let mut turned = 0.0;
    let mut last = phase(&o);
    let steps = steps_per_period * periods;
    for _ in 0..steps {
        o.sim.step_frame().unwrap();
        let now = phase(&o);
        turned += (now - last + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        last = now;
    }
    let exact = std::f64::consts::TAU * f64::from(periods);
    let e_end = total_energy_j(&o.sim) - e_eq;
    (exact / turned - 1.0, -(e_end / e0).ln() / f64::from(periods))
}

#[test]
fn the_integrators_have_their_order_on_a_linear_oscillator() {
    for integrator in Integrator::ALL {
        let [(p1, e1), (p2, e2), (p3, e3)] =
            [16, 32, 64].map(|n| period_and_energy_error(Method::Newton, integrator, n, 4));
        let note = format!(
            "{integrator}: period errors {p1:.3e} {p2:.3e} {p3:.3e}, energy decay per period {e1:.3e} {e2:.3e} {e3:.3e}"
        );
        // every scheme's period is second order (implicit Euler's phase error is (hω)²/3)
        for (a, b) in [(p1, p2), (p2, p3)] {
            assert!(a > 0.0 && (3.4..4.6).contains(&(a / b)), "{note}");
        }
        if integrator == Integrator::Euler {
            for (a, b) in [(e1, e2), (e2, e3)] {
                assert!(a > 0.0 && (1.6..2.4).contains(&(a / b)), "first-order energy loss; {note}");
            }
        } else if integrator == Integrator::Newmark {
            assert!([e1, e2, e3].iter().all(|e| e.abs() < 1e-9), "conserved energy; {note}");
            // the trapezoidal rule's phase error is (hω)²/12
            let h_omega = std::f64::consts::TAU / 16.0;
            assert!((p1 / (h_omega * h_omega / 12.0) - 1.0).abs() < 0.05, "{note}");
        } else {
            assert_eq!(integrator, Integrator::Bdf2);
            for (a, b) in [(e1, e2), (e2, e3)] {
                // third order per period once started; the implicit Euler start adds a second-order part
                assert!(a > 0.0 && a / b > 3.5, "energy decay of at least second order; {note}");
            }
            assert!(e1 < 0.1 * period_and_energy_error(Method::Newton, Integrator::Euler, 16, 4).1, "{note}");
        }
    }
}

#[test]
fn vbd_takes_the_same_steps_as_newton_on_a_linear_oscillator() {
    // one free node: VBD's block step is Newton's step, so the schemes, not the solvers, differ
    for integrator in Integrator::ALL {
        let newton = period_and_energy_error(Method::Newton, integrator, 32, 2);
        let vbd = period_and_energy_error(Method::Vbd, integrator, 32, 2);
        assert!(
            (newton.0 - vbd.0).abs() < 1e-6 && (newton.1 - vbd.1).abs() < 1e-6,
            "{integrator}: newton {newton:?}, vbd {vbd:?}"
        );
    }
}

fn cantilever(et: ElementType, method: Method, integrator: Integrator, fps: f64) -> Simulation {
    let mesh = one_cell_cantilever(et);
    let clamped = clamped_at_x0(&mesh);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
    let effects: Vec<Box<dyn Effect>> = vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped })];
    let mut settings = SolverSettings { method, integrator, frames_per_second: fps, ..SolverSettings::default() };
    settings.newton.tolerance = 1e-10;
    Simulation::new(mesh, material, settings, effects).unwrap()
}

/// The released cantilever's energy under Newmark over many periods of its first mode, with both
/// implicit solvers: bounded by the nonlinearity's O(h²) and the solver's tolerance.
#[test]
fn newmark_keeps_the_energy_of_an_undamped_beam_over_many_periods() {
    for et in [et("p1"), et("p2"), et("q2")] {
        for method in [Method::Newton, Method::Vbd] {
            let mut sim = cantilever(et, method, Integrator::Newmark, 400.0);
            if method == Method::Vbd {
                let mut s = *sim.settings();
                s.vbd.iterations = 40;
                sim.set_settings(s).unwrap();
            }
            let e0 = total_energy_j(&sim);
            let (mut peak_kinetic, mut drift, mut crossings, mut last_vz) = (0.0f64, 0.0f64, 0, 0.0);
            let tip = sim.positions.len() - 1;
            for _ in 0..4000 {
                sim.step_frame().unwrap();
                peak_kinetic = peak_kinetic.max(sim.kinetic_energy_j());
                drift = drift.max((total_energy_j(&sim) - e0).abs());
                let vz = sim.velocities[tip].z;
                if vz * last_vz < 0.0 {
                    crossings += 1;
                }
                last_vz = vz;
            }
            let periods = crossings / 2;
            assert!(periods >= 12, "{et} {method}: only {periods} periods in 10 s");
            let bound = if method == Method::Newton { 1e-3 } else { 2e-2 };
            assert!(
                drift < bound * peak_kinetic,
                "{et} {method}: energy drift {drift:.2e} J against a peak KE {peak_kinetic:.2e} J over {periods} periods"
            );
        }
    }
}

#[test]
fn implicit_euler_loses_the_energy_newmark_keeps() {
    let mut euler = cantilever(et("p2"), Method::Newton, Integrator::Euler, 1000.0);
    let mut newmark = cantilever(et("p2"), Method::Newton, Integrator::Newmark, 1000.0);
    let (e0_euler, e0) = (total_energy_j(&euler), total_energy_j(&newmark));
    for _ in 0..400 {
        newmark.step_frame().unwrap();
        euler.step_frame().unwrap();
    }
    let lost_euler = e0_euler - total_energy_j(&euler);
    let lost_newmark = (e0 - total_energy_j(&newmark)).abs();
    assert!(lost_euler > 20.0 * lost_newmark, "euler lost {lost_euler:.2e} J, newmark {lost_newmark:.2e} J");
}

#[test]
fn newmark_is_second_order_on_the_beam() {
    // (BDF2's order shows on the oscillator; on the beam, at these steps, its damping of the
    // modes a step does not resolve, different at each step, dominates the tip's difference: the
    // ratio measured 2.5)
    {
        let integrator = Integrator::Newmark;
        let tip = |h: f64| {
            let mut sim = cantilever(et("p2"), Method::Newton, integrator, 1.0 / h);
            let mut s = *sim.settings();
            s.newton.tolerance = 1e-12;
            sim.set_settings(s).unwrap();
            for _ in 0..(0.2 / h).round() as usize {
                sim.step_frame().unwrap();
            }
            let last = sim.positions.len() - 1;
            sim.positions[last]
        };
        let (a, b, c) = (tip(4e-3), tip(2e-3), tip(1e-3));
        let ratio = (a - b).norm() / (b - c).norm();
        assert!((3.0..5.5).contains(&ratio), "{integrator}: halving h must divide the error by ~4, got {ratio:.2}");
    }
}

#[test]
fn a_change_of_integrator_mid_run_starts_the_new_scheme_cleanly() {
    // a teacher switches from implicit Euler to Newmark mid-swing: the motion goes on from the
    // state reached (no jump in position; the energy from then on is kept)
    let mut sim = cantilever(et("p2"), Method::Newton, Integrator::Euler, 1000.0);
    for _ in 0..50 {
        sim.step_frame().unwrap();
    }
    let mut s = *sim.settings();
    s.integrator = Integrator::Newmark;
    sim.set_settings(s).unwrap();
    let before = sim.positions.clone();
    sim.step_frame().unwrap();
    let moved = sim.positions.iter().zip(&before).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    let speed = sim.velocities.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(moved < 2.0 * speed * 1e-3 + 1e-9, "moved {moved:.3e} m in one 1 ms step at {speed:.3e} m/s");
    let e_switch = total_energy_j(&sim);
    let mut drift = 0.0f64;
    for _ in 0..300 {
        sim.step_frame().unwrap();
        drift = drift.max((total_energy_j(&sim) - e_switch).abs());
    }
    assert!(drift < 1e-3 * e_switch.abs().max(sim.kinetic_energy_j()), "drift {drift:.3e} J after the switch");
}

/// BDF2 started its history afresh every other step: the first step's swap left `v_n` empty,
/// which the next step took for a new mesh (found by a NaN that spread through the restart's
/// gradient). After its start, every step is BDF2's: free fall's second differences are `g h²`
/// from the second step on, and a NaN stays at its node.
#[test]
fn bdf2_keeps_its_history_from_the_second_step_on() {
    let mesh = super::tests::beam(et("p2"), [2, 1, 1]);
    let material = Material::new(MaterialModel::StableNeoHookean, 1.0e5, 0.3, 1000.0).unwrap();
    let clamped = clamped_at_x0(&mesh);
    let effects: Vec<Box<dyn Effect>> = vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped })];
    let settings = SolverSettings { method: Method::Newton, integrator: Integrator::Bdf2, ..Default::default() };
    let mut sim = Simulation::new(mesh.clone(), material, settings, effects).unwrap();
    sim.step_frame().unwrap();
    let node = mesh.num_nodes() - 1;
    sim.positions[node].x = f64::NAN;
    let err = sim.step_frame().unwrap_err().to_string();
    assert!(err.contains(&format!("node {node}")), "{err}");
}

/// A scheme defined here and nowhere else: implicit Euler written through the history
/// ([`Scheme::predict`] keeps the prediction, [`Scheme::update`] sets `v = (x − x_n)/h`) under
/// another name, counting its calls. Not in [`Integrator::ALL`]; nothing outside this file
/// names it.
struct CountedEuler {
    predictions: std::sync::atomic::AtomicUsize,
    updates: std::sync::atomic::AtomicUsize,
}

static COUNTED_EULER: CountedEuler = CountedEuler {
    predictions: std::sync::atomic::AtomicUsize::new(0),
    updates: std::sync::atomic::AtomicUsize::new(0),
};

const COUNTED_EULER_INFO: IntegratorInfo = IntegratorInfo {
    name: "counted-euler",
    long_name: "implicit Euler through the history (a test's)",
    order: 1,
    motion: "As implicit Euler.",
    source: "this test",
    damps_motion: true,
    needs_converged_steps: false,
    vbd_chebyshev: true,
    vbd_start_from_prediction: false,
};

impl Scheme for CountedEuler {
    fn info(&self) -> &IntegratorInfo {
        &COUNTED_EULER_INFO
    }
    fn predict(&self, _state: &mut SchemeState, step: Prediction<'_>) -> f64 {
        self.predictions.fetch_add(1, Relaxed);
        step.h
    }
    fn update(&self, _state: &mut SchemeState, step: Update<'_>) {
        self.updates.fetch_add(1, Relaxed);
        for i in 0..step.velocities.len() {
            step.velocities[i] = step.euler(i);
        }
    }
}

/// A new integrator needs its file and its registry line only: a scheme registered nowhere runs
/// through [`Simulation::step_frame`] under Newton and VBD, the simulation and the solvers asking
/// its entry, and moves as the scheme it restates (implicit Euler) up to round-off.
#[test]
fn a_scheme_defined_in_a_test_runs_through_the_simulation_with_every_implicit_solver() {
    let counted = Integrator(&COUNTED_EULER);
    assert!(!Integrator::ALL.contains(&counted) && Integrator::from_name("counted-euler").is_none());
    assert_ne!(counted, Integrator::Euler);
    for method in [Method::Newton, Method::Vbd] {
        let mut ours = cantilever(et("p2"), method, counted, 200.0);
        let mut euler = cantilever(et("p2"), method, Integrator::Euler, 200.0);
        let (p0, u0) = (COUNTED_EULER.predictions.load(Relaxed), COUNTED_EULER.updates.load(Relaxed));
        for _ in 0..40 {
            ours.step_frame().unwrap();
            euler.step_frame().unwrap();
        }
        assert_eq!(ours.integrator(), counted);
        // (the tests run in parallel: other steps may count too, never fewer)
        assert!(COUNTED_EULER.predictions.load(Relaxed) - p0 >= 40, "{method}: its prediction was not asked");
        assert!(COUNTED_EULER.updates.load(Relaxed) - u0 >= 40, "{method}: its update was not asked");
        let tip = ours.positions.len() - 1;
        let sag = (euler.positions[tip] - euler.mesh().rest_positions[tip]).norm();
        assert!(sag > 1e-3, "{method}: the beam did not move ({sag} m)");
        for (a, b) in ours.positions.iter().zip(&euler.positions) {
            assert!((a - b).norm() < 1e-9 * sag.max(1.0), "{method}: {a} against implicit Euler's {b}");
        }
    }
}
