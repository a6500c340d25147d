//! One step of a solver: what it reads ([`StepInput`]), the effects' hooks it may call
//! ([`Hooks`]) and the trait every solver implements ([`StepSolver`]).

use super::error::SolverCounters;
use super::nan_guard::BadElement;
use super::settings::SolverSettings;
use crate::Vec3;
use crate::effect::{Effect, EffectState, ImplicitRole, NodeSpring};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;

/// What a step solver reads (everything but the positions it moves).
pub(crate) struct StepInput<'a> {
    pub mesh: &'a Mesh,
    pub geometry: &'a [BlockGeometry],
    pub material: &'a Material,
    pub masses_kg: &'a [f64],
    /// 0 for pinned and driven nodes: the solver leaves them where the effects put them.
    pub inv_mass: &'a [f64],
    /// `x_n`, the positions at the start of the step.
    pub prev_positions: &'a [Vec3],
    /// The body acceleration every free node feels (gravity), m/s² — already in the prediction.
    pub body_acceleration: Vec3,
    /// The step, seconds.
    pub h: f64,
    /// The inertia step `h̄` of the incremental potential's `m/(2h̄²)|x − y|²`, seconds: `h` for
    /// implicit Euler, `h/2` for Newmark, `2h/3` for BDF2 ([`super::integrator`]). The
    /// prediction `y` holds the body acceleration as `h̄² g`.
    pub inertia_h: f64,
    /// The integrator's guess of `x_{n+1}` when its scheme offers one
    /// ([`super::integrator::Scheme::offers_guess`]: Newmark's, the motion with its last
    /// acceleration kept), where VBD's adaptive start begins; None under the other schemes.
    pub guess: Option<&'a [Vec3]>,
    pub settings: &'a SolverSettings,
    /// Changes whenever the pinned nodes, the masses or the material may have changed.
    pub model_version: u64,
}

/// The effects' hooks a solver may call within a step, and their potentials.
pub(crate) struct Hooks<'a> {
    pub effects: &'a mut [Box<dyn Effect>],
    pub velocities: &'a mut [Vec3],
    pub prev_positions: &'a [Vec3],
    pub rest: &'a [Vec3],
    pub inv_mass: &'a [f64],
    pub time_secs: f64,
    pub h: f64,
    pub calls: &'a mut u64,
    /// Where the nodes a projection moved are marked (with a scratch copy of the positions), when
    /// the integrator must know them ([`super::integrator`]: a projected node's velocity is
    /// implicit Euler's, so a contact does not become an acceleration that bounces it back).
    pub projected: Option<(&'a mut [bool], &'a mut Vec<Vec3>)>,
}

impl Hooks<'_> {
    /// Runs the effects' projections: every effect's (`only` = None, XPBD), or only those of
    /// one role (contact under VBD).
    pub fn after_projection(&mut self, positions: &mut [Vec3], only: Option<ImplicitRole>) {
        let track =
            self.projected.is_some() && self.effects.iter().any(|e| only.is_none_or(|role| e.implicit_role() == role));
        if track && let Some((_, before)) = &mut self.projected {
            before.clear();
            before.extend_from_slice(positions);
        }
        for e in self.effects.iter_mut() {
            if only.is_some_and(|role| e.implicit_role() != role) {
                continue;
            }
            *self.calls += 1;
            e.after_projection(&mut EffectState {
                time_secs: self.time_secs,
                dt_secs: self.h,
                rest_positions: self.rest,
                positions,
                prev_positions: self.prev_positions,
                velocities: self.velocities,
                inv_mass: self.inv_mass,
            });
        }
        if track && let Some((marks, before)) = &mut self.projected {
            for ((m, x), b) in marks.iter_mut().zip(positions.iter()).zip(before.iter()) {
                *m |= x != b;
            }
        }
    }

    /// The node springs of the effects that are potentials (a dragged node's attachment).
    pub fn springs(&self) -> Vec<NodeSpring> {
        self.effects.iter().filter_map(|e| e.spring()).collect()
    }
}

/// A solver of the step: moves the free nodes from the prediction to `x_{n+1}`.
pub(crate) trait StepSolver: Send {
    /// At the start of a step, before any hook: `velocities` are `v_n`.
    fn begin_step(&mut self, _velocities: &[Vec3]) {}
    /// The history is gone (`warm`: a warm start at rest; otherwise a reset).
    fn reset_history(&mut self, _warm: bool, _num_nodes: usize) {}
    /// `positions` enter holding the prediction `y` (pinned and driven nodes already placed) and
    /// leave holding `x_{n+1}`. Runs the effects' projections as the method allows.
    fn solve_step(
        &mut self,
        input: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement>;
    /// The settings changed (the method did not); `geometry_changed`: so did the quadrature.
    fn rebuild(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings, geometry_changed: bool);
    /// The solver as `Any`, for the settings only one solver has (XPBD's SIMD batches and
    /// slabs, [`super::Simulation::set_simd_batches`]).
    fn as_any(&self) -> &dyn std::any::Any;
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
    /// A few words on the work it does, for a status line ("xpbd, 1,200 constraints").
    fn work_summary(&self, settings: &SolverSettings, counters: &SolverCounters) -> String;
    /// Whether the last step ended far from solved (a residual above a tenth of the load: VBD's
    /// after its recovery rounds, a Newton-type step's at its iteration limit): the step watch
    /// rejects it and takes it again in halves.
    fn last_step_failed(&self) -> bool {
        false
    }
    /// Why the last step failed, when the solver knows more than that it ended far from solved
    /// (VBD: the node whose update diverged).
    fn last_failure_why(&self) -> Option<String> {
        None
    }
    /// The step watch rejected the step that started at `time_secs` (it is taken again in halves).
    fn step_rejected(&mut self, _time_secs: f64) {}
    /// The policy a Newton-type solver's last step ran and why.
    fn newton_policy(&self) -> Option<&super::settings::NewtonPolicyReport> {
        None
    }
    /// The relative residual of each iteration of the last step (Newton; for tests).
    fn last_step_residuals(&self) -> &[f64] {
        &[]
    }
}
