//! Cubic tetrahedron P3 (20 nodes, Gmsh type 29).
//!
//! Nodes: 4 vertices; two nodes per edge at 1/3 and 2/3 along each edge in Gmsh's edge order
//! (0,1), (1,2), (2,0), (3,0), (3,2), (3,1), the first of the two nearer the edge's first
//! vertex; then one node at the centroid of each face, faces in Gmsh's order (0,2,1), (0,1,3),
//! (0,3,2), (3,1,2). In barycentric coordinates the Lagrange basis is: vertex
//! `½ L(3L − 1)(3L − 2)`, edge `9/2 L_a L_b (3 L_a − 1)` (a the nearer vertex), face
//! `27 L_a L_b L_c`; the paper's listing has duplicated edge functions (ERRATA.md), so the
//! basis is built from the nodes instead.
//!
//! Default quadrature degree 4 (Witherden–Vincent has no 4-exact tetrahedron rule smaller than
//! its degree-5 rule, 14 points): exact for `∇N_i · ∇N_j` of straight-sided elements.
//!
//! VTK: `VTK_LAGRANGE_TETRAHEDRON` (71); VTK's last three edges are (0,3), (1,3), (2,3), each
//! run towards vertex 3, and its faces come in the order (0,1,3), (1,2,3), (0,2,3), (0,1,2).

use super::ReferenceShape;
use super::lagrange::{LagrangeElement, total_degree_exponents};

const T: f64 = 1.0 / 3.0;
const S: f64 = 2.0 / 3.0;

pub static P3: LagrangeElement = LagrangeElement {
    name: "p3",
    description: "cubic tetrahedron (20 nodes)",
    shape: ReferenceShape::Tetrahedron,
    order: 3,
    nodes: &[
        [0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        // edge 0→1
        [T, 0., 0.],
        [S, 0., 0.],
        // edge 1→2
        [S, T, 0.],
        [T, S, 0.],
        // edge 2→0
        [0., S, 0.],
        [0., T, 0.],
        // edge 3→0
        [0., 0., S],
        [0., 0., T],
        // edge 3→2
        [0., T, S],
        [0., S, T],
        // edge 3→1
        [T, 0., S],
        [S, 0., T],
        // faces (0,2,1), (0,1,3), (0,3,2), (3,1,2)
        [T, T, 0.],
        [T, 0., T],
        [0., T, T],
        [T, T, T],
    ],
    exponents: || total_degree_exponents(3),
    default_quadrature_degree: 4,
    mass_quadrature_degree: 6,
    gmsh_type: 29,
    vtk_cell_type: 71,
    vtk_node_order: &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 10, 15, 14, 13, 12, 17, 19, 18, 16],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
