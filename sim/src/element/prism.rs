//! Linear prism (wedge, 6 nodes, Gmsh type 6): triangle (0,0), (1,0), (0,1) × z ∈ [-1,1].
//!
//! `N = ½(1 − x − y)(1 ∓ z), ½ x (1 ∓ z), ½ y (1 ∓ z)`, minus sign for the bottom triangle
//! (nodes 0–2), plus for the top (nodes 3–5): the Lagrange basis of P1(triangle) ⊗ P1(segment),
//! i.e. the monomials 1, x, y, z, xz, yz. (The paper lists only five of the six functions.)
//! Default quadrature degree 2 (Witherden–Vincent, 5 points).
//!
//! VTK: `VTK_WEDGE` (13), nodes in Gmsh's order (see `io::vtk`).

use super::ReferenceShape;
use super::lagrange::{Exponents, LagrangeElement};

fn exponents() -> Vec<Exponents> {
    vec![[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]]
}

pub static PRISM: LagrangeElement = LagrangeElement {
    name: "prism",
    description: "linear prism (6 nodes)",
    shape: ReferenceShape::Prism,
    order: 1,
    nodes: ReferenceShape::Prism.vertices(),
    exponents,
    default_quadrature_degree: 2,
    mass_quadrature_degree: 4,
    gmsh_type: 6,
    vtk_cell_type: 13,
    vtk_node_order: &[0, 1, 2, 3, 4, 5],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
