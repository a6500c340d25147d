use super::super::tests::elements;
use super::*;
use crate::element::ElementType;
use crate::fem::energy::{element_grads, gather};
use crate::material::{MaterialError, MaterialModel, VolumeMeasure};

/// StVK and Neo-Hookean (the models the mixed formulation takes) at ν = 0.45, measured per element.
fn mixed_materials() -> Vec<Material> {
    [MaterialModel::StVenantKirchhoff, MaterialModel::NeoHookean]
        .into_iter()
        .map(|m| Material::new(m, 1.0e5, 0.45, 1000.0).unwrap().with_volume_measure(VolumeMeasure::Element).unwrap())
        .collect()
}

/// The high-order elements the formulation runs on, each with element 0's rest data and a
/// deformed state (a stretch, a shear and a wobble of every node).
fn cases() -> Vec<(ElementType, Vec<Vec3>, Vec<Vec3>, Vec<Vec3>, Vec<f64>)> {
    elements()
        .into_iter()
        .filter(|(et, ..)| et.order() > 1)
        .map(|(et, mesh, geo)| {
            let nodes = mesh.blocks[0].element(0);
            let mut rest = vec![Vec3::zeros(); nodes.len()];
            gather(&mesh.rest_positions, nodes, &mut rest);
            let x: Vec<Vec3> = rest
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let k = i as f64;
                    Vec3::new(1.1 * p.x + 0.2 * p.y, 0.95 * p.y - 0.1 * p.z, p.z + 0.05 * p.x * p.y)
                        + 0.02 * Vec3::new((1.3 * k).sin(), (2.1 * k).cos(), (0.7 * k).sin())
                })
                .collect();
            (et, x, rest, element_grads(&geo[0], 0).to_vec(), geo[0].volumes(0).to_vec())
        })
        .collect()
}

#[test]
fn the_mixed_gradient_and_hessian_match_finite_differences() {
    let h = 1e-6;
    for (et, x, rest, grads, volumes) in cases() {
        for m in mixed_materials() {
            let n = x.len();
            let mut grad = vec![Vec3::zeros(); n];
            let u = element_energy_and_gradient(&x, &rest, &grads, &volumes, &m, &mut grad);
            assert!((u - element_energy(&x, &rest, &grads, &volumes, &m)).abs() <= 1e-12 * u.abs());
            let hess = element_hessian(&x, &rest, &grads, &volumes, &m, false);
            let scale = grad.iter().map(|g| g.amax()).fold(0.0, f64::max);
            let hscale = hess.amax();
            for i in 0..n {
                for a in 0..3 {
                    let mut xp = x.clone();
                    xp[i][a] += h;
                    let mut xm = x.clone();
                    xm[i][a] -= h;
                    let fd = (element_energy(&xp, &rest, &grads, &volumes, &m)
                        - element_energy(&xm, &rest, &grads, &volumes, &m))
                        / (2.0 * h);
                    assert!(
                        (fd - grad[i][a]).abs() <= 1e-6 * scale,
                        "{et} {}: ∂U/∂x[{i}][{a}] {fd} vs {}",
                        m.model,
                        grad[i][a]
                    );
                    let (mut gp, mut gm) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
                    element_energy_and_gradient(&xp, &rest, &grads, &volumes, &m, &mut gp);
                    element_energy_and_gradient(&xm, &rest, &grads, &volumes, &m, &mut gm);
                    for j in 0..n {
                        for b in 0..3 {
                            let fd = (gp[j][b] - gm[j][b]) / (2.0 * h);
                            let an = hess[(3 * j + b, 3 * i + a)];
                            assert!(
                                (fd - an).abs() <= 1e-5 * hscale,
                                "{et} {}: H[{j}{b}][{i}{a}] {fd} vs {an}",
                                m.model
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn a_node_s_share_is_its_row_of_the_mixed_gradient_and_its_diagonal_block() {
    for (et, x, rest, grads, volumes) in cases() {
        for m in mixed_materials() {
            let mut grad = vec![Vec3::zeros(); x.len()];
            element_energy_and_gradient(&x, &rest, &grads, &volumes, &m, &mut grad);
            let hess = element_hessian(&x, &rest, &grads, &volumes, &m, false);
            for a in [0, x.len() / 2, x.len() - 1] {
                let (g, b) = element_node_gradient_and_block(&x, &rest, &grads, &volumes, &m, a, false);
                assert!((g - grad[a]).norm() <= 1e-10 * grad[a].norm().max(1e-9), "{et}: node {a}'s gradient");
                let diag = hess.fixed_view::<3, 3>(3 * a, 3 * a).into_owned();
                assert!((b - diag).amax() <= 1e-10 * hess.amax(), "{et}: node {a}'s block");
            }
        }
    }
}

#[test]
fn measured_over_the_element_the_hydrostatic_energy_is_at_most_the_pointwise_one() {
    // Jensen: V_e k_h/2 C̄² ≤ Σ_q V_q k_h/2 C_h², equal when C_h is the same at every point (a
    // homogeneous deformation)
    for (et, x, rest, grads, volumes) in cases() {
        for m in mixed_materials() {
            let point = m.with_volume_measure(VolumeMeasure::Point).unwrap();
            let (mixed, plain) = (
                element_energy(&x, &rest, &grads, &volumes, &m),
                super::super::element_energy(&x, &rest, &grads, &volumes, &point),
            );
            assert!(mixed > 0.0 && mixed < plain, "{et} {}: mixed {mixed} vs plain {plain}", m.model);
            let homogeneous: Vec<Vec3> =
                rest.iter().map(|p| Vec3::new(1.1 * p.x + 0.2 * p.y, 0.95 * p.y, p.z)).collect();
            let (mixed, plain) = (
                element_energy(&homogeneous, &rest, &grads, &volumes, &m),
                super::super::element_energy(&homogeneous, &rest, &grads, &volumes, &point),
            );
            assert!((mixed - plain).abs() <= 1e-10 * plain, "{et} {}: homogeneous {mixed} vs {plain}", m.model);
        }
    }
}

#[test]
fn the_mixed_formulation_refuses_a_model_whose_deviatoric_term_is_unstable_alone() {
    for model in MaterialModel::ALL {
        let m = Material::new(*model, 1.0e5, 0.49, 1000.0).unwrap();
        let asked = m.with_volume_measure(VolumeMeasure::Element);
        match model.name() {
            "stvk" | "nh" => assert!(asked.is_ok(), "{model}: {asked:?}"),
            _ => {
                let Err(MaterialError::DeviatoricUnstable { min_eigenvalue_pa, .. }) = asked else {
                    panic!("{model}: {asked:?}")
                };
                assert!(min_eigenvalue_pa < 0.0);
                let message = asked.unwrap_err().to_string();
                assert!(message.contains(model.name()) && message.contains("use stvk or nh"), "{message}");
            }
        }
    }
}

/// P1 measured per node patch (`patch`): over a deformed 3×2×2 box of five tetrahedra per cell,
/// the mesh gradient is the energy's central difference, the assembled Hessian (exact and
/// projected: one pass of `patch::hessian_terms`) the gradient's, and every node's patch term
/// reaches nodes two edges apart.
#[test]
fn the_patch_gradient_and_hessian_match_finite_differences_over_the_mesh() {
    use crate::fem::energy::{total_energy, total_energy_and_gradient};
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    let mesh = BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(0.6, 0.4, 0.4), cells: [3, 2, 2] },
        element_type: ElementType::from_name("p1").unwrap(),
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap();
    let geo = crate::fem::geometry::precompute(&mesh, None).unwrap();
    let x: Vec<Vec3> = mesh
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let k = i as f64;
            Vec3::new(1.1 * p.x + 0.2 * p.y, 0.95 * p.y - 0.1 * p.z, p.z + 0.3 * p.x * p.y)
                + 0.01 * Vec3::new((1.3 * k).sin(), (2.1 * k).cos(), (0.7 * k).sin())
        })
        .collect();
    let n = mesh.num_nodes();
    for m in mixed_materials() {
        assert!(patch::has_patches(&mesh, &m));
        let mut grad = vec![Vec3::zeros(); n];
        let u = total_energy_and_gradient(&mesh, &geo, &m, &x, &mut grad);
        assert!((u - total_energy(&mesh, &geo, &m, &x)).abs() <= 1e-12 * u.abs());
        let plain = m.with_volume_measure(VolumeMeasure::Point).unwrap();
        assert!(u < total_energy(&mesh, &geo, &plain, &x), "the patch mean relaxes the volume: {u}");
        let mut hess = DMatrix::<f64>::zeros(3 * n, 3 * n);
        patch::hessian_terms(&mesh, &geo, &m, &x, false, |nodes, h| {
            for (li, &i) in nodes.iter().enumerate() {
                for (lj, &j) in nodes.iter().enumerate() {
                    for (a, b) in (0..3).flat_map(|a| (0..3).map(move |b| (a, b))) {
                        hess[(3 * i as usize + a, 3 * j as usize + b)] += h[(3 * li + a, 3 * lj + b)];
                    }
                }
            }
        });
        let (gscale, hscale) = (grad.iter().map(|g| g.amax()).fold(0.0, f64::max), hess.amax());
        let h = 1e-6;
        for d in 0..3 * n {
            let shifted = |s: f64| {
                let mut xs = x.clone();
                xs[d / 3][d % 3] += s;
                xs
            };
            let (xp, xm) = (shifted(h), shifted(-h));
            let fd = (total_energy(&mesh, &geo, &m, &xp) - total_energy(&mesh, &geo, &m, &xm)) / (2.0 * h);
            assert!(
                (fd - grad[d / 3][d % 3]).abs() <= 1e-6 * gscale,
                "{:?} dof {d}: {fd} vs {}",
                m.model,
                grad[d / 3][d % 3]
            );
            let (mut gp, mut gm) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
            total_energy_and_gradient(&mesh, &geo, &m, &xp, &mut gp);
            total_energy_and_gradient(&mesh, &geo, &m, &xm, &mut gm);
            for e in 0..3 * n {
                let fd = (gp[e / 3][e % 3] - gm[e / 3][e % 3]) / (2.0 * h);
                assert!(
                    (fd - hess[(e, d)]).abs() <= 1e-5 * hscale,
                    "{:?} ({e}, {d}): {fd} vs {}",
                    m.model,
                    hess[(e, d)]
                );
            }
        }
        // the patch terms couple nodes two edges apart: more pairs than the elements' own
        let coupled = |k: &DMatrix<f64>| {
            (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).filter(|&(i, j)| k[(3 * i, 3 * j)] != 0.0).count()
        };
        let plain_k = crate::solver::statics::assemble_dense(&mesh, &geo, &plain, &x);
        assert!(coupled(&hess) > coupled(&plain_k), "{} vs {}", coupled(&hess), coupled(&plain_k));
    }
}

/// The node block from the models' node blocks ([`point_node_block`], P1's VBD visit) is the
/// 9 × 9 tangent contracted ([`point_tangent`]), for StVK and Neo-Hookean, with and without a
/// pressure and a deviatoric share, at a deformed `F`.
#[test]
fn a_node_block_is_the_contracted_point_tangent() {
    let f = Mat3::new(1.1, 0.05, -0.02, 0.03, 0.93, 0.04, -0.01, 0.06, 1.04);
    let g = Vec3::new(0.7, -1.3, 0.4);
    for model in [MaterialModel::StVenantKirchhoff, MaterialModel::NeoHookean] {
        let material = Material::new(model, 1.0e5, 0.45, 1000.0).unwrap();
        let k_h = hydrostatic_stiffness_pa(&material);
        let pt = point(&material, k_h, &f);
        for (share, pressure) in [(1.0, 0.0), (0.1, 2.0e4), (0.1, -3.0e4)] {
            let want =
                crate::material::contract(&point_tangent(&material, k_h, share, pressure, &f, &pt, false), &g, &g);
            let got = point_node_block(&material, k_h, share, pressure, &f, &pt, &g);
            assert!((got - want).norm() <= 1e-9 * want.norm(), "{model:?} β {share} p {pressure}: {got} vs {want}");
        }
    }
}
