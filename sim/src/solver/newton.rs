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
//!   [`super::SolverCounters::unconverged_steps`].
//! - **Refactoring:** the numeric factor is kept between iterations and steps (same masses,
//!   pinned nodes, material and step) and refreshed at the current iterate when the residual
//!   falls by less than 4× in an iteration or the line search had to cut the step; near rest a
//!   step then costs a gradient and one back-substitution. With
//!   [`super::NewtonSettings::refactor_every_iteration`] it is pure Newton (quadratic near the
//!   solution).
//! - The factorisation runs on one thread (`Par::Seq`), so results do not depend on the thread
//!   count; the element Hessians are computed in parallel and summed in a fixed order.

use super::SolverCounters;
use super::method::{Hooks, Method, StepInput, StepSolver};
use super::nan_guard::{BadElement, ORIGIN_NEWTON};
use super::settings::SolverSettings;
use super::sparse::SparsePattern;
use crate::Vec3;
use crate::effect::NodeSpring;
use crate::fem::energy::total_energy_and_gradient;
use crate::fem::geometry::BlockGeometry;
use crate::mesh::Mesh;

/// The factorisation runs on one thread: results independent of the thread count.
const SEQ: faer::Par = faer::Par::Seq;

/// Residual decrease per iteration below which the kept factor is refreshed.
const SLOW_RATIO: f64 = 0.25;

pub(crate) struct Newton {
    pattern: Option<SparsePattern>,
    /// The model version and step the pattern and factor were made for.
    made_for: (u64, f64),
    /// The body's size (largest extent of the rest shape), for the step-size test.
    diagonal_m: f64,
    residuals: Vec<f64>,
    y: Vec<Vec3>,
    grad: Vec<Vec3>,
    trial: Vec<Vec3>,
    trial_grad: Vec<Vec3>,
}

impl Newton {
    pub fn new(mesh: &Mesh) -> Self {
        let (lo, hi) = mesh
            .rest_positions
            .iter()
            .fold((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        let diagonal_m = if mesh.rest_positions.is_empty() { 1.0 } else { (hi - lo).norm().max(f64::MIN_POSITIVE) };
        Self {
            pattern: None,
            made_for: (u64::MAX, 0.0),
            diagonal_m,
            residuals: Vec::new(),
            y: Vec::new(),
            grad: Vec::new(),
            trial: Vec::new(),
            trial_grad: Vec::new(),
        }
    }
}

/// The incremental potential and its gradient (free nodes only; held ones get a zero gradient);
/// also VBD's coarse correction's gradient ([`super::vbd_coarse`]).
pub(super) struct Potential<'a> {
    pub input: &'a StepInput<'a>,
    pub y: &'a [Vec3],
    pub springs: &'a [NodeSpring],
    /// `1/h²`.
    pub w: f64,
}

impl Potential<'_> {
    /// `E(x)` and `∇E(x)` (zero on held nodes), and the reactions `‖∇U − m a‖` at the held nodes.
    pub fn eval(&self, x: &[Vec3], grad: &mut [Vec3]) -> (f64, f64) {
        let s = self.input;
        let mut e = total_energy_and_gradient(s.mesh, s.geometry, s.material, x, grad);
        let mut reactions = 0.0;
        for (i, g) in grad.iter_mut().enumerate() {
            if s.inv_mass[i] == 0.0 {
                reactions += (*g - s.body_acceleration * s.masses_kg[i]).norm_squared();
                *g = Vec3::zeros();
                continue;
            }
            let d = x[i] - self.y[i];
            e += 0.5 * s.masses_kg[i] * self.w * d.norm_squared();
            *g += d * (s.masses_kg[i] * self.w);
        }
        for sp in self.springs {
            let i = sp.node as usize;
            let d = x[i] - sp.target_m;
            e += 0.5 * sp.stiffness_n_per_m * d.norm_squared();
            if s.inv_mass[i] > 0.0 {
                grad[i] += d * sp.stiffness_n_per_m;
            }
        }
        (e, reactions.sqrt())
    }
}

fn norm(v: &[Vec3]) -> f64 {
    v.iter().map(|g| g.norm_squared()).sum::<f64>().sqrt()
}

fn first_non_finite(x: &[Vec3], g: &[Vec3]) -> Option<usize> {
    x.iter().zip(g).position(|(a, b)| !a.iter().chain(b.iter()).all(|c| c.is_finite()))
}

impl StepSolver for Newton {
    fn method(&self) -> Method {
        Method::Newton
    }

    fn rebuild(&mut self, _mesh: &Mesh, _geometry: &[BlockGeometry], _settings: &SolverSettings, _geo: bool) {
        self.pattern = None;
    }

    fn last_step_residuals(&self) -> &[f64] {
        &self.residuals
    }

    fn solve_step(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let n = positions.len();
        let settings = s.settings.newton;
        let bad = |node: usize| BadElement::at_node(s.mesh, node, ORIGIN_NEWTON);
        if let Some(i) = super::nan_guard::first_non_finite_position(positions) {
            return Err(BadElement::at_node(s.mesh, i, super::nan_guard::ORIGIN_INPUT));
        }
        if self.pattern.is_none() || self.made_for != (s.model_version, s.h) {
            let pattern = SparsePattern::new(s.mesh, |i| s.inv_mass[i] == 0.0).map_err(|_| bad(0))?;
            self.pattern = Some(pattern);
            self.made_for = (s.model_version, s.h);
        }
        let pattern = self.pattern.as_mut().expect("made above");
        self.y.clear();
        self.y.extend_from_slice(positions);
        for (i, x) in positions.iter_mut().enumerate() {
            if s.inv_mass[i] > 0.0 {
                *x -= s.body_acceleration * (s.h * s.h);
            }
        }
        let springs = hooks.springs();
        let w = 1.0 / (s.h * s.h);
        let potential = Potential { input: s, y: &self.y, springs: &springs, w };
        let body_force: f64 = s.masses_kg.iter().map(|m| m * s.body_acceleration.norm()).sum();
        self.grad.resize(n, Vec3::zeros());
        self.trial_grad.resize(n, Vec3::zeros());
        let (mut energy, mut reactions) = potential.eval(positions, &mut self.grad);
        if let Some(node) = first_non_finite(positions, &self.grad) {
            return Err(bad(node));
        }
        if !energy.is_finite() {
            return Err(bad(0));
        }
        let diagonal: Vec<f64> = {
            let mut d = vec![0.0; pattern.free_dofs];
            for (dof, &k) in pattern.dof_of.iter().enumerate() {
                if k != usize::MAX {
                    d[k] = s.masses_kg[dof / 3] * w;
                }
            }
            for sp in &springs {
                for a in 0..3 {
                    let k = pattern.dof_of[3 * sp.node as usize + a];
                    if k != usize::MAX {
                        d[k] += sp.stiffness_n_per_m;
                    }
                }
            }
            d
        };
        self.residuals.clear();
        let mut step = vec![0.0; pattern.free_dofs];
        let mut refactor = settings.refactor_every_iteration || !pattern.is_factored();
        for _ in 0..settings.max_iterations {
            let residual = norm(&self.grad) / super::residual::load_scale(body_force, reactions);
            self.residuals.push(residual);
            if residual <= settings.tolerance {
                return Ok(());
            }
            counters.solver_iterations += 1;
            if refactor {
                // the exact Hessian where it is positive definite (quadratic convergence), else
                // the one projected per quadrature point
                let exact =
                    pattern.assemble_and_factor(s.mesh, s.geometry, s.material, positions, &diagonal, false, SEQ);
                if exact.is_err() {
                    pattern
                        .assemble_and_factor(s.mesh, s.geometry, s.material, positions, &diagonal, true, SEQ)
                        .map_err(|_| bad(0))?;
                    counters.factorizations += 1;
                }
                counters.factorizations += 1;
            }
            for (dof, &k) in pattern.dof_of.iter().enumerate() {
                if k != usize::MAX {
                    step[k] = -self.grad[dof / 3][dof % 3];
                }
            }
            pattern.solve_in_place(&mut step, SEQ);
            // backtracking on E: accept a decrease of E or, at its round-off floor, of the residual
            let mut t = 1.0;
            let mut accepted = false;
            let old_norm = norm(&self.grad);
            while t > 1e-8 {
                self.trial.clear();
                self.trial.extend_from_slice(positions);
                for (dof, &k) in pattern.dof_of.iter().enumerate() {
                    if k != usize::MAX {
                        self.trial[dof / 3][dof % 3] += t * step[k];
                    }
                }
                let (e, r) = potential.eval(&self.trial, &mut self.trial_grad);
                if e.is_finite() && (e <= energy || norm(&self.trial_grad) < old_norm) {
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
            positions.copy_from_slice(&self.trial);
            std::mem::swap(&mut self.grad, &mut self.trial_grad);
            let moved = step.iter().fold(0.0f64, |m, v| m.max(v.abs())) * t;
            if moved <= 1e-12 * self.diagonal_m {
                return Ok(());
            }
            let new_norm = norm(&self.grad);
            refactor = settings.refactor_every_iteration || t < 1.0 || new_norm > SLOW_RATIO * old_norm;
        }
        if let Some(node) = first_non_finite(positions, &self.grad) {
            return Err(bad(node));
        }
        counters.unconverged_steps += 1;
        Ok(())
    }
}
