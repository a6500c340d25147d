//! Triquadratic hexahedron Q2 (27 nodes, Gmsh type 12) on [-1,1]³ — beyond the paper.
//!
//! Nodes: 8 corners; 12 edge midpoints in Gmsh's edge order (0,1), (0,3), (0,4), (1,2), (1,5),
//! (2,3), (2,6), (3,7), (4,5), (4,7), (5,6), (6,7); 6 face centres in Gmsh's face order
//! z = −1, y = −1, x = −1, x = +1, y = +1, z = +1; the cell centre. The basis is the tensor
//! product of 1D quadratic Lagrange polynomials, built here by the Lagrange construction on Q2.
//! Default quadrature: 3×3×3 Gauss–Legendre (degree 5 in each variable).
//!
//! VTK: `VTK_TRIQUADRATIC_HEXAHEDRON` (29); VTK lists the edges of the bottom face, of the top
//! face, then the vertical ones, and the faces x = −1, x = +1, y = −1, y = +1, z = −1, z = +1.

use super::ReferenceShape;
use super::lagrange::{LagrangeElement, tensor_exponents};

pub static Q2: LagrangeElement = LagrangeElement {
    name: "q2",
    description: "triquadratic hexahedron (27 nodes)",
    shape: ReferenceShape::Hexahedron,
    order: 2,
    nodes: &[
        [-1., -1., -1.],
        [1., -1., -1.],
        [1., 1., -1.],
        [-1., 1., -1.],
        [-1., -1., 1.],
        [1., -1., 1.],
        [1., 1., 1.],
        [-1., 1., 1.],
        // edges
        [0., -1., -1.],
        [-1., 0., -1.],
        [-1., -1., 0.],
        [1., 0., -1.],
        [1., -1., 0.],
        [0., 1., -1.],
        [1., 1., 0.],
        [-1., 1., 0.],
        [0., -1., 1.],
        [-1., 0., 1.],
        [1., 0., 1.],
        [0., 1., 1.],
        // faces
        [0., 0., -1.],
        [0., -1., 0.],
        [-1., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        // centre
        [0., 0., 0.],
    ],
    exponents: || tensor_exponents(2),
    default_quadrature_degree: 5,
    mass_quadrature_degree: 5,
    gmsh_type: 12,
    vtk_cell_type: 29,
    vtk_node_order: &[0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25, 26],
    basis: std::sync::OnceLock::new(),
    faces: std::sync::OnceLock::new(),
};
