//! Quadratic tetrahedron P2 (10 nodes, Gmsh type 11).
//!
//! Nodes: the 4 vertices, then one node at the midpoint of each edge in Gmsh's edge order
//! (0,1), (1,2), (2,0), (3,0), (3,2), (3,1). Note that Gmsh puts edge (3,2) before (3,1): the
//! paper's listing (`N_8 = 4 x z`, `N_9 = 4 y z`) uses VTK's order instead. The shape functions
//! are the Lagrange basis of P2 on these nodes (vertex: `L(2L − 1)`, edge: `4 L_a L_b` in
//! barycentric coordinates).
//!
//! Default quadrature degree 2 (4 points, Witherden–Vincent): exact for the stiffness integrand
//! `∇N_i · ∇N_j` of straight-sided elements, the usual full integration for quadratic tetrahedra.
//!
//! VTK: `VTK_QUADRATIC_TETRA` (24); its last two edge nodes are those of edges (1,3) and (2,3),
//! Gmsh's (3,2) and (3,1) swapped.

use super::ReferenceShape;
use super::lagrange::{LagrangeElement, total_degree_exponents};

pub static P2: LagrangeElement = LagrangeElement {
    name: "p2",
    description: "quadratic tetrahedron (10 nodes)",
    shape: ReferenceShape::Tetrahedron,
    order: 2,
    nodes: &[
        [0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [0.5, 0., 0.],
        [0.5, 0.5, 0.],
        [0., 0.5, 0.],
        [0., 0., 0.5],
        [0., 0.5, 0.5],
        [0.5, 0., 0.5],
    ],
    exponents: || total_degree_exponents(2),
    default_quadrature_degree: 2,
    mass_quadrature_degree: 4,
    gmsh_type: 11,
    vtk_cell_type: 24,
    vtk_node_order: &[0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
