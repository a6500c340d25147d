//! Trilinear hexahedron Q1 (8 nodes, Gmsh type 5) on [-1,1]³.
//!
//! `N_i = ⅛ (1 + x x_i)(1 + y y_i)(1 + z z_i)` with `(x_i, y_i, z_i)` the corner coordinates,
//! which is the Lagrange basis of Q1 on the corners. Default quadrature: 2×2×2 Gauss–Legendre
//! (degree 3 in each variable), exact for the stiffness of parallelepiped elements.
//!
//! VTK: `VTK_HEXAHEDRON` (12), nodes in Gmsh's order.

use super::ReferenceShape;
use super::lagrange::{LagrangeElement, tensor_exponents};

pub static Q1: LagrangeElement = LagrangeElement {
    name: "q1",
    description: "trilinear hexahedron (8 nodes)",
    shape: ReferenceShape::Hexahedron,
    order: 1,
    nodes: ReferenceShape::Hexahedron.vertices(),
    exponents: || tensor_exponents(1),
    default_quadrature_degree: 3,
    mass_quadrature_degree: 3,
    gmsh_type: 5,
    vtk_cell_type: 12,
    vtk_node_order: &[0, 1, 2, 3, 4, 5, 6, 7],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
