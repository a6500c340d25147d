use super::*;
use crate::fem::energy::tests::{elements, materials};
use nalgebra::SymmetricEigen;

/// Inverse masses of an element's nodes that differ from node to node (as in a mesh).
fn masses(n: usize) -> Vec<f64> {
    (0..n).map(|i| 1.0 / (0.5 + 0.25 * (i % 5) as f64)).collect()
}

#[test]
fn omega2_bounds_the_largest_eigenvalue_from_above_within_its_safety_factor() {
    for (et, mesh, geo) in elements() {
        for material in materials() {
            let g = &geo[0];
            let w = masses(et.num_nodes());
            let rest = &mesh.rest_positions;
            let k = element_hessian(rest, rest, element_grads(g, 0), g.volumes(0), &material, false);
            let n = 3 * et.num_nodes();
            let a = DMatrix::from_fn(n, n, |r, c| w[r / 3].sqrt() * k[(r, c)] * w[c / 3].sqrt());
            let exact = SymmetricEigen::new(a).eigenvalues.max();
            let estimate = element_omega2(rest, &w, element_grads(g, 0), g.volumes(0), &material);
            assert!(
                estimate >= exact * 0.99 && estimate <= exact * OMEGA2_SAFETY * 1.0001,
                "{et} {:?}: {estimate} vs {exact}",
                material.model
            );
        }
    }
    // every node pinned: nothing can move
    let (_, mesh, geo) = &elements()[0];
    assert_eq!(
        element_omega2(&mesh.rest_positions, &[0.0; 4], element_grads(&geo[0], 0), geo[0].volumes(0), &materials()[0]),
        0.0
    );
}

#[test]
fn omega2_scales_with_youngs_modulus_over_density() {
    let (et, mesh, geo) = elements().into_iter().find(|(et, ..)| et.name() == "p2").expect("P2");
    let w = masses(et.num_nodes());
    let at = |e: f64, rho: f64| {
        let m = Material::new(crate::material::MaterialModel::StableNeoHookean, e, 0.3, rho).unwrap();
        // inverse masses scale with 1/ρ
        let w: Vec<f64> = w.iter().map(|wi| wi * 1000.0 / rho).collect();
        element_omega2(&mesh.rest_positions, &w, element_grads(&geo[0], 0), geo[0].volumes(0), &m)
    };
    let base = at(1e5, 1000.0);
    assert!((at(1e9, 1000.0) / base - 1e4).abs() < 1e-6 * 1e4);
    assert!((at(1e5, 10.0) / base - 100.0).abs() < 1e-6 * 100.0);
}

#[test]
fn guarded_substeps_keep_the_request_below_the_trigger_and_take_the_target_above_it() {
    // ω_max = 600 rad/s at 60 fps: h ω = 10 / n
    assert_eq!(guarded_substeps(50, 60.0, 600.0, 3.0, 1.0), (50, false));
    assert_eq!(guarded_substeps(4, 60.0, 600.0, 3.0, 1.0), (4, false)); // h ω = 2.5: as asked
    assert_eq!(guarded_substeps(3, 60.0, 600.0, 3.0, 1.0), (10, false)); // 3.3: down to 1
    assert_eq!(guarded_substeps(1, 60.0, 601.0, 3.0, 1.0), (11, false));
    assert_eq!(guarded_substeps(1, 60.0, 0.0, 3.0, 1.0), (1, false));
    assert_eq!(guarded_substeps(1, 60.0, 1e12, 3.0, 1.0), (GUARD_MAX_SUBSTEPS, true));
    // a request already finer than the target is kept
    assert_eq!(guarded_substeps(1, 60.0, 600.0, 3.0, 20.0), (1, false));
}

#[test]
fn the_energy_formulation_of_a_nearly_incompressible_material_is_guarded_from_h_omega_one_and_a_half() {
    use crate::material::MaterialModel;
    let at = |nu: f64| Material::new(MaterialModel::StableNeoHookean, 1e6, nu, 1000.0).unwrap();
    for model_nu in [0.0, 0.3, 0.4, 0.449] {
        assert_eq!(guard_trigger_h_omega(Formulation::Energy, &at(model_nu)), GUARD_TRIGGER_H_OMEGA, "ν = {model_nu}");
    }
    for nu in [0.45, 0.49, 0.499] {
        assert_eq!(
            guard_trigger_h_omega(Formulation::Energy, &at(nu)),
            GUARD_TRIGGER_NEAR_INCOMPRESSIBLE_ENERGY_H_OMEGA,
            "ν = {nu}"
        );
        assert_eq!(guard_trigger_h_omega(Formulation::Split, &at(nu)), GUARD_TRIGGER_H_OMEGA, "ν = {nu}");
    }
    // λ/μ = 2ν/(1 − 2ν) = 9 at the threshold
    let lame = at(NEAR_INCOMPRESSIBLE_POISSON_RATIO).lame();
    assert!((lame.lambda_pa / lame.mu_pa - 9.0).abs() < 1e-9);
}
