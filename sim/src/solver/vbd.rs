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
//! - **Initialisation** (§3.5 of the paper, [`super::VbdInit`]): by default
//!   `x⁰ = x_n + h v_n + h² ã ĝ` with `ã` the body's acceleration along gravity `ĝ` over the
//!   last step clamped to `[0, |g|]`, so a body at rest in equilibrium starts — and stays —
//!   exactly there: VBD's fixed point is the static equilibrium for any iteration count.
//! - **Acceleration** (§3.7): Chebyshev semi-iteration with spectral radius estimate `ρ`,
//!   `x⁽ᵏ⁾ = ω_k (x̄⁽ᵏ⁾ − x⁽ᵏ⁻²⁾) + x⁽ᵏ⁻²⁾`, `ω_1 = 1`, `ω_2 = 2/(2 − ρ²)`,
//!   `ω_k = 4/(4 − ρ² ω_{k−1})`; `ρ = 0.9` by default (measured: half the sweeps to settle the
//!   bending beam; the authors' code ships it off; 0.95 at 5 sweeps per step diverged).
//! - Effects: contact's projection runs after every sweep; attachments are springs in `G`.

use super::SolverCounters;
use super::method::{Hooks, Method, StepInput, StepSolver};
use super::nan_guard::{BadElement, ORIGIN_VBD};
use super::settings::{SolverSettings, VbdInit};
use crate::Vec3;
use crate::effect::{ImplicitRole, NodeSpring};
use crate::fem::energy::{element_grads, element_node_gradient_and_block, gather};
use crate::fem::geometry::BlockGeometry;
use crate::material::project_psd3;
use crate::mesh::Mesh;
use crate::mesh::adjacency::{NodeIncidence, colour_nodes};
use crate::xpbd::constraint::NodeScratch;
use crate::xpbd::kernels::SharedMut;
use nalgebra::Matrix3;

/// Fewest nodes per parallel task within a colour.
const MIN_NODES_PER_TASK: usize = 64;
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
}

impl Vbd {
    pub fn new(mesh: &Mesh, _settings: &SolverSettings) -> Self {
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
        }
    }
}

/// What a node update reads.
struct NodeUpdate<'a> {
    input: &'a StepInput<'a>,
    incidence: &'a NodeIncidence,
    y: &'a [Vec3],
    springs: &'a [NodeSpring],
    w: f64,
}

impl NodeUpdate<'_> {
    /// The Newton step of node `i` on `G` with the others fixed (`read` gives positions), or
    /// None when the node has no unbalanced force.
    fn delta(&self, i: usize, read: impl Fn(usize) -> Vec3) -> Result<Option<Vec3>, BadElement> {
        let s = self.input;
        let xi = read(i);
        let m_w = s.masses_kg[i] * self.w;
        let mut f = (self.y[i] - xi) * m_w;
        let mut h = Matrix3::identity() * m_w;
        for inc in self.incidence.of(i) {
            let (b, e) = (inc.block as usize, inc.element as usize);
            let nodes = s.mesh.blocks[b].element(e);
            let g = &s.geometry[b];
            let n = nodes.len();
            let (mut x, mut rest) = (NodeScratch::new(Vec3::zeros(), n), NodeScratch::new(Vec3::zeros(), n));
            let (x, rest) = (x.as_mut_slice(), rest.as_mut_slice());
            for (xk, &node) in x.iter_mut().zip(nodes) {
                *xk = read(node as usize);
            }
            gather(&s.mesh.rest_positions, nodes, rest);
            let (grad, block) = element_node_gradient_and_block(
                x,
                rest,
                element_grads(g, e),
                g.volumes(e),
                s.material,
                inc.local as usize,
                false,
            );
            f -= grad;
            h += project_psd3(&block);
        }
        for sp in self.springs.iter().filter(|sp| sp.node as usize == i) {
            f -= (xi - sp.target_m) * sp.stiffness_n_per_m;
            h += Matrix3::identity() * sp.stiffness_n_per_m;
        }
        if f == Vec3::zeros() {
            return Ok(None);
        }
        let delta = h.cholesky().map(|c| c.solve(&f));
        match delta {
            Some(d) if d.iter().all(|c| c.is_finite()) => Ok(Some(d)),
            _ => Err(BadElement::at_node(s.mesh, i, ORIGIN_VBD)),
        }
    }
}

impl StepSolver for Vbd {
    fn method(&self) -> Method {
        Method::Vbd
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

    fn rebuild(&mut self, _mesh: &Mesh, _geometry: &[BlockGeometry], _settings: &SolverSettings, _geo: bool) {}

    fn solve_step(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let h = s.h;
        if let Some(i) = super::nan_guard::first_non_finite_position(positions) {
            return Err(BadElement::at_node(s.mesh, i, super::nan_guard::ORIGIN_INPUT));
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
                VbdInit::Adaptive if g_norm == 0.0 => xn + vn * h,
                VbdInit::Adaptive if self.history < 2 => self.y[i],
                VbdInit::Adaptive => {
                    let dir = g / g_norm;
                    let a = ((vn - self.v_before[i]) / h).dot(&dir).clamp(0.0, g_norm);
                    let a = if a < ADAPTIVE_ACCELERATION_FLOOR_M_S2 { 0.0 } else { a };
                    xn + vn * h + dir * (a * h * h)
                }
            };
        }
        let springs = hooks.springs();
        let update =
            NodeUpdate { input: s, incidence: &self.incidence, y: &self.y, springs: &springs, w: 1.0 / (h * h) };
        let rho = s.settings.vbd.chebyshev_rho;
        let mut omega = 1.0;
        if rho > 0.0 {
            self.prev_prev.clear();
            self.prev_prev.extend_from_slice(positions);
            self.prev_iter.clear();
            self.prev_iter.extend_from_slice(positions);
        }
        for k in 1..=s.settings.vbd.iterations {
            for colour in &self.colours {
                counters.node_updates += sweep_colour(&update, colour, positions, s.settings.sweep.is_colour())?;
            }
            if rho > 0.0 {
                omega = match k {
                    1 => 1.0,
                    2 => 2.0 / (2.0 - rho * rho),
                    _ => 4.0 / (4.0 - rho * rho * omega),
                };
                if k >= 2 && omega > 1.0 {
                    for (i, x) in positions.iter_mut().enumerate() {
                        if s.inv_mass[i] > 0.0 {
                            *x = (*x - self.prev_prev[i]) * omega + self.prev_prev[i];
                        }
                    }
                }
                std::mem::swap(&mut self.prev_prev, &mut self.prev_iter);
                self.prev_iter.copy_from_slice(positions);
            }
            hooks.after_projection(positions, Some(ImplicitRole::Projection));
            counters.solver_iterations += 1;
        }
        Ok(())
    }
}

/// Updates the free nodes of one colour; returns how many moved.
fn sweep_colour(
    update: &NodeUpdate<'_>,
    colour: &[u32],
    positions: &mut [Vec3],
    parallel: bool,
) -> Result<u64, BadElement> {
    let inv_mass = update.input.inv_mass;
    if !parallel {
        let mut moved = 0;
        for &i in colour {
            let i = i as usize;
            if inv_mass[i] == 0.0 {
                continue;
            }
            if let Some(d) = update.delta(i, |k| positions[k])? {
                positions[i] += d;
                moved += 1;
            }
        }
        return Ok(moved);
    }
    use rayon::prelude::*;
    let shared = SharedMut::new(positions);
    colour
        .par_iter()
        .with_min_len(MIN_NODES_PER_TASK)
        .map(|&i| {
            let i = i as usize;
            if inv_mass[i] == 0.0 {
                return Ok(0);
            }
            // SAFETY: nodes of one colour share no element, so a node reads only nodes no other
            // task of this colour writes, and writes only itself.
            let read = |k: usize| unsafe { shared.read(k) };
            match update.delta(i, read)? {
                Some(d) => {
                    unsafe { shared.write(i, read(i) + d) };
                    Ok(1)
                }
                None => Ok(0),
            }
        })
        .sum()
}
