//! Element elastic energy, its gradient and Hessian (the FE model both XPBD and the static
//! reference solver use).
//!
//! For an element with gathered positions `x_i`, material gradients `∇_X N_i(r_q)` and
//! quadrature volumes `V_q = w_q det J(X, r_q)`:
//! - `U_e = Σ_q V_q ψ(F_q)`, `F_q = Σ_i x_i ⊗ ∇_X N_i(r_q)`;
//! - `∂U_e/∂x_i = Σ_q V_q P(F_q) ∇_X N_i(r_q)`;
//! - `∂²U_e/∂x_{ia}∂x_{jb} = Σ_q V_q Σ_{c,d} ∂P_{ac}/∂F_{bd} (∇_X N_i)_c (∇_X N_j)_d`;
//! - one node's share ([`element_node_gradient_and_block`], what a vertex block descent step of
//!   Chen et al., "Vertex Block Descent", SIGGRAPH 2024, needs): `∂U_e/∂x_a` and the 3 × 3
//!   diagonal block `∂²U_e/∂x_a∂x_a`, without the rest of the element Hessian.
//!
//! For the linear tetrahedron this is Bender et al.'s `V_0 P(F) D_m⁻ᵀ` (the paper, §2).
//!
//! The mesh passes ([`total_energy`], [`total_energy_and_gradient`]: what Newton, the static
//! solver and the residuals evaluate) run the kernel of `fixed.rs`, whose node count is a
//! compile-time constant for every element type of the project (the per-point sum XPBD's
//! specialised sweep shares); the generic per-element functions here are its tested reference
//! ([`total_energy_generic`], [`total_energy_and_gradient_generic`]) and serve any other node
//! count.

use crate::Vec3;
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::material::{Material, NodeVisit, VolumeMeasure, contract, contract_left, contract_right};
use crate::mesh::Mesh;
use nalgebra::DMatrix;

mod chunks;
mod fixed;
pub mod mixed;
pub use fixed::point_energy_and_gradient;

/// `Σ_q V_q (P(F_q) g_q, B(F_q, g_q))` over one node's visit of an element (vertex block descent):
/// the material's [`Material::node_visit`], or the mixed formulation's when its hydrostatic term
/// is measured over the element ([`mixed::node_visit`]).
#[inline]
pub fn node_visit(
    material: &Material,
    l: crate::material::Lame,
    visit: NodeVisit<'_>,
) -> (Vec3, nalgebra::Matrix3<f64>) {
    match material.volume_measure {
        VolumeMeasure::Point => material.node_visit(l, visit),
        VolumeMeasure::Element => mixed::node_visit(material, visit),
    }
}

/// `Σ_q V_q ψ(F_q)` of the element a visit's points are (or the mixed formulation's energy).
pub fn visit_energy(material: &Material, l: crate::material::Lame, visit: NodeVisit<'_>) -> f64 {
    if material.volume_measure != VolumeMeasure::Point {
        return mixed::visit_energy(material, visit);
    }
    let law = material.model.law();
    let mut e = 0.0;
    for (p, &v) in visit.volumes.iter().enumerate() {
        if v != 0.0 {
            let (f, _, _) = visit.point(p / visit.width, p % visit.width);
            e += v * law.energy_density(l, &f);
        }
    }
    e
}

/// `U_e` for gathered positions `x` (one per element node); `grads` holds the material
/// gradients of all quadrature points (`points × nodes`), `volumes` one entry per point.
pub fn element_energy(x: &[Vec3], rest: &[Vec3], grads: &[Vec3], volumes: &[f64], material: &Material) -> f64 {
    if material.volume_measure != VolumeMeasure::Point {
        return mixed::element_energy(x, rest, grads, volumes, material);
    }
    let n = x.len();
    volumes
        .iter()
        .enumerate()
        .map(|(q, v)| v * material.energy_density(&deformation_gradient(x, rest, &grads[q * n..(q + 1) * n])))
        .sum()
}

/// `U_e` and `∂U_e/∂x_i` (written to `grad_out`, one per node).
pub fn element_energy_and_gradient(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    grad_out: &mut [Vec3],
) -> f64 {
    if material.volume_measure != VolumeMeasure::Point {
        return mixed::element_energy_and_gradient(x, rest, grads, volumes, material, grad_out);
    }
    let n = x.len();
    grad_out.iter_mut().for_each(|g| *g = Vec3::zeros());
    let mut energy = 0.0;
    for (q, v) in volumes.iter().enumerate() {
        let g = &grads[q * n..(q + 1) * n];
        let (psi, p) = material.energy_density_and_pk1(&deformation_gradient(x, rest, g));
        energy += v * psi;
        let vp = p * *v;
        for (out, gi) in grad_out.iter_mut().zip(g) {
            *out += vp * gi;
        }
    }
    energy
}

/// The element Hessian `∂²U_e/∂x∂x` (3n × 3n, node-major: row `3 i + a`). With `projected`,
/// `dP/dF` is projected to positive semi-definite at each quadrature point, which makes the
/// element Hessian positive semi-definite (for Newton's method far from equilibrium).
pub fn element_hessian(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    projected: bool,
) -> DMatrix<f64> {
    if material.volume_measure != VolumeMeasure::Point {
        return mixed::element_hessian(x, rest, grads, volumes, material, projected);
    }
    let n = x.len();
    let mut h = PointBlocks::new(n);
    for (q, v) in volumes.iter().enumerate() {
        let g = &grads[q * n..(q + 1) * n];
        let f = deformation_gradient(x, rest, g);
        let c = if projected { material.dpdf_projected(&f) } else { material.dpdf(&f) };
        h.add(&c, g, *v);
    }
    h.finish()
}

/// An element Hessian summed point by point, `Σ_q V_q C_q(∇_X N_i, ∇_X N_j)` for a symmetric
/// tangent `C_q` (9×9) at each point: the one assembly [`element_hessian`] and the mixed
/// formulation's share.
pub(crate) struct PointBlocks {
    h: DMatrix<f64>,
    right: Vec<[f64; 27]>,
}

impl PointBlocks {
    pub(crate) fn new(nodes: usize) -> Self {
        Self { h: DMatrix::zeros(3 * nodes, 3 * nodes), right: vec![[0.0; 27]; nodes] }
    }

    /// Adds `V C(∇N_i, ∇N_j)` of one point (`g` its material gradients) to the upper blocks.
    pub(crate) fn add(&mut self, c: &crate::material::Mat9, g: &[Vec3], v: f64) {
        let m = self.h.nrows();
        let out = self.h.as_mut_slice();
        // the contraction in two stages (`contract_right` once per node, then 27 products per
        // pair) over the pairs `i ≥ j` only: `C` is symmetric (a Hessian), so block `(j, i)` is
        // block `(i, j)` transposed: the lower triangle is mirrored at the end (the diagonal
        // blocks' too, so that the result is exactly symmetric)
        for (t, gj) in self.right.iter_mut().zip(g) {
            *t = contract_right(c, &(gj * v));
        }
        for (j, t) in self.right.iter().enumerate() {
            for (i, gi) in g.iter().enumerate().skip(j) {
                let block = contract_left(t, gi);
                for b in 0..3 {
                    let column = &mut out[(3 * j + b) * m + 3 * i..(3 * j + b) * m + 3 * i + 3];
                    for (a, o) in column.iter_mut().enumerate() {
                        *o += block[(a, b)];
                    }
                }
            }
        }
    }

    /// The upper blocks mirrored: the exactly symmetric Hessian (3n × 3n, node-major).
    pub(crate) fn finish(mut self) -> DMatrix<f64> {
        let m = self.h.nrows();
        let out = self.h.as_mut_slice();
        for col in 0..m {
            for row in col + 1..m {
                out[row * m + col] = out[col * m + row];
            }
        }
        self.h
    }
}

/// One node's share of an element: `∂U_e/∂x_a = Σ_q V_q P(F_q) ∇_X N_a(r_q)` and the diagonal
/// block `B_ab = Σ_q V_q Σ_{c,d} ∂P_{ac}/∂F_{bd} (∇_X N_a)_c (∇_X N_a)_d` of the element Hessian
/// for local node `a` (with `projected`, `dP/dF` projected to positive semi-definite at each point
/// as in [`element_hessian`], which makes the block positive semi-definite).
pub fn element_node_gradient_and_block(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    a: usize,
    projected: bool,
) -> (Vec3, nalgebra::Matrix3<f64>) {
    if material.volume_measure != VolumeMeasure::Point {
        return mixed::element_node_gradient_and_block(x, rest, grads, volumes, material, a, projected);
    }
    let n = x.len();
    let mut grad = Vec3::zeros();
    let mut block = nalgebra::Matrix3::zeros();
    for (q, v) in volumes.iter().enumerate() {
        let g = &grads[q * n..(q + 1) * n];
        let f = deformation_gradient(x, rest, g);
        let (_, p) = material.energy_density_and_pk1(&f);
        grad += (p * g[a]) * *v;
        let ga = g[a];
        if !projected {
            block += material.node_block(&f, &ga) * *v;
            continue;
        }
        let b = contract(&material.dpdf_projected(&f), &ga, &ga);
        for r in 0..3 {
            for k in 0..3 {
                block[(r, k)] += v * b[(r, k)];
            }
        }
    }
    (grad, block)
}

/// Gathers the positions of an element's nodes into `out`.
#[inline]
pub fn gather(positions: &[Vec3], nodes: &[u32], out: &mut [Vec3]) {
    for (o, &n) in out.iter_mut().zip(nodes) {
        *o = positions[n as usize];
    }
}

/// One element with its node positions gathered, as [`for_each_element`] visits it.
pub struct GatheredElement<'a> {
    pub block: usize,
    pub element: usize,
    pub nodes: &'a [u32],
    pub geometry: &'a BlockGeometry,
    /// Deformed positions of the element's nodes.
    pub x: &'a [Vec3],
    /// Rest positions of the element's nodes.
    pub rest: &'a [Vec3],
}

impl GatheredElement<'_> {
    /// The material gradients of all its quadrature points (`points × nodes`).
    pub fn grads(&self) -> &[Vec3] {
        element_grads(self.geometry, self.element)
    }
    /// Its quadrature volumes `V_q`.
    pub fn volumes(&self) -> &[f64] {
        self.geometry.volumes(self.element)
    }
}

/// Visits every element (block by block, in element order) with its deformed (`positions`) and
/// rest node positions gathered into reused buffers.
pub fn for_each_element(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    positions: &[Vec3],
    mut visit: impl FnMut(&GatheredElement),
) {
    for (block, g) in geometry.iter().enumerate().take(mesh.blocks.len()) {
        for_each_block_element(mesh, block, g, positions, &mut visit);
    }
}

/// [`for_each_element`] over block `block` only (`geometry` its geometry).
fn for_each_block_element(
    mesh: &Mesh,
    block: usize,
    geometry: &BlockGeometry,
    positions: &[Vec3],
    mut visit: impl FnMut(&GatheredElement),
) {
    let b = &mesh.blocks[block];
    let (mut x, mut rest) = (vec![Vec3::zeros(); b.nodes_per_element()], vec![Vec3::zeros(); b.nodes_per_element()]);
    for (element, nodes) in b.elements().enumerate() {
        gather(positions, nodes, &mut x);
        gather(&mesh.rest_positions, nodes, &mut rest);
        visit(&GatheredElement { block, element, nodes, geometry, x: &x, rest: &rest });
    }
}

/// Total elastic energy of the mesh at `positions`: block by block through the kernel of
/// [`fixed`] for its node count (every element type of the project), else the generic one.
pub fn total_energy(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material, positions: &[Vec3]) -> f64 {
    mesh_pass(mesh, geometry, material, positions, None, true)
}

/// Total elastic energy and its gradient (`gradient_out` is overwritten), as [`total_energy`].
pub fn total_energy_and_gradient(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    positions: &[Vec3],
    gradient_out: &mut [Vec3],
) -> f64 {
    mesh_pass(mesh, geometry, material, positions, Some(gradient_out), true)
}

/// The generic kernels' mesh passes, element by element ([`element_energy`],
/// [`element_energy_and_gradient`]): what [`total_energy`] and [`total_energy_and_gradient`]
/// compute up to round-off, kept as the reference the specialised kernel is tested against.
pub fn total_energy_generic(mesh: &Mesh, geometry: &[BlockGeometry], material: &Material, positions: &[Vec3]) -> f64 {
    mesh_pass(mesh, geometry, material, positions, None, false)
}

/// See [`total_energy_generic`].
pub fn total_energy_and_gradient_generic(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    positions: &[Vec3],
    gradient_out: &mut [Vec3],
) -> f64 {
    mesh_pass(mesh, geometry, material, positions, Some(gradient_out), false)
}

/// The one mesh pass behind the four above: `Σ_e U_e` block by block, with the gradient into
/// `gradient_out` (overwritten) when given; each block through [`fixed`]'s kernel when
/// `specialised` and its node count has one, else element by element with the generic kernel.
fn mesh_pass(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    positions: &[Vec3],
    mut gradient_out: Option<&mut [Vec3]>,
    specialised: bool,
) -> f64 {
    if let Some(g) = gradient_out.as_deref_mut() {
        g.iter_mut().for_each(|v| *v = Vec3::zeros());
    }
    // the specialised kernels are the point law's: the mixed element takes the generic ones
    let specialised = specialised && material.volume_measure == VolumeMeasure::Point;
    // linear tetrahedra in the mixed formulation: measured per node patch, all blocks at once
    let mut total = if mixed::patch::has_patches(mesh, material) {
        mixed::patch::energy_and_gradient(mesh, geometry, material, positions, gradient_out.as_deref_mut())
    } else {
        0.0
    };
    for (bi, (block, g)) in mesh.blocks.iter().zip(geometry).enumerate() {
        if mixed::patch::is_patch_block(block, material) {
            continue;
        }
        let pass =
            fixed::Pass { block, geometry: g, rest: &mesh.rest_positions, x: positions, elements: 0..block.len() };
        let ranges = chunks::ranges_for(block.len());
        total += match gradient_out.as_deref_mut() {
            // a large block on every thread, in ranges fixed by its size (`chunks.rs`)
            Some(grad) if specialised && ranges > 1 && fixed::has_kernel(block.nodes_per_element()) => {
                chunks::energy_and_gradient_in_ranges(pass, ranges, grad, &|p, buf| {
                    fixed::block_energy_and_gradient::<true>(p, material, buf).unwrap_or_default()
                })
            }
            Some(grad) => specialised
                .then(|| fixed::block_energy_and_gradient::<true>(pass, material, grad))
                .flatten()
                .unwrap_or_else(|| generic_block_energy_and_gradient(mesh, bi, g, material, positions, grad)),
            None => specialised
                .then(|| fixed::block_energy_and_gradient::<false>(pass, material, &mut []))
                .flatten()
                .unwrap_or_else(|| generic_block_energy(mesh, bi, g, material, positions)),
        };
    }
    total
}

/// [`total_energy`] element by element with [`element_energy`] (the generic kernel: any node
/// count, nalgebra's sums), one block.
fn generic_block_energy(
    mesh: &Mesh,
    block: usize,
    geometry: &BlockGeometry,
    material: &Material,
    positions: &[Vec3],
) -> f64 {
    let mut total = 0.0;
    for_each_block_element(mesh, block, geometry, positions, |el| {
        total += element_energy(el.x, el.rest, el.grads(), el.volumes(), material);
    });
    total
}

/// [`total_energy_and_gradient`] with [`element_energy_and_gradient`], one block (the gradient
/// added to `gradient_out`).
fn generic_block_energy_and_gradient(
    mesh: &Mesh,
    block: usize,
    geometry: &BlockGeometry,
    material: &Material,
    positions: &[Vec3],
    gradient_out: &mut [Vec3],
) -> f64 {
    let mut ge = Vec::new();
    let mut total = 0.0;
    for_each_block_element(mesh, block, geometry, positions, |el| {
        ge.resize(el.nodes.len(), Vec3::zeros());
        total += element_energy_and_gradient(el.x, el.rest, el.grads(), el.volumes(), material, &mut ge);
        for (&n, gi) in el.nodes.iter().zip(&ge) {
            gradient_out[n as usize] += gi;
        }
    });
    total
}

/// All quadrature points' material gradients of element `e` (`points × nodes`).
#[inline]
pub fn element_grads(g: &BlockGeometry, e: usize) -> &[Vec3] {
    let len = g.points_per_element * g.nodes_per_element;
    &g.grad_in_material[e * len..(e + 1) * len]
}

#[cfg(test)]
pub(crate) mod tests;
