//! One VBD node update ([`NodeUpdate`]): the node's force and positive-definite block summed over
//! the elements holding it, the springs and the inertia term, and the 3×3 Newton step
//! `x_i ← x_i + t H_i⁻¹ f_i` by a hand-written Cholesky ([`solve_spd3`]), `t` halved from 1
//! until the node's share of the potential does not rise (at most [`MAX_BACKTRACKS`] times).

use super::lanes::{Fused, LaneView, add_outer_any};
use super::patch::PatchView;
use crate::Vec3;
use crate::effect::NodeSpring;
use crate::material::{Lame, NodeVisit, project_psd3};
use crate::math::shared::SharedMut;
use crate::mesh::adjacency::NodeIncidence;
use crate::solver::nan_guard::{BadElement, ORIGIN_VBD};
use crate::solver::step::StepInput;
use nalgebra::Matrix3;

/// What a node update reads.
pub(super) struct NodeUpdate<'a> {
    pub(super) input: &'a StepInput<'a>,
    pub(super) incidence: &'a NodeIncidence,
    pub(super) y: &'a [Vec3],
    pub(super) springs: &'a [NodeSpring],
    pub(super) w: f64,
    pub(super) lame: Lame,
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(super) fused: Fused,
    /// Backtrack each node step on the node's potential (VBD's recovery rounds).
    pub(super) line_search: bool,
}

impl NodeUpdate<'_> {
    /// Moves free node `i` by its Newton step on `G` with the others fixed, and the `F_q` of
    /// the elements holding it with it; returns whether it moved (not when it has no
    /// unbalanced force).
    ///
    /// # Safety
    /// No other thread may access node `i` or the `F_q` of an element holding it meanwhile
    /// (nodes of one colour share no element).
    pub(super) unsafe fn step(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        lanes: &[LaneView<'_>],
        patches: Option<&PatchView<'_>>,
    ) -> Result<bool, BadElement> {
        #[cfg(target_arch = "x86_64")]
        if self.fused.0 {
            // SAFETY: the CPU has AVX2 and FMA (detected); the caller's promise
            return unsafe { self.step_fused(i, positions, lanes, patches) };
        }
        // SAFETY: the caller's promise
        unsafe { self.step_in::<false>(i, positions, lanes, patches) }
    }

    /// [`NodeUpdate::step`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// [`NodeUpdate::step`]'s, and the CPU has AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn step_fused(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        lanes: &[LaneView<'_>],
        patches: Option<&PatchView<'_>>,
    ) -> Result<bool, BadElement> {
        // SAFETY: the caller's promise
        unsafe { self.step_in::<true>(i, positions, lanes, patches) }
    }

    /// # Safety
    /// [`NodeUpdate::step`]'s; with `FMA`, the CPU has AVX2 and FMA.
    #[inline(always)]
    pub(super) unsafe fn step_in<const FMA: bool>(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        lanes: &[LaneView<'_>],
        patches: Option<&PatchView<'_>>,
    ) -> Result<bool, BadElement> {
        let s = self.input;
        // SAFETY: the caller's promise
        let xi = unsafe { positions.read(i) };
        let m_w = s.masses_kg[i] * self.w;
        let mut f = (self.y[i] - xi) * m_w;
        let mut h = Matrix3::identity() * m_w;
        for inc in self.incidence.of(i) {
            let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
            if patches.is_some_and(|p| p.is_patch(b)) {
                continue;
            }
            let l = &lanes[b];
            // SAFETY: an element holding node i
            let fq = unsafe { l.f_mut(e) };
            let g = &l.geometry;
            let visit = NodeVisit { width: g.width, f: fq, grads: g.node_grads(e, a), volumes: g.volumes(e) };
            let (force, block) = match l.kernel {
                // SAFETY: the material's kernel for this width on this CPU
                Some(kernel) => unsafe { kernel(self.lame, visit) },
                None => crate::fem::energy::node_visit(s.material, self.lame, visit),
            };
            f -= force;
            h += project_psd3(&block);
        }
        if let Some(p) = patches {
            // SAFETY: the caller's promise (nodes of one colour lie more than two edges apart)
            let (force, block) = unsafe { p.node_share(s.material, i, lanes) };
            f -= force;
            h += block;
        }
        for sp in self.springs.iter().filter(|sp| sp.node as usize == i) {
            f -= (xi - sp.target_m) * sp.stiffness_n_per_m;
            h += Matrix3::identity() * sp.stiffness_n_per_m;
        }
        if f == Vec3::zeros() {
            return Ok(false);
        }
        let Some(d) = solve_spd3(&h, &f) else {
            return Err(BadElement::at_node(s.mesh, i, ORIGIN_VBD));
        };
        if !self.line_search {
            // SAFETY: the caller's promise
            unsafe {
                positions.write(i, xi + d);
                carry_points::<FMA>(self.incidence, i, d, lanes);
                carry_patches(s.material, patches, i, d, lanes);
            }
            return Ok(true);
        }
        // the step, backtracked until the node's potential does not rise (a full Newton step on
        // the projected block overshot near incompressibility: ν = 0.499 under torsion blew up)
        // SAFETY: the caller's promise
        let before = unsafe { self.local_energy(i, xi, lanes, patches) };
        let mut t = 1.0;
        let mut moved = Vec3::zeros();
        for _ in 0..=MAX_BACKTRACKS {
            let step = d * t - moved;
            // SAFETY: the caller's promise
            unsafe {
                carry_points::<FMA>(self.incidence, i, step, lanes);
                carry_patches(s.material, patches, i, step, lanes);
            }
            moved += step;
            // SAFETY: the caller's promise
            let after = unsafe { self.local_energy(i, xi + moved, lanes, patches) };
            if after <= before {
                // SAFETY: the caller's promise
                unsafe { positions.write(i, xi + moved) };
                return Ok(true);
            }
            t *= 0.5;
        }
        // no decrease along the step (round-off at a minimum): the node stays
        // SAFETY: the caller's promise
        unsafe {
            carry_points::<FMA>(self.incidence, i, -moved, lanes);
            carry_patches(s.material, patches, i, -moved, lanes);
        }
        Ok(false)
    }

    /// The node's share of the incremental potential at `xi`, with the `F_q` the lanes hold:
    /// `m_i/(2h̄²)|x_i − y_i|² + Σ_{e ∋ i} Σ_q V_q ψ(F_q) + Σ_k k_k/2 |x_i − t_k|²`.
    ///
    /// # Safety
    /// As [`NodeUpdate::step`].
    #[inline(always)]
    unsafe fn local_energy(&self, i: usize, xi: Vec3, lanes: &[LaneView<'_>], patches: Option<&PatchView<'_>>) -> f64 {
        let s = self.input;
        let mut e = 0.5 * s.masses_kg[i] * self.w * (xi - self.y[i]).norm_squared();
        if let Some(p) = patches {
            // SAFETY: the caller's promise
            e += unsafe { p.local_energy(s.material, i, lanes) };
        }
        for inc in self.incidence.of(i) {
            let (b, el) = (inc.block as usize, inc.element as usize);
            if patches.is_some_and(|p| p.is_patch(b)) {
                continue;
            }
            let l = &lanes[b];
            // SAFETY: an element holding node i
            let fq = unsafe { l.f_mut(el) };
            let g = &l.geometry;
            let visit = NodeVisit { width: g.width, f: fq, grads: g.node_grads(el, 0), volumes: g.volumes(el) };
            e += crate::fem::energy::visit_energy(s.material, self.lame, visit);
        }
        for sp in self.springs.iter().filter(|sp| sp.node as usize == i) {
            e += 0.5 * sp.stiffness_n_per_m * (xi - sp.target_m).norm_squared();
        }
        e
    }
}

/// The most halvings of a node's step ([`NodeUpdate::step`]).
const MAX_BACKTRACKS: u32 = 10;

/// `H⁻¹ f` for a symmetric positive definite 3 × 3 `H` by its Cholesky factor `L Lᵀ` (lower
/// triangle read); `None` when `H` is not positive definite or the result not finite.
#[inline(always)]
pub(super) fn solve_spd3(h: &Matrix3<f64>, f: &Vec3) -> Option<Vec3> {
    let l00 = h[(0, 0)].sqrt();
    let (l10, l20) = (h[(1, 0)] / l00, h[(2, 0)] / l00);
    let l11 = (h[(1, 1)] - l10 * l10).sqrt();
    let l21 = (h[(2, 1)] - l20 * l10) / l11;
    let l22 = (h[(2, 2)] - l20 * l20 - l21 * l21).sqrt();
    // L z = f, then Lᵀ d = z
    let z0 = f[0] / l00;
    let z1 = (f[1] - l10 * z0) / l11;
    let z2 = (f[2] - l20 * z0 - l21 * z1) / l22;
    let d2 = z2 / l22;
    let d1 = (z1 - l21 * d2) / l11;
    let d0 = (z0 - l10 * d1 - l20 * d2) / l00;
    // a non-positive pivot's square root is NaN (or zero, dividing to ±∞)
    let d = Vec3::new(d0, d1, d2);
    d.iter().all(|c| c.is_finite()).then_some(d)
}

/// Moves the patches' means with node `i` (moved by `d`, its elements' `F_q` carried), if the
/// mesh has patches.
///
/// # Safety
/// [`PatchView::carry`]'s.
#[inline(always)]
unsafe fn carry_patches(
    material: &crate::material::Material,
    patches: Option<&PatchView<'_>>,
    i: usize,
    d: Vec3,
    lanes: &[LaneView<'_>],
) {
    if let Some(p) = patches {
        // SAFETY: the caller's promise
        unsafe { p.carry(material, i, &d, lanes) };
    }
}

/// Moves the `F_q` of every element holding node `i` by `Δ ⊗ ∇_X N_a(r_q)` (node `i` moved by `d`).
///
/// # Safety
/// No other thread may access the `F_q` of an element holding node `i` meanwhile; with `FMA`,
/// the CPU has AVX2 and FMA.
#[inline(always)]
pub(super) unsafe fn carry_points<const FMA: bool>(
    incidence: &NodeIncidence,
    i: usize,
    d: Vec3,
    lanes: &[LaneView<'_>],
) {
    for inc in incidence.of(i) {
        let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
        let l = &lanes[b];
        // SAFETY: the caller's promise
        let fq = unsafe { l.f_mut(e) };
        // SAFETY: the caller's promise
        unsafe { add_outer_any::<FMA>(l.geometry.width, fq, &d, l.geometry.node_grads(e, a)) };
    }
}
