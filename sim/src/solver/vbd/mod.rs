//! Vertex block descent (Chen, Liu, Yang, Yuksel, "Vertex Block Descent", ACM Transactions on
//! Graphics 43(4), 2024): implicit Euler's incremental potential
//!
//! `G(x) = Σ_i m_i/(2h²) |x_i − y_i|² + Σ_e U_e(x) + Σ_k k_k/2 |x_{n_k} − t_k|²`
//!
//! minimised by block Gauss–Seidel over the nodes. Each free node `i` takes one 3×3 Newton step
//! on `G` with every other node fixed:
//!
//! `f_i = −(m_i/h²)(x_i − y_i) − Σ_{(e,a) ∋ i} Σ_q V_q P(F_q) ∇_X N_a(r_q) − Σ_k k_k (x_i − t_k)`,
//! `H_i = (m_i/h²) I + Σ_{(e,a) ∋ i} Π_PSD(B_{e,a}) + Σ_k k_k I`, `x_i ← x_i + H_i⁻¹ f_i`,
//!
//! the sums running over every element holding the node with the element's own quadrature and
//! material (a P3 node sums every quadrature point of every P3 element around it), `B_{e,a}` the
//! diagonal block of the element Hessian ([`crate::fem::energy::element_node_gradient_and_block`])
//! projected to positive semi-definite ([`crate::material::project_psd3`]), so `H_i` is positive
//! definite and the update a descent step. Nodes are coloured so that nodes of one colour share no
//! element ([`crate::mesh::adjacency::colour_nodes`]): colours run in order, the nodes of one
//! colour in parallel; each node reads only the others and writes only itself, so serial and
//! parallel sweeps, on any thread count, give the same bits.
//!
//! - **Initialisation** (§3.5 of the paper, [`super::VbdInit`]): by default, under implicit
//!   Euler, `x⁰ = x_n + h v_n + h² ã ĝ` with `ã` the body's acceleration along gravity `ĝ` over
//!   the last step clamped to `[0, |g|]`, so a body at rest in equilibrium starts — and stays —
//!   exactly there: VBD's fixed point is the static equilibrium for any iteration count (also
//!   under BDF2). Under Newmark, the integrator's guess (the motion with its last acceleration
//!   kept, at rest the same fixed point; [`super::step::StepInput::guess`]), and the step sweeps
//!   on until converged ([`super::VbdSettings::tolerance`]): Newmark damps nothing, so the error
//!   fixed sweeps leave feeds the next step's acceleration (10 sweeps blew the bending beam up
//!   within a second).
//! - **Acceleration** (§3.7): Chebyshev semi-iteration with spectral radius estimate `ρ`,
//!   `x⁽ᵏ⁾ = ω_k (x̄⁽ᵏ⁾ − x⁽ᵏ⁻²⁾) + x⁽ᵏ⁻²⁾`, `ω_1 = 1`, `ω_2 = 2/(2 − ρ²)`,
//!   `ω_k = 4/(4 − ρ² ω_{k−1})`; `ρ = 0.9` by default (measured: half the sweeps to settle the
//!   bending beam; the authors' code ships it off; 0.95 at 5 sweeps per step diverged).
//! - **Two-level correction** (ours, not the paper's; [`coarse`], on by default,
//!   `coarse_cells = 0` turns it off): before the sweeps, the step's `G` is minimised over
//!   smooth displacements — trilinear functions on a coarse grid over the body — by one Galerkin
//!   coarse-grid correction with a secant line search. The sweeps barely move smooth error (a
//!   beam's slow bending falls by about 0.5 % per sweep on Gmsh's P2 beam), so without it the
//!   steps stay far from converged there: with it that beam settles in 122 frames, as Newton,
//!   instead of 707, and each step costs two gradient evaluations more (plus the coarse matrix
//!   every ten steps). Chebyshev starts after it.
//! - Effects: contact's projection runs after every sweep; attachments are springs in `G`.
//!
//! **Cost.** A sweep visits every (node, element holding it) pair with the element's whole
//! quadrature, so it is kept to what the visit cannot avoid: the elements' `F_q` are cached
//! lane-major (four points per AVX2 register, [`PointLanes`]) and moved with each node and each
//! acceleration step instead of gathered and summed per visit; `P g` and the block come from one
//! call that shares their work ([`crate::material::Material::node_visit`], closed form for StVK
//! on four lanes); a block is tested positive definite by its leading minors before any
//! eigen-decomposition ([`crate::material::project_psd3`]); the node update and the `F_q` moves
//! are compiled for AVX2 and FMA where the CPU has them ([`Fused`]), and the 3 × 3 solve is a
//! hand-written Cholesky.
//! Measured on Gmsh's P2 beam (1,471 elements, docs/PERFORMANCE.md): about 530 instructions
//! per node-element visit, half of them the StVK law.

use super::error::SolverCounters;
use super::nan_guard::BadElement;
use super::potential::Potential;
use super::residual::load_scale;
use super::settings::{SolverSettings, VbdInit};
use super::step::{Hooks, StepInput, StepSolver};
use coarse::{CoarseSpace, coarse_cells};
use lanes::{Fused, LaneView, PointLanes, Snapshots};
use node::NodeUpdate;
use patch::{PatchView, Patches};

mod coarse;
mod lanes;
mod node;
mod patch;
use crate::Vec3;
use crate::effect::{ImplicitRole, NodeSpring};
use crate::fem::geometry::BlockGeometry;
use crate::math::shared::SharedMut;
use crate::mesh::Mesh;
use crate::mesh::adjacency::{NodeIncidence, colour_nodes};

/// Fewest nodes per parallel task within a colour.
const MIN_NODES_PER_TASK: usize = 16;
/// Below this, the adaptive initialisation's acceleration along gravity counts as zero, m/s².
const ADAPTIVE_ACCELERATION_FLOOR_M_S2: f64 = 1e-5;

pub(crate) struct Vbd {
    incidence: NodeIncidence,
    colours: Vec<Vec<u32>>,
    /// `v_n` and `v_{n−1}`, snapshots at the start of the last two steps.
    v_start: Vec<Vec3>,
    v_before: Vec<Vec3>,
    /// Snapshots held (0 after a reset, up to 2).
    history: u8,
    y: Vec<Vec3>,
    prev_iter: Vec<Vec3>,
    prev_prev: Vec<Vec3>,
    lanes: PointLanes,
    /// The `F_q` at the last two sweeps, for the acceleration.
    f_snapshots: Snapshots,
    fused: Fused,
    /// The two-level correction ([`coarse`]); None when `coarse_cells` is 0.
    coarse: Option<CoarseSpace>,
    /// The last step's residual stayed above [`ACCEPT_RESIDUAL`].
    failed: bool,
    /// P1's node patches under the mixed formulation ([`patch`]), built at the first step that
    /// needs them.
    patches: Option<Patches>,
    /// The node whose update diverged in the last step, if one did.
    diverged_at: Option<u32>,
}

impl Vbd {
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings) -> Self {
        let incidence = NodeIncidence::new(mesh);
        let colours = colour_nodes(mesh, &incidence);
        Self {
            incidence,
            colours,
            v_start: Vec::new(),
            v_before: Vec::new(),
            history: 0,
            y: Vec::new(),
            prev_iter: Vec::new(),
            prev_prev: Vec::new(),
            lanes: PointLanes::new(mesh, geometry),
            f_snapshots: Snapshots::default(),
            fused: Fused::detect(),
            coarse: CoarseSpace::for_settings(mesh, settings),
            failed: false,
            patches: None,
            diverged_at: None,
        }
    }
}

impl StepSolver for Vbd {
    fn work_summary(&self, settings: &SolverSettings, _counters: &SolverCounters) -> String {
        format!("vbd, {} sweeps", settings.vbd.iterations)
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }

    fn last_step_failed(&self) -> bool {
        self.failed
    }

    fn last_failure_why(&self) -> Option<String> {
        let node = self.diverged_at.filter(|_| self.failed)?;
        Some(format!("the vertex block update of node {node} lost its positive-definite block or came out non-finite"))
    }

    fn begin_step(&mut self, velocities: &[Vec3]) {
        let had = self.history >= 1 && self.v_start.len() == velocities.len();
        if had {
            std::mem::swap(&mut self.v_before, &mut self.v_start);
        }
        self.v_start.clear();
        self.v_start.extend_from_slice(velocities);
        self.history = if had { 2 } else { 1 };
    }

    fn reset_history(&mut self, warm: bool, num_nodes: usize) {
        // a warm start is at rest: its last velocity is zero, so the next step sees ã = 0
        self.history = if warm { 1 } else { 0 };
        self.v_start.clear();
        self.v_start.resize(num_nodes, Vec3::zeros());
    }

    fn rebuild(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings, geometry_changed: bool) {
        if geometry_changed {
            self.lanes = PointLanes::new(mesh, geometry);
            self.patches = None;
        }
        if geometry_changed || self.coarse.as_ref().map(CoarseSpace::target_cells) != coarse_cells(settings) {
            self.coarse = CoarseSpace::for_settings(mesh, settings);
        }
    }

    fn solve_step(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let h = s.h;
        super::nan_guard::check_input(s.mesh, positions)?;
        self.diverged_at = None;
        // the patches follow the material's formulation (a live switch to or from mixed)
        let wants_patches = crate::fem::energy::mixed::patch::has_patches(s.mesh, s.material);
        if !wants_patches || !self.patches.as_ref().is_some_and(|p| p.fits(s.mesh)) {
            self.patches =
                if wants_patches { Patches::new(s.mesh, s.geometry, s.material, &self.incidence) } else { None };
        }
        self.y.clear();
        self.y.extend_from_slice(positions);
        // the initial guess
        let g = s.body_acceleration;
        let g_norm = g.norm();
        for (i, x) in positions.iter_mut().enumerate() {
            if s.inv_mass[i] == 0.0 {
                continue;
            }
            let (xn, vn) = (s.prev_positions[i], self.v_start[i]);
            *x = match s.settings.vbd.init {
                VbdInit::Inertia => self.y[i],
                VbdInit::Previous => xn,
                VbdInit::Adaptive if s.guess.is_some() => s.guess.map_or(xn, |guess| guess[i]),
                VbdInit::Adaptive if g_norm == 0.0 => xn + vn * h,
                VbdInit::Adaptive if self.history < 2 => self.y[i],
                VbdInit::Adaptive => {
                    let dir = g / g_norm;
                    let a = ((vn - self.v_before[i]) / h).dot(&dir).clamp(0.0, g_norm);
                    let a = if a < ADAPTIVE_ACCELERATION_FLOOR_M_S2 { 0.0 } else { a };
                    if !s.settings.integrator.info().vbd_start_from_prediction {
                        xn + vn * h + dir * (a * h * h)
                    } else {
                        // the scheme's own prediction with ã in place of g (under implicit Euler
                        // the same point, `y = x_n + h v_n + h² g`): started from implicit Euler's
                        // explicit extrapolation instead, BDF2's unconverged sweeps lean towards
                        // an explicit scheme and gained energy on the undamped bending beam
                        // (+60 J in 25 s where Newton under BDF2 lost 32 J; issue #36)
                        self.y[i] + dir * ((a - g_norm) * s.inertia_h * s.inertia_h)
                    }
                }
            };
        }
        let springs = hooks.springs();
        let mut update = NodeUpdate {
            input: s,
            incidence: &self.incidence,
            y: &self.y,
            springs: &springs,
            w: 1.0 / (s.inertia_h * s.inertia_h),
            lame: s.material.lame(),
            fused: self.fused,
            line_search: false,
        };
        // rounds of sweeps: the first as the paper's VBD (Chebyshev-accelerated, full node
        // steps); when its residual is too large — more than the tolerance under Newmark, which
        // damps nothing, or more than [`ACCEPT_RESIDUAL`] of the load under the damping schemes
        // — more rounds, plain Gauss–Seidel with each node step backtracked on its potential, so
        // that every round lowers the step's potential, until it is met
        let target =
            if s.settings.integrator.info().needs_converged_steps { s.settings.vbd.tolerance } else { ACCEPT_RESIDUAL };
        let mut grad = Vec::new();
        let mut stale = true;
        let mut projected = false;
        for round in 0..MAX_ROUNDS {
            // (as the integrator's entry says, `vbd_chebyshev`; not under BDF2: Chebyshev's extrapolation leaves an unconverged step leaning to
            // overshoot, which BDF2, damping little and keeping such steps, turned into a steady
            // gain of energy on the undamped bending beam, +20 J in 50 s where Newton lost 66 J;
            // Newmark's steps converge, implicit Euler's damping outweighs it; issue #36)
            let accelerate = round == 0 && s.settings.integrator.info().vbd_chebyshev;
            let rho = if accelerate { s.settings.vbd.chebyshev_rho } else { 0.0 };
            update.line_search = round > 0;
            // the two-level correction: the smooth error the sweeps barely touch, first
            if let Some(c) = &mut self.coarse {
                if round == 0 {
                    c.begin_step(s, positions, &springs);
                }
                let corrected = c.correct(s, positions, &self.y, &springs);
                counters.coarse_corrections += u64::from(corrected && round == 0);
                stale |= corrected;
            }
            let mut omega = 1.0;
            if rho > 0.0 {
                self.prev_prev.clear();
                self.prev_prev.extend_from_slice(positions);
                self.prev_iter.clear();
                self.prev_iter.extend_from_slice(positions);
            }
            // the initial guess (and the correction) moved the positions as a whole: F_q from them,
            // then in step with each node move, each acceleration (F is affine in the positions, so
            // it mixes as they do) and, after a projection moved the positions, from them again
            for k in 1..=s.settings.vbd.iterations {
                if stale {
                    self.lanes.refresh(s.mesh, positions, self.fused);
                }
                if rho > 0.0 && k == 1 {
                    self.f_snapshots.start(&self.lanes);
                }
                let lanes = LaneView::of(&mut self.lanes, s.material);
                let parallel = s.settings.sweep.is_colour();
                let swept = match &mut self.patches {
                    Some(p) => {
                        p.refresh(s.mesh, s.material, &lanes);
                        let (view, colours) = p.view();
                        colours.iter().try_fold(0, |n, colour| {
                            Ok::<_, BadElement>(
                                n + sweep_colour(&update, colour, positions, &lanes, Some(&view), parallel)?,
                            )
                        })
                    }
                    None => self.colours.iter().try_fold(0, |n, colour| {
                        Ok::<_, BadElement>(n + sweep_colour(&update, colour, positions, &lanes, None, parallel)?)
                    }),
                };
                match swept {
                    Ok(n) => counters.node_updates += n,
                    Err(bad) => {
                        // a node's block lost positive definiteness or its step came out
                        // non-finite from finite input: the sweeps diverged (P3 mixed at
                        // ν = 0.4999 under full node steps), which a shorter step cures, so the
                        // step goes back to its start and is reported failed — the step watch
                        // takes it again in halves and, failing that, stops naming the node
                        positions.copy_from_slice(&self.y);
                        self.failed = true;
                        self.diverged_at = Some(bad.node);
                        return Ok(());
                    }
                }
                if rho > 0.0 {
                    omega = match k {
                        1 => 1.0,
                        2 => 2.0 / (2.0 - rho * rho),
                        _ => 4.0 / (4.0 - rho * rho * omega),
                    };
                    let mix = k >= 2 && omega > 1.0;
                    if mix {
                        for (i, x) in positions.iter_mut().enumerate() {
                            if s.inv_mass[i] > 0.0 {
                                *x = (*x - self.prev_prev[i]) * omega + self.prev_prev[i];
                            }
                        }
                    }
                    std::mem::swap(&mut self.prev_prev, &mut self.prev_iter);
                    self.prev_iter.copy_from_slice(positions);
                    self.f_snapshots.advance(&mut self.lanes, mix.then_some(omega));
                }
                let projections = *hooks.calls;
                hooks.after_projection(positions, Some(ImplicitRole::Projection));
                stale = *hooks.calls != projections;
                projected |= stale;
                #[cfg(test)]
                if !stale {
                    self.lanes.assert_in_step_with(s.mesh, positions);
                }
                counters.solver_iterations += 1;
            }
            // (a projection's push — contact's — is a force the potential does not hold: a step
            // with one is not measured by the potential's residual)
            if projected {
                self.failed = false;
                break;
            }
            let residual = relative_residual(s, positions, &self.y, &springs, &mut grad);
            self.failed = residual > ACCEPT_RESIDUAL;
            if residual <= target {
                break;
            }
            if round + 1 == MAX_ROUNDS {
                counters.unconverged_steps += 1;
            }
        }
        Ok(())
    }
}

/// The step residual (over the load) above which a VBD step under a damping scheme takes more
/// rounds of sweeps ([`Vbd`]'s rounds).
const ACCEPT_RESIDUAL: f64 = 1e-1;

/// The most rounds of sweeps a step takes where it must converge (Newmark).
const MAX_ROUNDS: u32 = 20;

/// The free residual of the step's incremental potential over the load (as Newton measures it).
fn relative_residual(s: &StepInput<'_>, x: &[Vec3], y: &[Vec3], springs: &[NodeSpring], grad: &mut Vec<Vec3>) -> f64 {
    grad.clear();
    grad.resize(x.len(), Vec3::zeros());
    let potential = Potential { input: s, y, springs, w: 1.0 / (s.inertia_h * s.inertia_h) };
    let (_, reactions) = potential.eval(x, grad);
    let norm = grad.iter().map(|g| g.norm_squared()).sum::<f64>().sqrt();
    norm / load_scale(potential.load_n(), reactions)
}

/// Updates the free nodes of one colour; returns how many moved.
fn sweep_colour(
    update: &NodeUpdate<'_>,
    colour: &[u32],
    positions: &mut [Vec3],
    lanes: &[LaneView<'_>],
    patches: Option<&PatchView<'_>>,
    parallel: bool,
) -> Result<u64, BadElement> {
    let inv_mass = update.input.inv_mass;
    let shared = SharedMut::new(positions);
    // SAFETY: nodes of one colour share no element, so each task touches only its node and the
    // F_q of elements no other task of this colour touches; with patches, they lie more than two
    // edges apart, so no two tasks touch one node's means.
    let node = |&i: &u32| -> Result<u64, BadElement> {
        let i = i as usize;
        if inv_mass[i] == 0.0 {
            return Ok(0);
        }
        Ok(u64::from(unsafe { update.step(i, shared, lanes, patches) }?))
    };
    if !parallel {
        return colour.iter().map(node).sum();
    }
    use rayon::prelude::*;
    colour.par_iter().with_min_len(MIN_NODES_PER_TASK).map(node).sum()
}

#[cfg(test)]
mod tests;
