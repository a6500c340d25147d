//! Lumped nodal masses by HRZ diagonal scaling (Hinton, Rock & Zienkiewicz 1976).
//!
//! Row-sum lumping `m_i = ρ ∫ N_i` fails for high-order elements: for the P2 tetrahedron the
//! vertex functions integrate to `−V/20`, a negative mass (P3 and Q2 have similar problems).
//! HRZ keeps the diagonal of the consistent mass matrix and rescales it to the element's mass:
//!
//! `m_i^e = ρ V_e · M_ii / Σ_j M_jj`, with `M_ii = ∫_e N_i² dV` and `V_e = ∫_e dV`.
//!
//! Every `M_ii` is positive (`N_i²` ≥ 0 and not identically zero), so every nodal mass is
//! positive, and the total is exactly `ρ V` for every element type. The integrals use the
//! element's mass quadrature degree (exact for `N_i N_j` on affine elements).

use crate::element::ElementType;
use crate::fem::geometry::{GeometryError, precompute_block};
use crate::mesh::Mesh;

/// Lumped mass of every node of `mesh` (kg) for density `density_kg_m3`.
pub fn lumped_masses_kg(mesh: &Mesh, density_kg_m3: f64) -> Result<Vec<f64>, GeometryError> {
    let mut masses = vec![0.0; mesh.num_nodes()];
    for block in &mesh.blocks {
        let et = block.element_type;
        let geo = precompute_block(&mesh.rest_positions, block, Some(et.mass_quadrature_degree()))?;
        let shape_sq = shape_values_squared(et, &geo.quadrature.points);
        let mut diag = vec![0.0; et.num_nodes()];
        for (e, nodes) in block.elements().enumerate() {
            diag.fill(0.0);
            let volumes = geo.volumes(e);
            for (q, v) in volumes.iter().enumerate() {
                for (d, n2) in diag.iter_mut().zip(&shape_sq[q]) {
                    *d += v * n2;
                }
            }
            let element_mass = density_kg_m3 * volumes.iter().sum::<f64>();
            let trace: f64 = diag.iter().sum();
            for (&n, d) in nodes.iter().zip(&diag) {
                masses[n as usize] += element_mass * d / trace;
            }
        }
    }
    Ok(masses)
}

/// `N_i(r_q)²` for every quadrature point.
fn shape_values_squared(et: ElementType, points: &[[f64; 3]]) -> Vec<Vec<f64>> {
    points
        .iter()
        .map(|r| {
            let mut n = vec![0.0; et.num_nodes()];
            et.shape_functions(r, &mut n);
            n.iter().map(|v| v * v).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::fem::quadrature;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    #[test]
    fn masses_are_positive_and_total_rho_v_for_every_element_type() {
        for et in ElementType::all() {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [4, 2, 2] },
                element_type: et,
                split: TetSplit::Five,
                refine: 0,
            }
            .build()
            .unwrap();
            let m = lumped_masses_kg(&mesh, 1000.0).unwrap();
            assert!(m.iter().all(|&mi| mi > 0.0), "{et}: a non-positive mass");
            let total: f64 = m.iter().sum();
            assert!((total - 500.0).abs() < 1e-9, "{et}: total {total} kg");
        }
    }

    #[test]
    fn row_sum_lumping_would_give_p2_vertices_negative_mass_which_is_why_hrz_is_used() {
        let p2 = ElementType::from_name("p2").unwrap();
        let rule = quadrature::rule(p2.shape(), 4).unwrap();
        let integral_of_vertex_function = rule.integrate(|r| {
            let mut n = [0.0; 10];
            p2.shape_functions(r, &mut n);
            n[0]
        });
        // ∫ L(2L − 1) = −V/20 on the reference tetrahedron (V = 1/6)
        assert!((integral_of_vertex_function + 1.0 / 120.0).abs() < 1e-14);
    }
}
