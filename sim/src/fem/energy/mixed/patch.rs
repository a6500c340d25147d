//! The mixed formulation on linear tetrahedra: the hydrostatic term measured over each node's
//! patch (the averaged nodal pressure tetrahedron of Bonet & Burton 1998, "A simple average
//! nodal pressure tetrahedral element for incompressible and nearly incompressible dynamic
//! explicit applications", *Commun. Numer. Meth. Engng* 14, with the hydrostatic term of the
//! material's own split in place of the volume ratio, as [`super`] does per element).
//!
//! A P1 element has one strain, so its element mean is its point and a constant pressure per
//! element changes nothing; the pressure is instead one value per node, the mean of the
//! hydrostatic term over the elements around it. With `V_e`, `C_e = Σ_q V_q C_h(F_q) / V_e` per
//! element and, per node `a`, `W_a = Σ_{e∋a} V_e/4`, `C̄_a = Σ_{e∋a} V_e C_e/4 / W_a`:
//!
//! `U = Σ_e Σ_q V_q ψ_d(F_q) + Σ_a W_a k_h/2 C̄_a²`;
//!
//! - gradient: `∂U/∂x_i = Σ_e Σ_q V_q (P_d + p̃_e G_h)(F_q) ∇N_i(r_q)` with the element's pressure
//!   `p̃_e = k_h Σ_{a∈e} C̄_a / 4`, the mean of its nodes' pressures: one mesh pass (element
//!   terms → node means → element means) makes it element-local again;
//! - Hessian: `Σ_e Σ_q V_q C(A_d + p̃_e H_h)(∇N_i, ∇N_j) + Σ_a W_a k_h ḡ_a ⊗ ḡ_a`,
//!   `ḡ_{a,i} = Σ_{e∋a,i} Σ_q V_q G_h ∇N_i / (4 W_a)`: the rank-one patch terms couple every two
//!   nodes of a patch, so the stiffness pattern widens to nodes two edges apart
//!   ([`pattern_pairs`]).
//!
//! A mesh of `n` nodes and about `5.5 n` tetrahedra then has `n` volume constraints for `3 n`
//! displacements instead of `5.5 n`: the ratio that releases the mesh from locking (Bonet &
//! Burton §2; Zienkiewicz, Taylor & Zhu, *The Finite Element Method*, §11.5 on the count).

use super::{hydrostatic_stiffness_pa, point, point_tangent};
use crate::Vec3;
use crate::element::ReferenceShape;
use crate::fem::energy::{PointBlocks, element_grads, gather};
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::material::{Material, VolumeMeasure};
use crate::mesh::{ElementBlock, Mesh};
use nalgebra::DMatrix;

/// Corners of a linear tetrahedron: each takes a quarter of its element's volume.
const CORNERS: usize = 4;

/// Whether `block` is measured per node patch under `material`: linear tetrahedra in the mixed
/// formulation.
pub fn is_patch_block(block: &ElementBlock, material: &Material) -> bool {
    material.volume_measure == VolumeMeasure::Element
        && block.element_type.shape() == ReferenceShape::Tetrahedron
        && block.element_type.order() == 1
}

/// Whether any block of `mesh` is measured per node patch.
pub fn has_patches(mesh: &Mesh, material: &Material) -> bool {
    mesh.blocks.iter().any(|b| is_patch_block(b, material))
}

/// The patch blocks' indices.
fn patch_blocks<'a>(mesh: &'a Mesh, material: &'a Material) -> impl Iterator<Item = usize> + 'a {
    (0..mesh.blocks.len()).filter(move |&b| is_patch_block(&mesh.blocks[b], material))
}

/// Visits every patch element (block by block, in mesh order) with its deformed and rest corner
/// positions gathered: `visit(block, element, nodes, geometry, x, rest)`.
fn for_each_patch_element(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    mut visit: impl FnMut(usize, usize, &[u32], &BlockGeometry, &[Vec3; CORNERS], &[Vec3; CORNERS]),
) {
    let (mut xl, mut rest) = ([Vec3::zeros(); CORNERS], [Vec3::zeros(); CORNERS]);
    for bi in patch_blocks(mesh, material) {
        let (block, g) = (&mesh.blocks[bi], &geometry[bi]);
        for (e, nodes) in block.elements().enumerate() {
            gather(x, nodes, &mut xl);
            gather(&mesh.rest_positions, nodes, &mut rest);
            visit(bi, e, nodes, g, &xl, &rest);
        }
    }
}

/// The nodal means at `x`: per node `W_a` and `C̄_a` (zero where no patch element touches it).
pub struct NodeMeans {
    pub weight_m3: Vec<f64>,
    pub c_bar: Vec<f64>,
}

impl NodeMeans {
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material, x: &[Vec3]) -> Self {
        let n = mesh.num_nodes();
        let (mut weight_m3, mut sum) = (vec![0.0; n], vec![0.0; n]);
        for_each_patch_element(mesh, geometry, material, x, |_, e, nodes, g, xl, rest| {
            let (v_e, c_sum) = element_sums(g, e, xl, rest, material);
            for &a in nodes {
                weight_m3[a as usize] += v_e / CORNERS as f64;
                sum[a as usize] += c_sum / CORNERS as f64;
            }
        });
        let c_bar = sum.iter().zip(&weight_m3).map(|(s, w)| if *w > 0.0 { s / w } else { 0.0 }).collect();
        Self { weight_m3, c_bar }
    }

    /// `Σ_a W_a k_h/2 C̄_a²`.
    fn hydrostatic_energy(&self, k_h: f64) -> f64 {
        self.weight_m3.iter().zip(&self.c_bar).map(|(w, c)| 0.5 * k_h * w * c * c).sum()
    }

    /// The element's pressure `p̃_e = k_h Σ_{a∈e} C̄_a / 4` (Pa).
    pub fn element_pressure_pa(&self, nodes: &[u32], k_h: f64) -> f64 {
        k_h * nodes.iter().map(|&a| self.c_bar[a as usize]).sum::<f64>() / nodes.len() as f64
    }
}

/// `(V_e, Σ_q V_q C_h(F_q))` of element `e`.
fn element_sums(g: &BlockGeometry, e: usize, x: &[Vec3], rest: &[Vec3], material: &Material) -> (f64, f64) {
    let grads = element_grads(g, e);
    let (mut v_e, mut sum) = (0.0, 0.0);
    for (q, &v) in g.volumes(e).iter().enumerate() {
        let f = deformation_gradient(x, rest, &grads[q * CORNERS..(q + 1) * CORNERS]);
        v_e += v;
        sum += v * material.split_terms(&f)[1].value;
    }
    (v_e, sum)
}

/// The patch blocks' share of the energy, `Σ_e Σ_q V_q ψ_d + Σ_a W_a k_h/2 C̄_a²`, with its
/// gradient added to `gradient_out` when given.
pub fn energy_and_gradient(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    mut gradient_out: Option<&mut [Vec3]>,
) -> f64 {
    let k_h = hydrostatic_stiffness_pa(material);
    let means = NodeMeans::new(mesh, geometry, material, x);
    let mut total = means.hydrostatic_energy(k_h);
    for_each_patch_element(mesh, geometry, material, x, |_, e, nodes, g, xl, rest| {
        let pressure = means.element_pressure_pa(nodes, k_h);
        let grads = element_grads(g, e);
        for (q, &v) in g.volumes(e).iter().enumerate() {
            let gq = &grads[q * CORNERS..(q + 1) * CORNERS];
            let pt = point(material, k_h, &deformation_gradient(xl, rest, gq));
            total += v * pt.psi_d;
            if let Some(out) = gradient_out.as_deref_mut() {
                let stress = (pt.p_d + pt.g_h * pressure) * v;
                for (&a, gi) in nodes.iter().zip(gq) {
                    out[a as usize] += stress * gi;
                }
            }
        }
    });
    total
}

/// The patch blocks' Hessian terms at `x`, each handed to `add` with its nodes: every element's
/// `Σ_q V_q C(A_d + p̃_e H_h)` (12 × 12; `projected`: `A_d + p̃_e H_h` projected to positive
/// semi-definite at each point) in mesh order, then every node's patch term `W_a k_h ḡ_a ⊗ ḡ_a`
/// (positive semi-definite already) over the patch's nodes, in node order.
pub fn hessian_terms(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    projected: bool,
    mut add: impl FnMut(&[u32], &DMatrix<f64>),
) {
    let k_h = hydrostatic_stiffness_pa(material);
    let means = NodeMeans::new(mesh, geometry, material, x);
    // per element, its corners' `Σ_q V_q G_h ∇N_i` (for the patch terms)
    let mut hydro: Vec<(usize, usize, [Vec3; CORNERS])> = Vec::new();
    for_each_patch_element(mesh, geometry, material, x, |bi, e, nodes, g, xl, rest| {
        let pressure = means.element_pressure_pa(nodes, k_h);
        let grads = element_grads(g, e);
        let mut blocks = PointBlocks::new(CORNERS);
        let mut gh = [Vec3::zeros(); CORNERS];
        for (q, &v) in g.volumes(e).iter().enumerate() {
            let gq = &grads[q * CORNERS..(q + 1) * CORNERS];
            let f = deformation_gradient(xl, rest, gq);
            let pt = point(material, k_h, &f);
            blocks.add(&point_tangent(material, k_h, pressure, &f, &pt, projected), gq, v);
            for (h, gi) in gh.iter_mut().zip(gq) {
                *h += pt.g_h * gi * v;
            }
        }
        add(nodes, &blocks.finish());
        hydro.push((bi, e, gh));
    });
    // the patches: node → the elements around it
    let around = elements_around(mesh, material);
    let mut patch_nodes: Vec<u32> = Vec::new();
    let mut g_bar: Vec<Vec3> = Vec::new();
    for (a, &w_a) in means.weight_m3.iter().enumerate() {
        if w_a <= 0.0 {
            continue;
        }
        patch_nodes.clear();
        g_bar.clear();
        for &k in around.of(a) {
            let (bi, e, gh) = &hydro[k];
            for (&i, h) in mesh.blocks[*bi].element(*e).iter().zip(gh) {
                let share = h / (CORNERS as f64 * w_a);
                match patch_nodes.iter().position(|&p| p == i) {
                    Some(at) => g_bar[at] += share,
                    None => {
                        patch_nodes.push(i);
                        g_bar.push(share);
                    }
                }
            }
        }
        let m = patch_nodes.len();
        let scale = w_a * k_h;
        let h = DMatrix::from_fn(3 * m, 3 * m, |r, c| scale * g_bar[r / 3][r % 3] * g_bar[c / 3][c % 3]);
        add(&patch_nodes, &h);
    }
}

/// Per node, the patch elements around it as indices into the patch elements in mesh order
/// (block by block, [`patch_elements`]): a compressed list.
pub struct Around {
    start: Vec<usize>,
    elements: Vec<usize>,
}

impl Around {
    /// The patch elements around node `a`.
    pub fn of(&self, a: usize) -> &[usize] {
        &self.elements[self.start[a]..self.start[a + 1]]
    }
}

/// The patch elements `(block, element)` in mesh order, block by block: what [`Around`] indexes.
pub fn patch_elements(mesh: &Mesh, material: &Material) -> Vec<(usize, usize)> {
    patch_blocks(mesh, material).flat_map(|bi| (0..mesh.blocks[bi].len()).map(move |e| (bi, e))).collect()
}

pub fn elements_around(mesh: &Mesh, material: &Material) -> Around {
    let n = mesh.num_nodes();
    let mut start = vec![0usize; n + 1];
    for bi in patch_blocks(mesh, material) {
        for nodes in mesh.blocks[bi].elements() {
            for &a in nodes {
                start[a as usize + 1] += 1;
            }
        }
    }
    for a in 0..n {
        start[a + 1] += start[a];
    }
    let mut next = start[..n].to_vec();
    let mut elements = vec![0usize; start[n]];
    let mut k = 0;
    for bi in patch_blocks(mesh, material) {
        for nodes in mesh.blocks[bi].elements() {
            for &a in nodes {
                elements[next[a as usize]] = k;
                next[a as usize] += 1;
            }
            k += 1;
        }
    }
    Around { start, elements }
}

/// The node pairs `(j, i)`, `i > j`, in the numbering `index` (`u32::MAX`: left out) that the
/// patch terms couple beyond the elements' own: every two nodes of a node's patch.
pub fn pattern_pairs(mesh: &Mesh, material: &Material, index: &[u32], pairs: &mut Vec<(u32, u32)>) {
    let around = elements_around(mesh, material);
    let flat: Vec<&[u32]> = patch_blocks(mesh, material).flat_map(|bi| mesh.blocks[bi].elements()).collect();
    let mut patch: Vec<u32> = Vec::new();
    for a in 0..mesh.num_nodes() {
        patch.clear();
        for &k in around.of(a) {
            patch.extend(flat[k].iter().map(|&i| index[i as usize]).filter(|&i| i != u32::MAX));
        }
        patch.sort_unstable();
        patch.dedup();
        for (s, &j) in patch.iter().enumerate() {
            pairs.extend(patch[s + 1..].iter().map(|&i| (j, i)));
        }
    }
}

/// Every patch element's pressure `p̃_e` (Pa) at `x`, block by block in mesh order (empty for a
/// block that is not measured per patch).
pub fn element_pressures_pa(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material, x: &[Vec3]) -> Vec<Vec<f64>> {
    let k_h = hydrostatic_stiffness_pa(material);
    let means = NodeMeans::new(mesh, geometry, material, x);
    mesh.blocks
        .iter()
        .map(|b| {
            if is_patch_block(b, material) {
                b.elements().map(|nodes| means.element_pressure_pa(nodes, k_h)).collect()
            } else {
                Vec::new()
            }
        })
        .collect()
}
