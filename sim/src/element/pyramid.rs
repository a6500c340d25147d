//! Linear pyramid (5 nodes, Gmsh type 7): base [-1,1]² at z = 0, apex (0,0,1).
//!
//! With `s = 1 − z`, the base functions are rational (no polynomial basis on 5 nodes is
//! conforming with both neighbouring tetrahedra and hexahedra):
//! `N_0 = (s − x)(s − y)/(4s)`, `N_1 = (s + x)(s − y)/(4s)`, `N_2 = (s + x)(s + y)/(4s)`,
//! `N_3 = (s − x)(s + y)/(4s)`, `N_4 = z`.
//! They reproduce 1, x, y, z and are linear on every face. Their derivatives are
//! `∂N/∂x = ±(s ± y)/(4s)`, `∂N/∂y = ±(s ± x)/(4s)`, `∂N/∂z = −¼ + σ_x σ_y x y/(4s²)`, finite
//! everywhere but at the apex (z = 1), where they depend on the direction of approach: no
//! quadrature rule used by hox samples the apex, and evaluation exactly there uses the limit
//! along the axis. (The paper's pyramid is the same element with its base rotated by 45°.)
//! Default quadrature degree 2 (Witherden–Vincent, 5 interior points).
//!
//! VTK: `VTK_PYRAMID` (14), nodes in Gmsh's order (see `io::vtk`).

use super::{Face, ReferenceElement, ReferenceShape};
use std::sync::OnceLock;

pub struct Pyramid {
    faces: OnceLock<Vec<Face>>,
}

pub static PYRAMID: Pyramid = Pyramid { faces: OnceLock::new() };

/// Signs (σ_x, σ_y) of the base vertices.
const SIGNS: [[f64; 2]; 4] = [[-1., -1.], [1., -1.], [1., 1.], [-1., 1.]];

/// `1 − z`, kept away from zero at the apex (where x = y = 0 inside the element).
fn base_scale(z: f64) -> f64 {
    (1.0 - z).max(1e-12)
}

impl ReferenceElement for Pyramid {
    fn name(&self) -> &'static str {
        "pyramid"
    }
    fn description(&self) -> &'static str {
        "linear pyramid (5 nodes)"
    }
    fn shape(&self) -> ReferenceShape {
        ReferenceShape::Pyramid
    }
    fn order(&self) -> usize {
        1
    }
    fn nodes(&self) -> &[[f64; 3]] {
        ReferenceShape::Pyramid.vertices()
    }
    fn shape_functions(&self, r: &[f64; 3], out: &mut [f64]) {
        let [x, y, z] = *r;
        let s = base_scale(z);
        for (o, [sx, sy]) in out.iter_mut().zip(SIGNS) {
            *o = (s + sx * x) * (s + sy * y) / (4.0 * s);
        }
        out[4] = z;
    }
    fn shape_gradients(&self, r: &[f64; 3], out: &mut [[f64; 3]]) {
        let [x, y, z] = *r;
        let s = base_scale(z);
        for (o, [sx, sy]) in out.iter_mut().zip(SIGNS) {
            *o =
                [sx * (s + sy * y) / (4.0 * s), sy * (s + sx * x) / (4.0 * s), -0.25 + sx * sy * x * y / (4.0 * s * s)];
        }
        out[4] = [0.0, 0.0, 1.0];
    }
    fn faces(&self) -> &[Face] {
        self.faces.get_or_init(|| super::build_faces(ReferenceShape::Pyramid, 1, self.nodes()))
    }
    fn default_quadrature_degree(&self) -> usize {
        2
    }
    fn mass_quadrature_degree(&self) -> usize {
        4
    }
    fn gmsh_type(&self) -> u32 {
        7
    }
    fn vtk_cell_type(&self) -> u8 {
        14
    }
    fn vtk_node_order(&self) -> &'static [usize] {
        &[0, 1, 2, 3, 4]
    }
}
