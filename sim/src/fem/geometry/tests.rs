use super::*;
use crate::element::tests::point_in;
use crate::mesh::ElementBlock;
use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
use nalgebra::Matrix3;
use proptest::prelude::*;

/// One element of type `et` whose nodes are its reference nodes pushed through a smooth
/// non-affine map: curved for high-order elements.
pub(crate) fn curved_element(et: ElementType, bend: f64) -> Mesh {
    let rest_positions = et
        .nodes()
        .iter()
        .map(|r| {
            let p = Vec3::from(*r);
            p + bend * Vec3::new((1.3 * p.y).sin() * 0.5, (0.7 * p.z + p.x).sin() * 0.3, (p.x * p.y) * 0.2)
        })
        .collect();
    Mesh { rest_positions, blocks: vec![ElementBlock::new(et, (0..et.num_nodes() as u32).collect())] }
}

fn all_types() -> impl Iterator<Item = ElementType> {
    ElementType::all()
}

fn matrix() -> impl Strategy<Value = Matrix3<f64>> {
    proptest::array::uniform9(-1.0..1.0f64).prop_map(|a| Matrix3::identity() + Matrix3::from_column_slice(&a) * 0.5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Patch test: an affine deformation x = A X + b gives F = A at every quadrature point,
    /// also on curved P2/P3/Q2 elements.
    #[test]
    fn affine_deformations_give_the_exact_constant_f(a in matrix(), b in proptest::array::uniform3(-1.0..1.0f64), bend in 0.0..0.15f64) {
        for et in all_types() {
            let mesh = curved_element(et, if et.order() > 1 { bend } else { 0.0 });
            let geo = precompute(&mesh, None).unwrap();
            let x: Vec<Vec3> = mesh.rest_positions.iter().map(|p| a * p + Vec3::from(b)).collect();
            let g = &geo[0];
            for q in 0..g.points_per_element {
                let nodes = mesh.blocks[0].element(0);
                let gather = |p: &[Vec3]| nodes.iter().map(|&n| p[n as usize]).collect::<Vec<Vec3>>();
                let f = deformation_gradient(&gather(&x), &gather(&mesh.rest_positions), g.gradients(0, q));
                prop_assert!((f - a).norm() < 1e-11, "{}: F = {} vs A = {}", et, f, a);
            }
        }
    }
}

#[test]
fn element_volumes_sum_to_the_box_volume_for_every_generated_mesh() {
    for et in all_types() {
        for split in [TetSplit::Five, TetSplit::Six] {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::new(-0.5, 0.0, 1.0), max_m: Vec3::new(1.5, 0.5, 1.5), cells: [4, 2, 3] },
                element_type: et,
                split,
                refine: if et.shape() == crate::element::ReferenceShape::Tetrahedron { 1 } else { 0 },
            }
            .build()
            .unwrap();
            let geo = precompute(&mesh, None).unwrap();
            for g in &geo {
                assert!(g.volume_m3.iter().all(|v| *v > 0.0), "{et}");
            }
            let v = total_volume_m3(&geo);
            assert!((v - 0.5).abs() < 1e-12, "{et} {split:?}: volume {v}");
        }
    }
}

#[test]
fn a_flat_element_is_rejected_naming_the_element_and_point() {
    for et in all_types() {
        let mut mesh = curved_element(et, 0.0);
        // squash everything onto the plane z = 0
        for p in &mut mesh.rest_positions {
            p.z = 0.0;
        }
        let err = precompute(&mesh, None).unwrap_err().to_string();
        assert!(err.contains("element 0") && err.contains("flat") && err.contains("quadrature point 0"), "{et}: {err}");
    }
}

#[test]
fn an_inverted_element_is_rejected() {
    for et in all_types() {
        let mut mesh = curved_element(et, 0.0);
        for p in &mut mesh.rest_positions {
            p.x = -p.x;
        }
        let err = precompute(&mesh, None).unwrap_err().to_string();
        assert!(err.contains("inverted") && err.contains(et.name()), "{et}: {err}");
    }
}

#[test]
fn material_gradients_sum_to_zero_and_volumes_are_positive_inside_elements() {
    for et in all_types() {
        let mesh = curved_element(et, 0.1);
        let g = &precompute(&mesh, Some(4)).unwrap()[0];
        for q in 0..g.points_per_element {
            let s: Vec3 = g.gradients(0, q).iter().sum();
            assert!(s.norm() < 1e-11, "{et}");
        }
        // the quadrature points are where the reference rule puts them
        assert!(g.quadrature.points.iter().all(|r| et.shape().contains(r, 1e-12)));
        let _ = point_in(et.shape(), [0.1, 0.2, 0.3, 0.4]);
    }
}
