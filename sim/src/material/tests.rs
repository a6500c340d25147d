use super::testing;
use super::*;
use proptest::prelude::*;

/// Every shared check of `testing` (finite differences of ψ → P → dP/dF and of the split
/// terms, symmetry, rest state, rotation invariance, linearisation), on every model of the
/// registry, [`MaterialModel::ALL`]: a new model is checked as soon as it is registered.
macro_rules! every_registered_model {
    ($($test:ident: $check:ident),* $(,)?) => {$(
        #[test]
        fn $test() {
            for &model in MaterialModel::ALL {
                eprintln!("{}: {model}", stringify!($check)); // names the model of a failure
                testing::$check(model);
            }
        }
    )*};
}

every_registered_model! {
    every_registered_model_has_zero_energy_and_stress_at_rest: check_rest_state,
    every_registered_model_has_pk1_matching_energy_finite_differences: check_pk1_matches_energy_fd,
    every_registered_model_has_dpdf_matching_pk1_finite_differences: check_dpdf_matches_pk1_fd,
    every_registered_model_has_dpdf_with_major_symmetry: check_dpdf_symmetric,
    every_registered_model_projects_dpdf_to_the_nearest_psd: check_projected_psd,
    every_registered_model_has_projected_dpdf_equal_to_dpdf_at_rest: check_projected_at_rest,
    every_registered_model_is_rotation_invariant: check_rotation_invariance,
    every_registered_model_satisfies_the_split_energy_identity: check_split_identity,
    every_registered_model_has_split_gradients_matching_finite_differences: check_split_gradients_fd,
    every_registered_model_linearises_to_linear_elasticity_at_rest: check_linearisation_at_rest,
    every_registered_model_agrees_between_energy_and_pk1_and_separate_calls: check_energy_and_pk1_consistent,
    every_registered_model_has_node_force_and_block_matching_dpdf: check_node_force_and_block_match_dpdf,
    every_registered_model_has_a_node_visit_summing_its_points: check_node_visit_matches_point_sum,
}

#[test]
fn registered_names_are_unique() {
    for (i, a) in MaterialModel::ALL.iter().enumerate() {
        for b in &MaterialModel::ALL[i + 1..] {
            assert_ne!(a.name(), b.name());
            assert_ne!(a, b);
        }
    }
}

#[test]
fn names_round_trip() {
    for &m in MaterialModel::ALL {
        assert_eq!(MaterialModel::from_name(m.name()), Some(m));
        assert_eq!(MaterialModel::from_name(&m.name().to_uppercase()), Some(m));
        assert_eq!(MaterialModel::from_name(m.long_name()), Some(m));
        assert_eq!(m.to_string(), m.name());
    }
    // the built-in models keep their names and places (a new model goes after them)
    let names: Vec<&str> = MaterialModel::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(names[..4], ["stvk", "snh", "snh-log", "nh"]);
    assert_eq!(MaterialModel::from_name(" SNH-Log "), Some(MaterialModel::StableNeoHookeanLog));
    assert_eq!(MaterialModel::from_name("stable Neo-Hookean with log term"), Some(MaterialModel::StableNeoHookeanLog));
    assert_eq!(MaterialModel::from_name(" StVK "), Some(MaterialModel::StVenantKirchhoff));
    assert_eq!(MaterialModel::from_name("NH"), Some(MaterialModel::NeoHookean));
    assert_eq!(MaterialModel::from_name("Snh"), Some(MaterialModel::StableNeoHookean));
    assert_eq!(MaterialModel::from_name("neo"), None);
    assert_eq!(MaterialModel::from_name(""), None);
    assert_eq!(MaterialModel::StVenantKirchhoff.long_name(), "Saint-Venant–Kirchhoff");
}

#[test]
fn lame_from_youngs_poisson() {
    let l = Lame::from_youngs_poisson(1.0, 0.25);
    assert!((l.mu_pa - 0.4).abs() < 1e-15);
    assert!((l.lambda_pa - 0.4).abs() < 1e-15);
    let l = Lame::from_youngs_poisson(2.0e6, 0.0);
    assert_eq!(l.lambda_pa, 0.0);
    assert!((l.mu_pa - 1.0e6).abs() < 1e-9);
    let m = Material::new(MaterialModel::NeoHookean, 1.0e5, 0.3, 1000.0).expect("valid");
    assert_eq!(m.lame(), Lame::from_youngs_poisson(1.0e5, 0.3));
}

#[test]
fn new_accepts_valid_parameters() {
    for &model in MaterialModel::ALL {
        for nu in [-0.99, -0.5, 0.0, 0.3, 0.49, 0.4999] {
            let m = Material::new(model, 1.0e6, nu, 1100.0).expect("valid parameters");
            assert_eq!(m.model, model);
            assert_eq!(m.youngs_modulus_pa, 1.0e6);
            assert_eq!(m.poisson_ratio, nu);
            assert_eq!(m.density_kg_m3, 1100.0);
        }
    }
}

fn err(model: MaterialModel, e: f64, nu: f64, rho: f64) -> String {
    match Material::new(model, e, nu, rho) {
        Ok(m) => panic!("accepted invalid parameters: {m:?}"),
        Err(err) => err.to_string(),
    }
}

#[test]
fn new_rejects_invalid_parameters_with_named_messages() {
    for &model in MaterialModel::ALL {
        for nu in [0.5, 0.7, -1.0, -1.5, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let msg = err(model, 1.0e6, nu, 1000.0);
            assert!(msg.contains("Poisson ratio"), "{msg}");
            assert!(msg.contains(model.name()), "{msg}");
        }
        for e in [0.0, -0.0, -3.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let msg = err(model, e, 0.3, 1000.0);
            assert!(msg.contains("Young's modulus"), "{msg}");
        }
        for rho in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let msg = err(model, 1.0e6, 0.3, rho);
            assert!(msg.contains("density"), "{msg}");
        }
    }
    assert_eq!(
        err(MaterialModel::StVenantKirchhoff, -3.0, 0.3, 1000.0),
        "Young's modulus must be a finite positive number of pascals, got -3"
    );
    assert_eq!(
        err(MaterialModel::StVenantKirchhoff, 1.0e6, 0.5, 1000.0),
        "Poisson ratio must lie in (-1, 0.5) for stvk (λ → ∞ at 0.5), got 0.5"
    );
    assert_eq!(
        err(MaterialModel::NeoHookean, 1.0e6, 0.3, -2.5),
        "density must be a finite positive number of kg/m³, got -2.5"
    );
    assert!(err(MaterialModel::NeoHookean, f64::NAN, 0.3, 1.0).ends_with("got NaN"));
    assert_eq!(
        Material::new(MaterialModel::NeoHookean, 1.0e6, 0.7, 1.0),
        Err(MaterialError::PoissonRatio { model: MaterialModel::NeoHookean, poisson_ratio: 0.7 })
    );
    // Valid-looking E and ν whose Lamé parameters overflow.
    let msg = err(MaterialModel::StableNeoHookean, 1.0e308, 0.5 - 1.0e-12, 1.0);
    assert!(msg.contains("Lamé"), "{msg}");
}

#[test]
fn cofactor_is_det_times_inverse_transpose() {
    testing::run(testing::general_matrix(1.5), |f| {
        prop_assume!(f.determinant().abs() > 1e-3);
        let inv_t = f.try_inverse().expect("invertible").transpose();
        let expected = inv_t * f.determinant();
        let cof = cofactor(&f);
        prop_assert!((cof - expected).norm() <= 1e-9 * (1.0 + expected.norm()));
        prop_assert!((det_minus_one(&f) - (f.determinant() - 1.0)).abs() <= 1e-12 * (1.0 + f.norm().powi(3)));
        Ok(())
    });
}

#[test]
fn cofactor_directional_matches_finite_differences() {
    testing::run((testing::general_matrix(1.5), testing::general_matrix(1.0)), |(f, df)| {
        let h = 1e-6;
        let fd = (cofactor(&(f + df * h)) - cofactor(&(f - df * h))) / (2.0 * h);
        let an = cofactor_directional(&f, &df);
        prop_assert!((fd - an).norm() <= 1e-7 * (1.0 + an.norm()));
        Ok(())
    });
}

#[test]
fn projection_of_known_matrix() {
    let mut d = Mat9::zeros();
    for i in 0..9 {
        d[(i, i)] = i as f64 - 4.0; // eigenvalues -4..4
    }
    let r = testing::random_orthogonal9(7);
    let m = r * d * r.transpose();
    let p = project_psd(&m);
    let mut expected = Mat9::zeros();
    for i in 0..9 {
        expected[(i, i)] = (i as f64 - 4.0).max(0.0);
    }
    let expected = r * expected * r.transpose();
    assert!((p - expected).norm() < 1e-12 * expected.norm().max(1.0), "{p}");
    // Already positive definite: returned unchanged (bit for bit).
    let mut pd = Mat9::zeros();
    for i in 0..9 {
        pd[(i, i)] = i as f64 + 1.0;
    }
    let pd = r * pd * r.transpose();
    let pd = (pd + pd.transpose()) * 0.5;
    assert_eq!(project_psd(&pd), pd);
    // Non-finite input passes through instead of looping.
    let mut bad = m;
    bad[(3, 4)] = f64::NAN;
    assert!(project_psd(&bad)[(3, 4)].is_nan());
}

#[test]
fn split_stiffness_is_positive_for_nonnegative_poisson_ratio() {
    testing::run((0.0f64..0.49, 3.0f64..9.0), |(nu, log_e)| {
        for &model in MaterialModel::ALL {
            let m = Material::new(model, 10f64.powf(log_e), nu, 1000.0).expect("valid");
            let k = m.split_stiffness_pa();
            prop_assert!(k[0] > 0.0);
            prop_assert!(k[1] >= 0.0);
        }
        Ok(())
    });
}

mod psd3 {
    use super::project_psd3;
    use nalgebra::{Matrix3, SymmetricEigen};

    /// A positive definite block comes back as it was; an indefinite one comes back with its
    /// negative eigenvalues at 0 and its eigenvectors kept (the nearest PSD matrix); non-finite
    /// input is returned as is.
    #[test]
    fn psd3_projection_keeps_pd_blocks_and_clamps_negative_eigenvalues() {
        let pd = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        assert_eq!(project_psd3(&pd), pd);
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, -3.0); // eigenvalues 3, -1, -3
        let p = project_psd3(&indefinite);
        let eig = SymmetricEigen::new(p).eigenvalues;
        let mut e: Vec<f64> = eig.iter().copied().collect();
        e.sort_by(f64::total_cmp);
        assert!(e[0].abs() < 1e-12 && e[1].abs() < 1e-12 && (e[2] - 3.0).abs() < 1e-12, "{e:?}");
        // the kept eigenvector (1, 1, 0)/√2 with eigenvalue 3
        let v = nalgebra::Vector3::new(1.0, 1.0, 0.0).normalize();
        assert!((p * v - 3.0 * v).norm() < 1e-12);
        let bad = Matrix3::new(f64::NAN, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(project_psd3(&bad)[(0, 0)].is_nan());
        // the fast path (positive leading minors) returns the symmetric part, not the input
        let asymmetric = Matrix3::new(4.0, 2.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 2.0);
        assert_eq!(project_psd3(&asymmetric), Matrix3::new(4.0, 1.0, 0.0, 1.0, 3.0, 0.0, 0.0, 0.0, 2.0));
        // first two minors positive, the determinant negative: not taken for definite
        let last_negative = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -1.0));
        assert_eq!(project_psd3(&last_negative), Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, 0.0)));
    }
}

/// A model stating only the constitutive core (names, ψ, P, ∂P/∂F: here Saint-Venant–Kirchhoff's,
/// through its registered law) and no solver capability, registered nowhere.
struct CoreOnly;

impl HyperelasticModel for CoreOnly {
    fn name(&self) -> &'static str {
        "core-only"
    }
    fn long_name(&self) -> &'static str {
        "the constitutive core alone (a test's)"
    }
    fn energy_density(&self, l: Lame, f: &Mat3) -> f64 {
        MaterialModel::StVenantKirchhoff.law().energy_density(l, f)
    }
    fn energy_density_and_pk1(&self, l: Lame, f: &Mat3) -> (f64, Mat3) {
        MaterialModel::StVenantKirchhoff.law().energy_density_and_pk1(l, f)
    }
    fn dpdf(&self, l: Lame, f: &Mat3) -> Mat9 {
        MaterialModel::StVenantKirchhoff.law().dpdf(l, f)
    }
}

/// A new material is its constitutive core: the optional capabilities' defaults (VBD's node
/// kernels, no fast law, no split constraints) run it under every solver as the model it
/// restates, and XPBD's split formulation, which needs a capability it lacks, refuses it by name.
#[test]
fn a_model_with_the_core_alone_runs_under_every_solver_and_the_split_formulation_refuses_it() {
    use crate::effect::{Clamp, Effect, Gravity};
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    use crate::solver::{Method, Simulation, SolverSettings};
    use crate::xpbd::constraint::Formulation;
    let core = MaterialModel(&CoreOnly);
    let (stvk, ours) = (
        Material::new(MaterialModel::StVenantKirchhoff, 1e5, 0.3, 1000.0).unwrap(),
        Material::new(core, 1e5, 0.3, 1000.0).unwrap(),
    );
    assert!(!MaterialModel::ALL.contains(&core) && !ours.has_split() && ours.fast_law().is_none());
    testing::check_pk1_matches_energy_fd(core);
    testing::check_node_force_and_block_match_dpdf(core);
    let et = crate::element::ElementType::from_name("p2").unwrap();
    let grid = BoxGrid { min_m: crate::Vec3::zeros(), max_m: crate::Vec3::new(0.5, 0.1, 0.1), cells: [2, 1, 1] };
    let mesh = BoxMeshSpec { grid, element_type: et, split: TetSplit::Five, refine: 0 }.build().unwrap();
    let clamped = mesh.nodes_where(|p| p.x.abs() < 1e-12);
    let effects = || -> Vec<Box<dyn Effect>> {
        vec![Box::new(Gravity::new(crate::Vec3::new(0.0, 0.0, -9.81))), Box::new(Clamp { nodes: clamped.clone() })]
    };
    for method in Method::ALL {
        let settings = SolverSettings { method, frames_per_second: 200.0, ..SolverSettings::default() };
        let mut a = Simulation::new(mesh.clone(), stvk, settings, effects()).unwrap();
        let mut b = Simulation::new(mesh.clone(), ours, settings, effects()).unwrap();
        for _ in 0..10 {
            a.step_frame().unwrap();
            b.step_frame().unwrap();
        }
        let sag = a.displacements().iter().map(|u| u.norm()).fold(0.0, f64::max);
        assert!(sag > 1e-6, "{method}: nothing moved");
        for (x, y) in a.positions.iter().zip(&b.positions) {
            assert!((x - y).norm() <= 1e-6 * sag, "{method}: {y} against StVK's {x}");
        }
    }
    let split = SolverSettings { formulation: Formulation::Split, ..SolverSettings::default() };
    let err = Simulation::new(mesh.clone(), ours, split, effects()).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(err.contains("split formulation") && err.contains(core.long_name()), "{err}");
    let mut sim = Simulation::new(mesh, stvk, split, effects()).unwrap();
    assert!(sim.set_material(ours).is_err(), "the split formulation took a model without split constraints");
}
