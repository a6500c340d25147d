//! The one Newton's method of hox: it minimises a potential `Φ` over the free degrees of freedom
//! for the static solver ([`super::statics`]: `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i` at one load
//! fraction) and for the Newton solver's steps (`newton.rs`: the incremental potential of
//! [`super::potential`] under any of the [`super::integrator`]s, the reference motion's Newmark
//! steps among them).
//!
//! Each iteration solves `K Δ = −∇Φ` with `K = D + Σ_e Σ_q V_q Gᵀ ∂P/∂F G` (`D` a diagonal such
//! as `M/h²` plus spring stiffnesses, none for statics) and backtracks on `Φ` (Nocedal & Wright,
//! *Numerical Optimization*, 2nd ed., §3.1 and §3.4). How `K Δ = −∇Φ` is solved is a
//! [`LinearSolver`]: the sparse Cholesky factor of `sparse.rs` (exact solves), or any other that
//! implements the trait (an iterative one is told the residual, so it can solve loosely far from
//! the solution: an inexact Newton, Nocedal & Wright §7.1). One policy for every caller:
//! - **Hessian:** the linear solver's choice (`sparse.rs`: the exact one where it is positive
//!   definite, for quadratic convergence, else `∂P/∂F` projected to positive semi-definite per
//!   quadrature point).
//! - **Factor reuse:** the numeric factor is kept between iterations (and, by the caller's
//!   pattern, between steps) and refreshed at the current iterate when the residual falls by less
//!   than 4× in an iteration or the line search had to cut the step;
//!   [`super::NewtonSettings::refactor_every_iteration`] refreshes it every iteration (pure
//!   Newton).
//! - **Line search:** halve `t` from 1 until `Φ` does not increase or, at `Φ`'s round-off floor,
//!   the residual falls; below `t = 1e-8` the step is refused: with a reused factor the factor
//!   is refreshed and the iteration retried, with a fresh one the method stops.
//! - **Convergence:** the free residual `‖∇Φ‖ ≤ tolerance · load`, the load as in
//!   [`super::StaticResidual`] (the body force, or the reactions if larger); or a full step
//!   (`t = 1`) that moves no coordinate by more than `1e-12` of the body's size and no longer
//!   reduces the residual 4× (stalled at round-off: converged for a time step, whose start may
//!   already be the minimiser; the static solver asks for the tolerance).
//! - **Bits:** the factorisation and solves run on one thread (`Par::Seq`) and the element
//!   Hessians are summed in a fixed order, so results do not depend on the thread count.
//! - **Settings:** tolerance, iteration limit and refactoring from [`super::NewtonSettings`].

use super::error::SolverCounters;
use super::residual::load_scale;
use super::settings::NewtonSettings;
use super::sparse::{SparseError, SparsePattern};
use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;

/// The factorisation runs on one thread: results independent of the thread count.
const SEQ: faer::Par = faer::Par::Seq;

/// Residual decrease per iteration below which the kept factor is refreshed.
const SLOW_RATIO: f64 = 0.25;

/// Smallest line-search fraction tried before the step is refused.
const MIN_STEP_FRACTION: f64 = 1e-8;

/// A potential Newton minimises.
pub(crate) trait Objective {
    /// `Φ(x)` and `∇Φ(x)` into `grad`, zero on held nodes, and the reactions (the norm of what
    /// the gradient would be on the held nodes), newtons.
    fn eval(&self, x: &[Vec3], grad: &mut [Vec3]) -> (f64, f64);
}

/// The elastic model whose Hessian `K` is assembled, plus the diagonal `D` (one value per free
/// DOF of the pattern, or empty for none).
pub(crate) struct HessianModel<'a> {
    pub mesh: &'a Mesh,
    pub geometry: &'a [BlockGeometry],
    pub material: &'a Material,
    pub diagonal: &'a [f64],
}

/// How a minimisation ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Outcome {
    /// The residual reached the tolerance.
    Converged { residual: f64 },
    /// A full step moved no coordinate by more than `1e-12` of the body's size and no longer
    /// reduced the residual (round-off).
    Stalled { residual: f64 },
    /// The iteration limit was reached, or the line search failed with a fresh factor; `x` holds
    /// the last accepted iterate.
    Unconverged { residual: f64 },
}

/// Why a minimisation stopped without an iterate.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Failure {
    /// A position or gradient entry of this node is not finite (0 when only `Φ` is).
    NonFinite { node: usize },
    /// `K`'s model could not be made (the sparse factor: not even projected).
    Factorisation(SparseError),
}

/// How the one Newton solves `K Δ = r` (module docs): it keeps a model of `K` (a factor, element
/// Hessians), made at an iterate when [`minimise`] asks, and solves with the last one made.
pub(crate) trait LinearSolver {
    /// A solver for `mesh` without the degrees of freedom of the nodes where `held(i)`.
    fn for_mesh(mesh: &Mesh, held: &dyn Fn(usize) -> bool) -> Result<Self, SparseError>
    where
        Self: Sized;
    /// Global DOF `3 i + a` → free DOF, `usize::MAX` for a held one.
    fn dof_of(&self) -> &[usize];
    /// The number of free degrees of freedom.
    fn free_dofs(&self) -> usize;
    /// Whether a model of `K` is held (so an iteration can start by solving).
    fn is_ready(&self) -> bool;
    /// Makes the model of `K` at `x`, counting its work in `counters`.
    fn update(
        &mut self,
        model: &HessianModel<'_>,
        x: &[Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), SparseError>;
    /// Solves `K s = r` in place with the last model; `relative_residual` is the Newton
    /// iteration's (an iterative solver's forcing term), ignored by an exact one.
    fn solve(&mut self, r: &mut [f64], relative_residual: f64, counters: &mut SolverCounters);
    /// A few words on its work for a status line ("12 factorisations").
    fn work_summary(counters: &SolverCounters) -> String
    where
        Self: Sized;
}

impl LinearSolver for SparsePattern {
    fn for_mesh(mesh: &Mesh, held: &dyn Fn(usize) -> bool) -> Result<Self, SparseError> {
        SparsePattern::new(mesh, held)
    }
    fn dof_of(&self) -> &[usize] {
        &self.dof_of
    }
    fn free_dofs(&self) -> usize {
        self.free_dofs
    }
    fn is_ready(&self) -> bool {
        self.is_factored()
    }
    /// The exact Hessian where it is positive definite, else the projected one.
    fn update(
        &mut self,
        model: &HessianModel<'_>,
        x: &[Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), SparseError> {
        let exact = self.assemble_and_factor(model.mesh, model.geometry, model.material, x, model.diagonal, false, SEQ);
        if exact.is_err() {
            self.assemble_and_factor(model.mesh, model.geometry, model.material, x, model.diagonal, true, SEQ)?;
            counters.factorizations += 1;
        }
        counters.factorizations += 1;
        Ok(())
    }
    fn solve(&mut self, r: &mut [f64], _relative_residual: f64, _counters: &mut SolverCounters) {
        let started = std::time::Instant::now();
        self.solve_in_place(r, SEQ);
        self.cost.solve_secs += started.elapsed().as_secs_f64();
    }
    fn work_summary(counters: &SolverCounters) -> String {
        format!("{} factorisations", counters.factorizations)
    }
}

/// Buffers kept between minimisations (no allocation per step).
#[derive(Default)]
pub(crate) struct Scratch {
    grad: Vec<Vec3>,
    trial: Vec<Vec3>,
    trial_grad: Vec<Vec3>,
    step: Vec<f64>,
    /// The relative residual at the start of each iteration of the last minimisation.
    pub residuals: Vec<f64>,
}

/// The body's size (the diagonal of its rest bounding box), for the stalled-step test.
pub(crate) fn body_size_m(rest: &[Vec3]) -> f64 {
    if rest.is_empty() {
        return 1.0;
    }
    let (lo, hi) = rest
        .iter()
        .fold((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    (hi - lo).norm().max(f64::MIN_POSITIVE)
}

fn norm(v: &[Vec3]) -> f64 {
    v.iter().map(|g| g.norm_squared()).sum::<f64>().sqrt()
}

fn first_non_finite(x: &[Vec3], g: &[Vec3]) -> Option<usize> {
    x.iter().zip(g).position(|(a, b)| !a.iter().chain(b.iter()).all(|c| c.is_finite()))
}

/// Minimises `objective` from `x` (held nodes already placed; they do not move) by Newton's
/// method with the policy of the module doc. `body_force_n` is the load the residual is measured
/// against (with the reactions); `on_iteration(residual)` is called at the start of every
/// iteration; the counters count iterations and factorisations.
#[allow(clippy::too_many_arguments)]
pub(crate) fn minimise(
    objective: &dyn Objective,
    model: &HessianModel<'_>,
    linear: &mut dyn LinearSolver,
    x: &mut [Vec3],
    settings: &NewtonSettings,
    body_force_n: f64,
    scratch: &mut Scratch,
    counters: &mut SolverCounters,
    on_iteration: &mut dyn FnMut(f64),
) -> Result<Outcome, Failure> {
    let n = x.len();
    let body_size = body_size_m(&model.mesh.rest_positions);
    scratch.grad.resize(n, Vec3::zeros());
    scratch.trial_grad.resize(n, Vec3::zeros());
    scratch.step.clear();
    scratch.step.resize(linear.free_dofs(), 0.0);
    scratch.residuals.clear();
    let (mut energy, mut reactions) = objective.eval(x, &mut scratch.grad);
    if let Some(node) = first_non_finite(x, &scratch.grad) {
        return Err(Failure::NonFinite { node });
    }
    if !energy.is_finite() {
        return Err(Failure::NonFinite { node: 0 });
    }
    let mut refactor = settings.refactor_every_iteration || !linear.is_ready();
    for _ in 0..settings.max_iterations {
        let residual = norm(&scratch.grad) / load_scale(body_force_n, reactions);
        scratch.residuals.push(residual);
        on_iteration(residual);
        if residual <= settings.tolerance {
            return Ok(Outcome::Converged { residual });
        }
        counters.solver_iterations += 1;
        if refactor {
            linear.update(model, x, counters).map_err(Failure::Factorisation)?;
        }
        let step = &mut scratch.step;
        for (dof, &k) in linear.dof_of().iter().enumerate() {
            if k != usize::MAX {
                step[k] = -scratch.grad[dof / 3][dof % 3];
            }
        }
        linear.solve(step, residual, counters);
        // backtracking on Φ: accept a decrease of Φ or, at its round-off floor, of the residual
        let mut t = 1.0;
        let mut accepted = false;
        let old_norm = norm(&scratch.grad);
        while t > MIN_STEP_FRACTION {
            scratch.trial.clear();
            scratch.trial.extend_from_slice(x);
            for (dof, &k) in linear.dof_of().iter().enumerate() {
                if k != usize::MAX {
                    scratch.trial[dof / 3][dof % 3] += t * step[k];
                }
            }
            let (e, r) = objective.eval(&scratch.trial, &mut scratch.trial_grad);
            if e.is_finite() && (e <= energy || norm(&scratch.trial_grad) < old_norm) {
                accepted = true;
                energy = e;
                reactions = r;
                break;
            }
            t *= 0.5;
        }
        if !accepted {
            if refactor {
                break;
            }
            refactor = true;
            continue;
        }
        x.copy_from_slice(&scratch.trial);
        std::mem::swap(&mut scratch.grad, &mut scratch.trial_grad);
        // a full step that moves nothing and no longer reduces the residual: the iterate is the
        // minimiser to round-off (a step the line search cut short, or one that still reduces
        // the residual, says nothing of the kind)
        let moved = step.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let new_norm = norm(&scratch.grad);
        if t == 1.0 && moved <= 1e-12 * body_size && new_norm > SLOW_RATIO * old_norm {
            let residual = new_norm / load_scale(body_force_n, reactions);
            return Ok(Outcome::Stalled { residual });
        }
        refactor = settings.refactor_every_iteration || t < 1.0 || new_norm > SLOW_RATIO * old_norm;
    }
    if let Some(node) = first_non_finite(x, &scratch.grad) {
        return Err(Failure::NonFinite { node });
    }
    let residual = norm(&scratch.grad) / load_scale(body_force_n, reactions);
    Ok(Outcome::Unconverged { residual })
}
