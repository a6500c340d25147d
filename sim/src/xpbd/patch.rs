//! XPBD's constraints of P1's nodal-strain tetrahedron with its averaged nodal pressure (Bonet &
//! Burton 1998, "A simple average nodal pressure tetrahedral element for incompressible and
//! nearly incompressible dynamic explicit applications"; Gee, Dohrmann, Key & Wall 2009, "A
//! uniform nodal strain tetrahedron with isochoric stabilization"; the energy is
//! `crate::fem::energy::mixed::patch`'s).
//!
//! The patch energy `U = β Σ_e V_e ψ_d(F_e) + Σ_a W_a [(1 − β) ψ_d(F̄_a) + k_h/2 C̄_a²]` becomes
//! three kinds of XPBD constraints (Macklin, Müller & Chentanez 2016, with the split of Macklin &
//! Müller 2021 into deviatoric and hydrostatic terms):
//! - per element, `C_e = √(2 β V_e ψ_d(F_e))`, unit compliance
//!   ([`super::constraint::project_deviatoric_constraint`]);
//! - per node `a`, its hydrostatic term `C_a = C̄_a = Σ_{e∋a} V_e C_h(F_e)/4 / W_a`,
//!   `W_a = Σ_{e∋a} V_e/4`, with compliance `α_a = 1/(k_h W_a)`, so that
//!   `C_a²/(2α_a) = W_a k_h/2 C̄_a²`; its gradient
//!   `∇_i C_a = Σ_{e∋a, e∋i} V_e/(4 W_a) G_h(F_e) ∇N_i^e` reaches every node of the patch (the
//!   elements around `a`);
//! - per node `a`, its deviatoric term `D_a = √(2 W_a (1 − β) ψ_d(F̄_a))`, unit compliance, at
//!   the averaged `F̄_a = Σ_{e∋a} V_e F_e/4 / W_a`, with `∇_i (D_a²/2) = W_a (1 − β) P_d(F̄_a)
//!   b̄_i`, `b̄_i = Σ_{e∋a, e∋i} V_e ∇N_i^e / (4 W_a)`.
//!
//! Together the constraints' potential is exactly the patch energy, so XPBD converges on the
//! same equilibrium as the static and Newton solvers. Every term vanishes at rest with its
//! gradient for the models the mixed formulation takes (StVK, Neo-Hookean;
//! `crate::material::Material::with_volume_measure` refuses stable Neo-Hookean), so projecting
//! them one after the other keeps a rest mesh at rest.
//!
//! Patches that share no node are projected concurrently: greedy colouring of the patches
//! (two patches conflict when a node lies in both), so a sweep does not depend on the thread
//! count.

use crate::Vec3;
use crate::fem::energy::mixed::deviatoric_density_and_stress;
use crate::fem::energy::mixed::patch::ELEMENT_DEVIATORIC_SHARE;
use crate::fem::energy::mixed::patch::{elements_around, patch_elements};
use crate::fem::energy::{element_grads, gather};
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::material::{Mat3, Material};
use crate::mesh::Mesh;
use crate::xpbd::constraint::{apply, weighted_dot, xpbd_block_step};

/// Corners of a linear tetrahedron: each takes a quarter of its element's volume.
const CORNERS: usize = 4;

/// Fewest patches per parallel task: a patch costs about as much as its dozen elements.
const MIN_PATCHES_PER_TASK: usize = 16;

/// Every node patch of a mesh's linear tetrahedra in the mixed formulation, with what projecting
/// its constraint needs.
pub struct Patches {
    /// Per patch, its node `a` (nodes no patch element touches have none).
    centre: Vec<u32>,
    /// Per patch, `W_a` (m³).
    weight_m3: Vec<f64>,
    /// Per patch, its range in `members` (`member_start[p]..member_start[p + 1]`).
    member_start: Vec<usize>,
    /// Per member, its element `(block, element)` and its corners' places in the patch's nodes.
    members: Vec<(u32, u32, [u16; CORNERS])>,
    /// Per patch, its range in `nodes`.
    node_start: Vec<usize>,
    nodes: Vec<u32>,
    /// The patches grouped so that no two of a group share a node.
    colours: Vec<Vec<u32>>,
}

/// Where projecting a patch met a non-finite correction: one of its elements and the node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BadPatch {
    pub block: usize,
    pub element: usize,
    pub node: u32,
}

/// What a patch sweep reads.
pub struct PatchInput<'a> {
    pub mesh: &'a Mesh,
    pub geometry: &'a [BlockGeometry],
    pub material: &'a Material,
    pub inv_mass: &'a [f64],
    /// `1/h²` (s⁻²).
    pub inv_dt2: f64,
}

impl Patches {
    /// The patches of `mesh`'s blocks measured per node patch under `material`; None when it has
    /// none.
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material) -> Option<Self> {
        let ids = patch_elements(mesh, material);
        if ids.is_empty() {
            return None;
        }
        let around = elements_around(mesh, material);
        let volume = |(bi, e): (usize, usize)| geometry[bi].volumes(e).iter().sum::<f64>();
        let mut patches = Patches {
            centre: Vec::new(),
            weight_m3: Vec::new(),
            member_start: vec![0],
            members: Vec::new(),
            node_start: vec![0],
            nodes: Vec::new(),
            colours: Vec::new(),
        };
        for a in 0..mesh.num_nodes() {
            let ks = around.of(a);
            let weight_m3: f64 = ks.iter().map(|&k| volume(ids[k]) / CORNERS as f64).sum();
            if ks.is_empty() || weight_m3 <= 0.0 {
                continue;
            }
            let first = patches.nodes.len();
            for &k in ks {
                let (bi, e) = ids[k];
                let mut local = [0u16; CORNERS];
                for (l, &i) in local.iter_mut().zip(mesh.blocks[bi].element(e)) {
                    let at = patches.nodes[first..].iter().position(|&p| p == i).unwrap_or_else(|| {
                        patches.nodes.push(i);
                        patches.nodes.len() - 1 - first
                    });
                    *l = at as u16;
                }
                patches.members.push((bi as u32, e as u32, local));
            }
            patches.centre.push(a as u32);
            patches.weight_m3.push(weight_m3);
            patches.member_start.push(patches.members.len());
            patches.node_start.push(patches.nodes.len());
        }
        patches.colours = patches.colour(mesh.num_nodes());
        Some(patches)
    }

    /// Number of patches (each holds two constraints).
    pub fn len(&self) -> usize {
        self.centre.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centre.is_empty()
    }

    /// Number of colours (groups of patches projected concurrently).
    pub fn num_colours(&self) -> usize {
        self.colours.len()
    }

    /// Patch `p`'s nodes.
    pub fn nodes(&self, p: usize) -> &[u32] {
        &self.nodes[self.node_start[p]..self.node_start[p + 1]]
    }

    /// Greedy colours: patches conflict when they share a node (patch `q` holds node `i` of
    /// patch `p` exactly when `i`'s own patch holds `q`'s centre, so the patches through the
    /// nodes of `p` are its neighbours).
    fn colour(&self, num_nodes: usize) -> Vec<Vec<u32>> {
        // node → the patches holding it
        let mut start = vec![0usize; num_nodes + 1];
        for &i in &self.nodes {
            start[i as usize + 1] += 1;
        }
        for i in 0..num_nodes {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut holding = vec![0u32; self.nodes.len()];
        for p in 0..self.len() {
            for &i in self.nodes(p) {
                holding[fill[i as usize]] = p as u32;
                fill[i as usize] += 1;
            }
        }
        crate::mesh::adjacency::greedy_colours(self.len(), |p, neighbour| {
            for &i in self.nodes(p) {
                for &q in &holding[start[i as usize]..start[i as usize + 1]] {
                    neighbour(q);
                }
            }
        })
    }

    /// Patch `p`'s two terms at the patch positions `x` (gathered in the patch's node order),
    /// from one visit of its elements: its hydrostatic constraint `C_a` with its gradient in
    /// `grad_h`, and its deviatoric energy `U_a = D_a²/2 = W_a (1 − β) ψ_d(F̄_a)` with its
    /// gradient in `grad_d` (one entry per patch node each).
    pub fn terms(
        &self,
        p: usize,
        input: &PatchInput<'_>,
        x: &[Vec3],
        grad_h: &mut [Vec3],
        grad_d: &mut [Vec3],
    ) -> (f64, f64) {
        grad_h.iter_mut().for_each(|g| *g = Vec3::zeros());
        grad_d.iter_mut().for_each(|g| *g = Vec3::zeros());
        let (mut xl, mut rest) = ([Vec3::zeros(); CORNERS], [Vec3::zeros(); CORNERS]);
        let share = 1.0 / (CORNERS as f64 * self.weight_m3[p]);
        let (mut c, mut f_bar) = (0.0, Mat3::zeros());
        for &(bi, e, local) in &self.members[self.member_start[p]..self.member_start[p + 1]] {
            let (bi, e) = (bi as usize, e as usize);
            for (xc, &l) in xl.iter_mut().zip(&local) {
                *xc = x[l as usize];
            }
            gather(&input.mesh.rest_positions, input.mesh.blocks[bi].element(e), &mut rest);
            let g = &input.geometry[bi];
            let grads = element_grads(g, e);
            for (q, &v) in g.volumes(e).iter().enumerate() {
                let gq = &grads[q * CORNERS..(q + 1) * CORNERS];
                let f = deformation_gradient(&xl, &rest, gq);
                let [_, h] = input.material.split_terms(&f);
                debug_assert_eq!(h.scale, 1.0, "a hydrostatic term is not a square root");
                let vs = v * share;
                c += vs * h.value;
                f_bar += f * vs;
                let vg = h.grad_f_scaled * vs;
                for (&l, gi) in local.iter().zip(gq) {
                    grad_h[l as usize] += vg * gi;
                    // `b̄_i`, multiplied by the stress below
                    grad_d[l as usize] += gi * vs;
                }
            }
        }
        let scale = self.weight_m3[p] * (1.0 - ELEMENT_DEVIATORIC_SHARE);
        let (psi_d, p_d) = deviatoric_density_and_stress(input.material, &f_bar);
        let stress = p_d * scale;
        for b in grad_d.iter_mut() {
            *b = stress * *b;
        }
        (c, scale * psi_d)
    }

    /// The patch constraints' potential `Σ_a [C_a²/(2 α_a) + D_a²/2] = Σ_a W_a [k_h/2 C̄_a² +
    /// (1 − β) ψ_d(F̄_a)]` at `positions`.
    pub fn potential_j(&self, input: &PatchInput<'_>, positions: &[Vec3]) -> f64 {
        let k_h = input.material.split_stiffness_pa()[1];
        let mut total = 0.0;
        for p in 0..self.len() {
            let x: Vec<Vec3> = self.nodes(p).iter().map(|&i| positions[i as usize]).collect();
            let (mut gh, mut gd) = (vec![Vec3::zeros(); x.len()], vec![Vec3::zeros(); x.len()]);
            let (c, u) = self.terms(p, input, &x, &mut gh, &mut gd);
            total += 0.5 * k_h * self.weight_m3[p] * c * c + u;
        }
        total
    }

    /// Projects patch `p`'s hydrostatic constraint `C_a` (compliance `1/(k_h W_a)`) and its
    /// deviatoric one `D_a` (unit compliance) together, the 2 × 2 block update
    /// ([`crate::xpbd::constraint::xpbd_block_step`]), from positions read by `read`, updating
    /// `lambdas` (the two multipliers); the corrected patch positions are left in `x` (gathered
    /// in the patch's node order). False when every node of the patch is pinned or nothing moves.
    fn project(
        &self,
        p: usize,
        input: &PatchInput<'_>,
        read: impl Fn(usize) -> Vec3,
        lambdas: &mut [f64],
        scratch: &mut Scratch,
    ) -> bool {
        let nodes = self.nodes(p);
        scratch.resize(nodes.len());
        for ((xi, wi), &i) in scratch.x.iter_mut().zip(scratch.w.iter_mut()).zip(nodes) {
            *xi = read(i as usize);
            *wi = input.inv_mass[i as usize];
        }
        if scratch.w.iter().all(|&w| w == 0.0) {
            return false;
        }
        let (c, energy) = self.terms(p, input, &scratch.x, &mut scratch.gh, &mut scratch.gd);
        // ψ_d ≥ 0 for StVK and Neo-Hookean (the models the mixed formulation takes)
        let d = (2.0 * energy.max(0.0)).sqrt();
        let (w, gh, gd) = (&scratch.w, &scratch.gh, &scratch.gd);
        let off = weighted_dot(w, gh, gd);
        let gram = [[weighted_dot(w, gh, gh), off], [off, weighted_dot(w, gd, gd)]];
        let alpha_tilde = [input.inv_dt2 / (input.material.split_stiffness_pa()[1] * self.weight_m3[p]), input.inv_dt2];
        match xpbd_block_step::<2>([c, d], [1.0, d], gram, alpha_tilde, [lambdas[0], lambdas[1]]) {
            Some((d_lambda, step)) => {
                lambdas[0] += d_lambda[0];
                lambdas[1] += d_lambda[1];
                apply(&mut scratch.x, &scratch.w, &scratch.gh, step[0]);
                apply(&mut scratch.x, &scratch.w, &scratch.gd, step[1]);
                true
            }
            None => false,
        }
    }

    /// One Gauss–Seidel sweep over every patch constraint, colour by colour (the patches of a
    /// colour concurrently): `lambdas` holds two multipliers per patch (hydrostatic, deviatoric). Returns the number of
    /// patches projected, or the first patch whose corrections came out non-finite (not
    /// written).
    pub fn sweep(
        &self,
        input: &PatchInput<'_>,
        positions: &mut [Vec3],
        lambdas: &mut [f64],
    ) -> Result<usize, BadPatch> {
        use rayon::prelude::*;
        assert_eq!(lambdas.len(), 2 * self.len(), "two multipliers per patch");
        let positions = crate::math::shared::SharedMut::new(positions);
        let lambdas = crate::math::shared::SharedMut::new(lambdas);
        let mut projected = 0;
        let mut serial_scratch = Scratch::default();
        for colour in &self.colours {
            let one = |scratch: &mut Scratch, &p: &u32| -> Result<usize, BadPatch> {
                let p = p as usize;
                // SAFETY: no two patches of a colour share a node, and each patch owns its
                // multiplier: the reads and writes of concurrent patches are disjoint.
                let read = |i: usize| unsafe { positions.read(i) };
                let lambda = unsafe { lambdas.slice_mut(2 * p, 2) };
                if !self.project(p, input, read, lambda, scratch) {
                    return Ok(0);
                }
                let nodes = self.nodes(p);
                if let Some(at) = scratch.x.iter().position(|x| !x.iter().all(|v| v.is_finite())) {
                    let (bi, e, _) = self.members[self.member_start[p]];
                    return Err(BadPatch { block: bi as usize, element: e as usize, node: nodes[at] });
                }
                for (x, &i) in scratch.x.iter().zip(nodes) {
                    // SAFETY: as above.
                    unsafe { positions.write(i as usize, *x) };
                }
                Ok(1)
            };
            // a colour too small to share runs on this thread (the same bits either way)
            let done: Result<usize, BadPatch> = if colour.len() < 2 * MIN_PATCHES_PER_TASK {
                colour.iter().map(|p| one(&mut serial_scratch, p)).sum()
            } else {
                colour.par_iter().with_min_len(MIN_PATCHES_PER_TASK).map_init(Scratch::default, one).sum()
            };
            projected += done?;
        }
        Ok(projected)
    }
}

/// A patch's gathered positions, inverse masses and its two terms' gradients (reused across
/// patches).
#[derive(Default)]
struct Scratch {
    x: Vec<Vec3>,
    w: Vec<f64>,
    gh: Vec<Vec3>,
    gd: Vec<Vec3>,
}

impl Scratch {
    fn resize(&mut self, len: usize) {
        self.x.resize(len, Vec3::zeros());
        self.w.resize(len, 0.0);
        self.gh.resize(len, Vec3::zeros());
        self.gd.resize(len, Vec3::zeros());
    }
}

#[cfg(test)]
mod tests;
