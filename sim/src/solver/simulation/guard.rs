//! The guards of a [`Simulation`]'s step: the **step watch** of the implicit solvers (a step that
//! throws a node further than the body's size, that the solver left far from solved, or that
//! raised the energy of a body no effect does work on, is taken again in halves and, failing
//! that, stops the run naming the solver and node; docs/STABILITY.md), XPBD's **frame watch**
//! (the same displacement check once per frame, a rejected frame taken again with twice the
//! substeps), and the **NaN guard**'s check and roll-back to the last finite state (module doc
//! of [`super::super`]).
//!
//! The displacement bound is the body's size (its rest bounding-box diagonal) plus how far the
//! effects may carry a node in the step ([`crate::effect::Effect::reach_m`]: a drive's path, a
//! drag's distance to its target), so that a fast drag across the body is not a blow-up.

use super::super::error::SimError;
use super::super::nan_guard::{BadElement, ORIGIN_STATE};
use super::Simulation;
use crate::Vec3;

/// The most times the step watch halves a rejected step ([`Simulation`]): down to 1/64.
pub const MAX_HALVINGS: u32 = 6;

/// The most a step may raise the mechanical energy of a body whose effects do no work, as a
/// fraction of the energy's scale ([`Simulation`]'s step watch): Newmark's own drift on a
/// nonlinear body is far below it, implicit Euler and BDF2 only lower the energy.
const ENERGY_GROWTH: f64 = 1e-2;

/// The least energy scale of that check, as a fraction of `μ V` (μ the shear modulus, V the rest
/// volume): the elastic energy of a strain of about 10⁻⁵. A body coming to rest with no load has
/// an energy that decays to the round-off of `U` (about `10⁻¹⁶ μ V`); against that scale a
/// round-off wobble read as a growth of tens of % (the stiff cantilever released, issue #36).
const ENERGY_FLOOR: f64 = 1e-10;

impl Simulation {
    /// An implicit step of `h` under the step watch: a step in which a free node moves, against
    /// the free nodes' mean motion, by more than the body's size, which the solver left far
    /// from solved ([`StepSolver::last_step_failed`]), or which raised the mechanical energy by more than [`ENERGY_GROWTH`] of its scale while no effect does work
    /// ([`Effect::does_no_work`]), is rejected — the state goes back to its
    /// start — and taken again as two steps of `h/2`, down to `h/2^`[`MAX_HALVINGS`]; past that
    /// the run stops with [`SimError::Diverged`] naming the node (or [`SimError::Unsolved`]),
    /// keeping the last sound state.
    pub(super) fn watched_step(&mut self, h: f64, halvings: u32) -> Result<(), SimError> {
        // (into buffers kept between steps: a step allocates nothing; a halving below restores
        // this state before it overwrites the buffers with its own start)
        self.watch_start.0.clone_from(&self.positions);
        self.watch_start.1.clone_from(&self.velocities);
        let (start_time, start_substeps) = (self.time_secs, self.substeps_in_frame);
        let watch_energy = self.effects.iter().all(|e| e.does_no_work());
        let energy_before = watch_energy.then(|| self.mechanical_energy_j());
        let bound_m = self.displacement_bound_m(h);
        self.advance(h)?;
        let excess = self.step_excess(&self.watch_start.0, bound_m);
        let failed = self.solver.last_step_failed();
        let gained = energy_before.and_then(|(total, scale)| {
            let (after, scale_after) = self.mechanical_energy_j();
            let floor =
                ENERGY_FLOOR * self.material.lame().mu_pa * crate::fem::geometry::total_volume_m3(&self.geometry);
            let growth = (after - total) / scale.max(scale_after).max(floor).max(f64::MIN_POSITIVE);
            (growth > ENERGY_GROWTH).then_some(growth)
        });
        if excess.is_none() && !failed && gained.is_none() {
            return Ok(());
        }
        self.positions.clone_from(&self.watch_start.0);
        self.velocities.clone_from(&self.watch_start.1);
        (self.time_secs, self.substeps_in_frame) = (start_time, start_substeps);
        self.prev_positions.copy_from_slice(&self.positions);
        self.history.clear();
        self.solver.reset_history(false, self.positions.len());
        self.solver.step_rejected(start_time);
        self.counters.rejected_steps += 1;
        if halvings == MAX_HALVINGS {
            let err = match excess {
                Some((node, moved_m)) => SimError::Diverged {
                    solver: self.settings.method.name(),
                    node,
                    moved_m,
                    size_m: bound_m,
                    span: "step",
                    frame: self.frames + 1,
                    time_secs: self.time_secs + h,
                    halvings,
                    h_secs: h,
                },
                None => SimError::Unsolved {
                    solver: self.settings.method.name(),
                    frame: self.frames + 1,
                    time_secs: self.time_secs + h,
                    why: match (gained, self.solver.last_failure_why()) {
                        (Some(growth), _) => format!(
                            "the step raised the energy of a body no effect does work on by {:.1} % of its scale",
                            100.0 * growth
                        ),
                        (None, Some(why)) => why,
                        (None, None) => "the unbalanced force stayed above a tenth of the load".into(),
                    },
                    halvings,
                    h_secs: h,
                },
            };
            self.failure = Some(err.clone());
            return Err(err);
        }
        self.watched_step(0.5 * h, halvings + 1)?;
        self.watched_step(0.5 * h, halvings + 1)
    }

    /// The mechanical energy `K + U − Σ m_i g·(x_i − X_i)` (free nodes), J, and its scale
    /// `K + U + |V_g|`, for the step watch.
    fn mechanical_energy_j(&self) -> (f64, f64) {
        let g = self.body_acceleration_m_s2();
        let gravity: f64 = (0..self.positions.len())
            .filter(|&i| self.inv_mass[i] > 0.0)
            .map(|i| -self.masses_kg[i] * g.dot(&(self.positions[i] - self.mesh.rest_positions[i])))
            .sum();
        let (kinetic, elastic) = (self.kinetic_energy_j(), self.elastic_energy_j());
        (kinetic + elastic + gravity, kinetic + elastic + gravity.abs())
    }

    /// XPBD's frame watch: the frame's substeps, then the step watch's displacement check over
    /// the frame. A frame in which a free node moved, against the free nodes' mean motion, by
    /// more than [`Self::displacement_bound_m`] is rejected (the state goes back to the frame's
    /// start) and taken again with twice the substeps, up to 2^[`MAX_HALVINGS`] times as many;
    /// past that the run stops with [`SimError::Diverged`] naming XPBD, the frame and the node.
    /// Once per frame, not per substep: watching every substep cost 10–25 % of a P2 8×2×2 frame
    /// (docs/STABILITY.md); a copy of the state and one pass over the nodes per frame is a few
    /// microseconds against its milliseconds. The stability guard keeps XPBD's substeps below its
    /// stability limit and the NaN guard checks every substep, as before.
    pub(super) fn watched_frame(&mut self) -> Result<(), SimError> {
        self.watch_start.0.clone_from(&self.positions);
        self.watch_start.1.clone_from(&self.velocities);
        let start_time = self.time_secs;
        let frame_secs = 1.0 / self.settings.frames_per_second;
        let bound_m = self.displacement_bound_m(frame_secs);
        let mut substeps = self.substeps_per_frame;
        for doublings in 0..=MAX_HALVINGS {
            let h = frame_secs / substeps as f64;
            self.substeps_in_frame = 0;
            for _ in 0..substeps {
                if let Some(e) = &self.failure {
                    return Err(e.clone());
                }
                self.advance(h)?;
            }
            let Some((node, moved_m)) = self.step_excess(&self.watch_start.0, bound_m) else {
                return Ok(());
            };
            self.positions.clone_from(&self.watch_start.0);
            self.velocities.clone_from(&self.watch_start.1);
            self.time_secs = start_time;
            self.prev_positions.copy_from_slice(&self.positions);
            self.counters.rejected_steps += 1;
            if doublings == MAX_HALVINGS {
                let err = SimError::Diverged {
                    solver: self.settings.method.name(),
                    node,
                    moved_m,
                    size_m: bound_m,
                    span: "frame",
                    frame: self.frames + 1,
                    time_secs: start_time + frame_secs,
                    halvings: doublings,
                    h_secs: h,
                };
                self.failure = Some(err.clone());
                return Err(err);
            }
            substeps *= 2;
        }
        unreachable!("the loop returns at its last doubling")
    }

    /// How far a free node may move, against the free nodes' mean motion, in a step of `h` from
    /// now: the body's size, plus how far the body is from its rest shape (a node pushed through
    /// its element snaps back that far: the corner of tests/tests/robustness.rs, 0.75 m in one
    /// frame of a 0.53 m body), plus the farthest any effect may carry a node in the step.
    fn displacement_bound_m(&self, h: f64) -> f64 {
        let reach = self
            .effects
            .iter()
            .map(|e| e.reach_m(&self.positions, &self.mesh.rest_positions, self.time_secs, h))
            .fold(0.0, f64::max);
        let (_, deformed) = self.farthest_against_mean(&self.mesh.rest_positions);
        self.body_size_m + deformed + reach
    }

    /// The free node farthest from `reference` against the free nodes' mean offset from it, and
    /// how far: the motion of a step (`reference` its start) or the deformation (the rest shape).
    fn farthest_against_mean(&self, reference: &[Vec3]) -> (usize, f64) {
        let free = |i: &usize| self.inv_mass[*i] > 0.0;
        let n = (0..reference.len()).filter(free).count().max(1) as f64;
        let mean = (0..reference.len()).filter(free).map(|i| self.positions[i] - reference[i]).sum::<Vec3>() / n;
        (0..reference.len())
            .filter(free)
            .map(|i| (i, (self.positions[i] - reference[i] - mean).norm()))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a })
    }

    /// The free node that moved most in the step from `start` against the free nodes' mean
    /// motion, and how far, when that is more than `bound_m`.
    fn step_excess(&self, start: &[Vec3], bound_m: f64) -> Option<(usize, f64)> {
        let (node, moved) = self.farthest_against_mean(start);
        (moved > bound_m).then_some((node, moved))
    }
}

impl Simulation {
    // The NaN guard (module doc of `solver`).
    /// The first node whose position or velocity is not finite, with an element holding it.
    pub(crate) fn first_non_finite(&self) -> Option<BadElement> {
        let node = self
            .positions
            .iter()
            .zip(&self.velocities)
            .position(|(x, v)| !(x.iter().chain(v.iter()).all(|c| c.is_finite())))?;
        Some(BadElement::at_node(&self.mesh, node, ORIGIN_STATE))
    }

    /// Builds the NaN guard's error, puts the state back to the last finite positions (the
    /// start of this substep, else the rest shape) at rest, and stops the simulation until reset.
    pub(crate) fn fail(&mut self, bad: BadElement) -> SimError {
        let err = SimError::NonFinite {
            solver: self.settings.method.name(),
            block: bad.block,
            element: bad.element,
            element_type: self
                .mesh
                .blocks
                .get(bad.block)
                .map(|b| b.element_type.to_string())
                .unwrap_or_else(|| "none".into()),
            node: bad.node as usize,
            origin: bad.origin,
            frame: self.frames + 1,
            substep_in_frame: self.substeps_in_frame,
            substeps_per_frame: self.substeps_per_frame,
            substep: self.counters.substeps,
            time_secs: self.time_secs,
        };
        let last = if self.prev_positions.iter().all(|x| x.iter().all(|c| c.is_finite())) {
            &self.prev_positions
        } else {
            &self.mesh.rest_positions
        };
        self.positions.clone_from(last);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.failure = Some(err.clone());
        err
    }
}
