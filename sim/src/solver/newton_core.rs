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
//!   pattern, between steps) and refreshed at the current iterate when the line search had to cut
//!   the step or the residual fell less than 4× in an iteration. In the interactive mode
//!   ([`super::NewtonPolicy::Interactive`]; chosen by the problem by default, `newton.rs`) the
//!   4× rule gives way to a weighing: the factor is refreshed when
//!   the residual no longer halves, or when keeping it costs more than a refresh:
//!   a refresh costs [`LinearSolver::refresh_cost_in_iterations`] iterations `R`; an iteration
//!   whose residual fell by less than 4× (ratio `ρ`) predicts `n = ln(tol/r)/ln ρ` more kept-factor
//!   iterations where a fresh factor needs about one, and the factor is refreshed when
//!   `debt + n − 1 > R`, the debt being the iterations beyond two per minimisation spent with it
//!   since its last refresh (a rent-or-buy rule: a factor that is always slightly slow is still
//!   refreshed, after about `R` iterations' worth of slowness; issue #37: the fixed 4× rule
//!   refactorised in frames a fresh factor took as many iterations as the kept one);
//!   [`super::NewtonSettings::refactor_every_iteration`] refreshes it every iteration (pure
//!   Newton).
//! - **Quasi-Newton correction of the kept factor** (interactive mode): with an exact linear
//!   solver (the factor),
//!   each accepted step's secant pair `(s, y)` (`y` the gradient's change) is kept, the last
//!   [`SECANT_PAIRS`] of them since the factor was made, and the step is L-BFGS's two-loop
//!   recursion with the factor's `K⁻¹` as its initial inverse Hessian (Nocedal & Wright §7.2;
//!   Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time simulation of hyperelastic
//!   materials", ACM TOG 36(3), prefactor one matrix and correct it so). The pairs stay valid
//!   across time steps, whose potentials differ by a linear term only. On the P2 tube settling,
//!   the factorisations fell from 18 to 5 (docs/journal/performance.md session 24).
//! - **Precision** (interactive mode): a time step's factor (an inertia diagonal `D`) is single
//!   precision
//!   (`sparse.rs`: half the solves' memory traffic), its error corrected by the iteration; a
//!   static solve's stiffness alone keeps double precision.
//! - **Line search:** halve `t` from 1 until `Φ` does not increase or, at `Φ`'s round-off floor,
//!   the residual falls; below `t = 1e-8` the step is refused: with a reused factor the factor
//!   is refreshed and the iteration retried, with a fresh one the method stops.
//! - **Convergence:** the free residual `‖∇Φ‖ ≤ tolerance · load`, the load as in
//!   [`super::StaticResidual`] (the body force, or the reactions if larger); or a full step
//!   (`t = 1`) that moves no coordinate by more than `1e-12` of the body's size and no longer
//!   reduces the residual 4× (stalled at round-off: converged for a time step, whose start may
//!   already be the minimiser; the static solver asks for the tolerance).
//! - **Bits:** the factorisation and solves run on one thread (`Par::Seq`), the element
//!   Hessians are summed in a fixed order and the gradient passes add their ranges in a fixed
//!   order (`fem::energy`), so results do not depend on the thread count. (faer's parallel
//!   factorisation on two threads made the 34k-unknown bracket's factorising frames slower,
//!   p95 297 ms against 211, docs/journal/performance.md session 31.)
//! - **Settings:** tolerance, iteration limit and refactoring from [`super::NewtonSettings`].

use super::error::SolverCounters;
use super::residual::load_scale;
use super::settings::{NewtonPolicy, NewtonSettings};
use super::sparse::{SparseError, SparsePattern};

/// The factorisation runs on one thread: results independent of the thread count.
const SEQ: faer::Par = faer::Par::Seq;
use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;

/// Residual decrease per iteration at or below which the kept factor is kept without weighing.
const SLOW_RATIO: f64 = 0.25;

/// Residual decrease per iteration above which the kept factor is refreshed whatever it costs.
const STALE_RATIO: f64 = 0.5;

/// Secant pairs the quasi-Newton correction of the kept factor remembers.
const SECANT_PAIRS: usize = 8;

/// Iterations per minimisation a fresh factor takes at least (from a step's predictor to the
/// tolerance); the first whole minimisation after a refresh tells how many it does take, and the
/// iterations later ones take beyond that count as the kept factor's debt.
const FRESH_ITERATIONS: usize = 2;

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
    /// A solver for `mesh` under `material` (whose formulation may widen the coupling:
    /// [`crate::fem::energy::mixed::patch`]) without the degrees of freedom of the nodes where
    /// `held(i)`.
    fn for_mesh(mesh: &Mesh, material: &Material, held: &dyn Fn(usize) -> bool) -> Result<Self, SparseError>
    where
        Self: Sized;
    /// Global DOF `3 i + a` → free DOF, `usize::MAX` for a held one.
    fn dof_of(&self) -> &[usize];
    /// The number of free degrees of freedom.
    fn free_dofs(&self) -> usize;
    /// Whether a model of `K` is held (so an iteration can start by solving).
    fn is_ready(&self) -> bool;
    /// Drops the model of `K` (the potential changed, not the pattern: the next iteration remakes
    /// it on the pattern kept).
    fn forget_model(&mut self);
    /// Whether a time step's model may be kept in single precision (the interactive mode).
    fn set_single_precision(&mut self, _single: bool) {}
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
    /// What remaking the model costs, in iterations with the kept one (the factor reuse rule of
    /// the module docs). An estimate from counts, never a clock, so that runs are repeatable.
    fn refresh_cost_in_iterations(&self) -> f64 {
        1.0
    }
    /// Whether a solve applies one fixed linear operator (an exact factor's `K⁻¹`), so that the
    /// kept model may be corrected by secant pairs (module docs); an iterative solver's varying
    /// inexact solves are used as they come.
    fn solves_exactly(&self) -> bool {
        false
    }
    /// A few words on its work for a status line ("12 factorisations").
    fn work_summary(counters: &SolverCounters) -> String
    where
        Self: Sized;
}

impl LinearSolver for SparsePattern {
    fn for_mesh(mesh: &Mesh, material: &Material, held: &dyn Fn(usize) -> bool) -> Result<Self, SparseError> {
        SparsePattern::new(mesh, material, held)
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
    fn forget_model(&mut self) {
        self.forget_factor();
    }
    fn set_single_precision(&mut self, single: bool) {
        self.single_precision = single;
    }
    /// The exact Hessian where it is positive definite, else the projected one.
    fn update(
        &mut self,
        model: &HessianModel<'_>,
        x: &[Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), SparseError> {
        // with an inertia diagonal (a time step) the factor is kept in single precision, its
        // error corrected by the iteration; a static solve's stiffness alone is too ill-conditioned
        let single = self.single_precision && !model.diagonal.is_empty();
        let attempts: &[(bool, bool)] =
            if single { &[(false, true), (true, true), (true, false)] } else { &[(false, false), (true, false)] };
        let mut last = Err(SparseError::NotPositiveDefinite);
        for &(projected, single) in attempts {
            counters.factorizations += 1;
            last = self.assemble_and_factor(
                model.mesh,
                model.geometry,
                model.material,
                x,
                model.diagonal,
                projected,
                single,
                SEQ,
            );
            if last.is_ok() {
                break;
            }
        }
        last
    }
    /// A factorisation's floating-point work grows as the factor's entries times its mean column
    /// length, a solve's memory traffic as its entries: their ratio is the mean column length
    /// over a rate measured on the P2 tube (4,911 nodes, 260 entries per column: in single
    /// precision a factorisation 60–75 ms, an iteration with the kept factor 3.5–4.5 ms,
    /// docs/journal/performance.md session 24).
    fn refresh_cost_in_iterations(&self) -> f64 {
        const ENTRIES_PER_COLUMN_PER_ITERATION: f64 = 15.0;
        let per_column = self.cost.factor_nonzeros as f64 / self.free_dofs.max(1) as f64;
        (per_column / ENTRIES_PER_COLUMN_PER_ITERATION).max(2.0)
    }
    fn solves_exactly(&self) -> bool {
        true
    }
    fn solve(&mut self, r: &mut [f64], _relative_residual: f64, _counters: &mut SolverCounters) {
        let started = web_time::Instant::now();
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
    /// Iterations spent with the kept factor beyond [`Self::fresh_iterations`] per minimisation
    /// since it was made (the factor reuse rule of the module docs).
    debt_iterations: f64,
    /// The iterations of the first whole minimisation with the kept factor (at least
    /// [`FRESH_ITERATIONS`]), `None` until one has ended.
    fresh_iterations: Option<usize>,
    /// The secant pairs gathered since the kept factor was made (module docs: the quasi-Newton
    /// correction), oldest first.
    pairs: SecantPairs,
    /// The free gradient before the last accepted step.
    grad_free: Vec<f64>,
}

/// Secant pairs `(s, y, 1/(s·y))` of the potential in free degrees of freedom (`s` an accepted
/// step, `y` the gradient's change over it), for the two-loop recursion of L-BFGS (Nocedal &
/// Wright §7.2, Algorithm 7.4) with the kept factor as the initial inverse Hessian.
#[derive(Default)]
pub(crate) struct SecantPairs {
    pairs: std::collections::VecDeque<(Vec<f64>, Vec<f64>, f64)>,
    alphas: Vec<f64>,
}

impl SecantPairs {
    fn clear(&mut self) {
        self.pairs.clear();
    }

    /// Adds `(s, y)` when it has positive curvature (`s·y > 0`, so the update stays positive
    /// definite), dropping the oldest beyond [`SECANT_PAIRS`].
    fn push(&mut self, s: &[f64], y: &[f64]) {
        let sy: f64 = s.iter().zip(y).map(|(a, b)| a * b).sum();
        let (ss, yy): (f64, f64) = (s.iter().map(|a| a * a).sum(), y.iter().map(|b| b * b).sum());
        if !(sy > 1e-12 * (ss * yy).sqrt()) {
            return;
        }
        let (mut s_kept, mut y_kept) = if self.pairs.len() == SECANT_PAIRS {
            self.pairs.pop_front().map(|(a, b, _)| (a, b)).unwrap_or_default()
        } else {
            Default::default()
        };
        s_kept.clear();
        s_kept.extend_from_slice(s);
        y_kept.clear();
        y_kept.extend_from_slice(y);
        self.pairs.push_back((s_kept, y_kept, 1.0 / sy));
    }

    /// `q ← H q` with `H` the L-BFGS inverse over `solve` (the kept factor's `K⁻¹`).
    fn apply(&mut self, q: &mut [f64], solve: &mut dyn FnMut(&mut [f64])) {
        self.alphas.clear();
        for (s, y, rho) in self.pairs.iter().rev() {
            let alpha = rho * dot(s, q);
            q.iter_mut().zip(y).for_each(|(v, yi)| *v -= alpha * yi);
            self.alphas.push(alpha);
        }
        solve(q);
        for ((s, y, rho), alpha) in self.pairs.iter().zip(self.alphas.iter().rev()) {
            let beta = rho * dot(y, q);
            q.iter_mut().zip(s).for_each(|(v, si)| *v += (alpha - beta) * si);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Whether the kept factor should be refreshed after an iteration that reduced the residual
/// from `old_norm` to `new_norm` with a full step, `target` being the converged residual and
/// `refresh_cost` a refresh's cost in iterations (module docs).
fn kept_factor_costs_more(old_norm: f64, new_norm: f64, target: f64, refresh_cost: f64, debt: f64) -> bool {
    let ratio = new_norm / old_norm;
    if new_norm <= target || ratio <= SLOW_RATIO {
        return false;
    }
    if !(ratio < STALE_RATIO) {
        return true;
    }
    let remaining = ((target / new_norm).ln() / ratio.ln()).ceil();
    debt + remaining - 1.0 > refresh_cost
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
    let refresh_cost = linear.refresh_cost_in_iterations();
    // the caller resolves `Auto` (`newton.rs`); left unresolved it is the careful policy
    let interactive = settings.policy == NewtonPolicy::Interactive;
    linear.set_single_precision(interactive);
    let correct_by_secants = interactive && linear.solves_exactly() && !settings.refactor_every_iteration;
    if scratch.pairs.pairs.front().is_some_and(|(s, _, _)| s.len() != linear.free_dofs()) {
        scratch.pairs.clear();
    }
    let mut solves = 0usize;
    let mut refreshed_midway = false;
    // the kept factor's debt grows by the iterations beyond a fresh factor's when a minimisation
    // ends; the first one wholly with a fresh factor sets what a fresh factor's are
    let settle_debt = |scratch: &mut Scratch, solves: usize, refreshed_midway: bool| match scratch.fresh_iterations {
        None if !refreshed_midway => scratch.fresh_iterations = Some(solves.max(FRESH_ITERATIONS)),
        None => {}
        Some(fresh) => scratch.debt_iterations += solves.saturating_sub(fresh) as f64,
    };
    for iteration in 0..settings.max_iterations {
        let scale = load_scale(body_force_n, reactions);
        let residual = norm(&scratch.grad) / scale;
        scratch.residuals.push(residual);
        on_iteration(residual);
        if residual <= settings.tolerance {
            settle_debt(scratch, solves, refreshed_midway);
            return Ok(Outcome::Converged { residual });
        }
        counters.solver_iterations += 1;
        if refactor {
            linear.update(model, x, counters).map_err(Failure::Factorisation)?;
            scratch.debt_iterations = 0.0;
            scratch.fresh_iterations = None;
            scratch.pairs.clear();
            refreshed_midway = solves > 0;
        }
        solves += 1;
        let step = &mut scratch.step;
        scratch.grad_free.resize(step.len(), 0.0);
        for (dof, &k) in linear.dof_of().iter().enumerate() {
            if k != usize::MAX {
                scratch.grad_free[k] = scratch.grad[dof / 3][dof % 3];
                step[k] = -scratch.grad[dof / 3][dof % 3];
            }
        }
        if correct_by_secants {
            scratch.pairs.apply(step, &mut |q| linear.solve(q, residual, counters));
        } else {
            linear.solve(step, residual, counters);
        }
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
        if correct_by_secants {
            // s = t Δ, y = ∇Φ(x + s) − ∇Φ(x), in free degrees of freedom (grad_free becomes y)
            for (dof, &k) in linear.dof_of().iter().enumerate() {
                if k != usize::MAX {
                    scratch.grad_free[k] = scratch.grad[dof / 3][dof % 3] - scratch.grad_free[k];
                }
            }
            step.iter_mut().for_each(|v| *v *= t);
            scratch.pairs.push(step, &scratch.grad_free);
        }
        // a full step that moves nothing and no longer reduces the residual: the iterate is the
        // minimiser to round-off (a step the line search cut short, or one that still reduces
        // the residual, says nothing of the kind)
        let moved = step.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let new_norm = norm(&scratch.grad);
        if t == 1.0 && moved <= 1e-12 * body_size && new_norm > SLOW_RATIO * old_norm {
            let residual = new_norm / load_scale(body_force_n, reactions);
            settle_debt(scratch, solves, refreshed_midway);
            return Ok(Outcome::Stalled { residual });
        }
        let target = settings.tolerance * load_scale(body_force_n, reactions);
        // a step's first iteration says little of the factor: from the predictor even a fresh
        // factor's full Newton step contracts the residual only 2–3× on a swinging body (the
        // nonlinearity), and a fresh factor then converges quadratically
        let slow = if interactive {
            iteration > 0 && kept_factor_costs_more(old_norm, new_norm, target, refresh_cost, scratch.debt_iterations)
        } else {
            new_norm > SLOW_RATIO * old_norm
        };
        refactor = settings.refactor_every_iteration || t < 1.0 || slow;
    }
    settle_debt(scratch, solves, refreshed_midway);
    if let Some(node) = first_non_finite(x, &scratch.grad) {
        return Err(Failure::NonFinite { node });
    }
    let residual = norm(&scratch.grad) / load_scale(body_force_n, reactions);
    Ok(Outcome::Unconverged { residual })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two-loop recursion satisfies the newest secant equation `H y = s` whatever the
    /// initial inverse, and with no pairs it is that inverse; a pair of negative curvature is
    /// left out.
    #[test]
    fn the_secant_correction_satisfies_the_newest_secant_equation() {
        let n = 7;
        // a symmetric positive definite A: secant pairs of the quadratic ½ xᵀ A x
        let a = |x: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    (0..n).map(|j| x[j] * if i == j { 4.0 + i as f64 } else { 1.0 / (1.0 + (i + j) as f64) }).sum()
                })
                .collect()
        };
        // the initial inverse: a diagonal, far from A⁻¹
        let mut initial = |q: &mut [f64]| q.iter_mut().enumerate().for_each(|(i, v)| *v /= 1.0 + 0.5 * i as f64);
        let mut pairs = SecantPairs::default();
        let mut q: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let plain: Vec<f64> = q.iter().enumerate().map(|(i, v)| v / (1.0 + 0.5 * i as f64)).collect();
        pairs.apply(&mut q, &mut initial);
        assert_eq!(q, plain, "no pairs: the initial inverse");
        for k in 0..(SECANT_PAIRS + 3) {
            let s: Vec<f64> = (0..n).map(|i| ((k * n + i) as f64 * 0.7).cos()).collect();
            let y = a(&s);
            pairs.push(&s, &y);
            let mut hy = y.clone();
            pairs.apply(&mut hy, &mut initial);
            let gap = hy.iter().zip(&s).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            assert!(gap < 1e-12, "pair {k}: H y differs from s by {gap:e}");
            assert!(pairs.pairs.len() <= SECANT_PAIRS);
        }
        let before = pairs.pairs.len();
        let s = vec![1.0; n];
        let y: Vec<f64> = a(&s).iter().map(|v| -v).collect();
        pairs.push(&s, &y);
        assert_eq!(pairs.pairs.len(), before, "a pair of negative curvature is refused");
    }

    /// The refresh rule: a fast kept factor is kept, a slow one refreshed when what it would
    /// still cost outweighs a factorisation, a diverging one always.
    #[test]
    fn the_kept_factor_is_refreshed_when_it_costs_more_than_a_factorisation() {
        let target = 1e-6;
        assert!(!kept_factor_costs_more(1.0, 0.2, target, 10.0, 0.0), "4× or better: kept");
        assert!(!kept_factor_costs_more(1.0, 0.4, 0.5, 10.0, 0.0), "one more iteration: kept");
        assert!(kept_factor_costs_more(1.0, 0.4, target, 10.0, 0.0), "15 more iterations at 0.4: refreshed");
        assert!(!kept_factor_costs_more(1.0, 0.4, target, 20.0, 0.0), "unless a factorisation costs more");
        assert!(kept_factor_costs_more(1.0, 0.3, 1e-3, 10.0, 9.0), "the debt counts");
        assert!(kept_factor_costs_more(1.0, 0.95, 0.9, 1e9, 0.0), "no longer halving: refreshed");
        assert!(!kept_factor_costs_more(1.0, 0.95, 0.96, 1e9, 0.0), "converged: nothing to refresh");
    }
}
