//! XPBD constraint kernels: pure functions from (gathered positions, inverse masses, rest data,
//! compliance) to corrections, apart from the stateful solver that gathers and scatters.
//!
//! **The XPBD update** (Macklin, Müller & Chentanez 2016, "XPBD: position-based simulation of
//! compliant constrained dynamics"), written once in [`xpbd_step`]: for a constraint `C` with
//! compliance `α`, time step `h`, `α̃ = α/h²` and accumulated multiplier `λ`,
//! `Δλ = −(C + α̃ λ) / (Σ_i w_i |∇_i C|² + α̃)`, `Δx_i = w_i ∇_i C Δλ`.
//! Kernels pass the gradient scaled, `g_i = s ∇_i C`: with `s = 1` this is the update above;
//! with `s = C` (constraints `C = √(2U) ≥ 0`, whose gradient `∇U / C` is 0/0 at rest) it
//! becomes `Δx_i = w_i g_i · step`, `step = −(C + α̃λ) s / (Σ w_i |g_i|² + α̃ s²)`,
//! `Δλ = s · step`, which never divides by `C`. For the energy constraint, where
//! `g_i = ∇_i U` and `s = C = √(2U)`, with λ = 0 this is the issue's
//! `Δλ' = −2U / (Σ_i w_i |∇_i U|² + 2U α̃)`.
//!
//! **Formulations** (energy and split have exactly the FE model's potential energy, up to a constant):
//! - [`Formulation::Energy`]: one constraint per element, `C = √(2 U_e)`, unit compliance
//!   (`α = 1`), so the XPBD potential `C²/(2α) = U_e`. This is the paper's formulation.
//! - [`Formulation::Mixed`]: one constraint per element as for the energy formulation, of the
//!   mixed element's energy (the hydrostatic term measured over the element,
//!   `crate::fem::energy::mixed`): no longer the same potential, but one that does not lock. On
//!   linear tetrahedra, whose pressure is one per node patch, the element keeps its deviatoric
//!   energy ([`project_deviatoric_constraint`]) and each node patch has a hydrostatic constraint
//!   ([`super::patch`]): together exactly the patch energy.
//! - [`Formulation::Split`]: per quadrature point, the deviatoric and hydrostatic constraints of
//!   [`Material::split_terms`] (Macklin & Müller 2021, "A constraint-based formulation of stable
//!   Neo-Hookean materials"), with compliances `α_t = 1/(k_t V_q)`, so that
//!   `Σ_t C_t²/(2α_t) = V_q (ψ(F_q) − offset)`. Gradients: `∇_i C = (∂C/∂F) ∇_X N_i`.
//!   The two terms of a point are solved together as a 2×2 block ([`xpbd_block_step`]), as
//!   Macklin & Müller do: for stable Neo-Hookean neither term vanishes at rest (only their
//!   stresses cancel), and projecting them one after the other would push a rest element.

use crate::Vec3;
use crate::fem::energy::element_energy_and_gradient;
use crate::fem::geometry::deformation_gradient;
use crate::material::{Material, SplitTerm};

/// Nodes per element up to which the generic kernels keep their per-node scratch on the stack
/// (Q2's 27: every built-in element); a larger element takes it from the heap
/// ([`NodeScratch`]), so any registered element goes through the generic kernels.
pub const MAX_NODES: usize = 27;

/// Per-node scratch of `len` values: on the stack for up to [`MAX_NODES`] nodes, on the heap
/// beyond (an element larger than every built-in one).
pub struct NodeScratch<T> {
    stack: [T; MAX_NODES],
    heap: Vec<T>,
    len: usize,
}

impl<T: Copy> NodeScratch<T> {
    /// `len` copies of `fill`.
    #[inline]
    pub fn new(fill: T, len: usize) -> Self {
        let heap = if len > MAX_NODES { vec![fill; len] } else { Vec::new() };
        Self { stack: [fill; MAX_NODES], heap, len }
    }

    /// The `len` values.
    #[inline]
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        if self.len <= MAX_NODES { &mut self.stack[..self.len] } else { &mut self.heap }
    }
}

/// How element energies become XPBD constraints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Formulation {
    /// One constraint `C = √(2U_e)` per element (the paper's).
    #[default]
    Energy,
    /// Deviatoric and hydrostatic constraints per quadrature point (Macklin & Müller 2021).
    Split,
    /// The mixed formulation: the material's hydrostatic term measured over the element (one
    /// constant pressure per element, `crate::fem::energy::mixed`), which cures volumetric
    /// locking; for XPBD one constraint `C = √(2 U_e)` of that energy per element. Every solver
    /// runs it (the implicit ones minimise the same energy).
    Mixed,
}

impl Formulation {
    pub const ALL: [Formulation; 3] = [Formulation::Energy, Formulation::Split, Formulation::Mixed];
    pub fn name(self) -> &'static str {
        match self {
            Self::Energy => "energy",
            Self::Split => "split",
            Self::Mixed => "mixed",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name().eq_ignore_ascii_case(s))
    }
    /// Number of multipliers λ per element with `points` quadrature points.
    pub fn multipliers_per_element(self, points: usize) -> usize {
        match self {
            Self::Energy | Self::Mixed => 1,
            Self::Split => 2 * points,
        }
    }
    /// Where the formulation measures the material's hydrostatic term.
    pub fn volume_measure(self) -> crate::material::VolumeMeasure {
        match self {
            Self::Energy | Self::Split => crate::material::VolumeMeasure::Point,
            Self::Mixed => crate::material::VolumeMeasure::Element,
        }
    }
}

impl std::fmt::Display for Formulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The XPBD update, written once, for a block of `K` constraints solved together (`K = 1`: the
/// classic scalar update; `K = 2`: the coupled deviatoric/hydrostatic pair of Macklin & Müller
/// 2021, which keeps a rest element exactly at rest even when each term alone is not zero there).
///
/// `c[t]`: constraint values; `s[t]`: scales of the gradients the caller holds
/// (`g_t = s_t ∇C_t`); `gram[(t, u)] = Σ_i w_i g_t,i · g_u,i`; `alpha_tilde[t] = α_t/h²`;
/// `lambda[t]`: accumulated multipliers. Solves
/// `(gram + diag(α̃_t s_t²)) step = −s ∘ (c + α̃ ∘ λ)` and returns `(Δλ, step)` with
/// `Δλ_t = s_t step_t` and `Δx_i = w_i Σ_t step_t g_t,i`. Constraints with no gradient and no
/// compliance (a `√(2U)` constraint at rest) are left out; None when nothing is left.
#[inline]
pub fn xpbd_block_step<const K: usize>(
    c: [f64; K],
    s: [f64; K],
    gram: [[f64; K]; K],
    alpha_tilde: [f64; K],
    lambda: [f64; K],
) -> Option<([f64; K], [f64; K])> {
    let mut a = gram;
    let mut b = [0.0; K];
    let mut active = [false; K];
    for t in 0..K {
        a[t][t] += alpha_tilde[t] * s[t] * s[t];
        b[t] = -(c[t] + alpha_tilde[t] * lambda[t]) * s[t];
        active[t] = a[t][t] > f64::MIN_POSITIVE;
    }
    if !active.iter().any(|&x| x) {
        return None;
    }
    for t in 0..K {
        if !active[t] {
            // decouple the inactive constraint: its step is zero
            for u in 0..K {
                a[t][u] = 0.0;
                a[u][t] = 0.0;
            }
            a[t][t] = 1.0;
            b[t] = 0.0;
        }
    }
    let step = solve_small(a, b);
    if !step.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some((std::array::from_fn(|t| s[t] * step[t]), step))
}

/// Solves the small symmetric positive definite system `a x = b` by Gaussian elimination
/// (no pivoting needed: the active diagonal is positive and the matrix is a Gram matrix plus a
/// positive diagonal).
#[inline]
fn solve_small<const K: usize>(mut a: [[f64; K]; K], mut b: [f64; K]) -> [f64; K] {
    for k in 0..K {
        for r in k + 1..K {
            let f = a[r][k] / a[k][k];
            for c in k..K {
                a[r][c] -= f * a[k][c];
            }
            b[r] -= f * b[k];
        }
    }
    let mut x = [0.0; K];
    for k in (0..K).rev() {
        let tail: f64 = (k + 1..K).map(|c| a[k][c] * x[c]).sum();
        x[k] = (b[k] - tail) / a[k][k];
    }
    x
}

/// The scalar XPBD update (`K = 1`): `(Δλ, step)` with `Δx_i = step · w_i g_i`, where
/// `sum_w_grad2 = Σ_i w_i |g_i|²`.
#[inline]
pub fn xpbd_step(c: f64, s: f64, sum_w_grad2: f64, alpha_tilde: f64, lambda: f64) -> Option<(f64, f64)> {
    xpbd_block_step::<1>([c], [s], [[sum_w_grad2]], [alpha_tilde], [lambda]).map(|(l, st)| (l[0], st[0]))
}

/// Applies `Δx_i = step · w_i g_i` to gathered positions.
#[inline]
pub(crate) fn apply(x: &mut [Vec3], w: &[f64], g: &[Vec3], step: f64) {
    for ((xi, wi), gi) in x.iter_mut().zip(w).zip(g) {
        *xi += gi * (step * wi);
    }
}

/// `Σ_i w_i a_i · b_i`.
#[inline]
pub(crate) fn weighted_dot(w: &[f64], a: &[Vec3], b: &[Vec3]) -> f64 {
    w.iter().zip(a).zip(b).map(|((wi, ai), bi)| wi * ai.dot(bi)).sum()
}

/// Projects the energy constraint `C = √(2 U_e)` (compliance 1) of one element.
/// `x`: gathered positions (updated in place); `rest`: gathered rest positions; `w`: inverse
/// masses; `grads`, `volumes`: the element's rest data; `inv_dt2 = 1/h²`; `lambda`: the
/// element's multiplier (updated). Returns the element energy before the projection.
#[allow(clippy::too_many_arguments)]
pub fn project_energy_constraint(
    x: &mut [Vec3],
    rest: &[Vec3],
    w: &[f64],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    inv_dt2: f64,
    lambda: &mut f64,
) -> f64 {
    let mut grad = NodeScratch::new(Vec3::zeros(), x.len());
    let grad = grad.as_mut_slice();
    let energy = element_energy_and_gradient(x, rest, grads, volumes, material, grad);
    project_square_root(x, w, grad, energy, inv_dt2, lambda)
}

/// Projects the deviatoric energy constraint `C = √(2 β U_d)`, `U_d = Σ_q V_q ψ_d(F_q)`
/// (compliance 1, `β` the elements' share of the deviatoric energy), of one element whose
/// pressure and nodal strain are one per node patch ([`super::patch`]): as
/// [`project_energy_constraint`], with the rest left to the patch constraints.
#[allow(clippy::too_many_arguments)]
pub fn project_deviatoric_constraint(
    x: &mut [Vec3],
    rest: &[Vec3],
    w: &[f64],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    inv_dt2: f64,
    lambda: &mut f64,
) -> f64 {
    let mut grad = NodeScratch::new(Vec3::zeros(), x.len());
    let grad = grad.as_mut_slice();
    let energy = crate::fem::energy::mixed::deviatoric_energy_and_gradient(x, rest, grads, volumes, material, grad);
    // the element keeps its share β of the deviatoric energy; the node patches hold the rest
    let beta = crate::fem::energy::mixed::patch::ELEMENT_DEVIATORIC_SHARE;
    grad.iter_mut().for_each(|g| *g *= beta);
    project_square_root(x, w, grad, beta * energy, inv_dt2, lambda)
}

/// The update of `C = √(2U)` with `∇U` in `grad`: `s = C`, unit compliance. Returns `U`.
#[inline]
fn project_square_root(x: &mut [Vec3], w: &[f64], grad: &[Vec3], energy: f64, inv_dt2: f64, lambda: &mut f64) -> f64 {
    // ψ ≥ 0 for StVK and Neo-Hookean; the stable Neo-Hookean energy can dip below its rest
    // value under extreme compression: the constraint then has nothing to restore.
    let energy = energy.max(0.0);
    let c = (2.0 * energy).sqrt();
    if let Some((d_lambda, step)) = xpbd_step(c, c, weighted_dot(w, grad, grad), inv_dt2, *lambda) {
        *lambda += d_lambda;
        apply(x, w, grad, step);
    }
    energy
}

/// Projects the split constraints (deviatoric and hydrostatic, solved together) of every
/// quadrature point of one element, point after point. `lambdas` holds `2 × points`
/// multipliers.
#[allow(clippy::too_many_arguments)]
pub fn project_split_constraints(
    x: &mut [Vec3],
    rest: &[Vec3],
    w: &[f64],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    inv_dt2: f64,
    lambdas: &mut [f64],
) {
    let n = x.len();
    let stiffness = material.split_stiffness_pa();
    let (mut g0, mut g1) = (NodeScratch::new(Vec3::zeros(), n), NodeScratch::new(Vec3::zeros(), n));
    let (g0, g1) = (g0.as_mut_slice(), g1.as_mut_slice());
    for (q, v) in volumes.iter().enumerate() {
        let gq = &grads[q * n..(q + 1) * n];
        let terms = split_terms_and_gradients(x, rest, gq, material, [&mut *g0, &mut *g1]);
        let (g0, g1) = (&*g0, &*g1);
        let (a, b, d) = (weighted_dot(w, g0, g0), weighted_dot(w, g0, g1), weighted_dot(w, g1, g1));
        let alpha_tilde = [inv_dt2 / (stiffness[0] * v), inv_dt2 / (stiffness[1] * v)];
        let lambda = [lambdas[2 * q], lambdas[2 * q + 1]];
        let result =
            xpbd_block_step::<2>(terms.map(|t| t.value), terms.map(|t| t.scale), [[a, b], [b, d]], alpha_tilde, lambda);
        if let Some((d_lambda, step)) = result {
            lambdas[2 * q] += d_lambda[0];
            lambdas[2 * q + 1] += d_lambda[1];
            apply(x, w, g0, step[0]);
            apply(x, w, g1, step[1]);
        }
    }
}

/// The split terms (deviatoric, hydrostatic) at one quadrature point, with their scaled node
/// gradients `g_out[t][i] = s_t ∂C_t/∂x_i = s_t (∂C_t/∂F) ∇_X N_i` (one entry per node).
pub fn split_terms_and_gradients(
    x: &[Vec3],
    rest: &[Vec3],
    grads_q: &[Vec3],
    material: &Material,
    g_out: [&mut [Vec3]; 2],
) -> [SplitTerm; 2] {
    let f = deformation_gradient(x, rest, grads_q);
    let terms = material.split_terms(&f);
    for (g, term) in g_out.into_iter().zip(&terms) {
        for (gi, ni) in g.iter_mut().zip(grads_q) {
            *gi = term.grad_f_scaled * ni;
        }
    }
    terms
}

#[cfg(test)]
mod tests;
