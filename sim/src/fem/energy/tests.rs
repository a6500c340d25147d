use super::*;
use crate::element::ElementType;
use crate::fem::geometry::precompute;
use crate::fem::geometry::tests::curved_element;
use crate::material::{Mat3, MaterialModel};
use nalgebra::Rotation3;
use proptest::prelude::*;

pub(crate) fn materials() -> Vec<Material> {
    MaterialModel::ALL.iter().map(|&m| Material::new(m, 1.0e5, 0.3, 1000.0).unwrap()).collect()
}

/// A curved element of every type with its geometry.
pub(crate) fn elements() -> Vec<(ElementType, Mesh, Vec<BlockGeometry>)> {
    ElementType::all()
        .map(|et| {
            let mesh = curved_element(et, if et.order() > 1 { 0.1 } else { 0.0 });
            let geo = precompute(&mesh, None).unwrap();
            (et, mesh, geo)
        })
        .collect()
}

fn perturbed(mesh: &Mesh, seed: &[f64]) -> Vec<Vec3> {
    mesh.rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p + 0.08
                * Vec3::new(seed[(3 * i) % seed.len()], seed[(3 * i + 1) % seed.len()], seed[(3 * i + 2) % seed.len()])
        })
        .collect()
}

#[test]
fn rigid_motions_give_zero_energy_and_zero_gradient() {
    for (et, mesh, geo) in elements() {
        for material in materials() {
            for (axis, t) in
                [(Vec3::new(0.3, -1.2, 0.7), Vec3::new(1.0, 2.0, -3.0)), (Vec3::new(2.5, 0.1, 0.0), Vec3::zeros())]
            {
                let r = Rotation3::from_scaled_axis(axis);
                let x: Vec<Vec3> = mesh.rest_positions.iter().map(|p| r * p + t).collect();
                let mut grad = vec![Vec3::zeros(); x.len()];
                let u = total_energy_and_gradient(&mesh, &geo, &material, &x, &mut grad);
                let scale = material.youngs_modulus_pa * total_volume(&geo);
                assert!(u.abs() < 1e-12 * scale, "{et} {:?}: U = {u}", material.model);
                let gmax = grad.iter().map(|g| g.norm()).fold(0.0, f64::max);
                assert!(gmax < 1e-10 * scale, "{et} {:?}: |∇U| = {gmax}", material.model);
            }
        }
    }
}

/// Smallest det F over the quadrature points of a mesh ([`crate::measure::min_det_f`]).
fn min_det_f(mesh: &Mesh, geo: &[BlockGeometry], x: &[Vec3]) -> f64 {
    crate::measure::min_det_f(mesh, geo, x).expect("elements").det_f
}

fn total_volume(geo: &[BlockGeometry]) -> f64 {
    crate::fem::geometry::total_volume_m3(geo)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn energy_gradients_match_finite_differences(seed in proptest::collection::vec(-1.0..1.0f64, 81)) {
        let h = 1e-6;
        for (et, mesh, geo) in elements() {
            let x = perturbed(&mesh, &seed);
            let min_j = min_det_f(&mesh, &geo, &x);
            for material in materials() {
                // Neo-Hookean's ln J is continued linearly below J = 1e-6: finite differences
                // across that seam are meaningless, so keep NH to well-shaped deformations.
                if material.model == MaterialModel::NeoHookean && min_j < 0.2 {
                    continue;
                }
                let mut grad = vec![Vec3::zeros(); x.len()];
                total_energy_and_gradient(&mesh, &geo, &material, &x, &mut grad);
                let gmax = grad.iter().map(|g| g.norm()).fold(0.0, f64::max);
                for i in 0..x.len() {
                    for d in 0..3 {
                        let (mut xp, mut xm) = (x.clone(), x.clone());
                        xp[i][d] += h;
                        xm[i][d] -= h;
                        let fd = (total_energy(&mesh, &geo, &material, &xp) - total_energy(&mesh, &geo, &material, &xm)) / (2.0 * h);
                        prop_assert!((fd - grad[i][d]).abs() < 1e-6 * gmax.max(1.0), "{} {:?} node {} dim {}: {} vs {}", et, material.model, i, d, grad[i][d], fd);
                    }
                }
            }
        }
    }
}

/// The fixed-node-count kernel (`fixed.rs`), with fused multiply–adds and without, against the
/// generic one element by element, for every element type and material on a curved element
/// moved off its rest shape: the same energy and gradient up to round-off, the energy-only pass
/// the same sum as the one with the gradient, and no element type left to the generic kernel.
#[test]
fn the_fixed_node_count_kernel_matches_the_generic_one_for_every_element_type_and_material() {
    let seed: Vec<f64> = (0..81).map(|k| ((k * 7919) % 200) as f64 / 100.0 - 1.0).collect();
    for (et, mesh, geo) in elements() {
        let x = perturbed(&mesh, &seed);
        for material in materials() {
            let mut g_ref = vec![Vec3::zeros(); x.len()];
            let e_ref = total_energy_and_gradient_generic(&mesh, &geo, &material, &x, &mut g_ref);
            assert!(e_ref > 0.0, "{et} {:?}: a deformed element stores energy", material.model);
            let scale = g_ref.iter().map(|g| g.norm()).fold(0.0, f64::max);
            let name = format!("{et} {:?}", material.model);
            for fma in [false, true] {
                let mut g = vec![Vec3::zeros(); x.len()];
                let pass = fixed::Pass {
                    block: &mesh.blocks[0],
                    geometry: &geo[0],
                    rest: &mesh.rest_positions,
                    x: &x,
                    elements: 0..mesh.blocks[0].len(),
                };
                let e = fixed::block_energy_and_gradient_fused::<true>(pass.clone(), &material, &mut g, fma)
                    .unwrap_or_else(|| panic!("{name}: no specialised kernel"));
                let e_only = fixed::block_energy_and_gradient_fused::<false>(pass, &material, &mut [], fma)
                    .expect("specialised");
                assert!((e - e_ref).abs() <= 1e-12 * e_ref, "{name} fma {fma}: U {e} against {e_ref}");
                assert_eq!(e.to_bits(), e_only.to_bits(), "{name} fma {fma}: the energy-only pass");
                for (i, (a, b)) in g.iter().zip(&g_ref).enumerate() {
                    assert!((a - b).norm() <= 1e-12 * scale, "{name} fma {fma} node {i}: {a:?} against {b:?}");
                }
            }
            let mut g = vec![Vec3::repeat(7.0); x.len()];
            let e = total_energy_and_gradient(&mesh, &geo, &material, &x, &mut g);
            assert!((e - e_ref).abs() <= 1e-12 * e_ref, "{name}: the mesh pass");
            assert!(g.iter().zip(&g_ref).all(|(a, b)| (a - b).norm() <= 1e-12 * scale), "{name}: overwritten");
            let e = total_energy(&mesh, &geo, &material, &x);
            assert!((e - total_energy_generic(&mesh, &geo, &material, &x)).abs() <= 1e-12 * e_ref, "{name}: U alone");
        }
    }
}

#[test]
fn element_hessians_match_finite_differences_of_the_gradient() {
    let seed: Vec<f64> = (0..81).map(|k| ((k * 7919) % 200) as f64 / 100.0 - 1.0).collect();
    let h = 1e-6;
    for (et, mesh, geo) in elements() {
        for material in materials() {
            let x = perturbed(&mesh, &seed);
            let g = &geo[0];
            let hess = element_hessian(&x, &mesh.rest_positions, element_grads(g, 0), g.volumes(0), &material, false);
            let n = x.len();
            let mut gp = vec![Vec3::zeros(); n];
            let mut gm = vec![Vec3::zeros(); n];
            let hmax = hess.amax();
            for j in 0..n {
                for b in 0..3 {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[j][b] += h;
                    xm[j][b] -= h;
                    element_energy_and_gradient(
                        &xp,
                        &mesh.rest_positions,
                        element_grads(g, 0),
                        g.volumes(0),
                        &material,
                        &mut gp,
                    );
                    element_energy_and_gradient(
                        &xm,
                        &mesh.rest_positions,
                        element_grads(g, 0),
                        g.volumes(0),
                        &material,
                        &mut gm,
                    );
                    for i in 0..n {
                        for a in 0..3 {
                            let fd = (gp[i][a] - gm[i][a]) / (2.0 * h);
                            let an = hess[(3 * i + a, 3 * j + b)];
                            assert!(
                                (fd - an).abs() < 1e-5 * hmax,
                                "{et} {:?}: H[{i}{a},{j}{b}] {an} vs {fd}",
                                material.model
                            );
                        }
                    }
                }
            }
            // symmetric, and the projected Hessian is positive semi-definite
            assert!((&hess - hess.transpose()).amax() < 1e-9 * hmax);
            let hp = element_hessian(&x, &mesh.rest_positions, element_grads(g, 0), g.volumes(0), &material, true);
            let min_eig = hp.symmetric_eigenvalues().min();
            assert!(min_eig > -1e-9 * hmax, "{et}: projected Hessian has eigenvalue {min_eig}");
        }
    }
}

#[test]
fn the_p1_gradient_is_benders_v0_p_dm_inv_t() {
    let et = ElementType::from_name("p1").unwrap();
    let (_, mesh, geo) = elements().into_iter().find(|(e, _, _)| *e == et).unwrap();
    let x = perturbed(&mesh, &[0.3, -0.2, 0.5, 0.1, 0.9, -0.4]);
    let material = materials()[0];
    let mut grad = vec![Vec3::zeros(); 4];
    total_energy_and_gradient(&mesh, &geo, &material, &x, &mut grad);
    let x0 = &mesh.rest_positions;
    let dm = Mat3::from_columns(&[x0[1] - x0[0], x0[2] - x0[0], x0[3] - x0[0]]);
    let ds = Mat3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
    let dm_inv = dm.try_inverse().unwrap();
    let f = ds * dm_inv;
    let v0 = dm.determinant() / 6.0;
    let h = material.pk1(&f) * dm_inv.transpose() * v0;
    for k in 0..3 {
        assert!((h.column(k) - grad[k + 1]).norm() < 1e-9 * h.norm());
    }
    assert!((grad[0] + h.column(0) + h.column(1) + h.column(2)).norm() < 1e-9 * h.norm());
}

/// A node's gradient and diagonal block (what vertex block descent needs) are the node's rows of
/// the element gradient and the diagonal 3 × 3 block of the element Hessian, projected or not,
/// for every element type and material at a deformed state.
#[test]
fn node_block_is_the_diagonal_block_of_the_element_hessian() {
    let seed: Vec<f64> = (0..81).map(|k| ((k * 37 % 101) as f64 / 50.0) - 1.0).collect();
    for (et, mesh, geo) in elements() {
        let x = perturbed(&mesh, &seed);
        let block = &mesh.blocks[0];
        let nodes = block.element(0);
        let (mut xe, mut rest) = (vec![Vec3::zeros(); nodes.len()], vec![Vec3::zeros(); nodes.len()]);
        gather(&x, nodes, &mut xe);
        gather(&mesh.rest_positions, nodes, &mut rest);
        let (grads, volumes) = (element_grads(&geo[0], 0), geo[0].volumes(0));
        for material in materials() {
            let mut grad = vec![Vec3::zeros(); nodes.len()];
            element_energy_and_gradient(&xe, &rest, grads, volumes, &material, &mut grad);
            for projected in [false, true] {
                let h = element_hessian(&xe, &rest, grads, volumes, &material, projected);
                let scale = h.abs().max().max(1e-300);
                for a in 0..nodes.len() {
                    let (g, b) = element_node_gradient_and_block(&xe, &rest, grads, volumes, &material, a, projected);
                    let gscale = grad.iter().map(|v| v.norm()).fold(0.0, f64::max).max(1e-300);
                    assert!((g - grad[a]).norm() <= 1e-12 * gscale, "{et} {:?} node {a}: gradient", material.model);
                    let expected = h.fixed_view::<3, 3>(3 * a, 3 * a);
                    assert!(
                        (b - expected).abs().max() <= 1e-12 * scale,
                        "{et} {:?} node {a} projected {projected}: {b} vs {expected}",
                        material.model
                    );
                }
            }
        }
    }
}

/// The element Hessian as it was first written: every node pair's block by the one-stage
/// [`contract`], both triangles summed. The scalar path [`element_hessian`]'s two-stage,
/// one-triangle kernel (issue #37) is checked against.
fn element_hessian_by_pairs(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    projected: bool,
) -> DMatrix<f64> {
    let n = x.len();
    let mut h = DMatrix::zeros(3 * n, 3 * n);
    for (q, v) in volumes.iter().enumerate() {
        let g = &grads[q * n..(q + 1) * n];
        let f = deformation_gradient(x, rest, g);
        let c = if projected { material.dpdf_projected(&f) } else { material.dpdf(&f) };
        for i in 0..n {
            for j in 0..n {
                let block = contract(&c, &g[i], &g[j]);
                for a in 0..3 {
                    for b in 0..3 {
                        h[(3 * i + a, 3 * j + b)] += v * block[(a, b)];
                    }
                }
            }
        }
    }
    h
}

/// The element Hessian's kernel (the contraction in two stages over one triangle, mirrored) sums
/// what the pairwise contraction sums, to round-off, projected or not, for every element type and
/// material at a deformed state; and it is exactly symmetric.
#[test]
fn the_one_triangle_hessian_matches_the_pairwise_contraction() {
    let seed: Vec<f64> = (0..81).map(|k| ((k * 53 % 97) as f64 / 48.0) - 1.0).collect();
    for (et, mesh, geo) in elements() {
        let x = perturbed(&mesh, &seed);
        let (grads, volumes) = (element_grads(&geo[0], 0), geo[0].volumes(0));
        for material in materials() {
            for projected in [false, true] {
                let fast = element_hessian(&x, &mesh.rest_positions, grads, volumes, &material, projected);
                let slow = element_hessian_by_pairs(&x, &mesh.rest_positions, grads, volumes, &material, projected);
                let scale = slow.abs().max().max(1e-300);
                let diff = (&fast - &slow).abs().max();
                assert!(
                    diff <= 1e-12 * scale,
                    "{et} {:?} projected {projected}: {diff:e} of {scale:e}",
                    material.model
                );
                assert_eq!(fast, fast.transpose(), "{et} {:?}: not exactly symmetric", material.model);
            }
        }
    }
}
