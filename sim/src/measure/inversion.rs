//! Whether any element is inverted: the smallest `det F` over every quadrature point of a mesh
//! (`det F ≤ 0` somewhere means an element turned inside out there), with where it occurs. `F` is
//! the finite-element model's own ([`crate::fem::geometry::deformation_gradient`]), so it is
//! exactly 1 at rest.

use crate::Vec3;
use crate::fem::energy::for_each_element;
use crate::fem::geometry::{BlockGeometry, deformation_gradient};
use crate::mesh::Mesh;

/// Where `det F` is smallest over every quadrature point of a mesh: the robustness checks'
/// "is any element inverted?" (`det F ≤ 0` somewhere) measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinDetF {
    /// The smallest `det F_q` found.
    pub det_f: f64,
    pub block: usize,
    pub element: usize,
    pub point: usize,
}

/// The smallest `det F_q = det(Σ_i x_i ⊗ ∇_X N_i(r_q))` over all elements and quadrature points
/// at `positions` (None for a mesh without elements), `F_q` from displacements
/// ([`deformation_gradient`], exactly 1 at rest). **NaN rule:** a non-finite `det F` (NaN or
/// ±∞ positions) counts as the smallest, −∞, and the first such point is the one reported, so
/// NaN positions are never reported as healthy. Ties keep the first point (block, element,
/// point order).
pub fn min_det_f(mesh: &Mesh, geometry: &[BlockGeometry], positions: &[Vec3]) -> Option<MinDetF> {
    let mut best: Option<MinDetF> = None;
    for_each_element(mesh, geometry, positions, |el| {
        for q in 0..el.geometry.points_per_element {
            let det = deformation_gradient(el.x, el.rest, el.geometry.gradients(el.element, q)).determinant();
            let det = if det.is_finite() { det } else { f64::NEG_INFINITY };
            if best.is_none_or(|m| det < m.det_f) {
                best = Some(MinDetF { det_f: det, block: el.block, element: el.element, point: q });
            }
        }
    });
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::fem::geometry::precompute;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    fn box_mesh(element_type: ElementType) -> Mesh {
        BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 1.0, 0.5), cells: [2, 1, 1] },
            element_type,
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap()
    }

    #[test]
    fn one_at_rest_and_negative_where_a_mirrored_node_inverts_an_element() {
        for e in ElementType::all() {
            let mesh = box_mesh(e);
            let geometry = precompute(&mesh, None).unwrap();
            let det = min_det_f(&mesh, &geometry, &mesh.rest_positions).unwrap().det_f;
            assert!((det - 1.0).abs() < 1e-12, "{}: {det}", e.name());
            // mirror one node through the body: some element inverts
            let mut inverted = mesh.rest_positions.clone();
            let n = mesh.blocks[0].element(0)[0] as usize;
            inverted[n].z = 2.0;
            let MinDetF { det_f: det, block: b, element: el, .. } = min_det_f(&mesh, &geometry, &inverted).unwrap();
            assert!(det < 0.0, "{}: {det}", e.name());
            assert!(mesh.blocks[b].element(el).contains(&(n as u32)));
        }
    }

    #[test]
    fn a_non_finite_position_counts_as_minus_infinity_at_its_first_point() {
        let mesh = box_mesh(ElementType::from_name("p1").unwrap());
        let geometry = precompute(&mesh, None).unwrap();
        let mut x = mesh.rest_positions.clone();
        let n = mesh.blocks[0].element(3)[1] as usize;
        x[n].y = f64::NAN;
        let m = min_det_f(&mesh, &geometry, &x).unwrap();
        assert_eq!(m.det_f, f64::NEG_INFINITY);
        let first = mesh.blocks[0].elements().position(|el| el.contains(&(n as u32))).unwrap();
        assert_eq!((m.block, m.element, m.point), (0, first, 0));
    }
}
