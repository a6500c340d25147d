//! Implicit (backward) Euler solved by Newton's method: each step minimises the incremental
//! potential
//!
//! `E(x) = Σ_i m_i/(2h²) |x_i − y_i|² + Σ_e U_e(x) + Σ_k k_k/2 |x_{n_k} − t_k|²`
//!
//! over the free nodes (held and driven nodes stay where the effects put them), `y` the inertial
//! prediction (gravity included), the last term the springs of potential effects (a dragged
//! node's attachment). Its minimiser satisfies `M (x − y)/h² = f(x)`, i.e. backward Euler
//! `M (v_{n+1} − v_n)/h = f(x_{n+1}) + M g`, `x_{n+1} = x_n + h v_{n+1}` (Martin et al. 2011,
//! "Example-based elastic materials"; Gast et al. 2015, "Optimization integrator for large time
//! steps"). Each iteration solves `K Δ = −∇E` with
//! `K = M/h² + Σ_e Σ_q V_q Gᵀ ∂P/∂F G + Σ_k k_k I` (sparse Cholesky, the static solver's
//! machinery: `sparse.rs`; the exact Hessian where it is positive definite, else `∂P/∂F`
//! projected to positive semi-definite per quadrature point) and backtracks on `E`.
//!
//! - **Start:** `x⁰ = x_n + h v_n` on free nodes (the prediction without the step's body
//!   acceleration): a body at rest in equilibrium starts converged.
//! - **Converged** when the free residual `‖∇E‖ ≤ tolerance · load` (the load as in
//!   [`super::StaticResidual`]: the body force, or the reactions if larger), or when a step moves
//!   no coordinate by more than `1e-12` of the body's size (a force-free step). A step that
//!   reaches `max_iterations` keeps its last iterate and is counted in
//!   [`super::SolverCounters::unconverged_steps`]; if its residual is still above a tenth of the
//!   load the step watch rejects it and takes it again in halves (as VBD's).
//! - **Refactoring:** the numeric factor is kept between iterations and steps (same masses,
//!   pinned nodes, material and step) and refreshed at the current iterate when the residual
//!   falls by less than 4× in an iteration or the line search had to cut the step; near rest a
//!   step then costs a gradient and one back-substitution. With
//!   [`super::NewtonSettings::refactor_every_iteration`] it is pure Newton (quadratic near the
//!   solution).
//! - **Policy** ([`NewtonPolicy`], issue #61): `Auto` (the default) keeps the factor across
//!   steps — the interactive mode of `newton_core.rs` — where a factorisation costs at least
//!   [`NewtonPolicy::INTERACTIVE_FROM_ITERATIONS`] iterations with the kept factor
//!   ([`LinearSolver::refresh_cost_in_iterations`], counted from the factor's size, never timed),
//!   and refreshes it carefully elsewhere; from the first step the step watch rejects
//!   ([`StepSolver::step_rejected`]: a node flung, an unsolved step, energy gained) it is careful
//!   for the rest of the run, on the same mesh and material. What ran and why is
//!   [`NewtonPolicyReport`].
//! - The factorisation runs on one thread (`Par::Seq`), so results do not depend on the thread
//!   count; the element Hessians are computed in parallel and summed in a fixed order.

use super::error::SolverCounters;
use super::nan_guard::{BadElement, ORIGIN_NEWTON};
use super::newton_core::{Failure, HessianModel, LinearSolver, Objective, Outcome, Scratch, minimise};
use super::potential::Potential;
use super::settings::{NewtonPolicy, NewtonPolicyReport, NewtonSettings, SolverSettings};
use super::sparse::SparsePattern;
use super::step::{Hooks, StepInput, StepSolver};
use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::mesh::Mesh;

/// Newton's method on the step's incremental potential with the linear solver `L` (the sparse
/// Cholesky factor of `sparse.rs` by default; any [`LinearSolver`], which is how another
/// Newton-type solver is made: `registry.rs`).
pub(crate) struct Newton<L: LinearSolver = SparsePattern> {
    pattern: Option<L>,
    /// The model version and inertia step the pattern and factor were made for.
    made_for: (u64, f64),
    y: Vec<Vec3>,
    scratch: Scratch,
    /// Whether the last step reached its iteration limit above [`UNSOLVED_RESIDUAL`] of the load.
    failed: bool,
    /// The policy the last step ran and why.
    report: Option<NewtonPolicyReport>,
    /// The policy and `refactor_every_iteration` the report was resolved for (it is resolved
    /// again when they change, the pattern is remade or `Auto` falls back: not every step).
    asked: Option<(NewtonPolicy, bool)>,
    /// Why `Auto` turned careful for good (a step the watch rejected under the interactive one).
    fell_back: Option<String>,
}

/// A step left by the iteration limit with an unbalanced force above this fraction of the load
/// is reported failed ([`StepSolver::last_step_failed`]): the step watch takes it again in halves,
/// as VBD's (issue #36: a Newton step at its limit was counted and warned about, and kept).
const UNSOLVED_RESIDUAL: f64 = 1e-1;

impl<L: LinearSolver> Newton<L> {
    pub fn new(_mesh: &Mesh) -> Self {
        Self {
            pattern: None,
            made_for: (u64::MAX, 0.0),
            y: Vec::new(),
            scratch: Scratch::default(),
            failed: false,
            report: None,
            asked: None,
            fell_back: None,
        }
    }
}

/// `asked` with its policy resolved ([`NewtonPolicy::Auto`] by the problem: module docs), and why.
fn resolve(asked: NewtonSettings, refresh_cost: f64, free_dofs: usize, fell_back: Option<&str>) -> NewtonPolicyReport {
    let threshold = NewtonPolicy::INTERACTIVE_FROM_ITERATIONS;
    let (ran, why) = match (asked.policy, fell_back) {
        (NewtonPolicy::Auto, Some(why)) => (NewtonPolicy::Careful, why.to_string()),
        (NewtonPolicy::Auto, None) if refresh_cost >= threshold && !asked.refactor_every_iteration => (
            NewtonPolicy::Interactive,
            format!(
                "auto: a factorisation of the {free_dofs} unknowns costs about {refresh_cost:.0} iterations with the kept factor (interactive from {threshold:.0}), so the factor is kept across steps"
            ),
        ),
        (NewtonPolicy::Auto, None) => (
            NewtonPolicy::Careful,
            format!(
                "auto: a factorisation of the {free_dofs} unknowns costs about {refresh_cost:.0} iterations with the kept factor (interactive from {threshold:.0}): refreshing it is cheap"
            ),
        ),
        (policy, _) => (policy, format!("asked for (newton_policy = {})", policy.name())),
    };
    NewtonPolicyReport { ran, why }
}

impl Objective for Potential<'_> {
    fn eval(&self, x: &[Vec3], grad: &mut [Vec3]) -> (f64, f64) {
        Potential::eval(self, x, grad)
    }
}

impl<L: LinearSolver + Send + 'static> StepSolver for Newton<L> {
    fn work_summary(&self, settings: &SolverSettings, counters: &SolverCounters) -> String {
        format!("{}, {}", settings.method, L::work_summary(counters))
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }

    fn rebuild(&mut self, _mesh: &Mesh, _geometry: &[BlockGeometry], _settings: &SolverSettings, _geo: bool) {
        self.pattern = None;
        self.fell_back = None;
        self.report = None;
    }

    fn last_step_residuals(&self) -> &[f64] {
        &self.scratch.residuals
    }

    fn last_step_failed(&self) -> bool {
        self.failed
    }

    fn step_rejected(&mut self, time_secs: f64) {
        let interactive = self.report.as_ref().is_some_and(|r| r.ran == NewtonPolicy::Interactive);
        let auto = self.asked.is_some_and(|(policy, _)| policy == NewtonPolicy::Auto);
        if interactive && auto && self.fell_back.is_none() {
            self.fell_back = Some(format!(
                "auto: interactive until the step watch rejected the step from {time_secs:.3} s; careful since (on this mesh and material)"
            ));
            self.report = None;
        }
    }

    fn newton_policy(&self) -> Option<&NewtonPolicyReport> {
        self.report.as_ref()
    }

    fn solve_step(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let settings = s.settings.newton;
        let bad = |node: usize| BadElement::at_node(s.mesh, node, ORIGIN_NEWTON);
        super::nan_guard::check_input(s.mesh, positions)?;
        match &mut self.pattern {
            Some(pattern) if self.made_for.0 == s.model_version => {
                if self.made_for.1 != s.inertia_h {
                    // only the inertia's weight M/h̄² changed (a multistep integrator's first
                    // steps): the same pattern, a new factor
                    pattern.forget_model();
                }
            }
            _ => {
                self.pattern = Some(L::for_mesh(s.mesh, s.material, &|i| s.inv_mass[i] == 0.0).map_err(|_| bad(0))?);
                self.fell_back = None;
                self.report = None;
            }
        }
        self.made_for = (s.model_version, s.inertia_h);
        let pattern = self.pattern.as_mut().expect("made above");
        let asked = (settings.policy, settings.refactor_every_iteration);
        if self.report.is_none() || self.asked != Some(asked) {
            let (cost, dofs) = (pattern.refresh_cost_in_iterations(), pattern.free_dofs());
            self.report = Some(resolve(settings, cost, dofs, self.fell_back.as_deref()));
            self.asked = Some(asked);
        }
        let ran = self.report.as_ref().map_or(NewtonPolicy::Careful, |r| r.ran);
        let settings = NewtonSettings { policy: ran, ..settings };
        self.y.clear();
        self.y.extend_from_slice(positions);
        for (i, x) in positions.iter_mut().enumerate() {
            if s.inv_mass[i] > 0.0 {
                *x -= s.body_acceleration * (s.inertia_h * s.inertia_h);
            }
        }
        let springs = hooks.springs();
        let w = 1.0 / (s.inertia_h * s.inertia_h);
        let potential = Potential { input: s, y: &self.y, springs: &springs, w };
        let body_force = potential.load_n();
        let diagonal = potential.hessian_diagonal(pattern.dof_of(), pattern.free_dofs());
        let model = HessianModel { mesh: s.mesh, geometry: s.geometry, material: s.material, diagonal: &diagonal };
        let outcome = minimise(
            &potential,
            &model,
            pattern,
            positions,
            &settings,
            body_force,
            &mut self.scratch,
            counters,
            &mut |_| {},
        );
        self.failed = matches!(outcome, Ok(Outcome::Unconverged { residual }) if residual > UNSOLVED_RESIDUAL);
        match outcome {
            Ok(Outcome::Converged { .. } | Outcome::Stalled { .. }) => Ok(()),
            Ok(Outcome::Unconverged { .. }) => {
                counters.unconverged_steps += 1;
                Ok(())
            }
            Err(Failure::NonFinite { node }) => Err(bad(node)),
            Err(Failure::Factorisation(_)) => Err(bad(0)),
        }
    }
}
