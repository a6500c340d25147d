//! Precomputed element geometry: per element and quadrature point, the material-space shape
//! function gradients and the quadrature volume.
//!
//! For element `e` with rest node positions `X_i` and quadrature point `r_q` (weight `w_q`):
//! - rest Jacobian `J(X, r_q) = Σ_i X_i ⊗ ∂N_i/∂r(r_q)`;
//! - material gradients `∇_X N_i = J(X, r_q)⁻ᵀ ∂N_i/∂r(r_q)`, so that the deformation gradient is
//!   `F_q = Σ_i x_i ⊗ ∇_X N_i = J(x, r_q) J(X, r_q)⁻¹`;
//! - quadrature volume `V_q = w_q det J(X, r_q)`; `Σ_q V_q` is the element's rest volume.
//!
//! A rest element with `det J ≤ 0` (inverted or flat) at a quadrature point is an error naming
//! the element and the point — never a silent NaN later.

use crate::Vec3;
use crate::element::ElementType;
use crate::fem::quadrature::{self, QuadratureError, QuadratureRule};
use crate::mesh::{ElementBlock, Mesh};
use nalgebra::Matrix3;

/// Precomputed data of one element block.
#[derive(Clone, Debug)]
pub struct BlockGeometry {
    pub element_type: ElementType,
    pub quadrature: QuadratureRule,
    pub nodes_per_element: usize,
    pub points_per_element: usize,
    /// `grad_in_material[(e * points_per_element + q) * nodes_per_element + i] = ∇_X N_i(r_q)`.
    pub grad_in_material: Vec<Vec3>,
    /// `volume_m3[e * points_per_element + q] = w_q det J(X, r_q)`.
    pub volume_m3: Vec<f64>,
}

impl BlockGeometry {
    /// Material gradients of element `e` at its quadrature point `q` (one per node).
    #[inline]
    pub fn gradients(&self, e: usize, q: usize) -> &[Vec3] {
        let start = (e * self.points_per_element + q) * self.nodes_per_element;
        &self.grad_in_material[start..start + self.nodes_per_element]
    }
    /// Quadrature volumes of element `e`.
    #[inline]
    pub fn volumes(&self, e: usize) -> &[f64] {
        &self.volume_m3[e * self.points_per_element..(e + 1) * self.points_per_element]
    }
    pub fn element_volume_m3(&self, e: usize) -> f64 {
        self.volumes(e).iter().sum()
    }
    pub fn num_elements(&self) -> usize {
        self.volume_m3.len() / self.points_per_element
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    #[error(
        "element {element} ({element_type}) is {what} at rest: det J = {det_j:.3e} at quadrature point {point} (reference coordinates {reference:?}); its nodes are {nodes:?}"
    )]
    BadElement {
        element_type: String,
        element: usize,
        point: usize,
        reference: [f64; 3],
        det_j: f64,
        what: &'static str,
        nodes: Vec<u32>,
    },
    #[error(transparent)]
    Quadrature(#[from] QuadratureError),
}

/// The element Jacobian `J(x, r) = Σ_i x_i ⊗ ∂N_i/∂r(r)` of the nodes `nodes` of `positions`
/// (`grad_ref[i] = ∂N_i/∂r` at the point `r`): at rest positions the map whose inverse gives the
/// material gradients and whose determinant the volumes; the probes' Newton iterations use it
/// too ([`crate::measure::probe`]). The one place it is computed.
#[inline]
pub fn jacobian(positions: &[Vec3], nodes: &[u32], grad_ref: &[[f64; 3]]) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    for (&n, g) in nodes.iter().zip(grad_ref) {
        j += positions[n as usize] * Vec3::from(*g).transpose();
    }
    j
}

/// Relative size under which `det J` counts as flat (relative to the element's edge scale cubed).
const FLAT_TOLERANCE: f64 = 1e-12;

/// Precomputes one block's geometry with the quadrature rule of `degree` (the element's default
/// when None).
pub fn precompute_block(
    positions: &[Vec3],
    block: &ElementBlock,
    degree: Option<usize>,
) -> Result<BlockGeometry, GeometryError> {
    let et = block.element_type;
    let rule = quadrature::rule(et.shape(), degree.unwrap_or(et.default_quadrature_degree()))?;
    let (nn, nq) = (et.num_nodes(), rule.len());
    let grads_ref: Vec<Vec<[f64; 3]>> = rule
        .points
        .iter()
        .map(|r| {
            let mut g = vec![[0.0; 3]; nn];
            et.shape_gradients(r, &mut g);
            g
        })
        .collect();
    let mut grad_in_material = Vec::with_capacity(block.len() * nq * nn);
    let mut volume_m3 = Vec::with_capacity(block.len() * nq);
    for (e, nodes) in block.elements().enumerate() {
        let scale = element_scale(positions, nodes);
        for (q, gr) in grads_ref.iter().enumerate() {
            let j = jacobian(positions, nodes, gr);
            let det_j = j.determinant();
            if !(det_j > FLAT_TOLERANCE * scale.powi(3) * et.shape().volume().recip()) {
                return Err(GeometryError::BadElement {
                    element_type: et.to_string(),
                    element: e,
                    point: q,
                    reference: rule.points[q],
                    det_j,
                    what: if det_j < 0.0 { "inverted" } else { "flat" },
                    nodes: nodes.to_vec(),
                });
            }
            let j_inv_t = j.try_inverse().expect("det J > 0").transpose();
            grad_in_material.extend(gr.iter().map(|g| j_inv_t * Vec3::from(*g)));
            volume_m3.push(rule.weights[q] * det_j);
        }
    }
    Ok(BlockGeometry {
        element_type: et,
        quadrature: rule,
        nodes_per_element: nn,
        points_per_element: nq,
        grad_in_material,
        volume_m3,
    })
}

/// Precomputes every block of `mesh`. `degree` overrides each element type's default.
pub fn precompute(mesh: &Mesh, degree: Option<usize>) -> Result<Vec<BlockGeometry>, GeometryError> {
    mesh.blocks.iter().map(|b| precompute_block(&mesh.rest_positions, b, degree)).collect()
}

/// Largest distance from the element's first node: its length scale.
fn element_scale(positions: &[Vec3], nodes: &[u32]) -> f64 {
    let p0 = positions[nodes[0] as usize];
    nodes.iter().map(|&n| (positions[n as usize] - p0).norm()).fold(0.0, f64::max)
}

/// The deformation gradient of one element at one point, `F = Σ_i x_i ⊗ ∇_X N_i`, from its
/// gathered positions `x`, rest positions `rest` and material gradients `grads` (one each per
/// node), evaluated as `I + Σ_i (x_i − X_i) ⊗ ∇_X N_i` (equal, since `Σ_i X_i ⊗ ∇_X N_i = I`):
/// computing from displacements avoids cancellation, so small strains keep their relative
/// accuracy and an element at rest has exactly `F = I` and zero energy. The one place `F` is
/// computed for gathered nodes ([`deformation_gradient_from`] the one sum).
#[inline]
pub fn deformation_gradient(x: &[Vec3], rest: &[Vec3], grads: &[Vec3]) -> Matrix3<f64> {
    deformation_gradient_from(x.iter().zip(rest).zip(grads).map(|((xi, ri), g)| (xi - ri, g)))
}

/// `F = I + Σ_i u_i ⊗ ∇_X N_i` from each node's displacement `u_i = x_i − X_i` and material
/// gradient, in the order given: [`deformation_gradient`]'s sum for nodes reached through an
/// index (the display fields, `crate::measure::field`). The specialised sweeps, which hold
/// their nodes in registers or lanes, form it once each in their own layout
/// (`crate::xpbd::kernels`, VBD's `F_q` cache).
#[inline]
pub fn deformation_gradient_from<'g>(nodes: impl IntoIterator<Item = (Vec3, &'g Vec3)>) -> Matrix3<f64> {
    let mut f = Matrix3::identity();
    for (u, g) in nodes {
        f += u * g.transpose();
    }
    f
}

/// Total rest volume of the mesh.
pub fn total_volume_m3(geometry: &[BlockGeometry]) -> f64 {
    geometry.iter().flat_map(|g| g.volume_m3.iter()).sum()
}

#[cfg(test)]
pub(crate) mod tests;
