//! Linear tetrahedron P1 (4 nodes, Gmsh type 4).
//!
//! `N_0 = 1 − x − y − z`, `N_1 = x`, `N_2 = y`, `N_3 = z` (the paper's P1; its supplementary
//! material misnumbers N_2/N_3). The gradients are constant, so one quadrature point integrates
//! the energy exactly: the default degree is 1 (one point at the centroid), as in the paper,
//! where `w_0 det J = V_0` recovers Bender's `V_0 P(F) D_m^{-T}`.
//!
//! VTK: `VTK_TETRA` (10), nodes in Gmsh's order.

use super::ReferenceShape;
use super::lagrange::{LagrangeElement, total_degree_exponents};

pub static P1: LagrangeElement = LagrangeElement {
    name: "p1",
    description: "linear tetrahedron (4 nodes)",
    shape: ReferenceShape::Tetrahedron,
    order: 1,
    nodes: ReferenceShape::Tetrahedron.vertices(),
    exponents: || total_degree_exponents(1),
    default_quadrature_degree: 1,
    mass_quadrature_degree: 2,
    gmsh_type: 4,
    vtk_cell_type: 10,
    vtk_node_order: &[0, 1, 2, 3],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
