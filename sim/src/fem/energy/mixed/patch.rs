//! The mixed formulation on linear tetrahedra: the hydrostatic term measured over each node's
//! patch (the averaged nodal pressure tetrahedron of Bonet & Burton 1998, "A simple average
//! nodal pressure tetrahedral element for incompressible and nearly incompressible dynamic
//! explicit applications", *Commun. Numer. Meth. Engng* 14, with the hydrostatic term of the
//! material's own split in place of the volume ratio, as [`super`] does per element).
//!
//! A P1 element has one strain, so its element mean is its point and a constant pressure per
//! element changes nothing; the pressure is instead one value per node, the mean of the
//! hydrostatic term over the elements around it. The pressure alone leaves the linear
//! tetrahedron stiff in bending (a fifth of the sag short on the 1,280-element beam at
//! ν = 0.499), so the deviatoric term is measured at the nodes too: the nodal-strain
//! tetrahedron (Dohrmann, Heinstein, Jung, Key & Witkowski 2000, "Node-based uniform strain
//! elements for three-node triangular and four-node tetrahedral meshes", *IJNME* 47) with the
//! isochoric stabilisation of Gee, Dohrmann, Key & Wall 2009 ("A uniform nodal strain
//! tetrahedron with isochoric stabilization", *IJNME* 78; Puso & Solberg 2006 before them): a
//! share `β` ([`ELEMENT_DEVIATORIC_SHARE`]) of the deviatoric energy stays on the elements,
//! which removes the nodal integration's spurious low-energy modes without bringing the volume
//! back. With `V_e`, `C_e = Σ_q V_q C_h(F_q) / V_e` per element and, per node `a`,
//! `W_a = Σ_{e∋a} V_e/4`, `C̄_a = Σ_{e∋a} V_e C_e/4 / W_a`, `F̄_a = Σ_{e∋a} Σ_q V_q F_q/4 / W_a`:
//!
//! `U = β Σ_e Σ_q V_q ψ_d(F_q) + Σ_a W_a [(1 − β) ψ_d(F̄_a) + k_h/2 C̄_a²]`;
//!
//! - gradient: `∂U/∂x_i = Σ_e Σ_q V_q (β P_d(F_q) + p̃_e G_h(F_q) + P̃_e) ∇N_i(r_q)` with the
//!   element's pressure `p̃_e = k_h Σ_{a∈e} C̄_a / 4` and nodal stress
//!   `P̃_e = (1 − β) Σ_{a∈e} P_d(F̄_a) / 4`, the means of its nodes': one mesh pass (element
//!   terms → node means → element means) makes it element-local again;
//! - Hessian: `Σ_e Σ_q V_q C(β A_d + p̃_e H_h)(∇N_i, ∇N_j)` plus, per node,
//!   `W_a [(1 − β) C(A_d(F̄_a))(b̄_{a,i}, b̄_{a,j}) + k_h ḡ_{a,i} ⊗ ḡ_{a,j}]` with
//!   `b̄_{a,i} = Σ_{e∋a,i} Σ_q V_q ∇N_i / (4 W_a)` (`∂F̄_a/∂x_i`) and
//!   `ḡ_{a,i} = Σ_{e∋a,i} Σ_q V_q G_h ∇N_i / (4 W_a)`: the patch terms couple every two nodes of
//!   a patch, so the stiffness pattern widens to nodes two edges apart ([`pattern_pairs`]).
//!
//! A mesh of `n` nodes and about `5.5 n` tetrahedra then has `n` volume constraints for `3 n`
//! displacements instead of `5.5 n`: the ratio that releases the mesh from locking (Bonet &
//! Burton §2; Zienkiewicz, Taylor & Zhu, *The Finite Element Method*, §11.5 on the count).

pub use super::hydrostatic_stiffness_pa;
use super::{point, point_node_block, point_tangent};
use crate::Vec3;
use crate::element::ReferenceShape;
use crate::fem::energy::{PointBlocks, element_grads, gather};
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::material::{Mat3, Material, VolumeMeasure};
use crate::mesh::{ElementBlock, Mesh};
use nalgebra::DMatrix;

/// Corners of a linear tetrahedron: each takes a quarter of its element's volume.
const CORNERS: usize = 4;

/// The elements' share `β` of the deviatoric energy, the rest measured at the nodes' averaged
/// deformation gradients: the isochoric stabilisation of Gee et al. 2009, its coefficient small
/// against 1 so that the nodal strain sets the bending stiffness. Measured in linear elasticity on
/// the bending beam of 1,280 tetrahedra at ν = 0.499 against the Taylor–Hood limit
/// (`scripts/taylor_hood.py`; the sketch in docs/journal/plans.md): 0.2 % short with 0.1, 4.5 %
/// with 0.2, 6 % too far with none (the nodal integration alone is too soft), 23 % short with the
/// element deviatoric term alone (`β = 1`, the averaged pressure of Bonet & Burton). hox's static
/// solution with 0.1 misses 0.3 % of the reference's sag (`solver::mixed_tests`,
/// docs/study/locking.md).
pub const ELEMENT_DEVIATORIC_SHARE: f64 = 0.1;

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

/// The nodal means at `x`: per node `W_a`, `C̄_a` and `F̄_a` (zero where no patch element
/// touches it).
pub struct NodeMeans {
    pub weight_m3: Vec<f64>,
    pub c_bar: Vec<f64>,
    pub f_bar: Vec<Mat3>,
}

impl NodeMeans {
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material, x: &[Vec3]) -> Self {
        let n = mesh.num_nodes();
        let (mut weight_m3, mut sum, mut f_sum) = (vec![0.0; n], vec![0.0; n], vec![Mat3::zeros(); n]);
        for_each_patch_element(mesh, geometry, material, x, |_, e, nodes, g, xl, rest| {
            let sums = element_sums(g, e, xl, rest, material);
            for &a in nodes {
                weight_m3[a as usize] += sums.volume_m3 / CORNERS as f64;
                sum[a as usize] += sums.c / CORNERS as f64;
                f_sum[a as usize] += sums.f / CORNERS as f64;
            }
        });
        let mean = |w: f64| if w > 0.0 { 1.0 / w } else { 0.0 };
        let c_bar = sum.iter().zip(&weight_m3).map(|(s, &w)| s * mean(w)).collect();
        let f_bar = f_sum.iter().zip(&weight_m3).map(|(f, &w)| f * mean(w)).collect();
        Self { weight_m3, c_bar, f_bar }
    }

    /// `Σ_a W_a k_h/2 C̄_a²`.
    fn hydrostatic_energy(&self, k_h: f64) -> f64 {
        self.weight_m3.iter().zip(&self.c_bar).map(|(w, c)| 0.5 * k_h * w * c * c).sum()
    }

    /// The nodes' deviatoric share `Σ_a W_a (1 − β) ψ_d(F̄_a)` and, per node, its stress
    /// `(1 − β) P_d(F̄_a)` (zero where no patch element touches it).
    fn nodal_deviatoric(&self, material: &Material, k_h: f64) -> (f64, Vec<Mat3>) {
        let share = 1.0 - ELEMENT_DEVIATORIC_SHARE;
        let mut energy = 0.0;
        let stress = self
            .weight_m3
            .iter()
            .zip(&self.f_bar)
            .map(|(&w, f)| {
                if w <= 0.0 {
                    return Mat3::zeros();
                }
                let pt = point(material, k_h, f);
                energy += w * share * pt.psi_d;
                pt.p_d * share
            })
            .collect();
        (energy, stress)
    }

    /// The element's pressure `p̃_e = k_h Σ_{a∈e} C̄_a / 4` (Pa).
    pub fn element_pressure_pa(&self, nodes: &[u32], k_h: f64) -> f64 {
        k_h * nodes.iter().map(|&a| self.c_bar[a as usize]).sum::<f64>() / nodes.len() as f64
    }
}

/// An element's volume and its points' sums `Σ_q V_q C_h(F_q)`, `Σ_q V_q F_q`.
struct ElementSums {
    volume_m3: f64,
    c: f64,
    f: Mat3,
}

/// Element `e`'s [`ElementSums`].
fn element_sums(g: &BlockGeometry, e: usize, x: &[Vec3], rest: &[Vec3], material: &Material) -> ElementSums {
    let grads = element_grads(g, e);
    let mut sums = ElementSums { volume_m3: 0.0, c: 0.0, f: Mat3::zeros() };
    for (q, &v) in g.volumes(e).iter().enumerate() {
        let f = deformation_gradient(x, rest, &grads[q * CORNERS..(q + 1) * CORNERS]);
        sums.volume_m3 += v;
        sums.c += v * material.split_terms(&f)[1].value;
        sums.f += f * v;
    }
    sums
}

/// The patch blocks' share of the energy (the module's `U`), with its gradient added to
/// `gradient_out` when given.
pub fn energy_and_gradient(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    mut gradient_out: Option<&mut [Vec3]>,
) -> f64 {
    let k_h = hydrostatic_stiffness_pa(material);
    let beta = ELEMENT_DEVIATORIC_SHARE;
    let means = NodeMeans::new(mesh, geometry, material, x);
    let (nodal_energy, nodal_stress) = means.nodal_deviatoric(material, k_h);
    let mut total = means.hydrostatic_energy(k_h) + nodal_energy;
    for_each_patch_element(mesh, geometry, material, x, |_, e, nodes, g, xl, rest| {
        let pressure = means.element_pressure_pa(nodes, k_h);
        let nodal: Mat3 = nodes.iter().map(|&a| nodal_stress[a as usize]).sum::<Mat3>() / CORNERS as f64;
        let grads = element_grads(g, e);
        for (q, &v) in g.volumes(e).iter().enumerate() {
            let gq = &grads[q * CORNERS..(q + 1) * CORNERS];
            let pt = point(material, k_h, &deformation_gradient(xl, rest, gq));
            total += beta * v * pt.psi_d;
            if let Some(out) = gradient_out.as_deref_mut() {
                let stress = (pt.p_d * beta + pt.g_h * pressure + nodal) * v;
                for (&a, gi) in nodes.iter().zip(gq) {
                    out[a as usize] += stress * gi;
                }
            }
        }
    });
    total
}

/// The patch blocks' Hessian terms at `x`, each handed to `add` with its nodes: every element's
/// `Σ_q V_q C(β A_d + p̃_e H_h)` (12 × 12; `projected`: `β A_d + p̃_e H_h` projected to positive
/// semi-definite at each point) in mesh order, then every node's patch term
/// `W_a [(1 − β) C(A_d(F̄_a))(b̄_i, b̄_j) + k_h ḡ_i ⊗ ḡ_j]` (`projected`: `A_d(F̄_a)` projected;
/// the rank-one term is positive semi-definite already) over the patch's nodes, in node order.
pub fn hessian_terms(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    projected: bool,
    mut add: impl FnMut(&[u32], &DMatrix<f64>),
) {
    let k_h = hydrostatic_stiffness_pa(material);
    let beta = ELEMENT_DEVIATORIC_SHARE;
    let means = NodeMeans::new(mesh, geometry, material, x);
    // per element, its corners' `Σ_q V_q G_h ∇N_i` and `Σ_q V_q ∇N_i` (for the patch terms)
    let mut sums: Vec<(usize, usize, [Vec3; CORNERS], [Vec3; CORNERS])> = Vec::new();
    for_each_patch_element(mesh, geometry, material, x, |bi, e, nodes, g, xl, rest| {
        let pressure = means.element_pressure_pa(nodes, k_h);
        let grads = element_grads(g, e);
        let mut blocks = PointBlocks::new(CORNERS);
        let (mut gh, mut vg) = ([Vec3::zeros(); CORNERS], [Vec3::zeros(); CORNERS]);
        for (q, &v) in g.volumes(e).iter().enumerate() {
            let gq = &grads[q * CORNERS..(q + 1) * CORNERS];
            let f = deformation_gradient(xl, rest, gq);
            let pt = point(material, k_h, &f);
            blocks.add(&point_tangent(material, k_h, beta, pressure, &f, &pt, projected), gq, v);
            for ((h, n), gi) in gh.iter_mut().zip(vg.iter_mut()).zip(gq) {
                *h += pt.g_h * gi * v;
                *n += gi * v;
            }
        }
        add(nodes, &blocks.finish());
        sums.push((bi, e, gh, vg));
    });
    // the patches: node → the elements around it
    let around = elements_around(mesh, material);
    let mut patch_nodes: Vec<u32> = Vec::new();
    let (mut g_bar, mut b_bar): (Vec<Vec3>, Vec<Vec3>) = (Vec::new(), Vec::new());
    for (a, &w_a) in means.weight_m3.iter().enumerate() {
        if w_a <= 0.0 {
            continue;
        }
        patch_nodes.clear();
        g_bar.clear();
        b_bar.clear();
        let share = 1.0 / (CORNERS as f64 * w_a);
        for &k in around.of(a) {
            let (bi, e, gh, vg) = &sums[k];
            for ((&i, h), n) in mesh.blocks[*bi].element(*e).iter().zip(gh).zip(vg) {
                let at = patch_nodes.iter().position(|&p| p == i).unwrap_or_else(|| {
                    patch_nodes.push(i);
                    g_bar.push(Vec3::zeros());
                    b_bar.push(Vec3::zeros());
                    patch_nodes.len() - 1
                });
                g_bar[at] += h * share;
                b_bar[at] += n * share;
            }
        }
        let f_bar = &means.f_bar[a];
        let mut blocks = PointBlocks::new(patch_nodes.len());
        let pt = point(material, k_h, f_bar);
        blocks.add(&point_tangent(material, k_h, 1.0, 0.0, f_bar, &pt, projected), &b_bar, w_a * (1.0 - beta));
        let mut h = blocks.finish();
        let scale = w_a * k_h;
        for c in 0..h.ncols() {
            for r in 0..h.nrows() {
                h[(r, c)] += scale * g_bar[r / 3][r % 3] * g_bar[c / 3][c % 3];
            }
        }
        add(&patch_nodes, &h);
    }
}

/// One node `i`'s share of a patch element `e ∋ i` for a vertex block descent node update
/// (`crate::solver::vbd`): with `p̃_e` the element's pressure, `g = ∇_X N_i`, `V = V_e`,
/// the gradient of the element's own share `V β P_d(F_e) g` (the pressure's `V p̃_e G_h g` is
/// the patches' hydrostatic gradient, which [`patch_node_share`] counts), the 3 × 3 block
/// `V C(β A_d + p̃_e H_h)(g, g)` (not projected) and `V G_h(F_e) g`, the element's part of the
/// patches' `ḡ_{a,i}` (the module's Hessian, read on node `i`'s diagonal).
pub fn element_node_share(
    material: &Material,
    pressure_pa: f64,
    f: &Mat3,
    g: &Vec3,
    volume_m3: f64,
) -> (Vec3, nalgebra::Matrix3<f64>, Vec3) {
    let k_h = hydrostatic_stiffness_pa(material);
    let beta = ELEMENT_DEVIATORIC_SHARE;
    let pt = point(material, k_h, f);
    let gradient = pt.p_d * g * (beta * volume_m3);
    let block = point_node_block(material, k_h, beta, pressure_pa, f, &pt, g);
    (gradient, block * volume_m3, pt.g_h * g * volume_m3)
}

/// Node `a`'s patch term seen from node `i` of its patch (a vertex block descent node update):
/// the gradient `W_a [(1 − β) P_d(F̄_a) b̄_{a,i} + k_h C̄_a ḡ_{a,i}]` and the positive
/// semi-definite 3 × 3 block `W_a [(1 − β) Π(C(A_d(F̄_a))(b̄, b̄)) + k_h ḡ ḡᵀ]` (`Π`: the
/// projection to positive semi-definite of the 3 × 3 block, as the nodes' element blocks are).
pub fn patch_node_share(
    material: &Material,
    weight_m3: f64,
    f_bar: &Mat3,
    c_bar: f64,
    b_bar: &Vec3,
    g_bar: &Vec3,
) -> (Vec3, nalgebra::Matrix3<f64>) {
    let k_h = hydrostatic_stiffness_pa(material);
    let share = 1.0 - ELEMENT_DEVIATORIC_SHARE;
    let pt = point(material, k_h, f_bar);
    let gradient = (pt.p_d * b_bar * share + g_bar * (k_h * c_bar)) * weight_m3;
    let deviatoric = crate::material::project_psd3(&point_node_block(material, k_h, 1.0, 0.0, f_bar, &pt, b_bar));
    (gradient, (deviatoric * share + g_bar * g_bar.transpose() * k_h) * weight_m3)
}

/// A patch element's share of the energy that stays on it, `β V_e ψ_d(F_e)`, and its
/// hydrostatic term `C_h(F_e)` (what the node means average).
pub fn element_share_and_hydrostatic(material: &Material, f: &Mat3, volume_m3: f64) -> (f64, f64) {
    let pt = point(material, hydrostatic_stiffness_pa(material), f);
    (ELEMENT_DEVIATORIC_SHARE * volume_m3 * pt.psi_d, pt.c_h)
}

/// Node `a`'s patch energy `W_a [(1 − β) ψ_d(F̄_a) + k_h/2 C̄_a²]`.
pub fn patch_energy(material: &Material, weight_m3: f64, f_bar: &Mat3, c_bar: f64) -> f64 {
    let k_h = hydrostatic_stiffness_pa(material);
    let pt = point(material, k_h, f_bar);
    weight_m3 * ((1.0 - ELEMENT_DEVIATORIC_SHARE) * pt.psi_d + 0.5 * k_h * c_bar * c_bar)
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
