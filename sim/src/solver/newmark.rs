//! The reference motion's integrator: Newmark's average-acceleration scheme (the trapezoidal
//! rule, β = 1/4, γ = 1/2; Newmark 1959, "A method of computation for structural dynamics"),
//! implicit, second order and free of numerical damping: on a linear system it conserves the
//! energy exactly, so the motion it gives decays only through the model's own damping (none in
//! the bending scene's free release).
//!
//! Each step of `h` solves, for the free nodes,
//!
//! `M a_{n+1} = f(x_{n+1}) + M g`, `x_{n+1} = x_n + h v_n + (h²/4)(a_n + a_{n+1})`,
//!
//! i.e. with `ỹ = x_n + h v_n + (h²/4) a_n`, `a_{n+1} = (4/h²)(x_{n+1} − ỹ)`, the minimiser of
//!
//! `(2/h²)(x − ỹ)ᵀ M (x − ỹ) + U(x) − (M g)ᵀ x`,
//!
//! which is the backward-Euler incremental potential ([`super::potential`]) with the step `h/2` and
//! the prediction `ỹ + (h²/4) g`: the one Newton ([`super::newton_core`]) solves it.
//! Then `v_{n+1} = v_n + (h/2)(a_n + a_{n+1})`. The start is `a_0 = g − ∇U(x_0)/m` on the free
//! nodes (`g` for a body released from rest), zero on the held ones.
//!
//! Only gravity and clamps are honoured (the reference motion of the bending beam needs no
//! more); any other effect is refused by name.

use super::error::{SimError, SolverCounters};
use super::nan_guard::{BadElement, ORIGIN_NEWTON};
use super::newton_core::{Failure, HessianModel, Outcome, Scratch, minimise};
use super::potential::Potential;
use super::settings::SolverSettings;
use super::simulation::Simulation;
use super::sparse::SparsePattern;
use super::step::StepInput;
use crate::Vec3;
use crate::fem::energy::total_energy_and_gradient;

/// The effects the Newmark integrator honours.
const HONOURED: [&str; 2] = ["gravity", "clamp"];

/// A Newmark (average acceleration) integrator driving a [`Simulation`]'s positions and
/// velocities with a fixed step, for reference motions. It reads the simulation's model through
/// its public interface and solves each step with the one Newton ([`super::newton_core`]).
pub struct Newmark {
    pattern: Option<SparsePattern>,
    scratch: Scratch,
    accelerations_m_s2: Vec<Vec3>,
    h_secs: f64,
    time_secs: f64,
    counters: SolverCounters,
    settings: SolverSettings,
}

impl Newmark {
    /// Starts from `sim`'s current state (its positions and velocities) with steps of `h_secs`;
    /// Newton's tolerance is `tolerance` (relative to the load, as in [`super::NewtonSettings`]).
    pub fn new(sim: &Simulation, h_secs: f64, tolerance: f64) -> Result<Self, SimError> {
        if !(h_secs.is_finite() && h_secs > 0.0) {
            return Err(SimError::Settings(format!("the Newmark step must be positive and finite, got {h_secs}")));
        }
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(SimError::Settings(format!("the Newmark tolerance must be in (0, 1), got {tolerance}")));
        }
        if let Some(e) = sim.effects().iter().find(|e| !HONOURED.contains(&e.name())) {
            return Err(SimError::Unsupported {
                solver: "newmark",
                effect: e.name(),
                supported_by: "xpbd, vbd, newton".into(),
            });
        }
        let g = sim.body_acceleration_m_s2();
        let mut grad = vec![Vec3::zeros(); sim.positions.len()];
        total_energy_and_gradient(sim.mesh(), sim.geometry(), sim.material(), &sim.positions, &mut grad);
        let inv_mass = sim.inv_mass();
        let accelerations_m_s2 = grad
            .iter()
            .enumerate()
            .map(|(i, f)| if inv_mass[i] > 0.0 { g - f * inv_mass[i] } else { Vec3::zeros() })
            .collect();
        let mut settings = *sim.settings();
        settings.newton.tolerance = tolerance;
        settings.newton.refactor_every_iteration = false;
        Ok(Self {
            pattern: None,
            scratch: Scratch::default(),
            accelerations_m_s2,
            h_secs,
            time_secs: 0.0,
            counters: SolverCounters::default(),
            settings,
        })
    }

    /// Simulated time since the start, seconds.
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }

    /// Newton's counters over all steps so far.
    pub fn counters(&self) -> SolverCounters {
        self.counters
    }

    /// One step of `h`: moves `sim.positions` and `sim.velocities` (free nodes; held nodes stay).
    pub fn step(&mut self, sim: &mut Simulation) -> Result<(), SimError> {
        let h = self.h_secs;
        let g = sim.body_acceleration_m_s2();
        let n = sim.positions.len();
        let inv_mass = sim.inv_mass().to_vec();
        // ỹ = x_n + h v_n + (h²/4) a_n; the half-step problem's prediction is ỹ + (h²/4) g and
        // its start ỹ (the prediction without the step's body acceleration, as Newton's)
        let mut tilde = sim.positions.clone();
        for i in 0..n {
            if inv_mass[i] > 0.0 {
                tilde[i] += sim.velocities[i] * h + self.accelerations_m_s2[i] * (0.25 * h * h);
            }
        }
        let y: Vec<Vec3> =
            tilde.iter().zip(&inv_mass).map(|(t, &w)| if w > 0.0 { t + g * (0.25 * h * h) } else { *t }).collect();
        let mut x = tilde.clone();
        let outcome = {
            let mesh = sim.mesh();
            if self.pattern.is_none() {
                let pattern = SparsePattern::new(mesh, |i| inv_mass[i] == 0.0)
                    .map_err(|e| SimError::Settings(format!("Newmark's stiffness pattern: {e:?}")))?;
                self.pattern = Some(pattern);
            }
            let pattern = self.pattern.as_mut().expect("made above");
            let w = 4.0 / (h * h);
            let input = StepInput {
                mesh,
                geometry: sim.geometry(),
                material: sim.material(),
                masses_kg: sim.masses_kg(),
                inv_mass: &inv_mass,
                prev_positions: &sim.positions,
                body_acceleration: g,
                h: 0.5 * h,
                settings: &self.settings,
                model_version: 0,
            };
            let potential = Potential { input: &input, y: &y, springs: &[], w };
            let diagonal = potential.hessian_diagonal(pattern);
            let model = HessianModel { mesh, geometry: sim.geometry(), material: sim.material(), diagonal: &diagonal };
            let body_force = potential.body_force_n();
            minimise(
                &potential,
                &model,
                pattern,
                &mut x,
                &self.settings.newton,
                body_force,
                &mut self.scratch,
                &mut self.counters,
                &mut |_| {},
            )
        };
        match outcome {
            Ok(Outcome::Converged { .. } | Outcome::Stalled { .. }) => {}
            Ok(Outcome::Unconverged { .. }) => self.counters.unconverged_steps += 1,
            Err(Failure::NonFinite { node }) => {
                let bad = BadElement::at_node(sim.mesh(), node, ORIGIN_NEWTON);
                return Err(sim.fail(bad));
            }
            Err(Failure::Factorisation(_)) => {
                let bad = BadElement::at_node(sim.mesh(), 0, ORIGIN_NEWTON);
                return Err(sim.fail(bad));
            }
        }
        let four_over_h2 = 4.0 / (h * h);
        for i in 0..n {
            if inv_mass[i] == 0.0 {
                continue;
            }
            let a_next = (x[i] - tilde[i]) * four_over_h2;
            sim.velocities[i] += (self.accelerations_m_s2[i] + a_next) * (0.5 * h);
            self.accelerations_m_s2[i] = a_next;
            sim.positions[i] = x[i];
        }
        self.time_secs += h;
        match sim.first_non_finite() {
            Some(bad) => Err(sim.fail(bad)),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::{Clamp, Damping, Effect, Gravity};
    use crate::element::ElementType;
    use crate::material::{Material, MaterialModel};
    use crate::solver::tests::{G, clamped_at_x0, one_cell_cantilever};

    fn et(name: &str) -> ElementType {
        ElementType::from_name(name).unwrap()
    }

    fn cantilever(et: ElementType) -> Simulation {
        let mesh = one_cell_cantilever(et);
        let clamped = clamped_at_x0(&mesh);
        let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
        let effects: Vec<Box<dyn Effect>> = vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped })];
        Simulation::new(mesh, material, crate::solver::SolverSettings::default(), effects).unwrap()
    }

    /// Kinetic + elastic − gravity work: conserved by the trapezoidal rule up to the Newton
    /// tolerance and the nonlinearity's O(h²) drift.
    fn total_energy_j(sim: &Simulation) -> f64 {
        let g = sim.body_acceleration_m_s2();
        let potential: f64 = sim
            .positions
            .iter()
            .zip(&sim.mesh().rest_positions)
            .zip(sim.masses_kg())
            .map(|((x, x0), m)| -m * g.dot(&(x - x0)))
            .sum();
        sim.kinetic_energy_j() + sim.elastic_energy_j() + potential
    }

    #[test]
    fn newmark_conserves_the_energy_of_a_released_cantilever() {
        for et in [et("p1"), et("p2"), et("q2")] {
            let mut sim = cantilever(et);
            let mut newmark = Newmark::new(&sim, 1e-3, 1e-10).unwrap();
            let e0 = total_energy_j(&sim);
            let (mut peak_kinetic, mut drift) = (0.0f64, 0.0f64);
            for _ in 0..400 {
                newmark.step(&mut sim).unwrap();
                peak_kinetic = peak_kinetic.max(sim.kinetic_energy_j());
                drift = drift.max((total_energy_j(&sim) - e0).abs());
            }
            assert!(peak_kinetic > 0.0, "{et}: the cantilever must move");
            assert!(
                drift < 1e-3 * peak_kinetic,
                "{et}: energy drift {drift:.2e} J against a peak KE {peak_kinetic:.2e} J"
            );
        }
    }

    #[test]
    fn backward_euler_loses_the_energy_newmark_keeps() {
        // the contrast that makes Newmark the reference: at the same step, implicit Euler damps
        let mut euler = cantilever(et("p2"));
        let mut settings = *euler.settings();
        settings.method = crate::solver::Method::Newton;
        settings.frames_per_second = 1000.0;
        euler.set_settings(settings).unwrap();
        let mut sim = cantilever(et("p2"));
        let mut newmark = Newmark::new(&sim, 1e-3, 1e-10).unwrap();
        let (e0_euler, e0) = (total_energy_j(&euler), total_energy_j(&sim));
        for _ in 0..400 {
            newmark.step(&mut sim).unwrap();
            euler.step_frame().unwrap();
        }
        let lost_euler = e0_euler - total_energy_j(&euler);
        let lost_newmark = (e0 - total_energy_j(&sim)).abs();
        assert!(lost_euler > 20.0 * lost_newmark, "euler lost {lost_euler:.2e} J, newmark {lost_newmark:.2e} J");
    }

    #[test]
    fn newmark_is_second_order_in_the_step() {
        let tip = |h: f64| {
            let mut sim = cantilever(et("p2"));
            let mut newmark = Newmark::new(&sim, h, 1e-12).unwrap();
            let steps = (0.2 / h).round() as usize;
            for _ in 0..steps {
                newmark.step(&mut sim).unwrap();
            }
            let last = sim.positions.len() - 1;
            sim.positions[last]
        };
        let (a, b, c) = (tip(4e-3), tip(2e-3), tip(1e-3));
        let ratio = (a - b).norm() / (b - c).norm();
        assert!((3.0..5.5).contains(&ratio), "halving h must divide the error by ~4, got {ratio:.2}");
    }

    #[test]
    fn newmark_refuses_an_effect_it_does_not_honour() {
        let mut sim = cantilever(et("p1"));
        sim.add_effect(Box::new(Damping { rate_per_sec: 1.0 })).unwrap();
        let err = Newmark::new(&sim, 1e-3, 1e-8).err().expect("refused").to_string();
        assert!(err.contains("newmark") && err.contains("damping"), "{err}");
    }
}
