//! VBD on P1's node patches (the mixed formulation's nodal-strain tetrahedron,
//! [`crate::fem::energy::mixed::patch`]): the energy
//!
//! `U = β Σ_e V_e ψ_d(F_e) + Σ_a W_a [(1 − β) ψ_d(F̄_a) + k_h/2 C̄_a²]`
//!
//! couples every node of a patch through its means `F̄_a`, `C̄_a`, so node `i`'s update reads the
//! patches of all its neighbours `a` (node `i` included). With the other nodes fixed, its force
//! and block are (Chen et al. 2024's node step on this `U`)
//!
//! `f_i = −Σ_{e∋i} V_e (β P_d + p̃_e G_h)(F_e) ∇N_i − Σ_a W_a [(1 − β) P_d(F̄_a) b̄_{a,i} + k_h C̄_a ḡ_{a,i}]`,
//! `H_i = Σ_{e∋i} Π(V_e C(β A_d + p̃_e H_h)(∇N_i, ∇N_i)) + Σ_a W_a [(1 − β) Π(C(A_d(F̄_a))(b̄, b̄)) + k_h ḡ ḡᵀ]`
//!
//! with `b̄_{a,i} = Σ_{e∋a,i} V_e ∇N_i / (4 W_a)` (fixed, kept per neighbour) and
//! `ḡ_{a,i} = Σ_{e∋a,i} V_e G_h(F_e) ∇N_i / (4 W_a)` (summed per visit), `Π` the projection of a
//! 3 × 3 block to positive semi-definite ([`crate::material::project_psd3`]). [`Patches`] keeps
//! `C_e`, `F̄_a` and `C̄_a` in step with the positions: from the elements' `F_e` (the lanes') at
//! the start of every sweep, then moved with each node (`F̄_a` by `V_e/(4 W_a) Δ ⊗ ∇N_i`, `C̄_a`
//! by `V_e/(4 W_a)` times the change of `C_e`). Two nodes whose patches share a node would then
//! write the same mean, so the nodes are coloured two edges apart ([`colour_two_apart`]) instead of
//! one: the same bits on any thread count.

use super::lanes::LaneView;
use crate::Vec3;
use crate::fem::energy::element_grads;
use crate::fem::energy::mixed::patch::{
    element_node_share, element_share_and_hydrostatic, hydrostatic_stiffness_pa, is_patch_block, patch_energy,
    patch_node_share,
};
use crate::fem::geometry::BlockGeometry;
use crate::material::{Mat3, Material, project_psd3};
use crate::math::shared::SharedMut;
use crate::mesh::Mesh;
use crate::mesh::adjacency::{NodeIncidence, greedy_colours};
use std::cell::RefCell;

/// Corners of a linear tetrahedron.
const CORNERS: usize = 4;

/// One patch element holding a node, as the node's visit reads it.
#[derive(Clone, Copy)]
struct Holding {
    block: u16,
    /// The node's index in the element.
    local: u16,
    element: u32,
    /// The element's corners' slots in the node's neighbour list.
    slots: [u16; CORNERS],
}

/// What VBD keeps of the patches (module docs): their fixed geometry, the means in step with the
/// positions and the colouring two edges apart.
pub(super) struct Patches {
    fixed: Fixed,
    /// Per node: `F̄_a`, `C̄_a`.
    f_bar: Vec<Mat3>,
    c_bar: Vec<f64>,
    /// Per patch element: `C_h(F_e)`.
    c_e: Vec<f64>,
    /// The nodes by colour, no two of one colour within two edges.
    colours: Vec<Vec<u32>>,
}

/// The patches' fixed part.
struct Fixed {
    /// Per block, whether it is measured per patch, and the offset of its elements in `c_e`.
    patch_block: Vec<bool>,
    offset: Vec<usize>,
    /// Per node, `W_a` (zero where no patch element touches it).
    weight_m3: Vec<f64>,
    /// Per node `i`: its neighbours `a` (`i` included) in increasing order, `b̄_{a,i}` with each.
    neighbour_start: Vec<u32>,
    neighbours: Vec<u32>,
    b_bar: Vec<Vec3>,
    /// Per node: the patch elements holding it.
    holding_start: Vec<u32>,
    holding: Vec<Holding>,
    /// The number of nodes and elements it was built for.
    built_for: (usize, usize),
}

thread_local! {
    /// A visit's `ḡ_{a,i}` per neighbour slot (grown once per thread: frames stay allocation-free).
    static G_BAR: RefCell<Vec<Vec3>> = const { RefCell::new(Vec::new()) };
}

impl Patches {
    /// The patches of `mesh` under `material`, None when it has none.
    pub(super) fn new(
        mesh: &Mesh,
        geometry: &[BlockGeometry],
        material: &Material,
        incidence: &NodeIncidence,
    ) -> Option<Self> {
        let patch_block: Vec<bool> = mesh.blocks.iter().map(|b| is_patch_block(b, material)).collect();
        if !patch_block.iter().any(|&p| p) {
            return None;
        }
        let n = mesh.num_nodes();
        let mut offset = vec![0usize; mesh.blocks.len()];
        let mut count = 0;
        for (b, block) in mesh.blocks.iter().enumerate() {
            offset[b] = count;
            if patch_block[b] {
                count += block.len();
            }
        }
        let mut weight_m3 = vec![0.0; n];
        for (b, block) in mesh.blocks.iter().enumerate().filter(|(b, _)| patch_block[*b]) {
            for (e, nodes) in block.elements().enumerate() {
                let v: f64 = geometry[b].volumes(e).iter().sum();
                for &a in nodes {
                    weight_m3[a as usize] += v / CORNERS as f64;
                }
            }
        }
        let (mut neighbour_start, mut neighbours, mut b_bar) = (vec![0u32], Vec::new(), Vec::new());
        let (mut holding_start, mut holding) = (vec![0u32], Vec::new());
        let mut local_list: Vec<u32> = Vec::new();
        for i in 0..n {
            local_list.clear();
            let patch_incs = || incidence.of(i).iter().filter(|inc| patch_block[inc.block as usize]);
            for inc in patch_incs() {
                local_list.extend_from_slice(mesh.blocks[inc.block as usize].element(inc.element as usize));
            }
            local_list.sort_unstable();
            local_list.dedup();
            let base = neighbours.len();
            neighbours.extend_from_slice(&local_list);
            b_bar.resize(neighbours.len(), Vec3::zeros());
            for inc in patch_incs() {
                let (b, e) = (inc.block as usize, inc.element as usize);
                let nodes = mesh.blocks[b].element(e);
                let g = &geometry[b];
                let grad_i = element_grads(g, e)[inc.local as usize];
                let v: f64 = g.volumes(e).iter().sum();
                let mut slots = [0u16; CORNERS];
                for (slot, &a) in slots.iter_mut().zip(nodes) {
                    let k = local_list.binary_search(&a).expect("a corner of an element holding the node");
                    *slot = u16::try_from(k).expect("fewer than 65,536 neighbours");
                    b_bar[base + k] += grad_i * (v / (CORNERS as f64 * weight_m3[a as usize]));
                }
                holding.push(Holding { block: inc.block, local: inc.local, element: inc.element, slots });
            }
            neighbour_start.push(neighbours.len() as u32);
            holding_start.push(holding.len() as u32);
        }
        let colours = colour_two_apart(mesh, incidence);
        let fixed = Fixed {
            patch_block,
            offset,
            weight_m3,
            neighbour_start,
            neighbours,
            b_bar,
            holding_start,
            holding,
            built_for: (n, mesh.blocks.iter().map(|b| b.len()).sum()),
        };
        Some(Self { fixed, f_bar: vec![Mat3::zeros(); n], c_bar: vec![0.0; n], c_e: vec![0.0; count], colours })
    }

    /// Whether these patches were built for `mesh` (its node and element counts).
    pub(super) fn fits(&self, mesh: &Mesh) -> bool {
        self.fixed.built_for == (mesh.num_nodes(), mesh.blocks.iter().map(|b| b.len()).sum())
    }

    /// `C_e`, `F̄_a` and `C̄_a` from the elements' `F_e` the lanes hold.
    pub(super) fn refresh(&mut self, mesh: &Mesh, material: &Material, lanes: &[LaneView<'_>]) {
        self.f_bar.iter_mut().for_each(|f| *f = Mat3::zeros());
        self.c_bar.iter_mut().for_each(|c| *c = 0.0);
        let fixed = &self.fixed;
        for (b, block) in mesh.blocks.iter().enumerate().filter(|(b, _)| fixed.patch_block[*b]) {
            let l = &lanes[b];
            for (e, nodes) in block.elements().enumerate() {
                // SAFETY: one thread
                let (f, _, v) = element_of(l, unsafe { l.f_mut(e) }, e, 0);
                let (_, c) = element_share_and_hydrostatic(material, &f, v);
                self.c_e[fixed.offset[b] + e] = c;
                for &a in nodes {
                    let s = v / (CORNERS as f64 * fixed.weight_m3[a as usize]);
                    self.f_bar[a as usize] += f * s;
                    self.c_bar[a as usize] += c * s;
                }
            }
        }
    }

    /// (Tests.) Node `a`'s `C̄_a` and `F̄_a`.
    #[cfg(test)]
    pub(super) fn mean(&self, a: usize) -> (f64, Mat3) {
        (self.c_bar[a], self.f_bar[a])
    }

    /// The means as a sweep's node updates share them, and the colours they run in.
    pub(super) fn view(&mut self) -> (PatchView<'_>, &[Vec<u32>]) {
        let Patches { fixed, f_bar, c_bar, c_e, colours } = self;
        let view = PatchView {
            patches: fixed,
            f_bar: SharedMut::new(f_bar),
            c_bar: SharedMut::new(c_bar),
            c_e: SharedMut::new(c_e),
        };
        (view, colours)
    }
}

/// A linear tetrahedron's `F_e`, `∇N_a` (node `a`) and `V_e` from its lanes: `F` and the
/// gradients are the same at every point (those of its first, lane 0 of chunk 0), the volume the
/// points' sum (padding zero).
#[inline(always)]
fn element_of(l: &LaneView<'_>, f: &[f64], e: usize, a: usize) -> (Mat3, Vec3, f64) {
    let w = l.geometry.width;
    let grads = l.geometry.node_grads(e, a);
    (
        Mat3::from_fn(|r, c| f[(3 * r + c) * w]),
        Vec3::new(grads[0], grads[w], grads[2 * w]),
        l.geometry.volumes(e).iter().sum(),
    )
}

/// The patches during a sweep: the fixed part read, the means written by the node updates of a
/// colour in parallel (each its own patches').
pub(super) struct PatchView<'a> {
    patches: &'a Fixed,
    f_bar: SharedMut<Mat3>,
    c_bar: SharedMut<f64>,
    c_e: SharedMut<f64>,
}

// (the raw views are shared by the tasks of one colour, which touch disjoint entries)
// SAFETY: see above
unsafe impl Sync for PatchView<'_> {}

impl PatchView<'_> {
    fn holding(&self, i: usize) -> &[Holding] {
        let p = self.patches;
        &p.holding[p.holding_start[i] as usize..p.holding_start[i + 1] as usize]
    }
    fn neighbours(&self, i: usize) -> (&[u32], &[Vec3]) {
        let p = self.patches;
        let range = p.neighbour_start[i] as usize..p.neighbour_start[i + 1] as usize;
        (&p.neighbours[range.clone()], &p.b_bar[range])
    }

    /// Whether block `b` is measured per patch.
    #[inline(always)]
    pub(super) fn is_patch(&self, b: usize) -> bool {
        self.patches.patch_block[b]
    }

    /// Node `i`'s patch gradient `∂U/∂x_i` and positive semi-definite block (module docs).
    ///
    /// # Safety
    /// No other thread may access the elements holding node `i` or the means of its neighbours
    /// meanwhile (nodes of one colour lie more than two edges apart).
    pub(super) unsafe fn node_share(&self, material: &Material, i: usize, lanes: &[LaneView<'_>]) -> (Vec3, Mat3) {
        let k_h = hydrostatic_stiffness_pa(material);
        let (neighbours, b_bar) = self.neighbours(i);
        let w = &self.patches.weight_m3;
        let (mut gradient, mut block) = (Vec3::zeros(), Mat3::zeros());
        G_BAR.with_borrow_mut(|g_bar| {
            g_bar.clear();
            g_bar.resize(neighbours.len(), Vec3::zeros());
            for h in self.holding(i) {
                let l = &lanes[h.block as usize];
                let e = h.element as usize;
                // SAFETY: an element holding node i (the caller's promise)
                let (f, g, v) = element_of(l, unsafe { l.f_mut(e) }, e, h.local as usize);
                // SAFETY: the element's corners are node i's neighbours (the caller's promise)
                let c_sum: f64 =
                    h.slots.iter().map(|&s| unsafe { self.c_bar.read(neighbours[s as usize] as usize) }).sum();
                let (ge, be, gh) = element_node_share(material, k_h * c_sum / CORNERS as f64, &f, &g, v);
                gradient += ge;
                block += project_psd3(&be);
                for &s in &h.slots {
                    g_bar[s as usize] += gh / (CORNERS as f64 * w[neighbours[s as usize] as usize]);
                }
            }
            for ((&a, b), gb) in neighbours.iter().zip(b_bar).zip(g_bar.iter()) {
                let a = a as usize;
                // SAFETY: a neighbour of node i (the caller's promise)
                let (f_bar, c_bar) = unsafe { (self.f_bar.read(a), self.c_bar.read(a)) };
                let (ga, ba) = patch_node_share(material, w[a], &f_bar, c_bar, b, gb);
                gradient += ga;
                block += ba;
            }
        });
        (gradient, block)
    }

    /// Node `i` moved by `d` (the lanes' `F_e` already carried): its elements' `C_e` and its
    /// neighbours' means follow.
    ///
    /// # Safety
    /// As [`PatchView::node_share`].
    pub(super) unsafe fn carry(&self, material: &Material, i: usize, d: &Vec3, lanes: &[LaneView<'_>]) {
        let (neighbours, _) = self.neighbours(i);
        let w = &self.patches.weight_m3;
        for h in self.holding(i) {
            let l = &lanes[h.block as usize];
            let e = h.element as usize;
            // SAFETY: an element holding node i (the caller's promise)
            let (f, g, v) = element_of(l, unsafe { l.f_mut(e) }, e, h.local as usize);
            let (_, c) = element_share_and_hydrostatic(material, &f, v);
            let k = self.patches.offset[h.block as usize] + e;
            // SAFETY: the caller's promise, as above
            let dc = c - unsafe { self.c_e.read(k) };
            unsafe { self.c_e.write(k, c) };
            let df = d * g.transpose();
            for &s in &h.slots {
                let a = neighbours[s as usize] as usize;
                let share = v / (CORNERS as f64 * w[a]);
                // SAFETY: a neighbour of node i (the caller's promise)
                unsafe {
                    self.f_bar.write(a, self.f_bar.read(a) + df * share);
                    self.c_bar.write(a, self.c_bar.read(a) + dc * share);
                }
            }
        }
    }

    /// Node `i`'s share of the patch energy: `Σ_{e∋i} β V_e ψ_d(F_e) + Σ_a W_a [(1 − β) ψ_d(F̄_a)
    /// + k_h/2 C̄_a²]` over its neighbours `a`.
    ///
    /// # Safety
    /// As [`PatchView::node_share`].
    pub(super) unsafe fn local_energy(&self, material: &Material, i: usize, lanes: &[LaneView<'_>]) -> f64 {
        let mut energy = 0.0;
        for h in self.holding(i) {
            let l = &lanes[h.block as usize];
            let e = h.element as usize;
            // SAFETY: an element holding node i (the caller's promise)
            let (f, _, v) = element_of(l, unsafe { l.f_mut(e) }, e, 0);
            energy += element_share_and_hydrostatic(material, &f, v).0;
        }
        let (neighbours, _) = self.neighbours(i);
        for &a in neighbours {
            let a = a as usize;
            // SAFETY: a neighbour of node i (the caller's promise)
            let (f_bar, c_bar) = unsafe { (self.f_bar.read(a), self.c_bar.read(a)) };
            energy += patch_energy(material, self.patches.weight_m3[a], &f_bar, c_bar);
        }
        energy
    }
}

/// Nodes by colour, no two of one colour within two edges of each other (sharing an element, or
/// each sharing one with a third node): greedy in node order, deterministic.
pub(super) fn colour_two_apart(mesh: &Mesh, incidence: &NodeIncidence) -> Vec<Vec<u32>> {
    let n = mesh.num_nodes();
    let mut start = vec![0usize];
    let mut adjacent: Vec<u32> = Vec::new();
    let mut list: Vec<u32> = Vec::new();
    for i in 0..n {
        list.clear();
        for inc in incidence.of(i) {
            list.extend_from_slice(mesh.blocks[inc.block as usize].element(inc.element as usize));
        }
        list.sort_unstable();
        list.dedup();
        adjacent.extend_from_slice(&list);
        start.push(adjacent.len());
    }
    greedy_colours(n, |i, visit| {
        for &a in &adjacent[start[i]..start[i + 1]] {
            for &b in &adjacent[start[a as usize]..start[a as usize + 1]] {
                visit(b);
            }
        }
    })
}
