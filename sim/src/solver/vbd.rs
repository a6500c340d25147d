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
//!
//! **Cost.** A sweep visits every (node, element holding it) pair with the element's whole
//! quadrature, so it is kept to what the visit cannot avoid: the elements' `F_q` are cached and
//! moved with each node ([`PointGradients`]) instead of gathered and summed per visit; `P g` and
//! the block come from one call that shares their work ([`crate::material::Material::node_force_and_block`],
//! closed form for StVK); the projection of a block that is already positive definite is one
//! 3 × 3 Cholesky factorisation, not an eigen-decomposition.

use super::SolverCounters;
use super::method::{Hooks, Method, StepInput, StepSolver};
use super::nan_guard::{BadElement, ORIGIN_VBD};
use super::settings::{SolverSettings, VbdInit};
use crate::Vec3;
use crate::effect::{ImplicitRole, NodeSpring};
use crate::fem::energy::{element_grads, gather};
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::material::{Lame, NodeVisit, project_psd3};
use crate::mesh::Mesh;
use crate::mesh::adjacency::{NodeIncidence, colour_nodes};
use crate::xpbd::constraint::NodeScratch;
use crate::xpbd::kernels::SharedMut;
use nalgebra::Matrix3;

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
    f_points: PointGradients,
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
            f_points: PointGradients::default(),
        }
    }
}

/// `F_q` of every quadrature point of every element, block by block (`e · points + q`), kept in
/// step with the positions: refreshed from them before each sweep ([`PointGradients::refresh`]),
/// then moved by `Δ ⊗ ∇_X N_a(r_q)` when node `a` of the element moves by `Δ` (`F` is linear in
/// the positions), so a node visit reads its elements' `F_q` instead of gathering their nodes.
#[derive(Default)]
struct PointGradients {
    blocks: Vec<Vec<Matrix3<f64>>>,
}

/// Fewest elements per parallel task of [`PointGradients::refresh`].
const MIN_ELEMENTS_PER_TASK: usize = 256;

impl PointGradients {
    fn refresh(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], positions: &[Vec3]) {
        use rayon::prelude::*;
        self.blocks.resize_with(mesh.blocks.len(), Vec::new);
        for ((fb, block), g) in self.blocks.iter_mut().zip(&mesh.blocks).zip(geometry) {
            let (n, points) = (g.nodes_per_element, g.points_per_element);
            fb.resize(block.len() * points, Matrix3::zeros());
            fb.par_chunks_mut(points).with_min_len(MIN_ELEMENTS_PER_TASK).enumerate().for_each(|(e, out)| {
                let nodes = block.element(e);
                let (mut x, mut rest) = (NodeScratch::new(Vec3::zeros(), n), NodeScratch::new(Vec3::zeros(), n));
                let (x, rest) = (x.as_mut_slice(), rest.as_mut_slice());
                gather(positions, nodes, x);
                gather(&mesh.rest_positions, nodes, rest);
                let grads = element_grads(g, e);
                for (q, f) in out.iter_mut().enumerate() {
                    *f = deformation_gradient(x, rest, &grads[q * n..(q + 1) * n]);
                }
            });
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
    lame: Lame,
}

impl NodeUpdate<'_> {
    /// Moves free node `i` by its Newton step on `G` with the others fixed, and the `F_q` of
    /// the elements holding it with it; returns whether it moved (not when it has no
    /// unbalanced force).
    ///
    /// # Safety
    /// No other thread may access node `i` or the `F_q` of an element holding it meanwhile
    /// (nodes of one colour share no element).
    unsafe fn step(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        f_points: &[SharedMut<Matrix3<f64>>],
    ) -> Result<bool, BadElement> {
        let s = self.input;
        // SAFETY: the caller's promise
        let xi = unsafe { positions.read(i) };
        let m_w = s.masses_kg[i] * self.w;
        let mut f = (self.y[i] - xi) * m_w;
        let mut h = Matrix3::identity() * m_w;
        for inc in self.incidence.of(i) {
            let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
            let g = &s.geometry[b];
            let (n, points) = (g.nodes_per_element, g.points_per_element);
            // SAFETY: an element holding node i
            let fq: &[Matrix3<f64>] = unsafe { f_points[b].slice_mut(e * points, points) };
            let visit = NodeVisit { f: fq, grads: &element_grads(g, e)[a..], stride: n, volumes: g.volumes(e) };
            let (force, block) = s.material.node_visit(self.lame, visit);
            f -= force;
            h += project_psd3(&block);
        }
        for sp in self.springs.iter().filter(|sp| sp.node as usize == i) {
            f -= (xi - sp.target_m) * sp.stiffness_n_per_m;
            h += Matrix3::identity() * sp.stiffness_n_per_m;
        }
        if f == Vec3::zeros() {
            return Ok(false);
        }
        let d = match h.cholesky().map(|c| c.solve(&f)) {
            Some(d) if d.iter().all(|c| c.is_finite()) => d,
            _ => return Err(BadElement::at_node(s.mesh, i, ORIGIN_VBD)),
        };
        // SAFETY: the caller's promise
        unsafe {
            positions.write(i, xi + d);
            carry_points(self.incidence, s.geometry, i, d, f_points);
        }
        Ok(true)
    }
}

/// Moves the `F_q` of every element holding node `i` by `Δ ⊗ ∇_X N_a(r_q)` (node `i` moved by `d`).
///
/// # Safety
/// No other thread may access the `F_q` of an element holding node `i` meanwhile.
unsafe fn carry_points(
    incidence: &NodeIncidence,
    geometry: &[BlockGeometry],
    i: usize,
    d: Vec3,
    f_points: &[SharedMut<Matrix3<f64>>],
) {
    for inc in incidence.of(i) {
        let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
        let g = &geometry[b];
        let (n, points) = (g.nodes_per_element, g.points_per_element);
        let grads = element_grads(g, e);
        // SAFETY: the caller's promise
        let fq = unsafe { f_points[b].slice_mut(e * points, points) };
        for (q, fq) in fq.iter_mut().enumerate() {
            *fq += d * grads[q * n + a].transpose();
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
        let update = NodeUpdate {
            input: s,
            incidence: &self.incidence,
            y: &self.y,
            springs: &springs,
            w: 1.0 / (h * h),
            lame: s.material.lame(),
        };
        let rho = s.settings.vbd.chebyshev_rho;
        let mut omega = 1.0;
        if rho > 0.0 {
            self.prev_prev.clear();
            self.prev_prev.extend_from_slice(positions);
            self.prev_iter.clear();
            self.prev_iter.extend_from_slice(positions);
        }
        for k in 1..=s.settings.vbd.iterations {
            // positions moved as a whole since the last sweep (initial guess, acceleration,
            // contact): F_q from them, then in step with each node move
            self.f_points.refresh(s.mesh, s.geometry, positions);
            let f_points: Vec<_> = self.f_points.blocks.iter_mut().map(|fb| SharedMut::new(fb)).collect();
            for colour in &self.colours {
                counters.node_updates +=
                    sweep_colour(&update, colour, positions, &f_points, s.settings.sweep.is_colour())?;
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
    f_points: &[SharedMut<Matrix3<f64>>],
    parallel: bool,
) -> Result<u64, BadElement> {
    let inv_mass = update.input.inv_mass;
    let shared = SharedMut::new(positions);
    // SAFETY: nodes of one colour share no element, so each task touches only its node and the
    // F_q of elements no other task of this colour touches.
    let node = |&i: &u32| -> Result<u64, BadElement> {
        let i = i as usize;
        if inv_mass[i] == 0.0 {
            return Ok(0);
        }
        Ok(u64::from(unsafe { update.step(i, shared, f_points) }?))
    };
    if !parallel {
        return colour.iter().map(node).sum();
    }
    use rayon::prelude::*;
    colour.par_iter().with_min_len(MIN_NODES_PER_TASK).map(node).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::fem::geometry::precompute;

    /// The cached `F_q` carried along node moves are the `F_q` recomputed from the moved
    /// positions (to rounding), on every element type, a mixed mesh's shared nodes included.
    #[test]
    fn carried_point_gradients_match_recomputed_ones_for_every_element_type() {
        for et in ElementType::all() {
            let mesh = super::super::tests::one_cell_cantilever(et);
            let geometry = precompute(&mesh, None).unwrap();
            let incidence = NodeIncidence::new(&mesh);
            let mut x = mesh.rest_positions.clone();
            let mut cached = PointGradients::default();
            cached.refresh(&mesh, &geometry, &x);
            for (k, i) in (0..mesh.num_nodes()).step_by(3).enumerate() {
                let d = Vec3::new(0.01 * k as f64, -0.02, 0.015 * (k % 4) as f64);
                x[i] += d;
                let shared: Vec<_> = cached.blocks.iter_mut().map(|b| SharedMut::new(b)).collect();
                // SAFETY: one thread
                unsafe { carry_points(&incidence, &geometry, i, d, &shared) };
            }
            let mut fresh = PointGradients::default();
            fresh.refresh(&mesh, &geometry, &x);
            for (a, b) in cached.blocks.iter().flatten().zip(fresh.blocks.iter().flatten()) {
                assert!((a - b).norm() < 1e-12, "{et}: carried {a} vs recomputed {b}");
            }
            assert!(fresh.blocks.iter().flatten().any(|f| (f - Matrix3::identity()).norm() > 1e-3), "{et}: moved");
        }
    }
}
