//! Test-only helpers: strategies, finite differences and the property checks
//! shared by every material model (run on every model of the registry by the
//! `every_registered_model_*` tests in `material/mod.rs`).

use super::{Lame, Mat3, Mat9, Material, MaterialModel, NodeVisit};
use nalgebra::{Rotation3, SymmetricEigen, Vector3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Cases per property (the brief asks for ≥ 64).
pub const CASES: u32 = 128;
const _: () = assert!(CASES >= 64);

/// Central finite-difference step on F entries (F is O(1)).
const FD_STEP: f64 = 1e-6;
/// Relative tolerance of finite-difference comparisons.
const FD_RTOL: f64 = 1e-6;

/// Runs `test` on `CASES` values of `strategy`, panicking with the shrunk
/// counter-example on failure.
pub fn run<S: Strategy>(strategy: S, test: impl Fn(S::Value) -> Result<(), TestCaseError>)
where
    S::Value: std::fmt::Debug,
{
    let mut runner = TestRunner::new(Config { cases: CASES, failure_persistence: None, ..Config::default() });
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{e}");
    }
}

/// Valid material with E ∈ [1e3, 1e9] Pa (log-uniform) and ν ∈ [nu_min, nu_max).
pub fn material_with_nu(model: MaterialModel, nu_min: f64, nu_max: f64) -> impl Strategy<Value = Material> {
    (3.0f64..9.0, nu_min..nu_max).prop_map(move |(log_e, nu)| {
        Material::new(model, 10f64.powf(log_e), nu, 1000.0).expect("strategy yields valid parameters")
    })
}

/// Valid material with ν ∈ [−0.45, 0.48).
pub fn material(model: MaterialModel) -> impl Strategy<Value = Material> {
    material_with_nu(model, -0.45, 0.48)
}

/// Matrix with entries uniform in [−amplitude, amplitude].
pub fn general_matrix(amplitude: f64) -> impl Strategy<Value = Mat3> {
    prop::array::uniform9(-amplitude..amplitude).prop_map(|a| Mat3::from_column_slice(&a))
}

/// F = I + amplitude·R, R entries in [−1, 1]; `det F` at least 0.05 above where the model's law
/// stops being smooth ([`super::HyperelasticModel::smooth_above_det_f`]: Neo-Hookean's J floor
/// 0.2), so finite differences never straddle a seam.
pub fn deformation_with_amplitude(model: MaterialModel, amplitude: f64) -> impl Strategy<Value = Mat3> {
    let above = model.law().smooth_above_det_f() + 0.05;
    general_matrix(amplitude)
        .prop_map(|r| Mat3::identity() + r)
        .prop_filter("finite differences need det F where the law is smooth", move |f| f.determinant() > above)
}

/// F = I + 0.3·R (`det F` in the smooth range, see [`deformation_with_amplitude`]).
pub fn deformation(model: MaterialModel) -> impl Strategy<Value = Mat3> {
    deformation_with_amplitude(model, 0.3)
}

/// Uniformly spread rotation matrices (axis-angle vectors in a cube).
pub fn rotation() -> impl Strategy<Value = Mat3> {
    prop::array::uniform3(-std::f64::consts::PI..std::f64::consts::PI)
        .prop_map(|a| Rotation3::new(Vector3::from(a)).into_inner())
}

/// Central differences of a scalar function of F.
pub fn fd_gradient(f: &Mat3, g: impl Fn(&Mat3) -> f64) -> Mat3 {
    let mut out = Mat3::zeros();
    for i in 0..9 {
        let mut fp = *f;
        fp[i] += FD_STEP;
        let mut fm = *f;
        fm[i] -= FD_STEP;
        out[i] = (g(&fp) - g(&fm)) / (2.0 * FD_STEP);
    }
    out
}

/// Central differences of a matrix function of F, as a 9×9 matrix on vec(F).
pub fn fd_jacobian(f: &Mat3, p: impl Fn(&Mat3) -> Mat3) -> Mat9 {
    let mut out = Mat9::zeros();
    for j in 0..9 {
        let mut fp = *f;
        fp[j] += FD_STEP;
        let mut fm = *f;
        fm[j] -= FD_STEP;
        let col = (p(&fp) - p(&fm)) / (2.0 * FD_STEP);
        for i in 0..9 {
            out[(i, j)] = col[i];
        }
    }
    out
}

pub fn min_eigenvalue(m: &Mat9) -> f64 {
    SymmetricEigen::new((m + m.transpose()) * 0.5).eigenvalues.min()
}

/// Deterministic pseudo-random orthogonal 9×9 matrix.
pub fn random_orthogonal9(seed: u64) -> Mat9 {
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let m = Mat9::from_fn(|_, _| {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    });
    m.qr().q()
}

/// Linear-elasticity tensor μ(δik δjl + δil δjk) + λ δij δkl as a 9×9 matrix
/// (row i + 3j for P[i,j], column k + 3l for F[k,l]).
pub fn linear_elasticity_tensor(l: Lame) -> Mat9 {
    let d = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
    let mut c = Mat9::zeros();
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                for m in 0..3 {
                    c[(i + 3 * j, k + 3 * m)] =
                        l.mu_pa * (d(i, k) * d(j, m) + d(i, m) * d(j, k)) + l.lambda_pa * d(i, j) * d(k, m);
                }
            }
        }
    }
    c
}

// ---------------------------------------------------------------------------
// Checks shared by every model.

pub fn check_rest_state(model: MaterialModel) {
    run(material(model), |m| {
        let i = Mat3::identity();
        prop_assert_eq!(m.energy_density(&i), 0.0);
        prop_assert_eq!(m.pk1(&i), Mat3::zeros());
        prop_assert_eq!(m.energy_density_and_pk1(&i), (0.0, Mat3::zeros()));
        Ok(())
    });
}

pub fn check_pk1_matches_energy_fd(model: MaterialModel) {
    run((material(model), deformation(model)), |(m, f)| {
        let p = m.pk1(&f);
        let fd = fd_gradient(&f, |g| m.energy_density(g));
        let scale = p.norm() + m.lame().mu_pa;
        prop_assert!((p - fd).norm() <= FD_RTOL * scale, "P = {p}, finite differences = {fd}");
        Ok(())
    });
}

pub fn check_dpdf_matches_pk1_fd(model: MaterialModel) {
    run((material(model), deformation(model)), |(m, f)| {
        let h = m.dpdf(&f);
        let fd = fd_jacobian(&f, |g| m.pk1(g));
        let scale = h.norm() + m.lame().mu_pa;
        prop_assert!((h - fd).norm() <= FD_RTOL * scale, "dP/dF = {h}, finite differences = {fd}");
        Ok(())
    });
}

pub fn check_dpdf_symmetric(model: MaterialModel) {
    run((material(model), deformation(model)), |(m, f)| {
        let h = m.dpdf(&f);
        prop_assert!((h - h.transpose()).norm() <= 1e-12 * h.norm());
        // P really is a gradient: the finite-difference Jacobian of P (which
        // never sees the symmetrisation in `dpdf`) is symmetric too.
        let fd = fd_jacobian(&f, |g| m.pk1(g));
        prop_assert!((fd - fd.transpose()).norm() <= FD_RTOL * (fd.norm() + m.lame().mu_pa));
        Ok(())
    });
}

pub fn check_projected_psd(model: MaterialModel) {
    run((material(model), deformation_with_amplitude(model, 0.6)), |(m, f)| {
        let h = m.dpdf(&f);
        let p = m.dpdf_projected(&f);
        let scale = h.norm();
        prop_assert!((p - p.transpose()).norm() <= 1e-12 * scale);
        prop_assert!(min_eigenvalue(&p) >= -1e-9 * scale);
        // Nearest PSD matrix in the Frobenius norm: the distance is the
        // norm of the clamped (negative) eigenvalues.
        let eig = SymmetricEigen::new(h).eigenvalues;
        let negative_part = eig.iter().filter(|l| **l < 0.0).map(|l| l * l).sum::<f64>().sqrt();
        prop_assert!(((p - h).norm() - negative_part).abs() <= 1e-9 * scale);
        if negative_part <= 1e-12 * scale {
            prop_assert!((p - h).norm() <= 1e-9 * scale);
        }
        Ok(())
    });
}

pub fn check_projected_at_rest(model: MaterialModel) {
    run(material(model), |m| {
        let i = Mat3::identity();
        let h = m.dpdf(&i);
        let p = m.dpdf_projected(&i);
        prop_assert!(min_eigenvalue(&h) >= -1e-9 * h.norm());
        prop_assert!((p - h).norm() <= 1e-9 * h.norm());
        Ok(())
    });
}

pub fn check_rotation_invariance(model: MaterialModel) {
    run((material(model), deformation(model), rotation()), |(m, f, r)| {
        let (psi, p) = m.energy_density_and_pk1(&f);
        let (psi_r, p_r) = m.energy_density_and_pk1(&(r * f));
        let mu = m.lame().mu_pa;
        prop_assert!((psi - psi_r).abs() <= 1e-9 * (psi.abs() + mu), "{psi} vs {psi_r}");
        prop_assert!((p_r - r * p).norm() <= 1e-9 * (p.norm() + mu));
        Ok(())
    });
}

fn split_energy(m: &Material, f: &Mat3) -> f64 {
    let k = m.split_stiffness_pa();
    let terms = m.split_terms(f);
    0.5 * k[0] * terms[0].value.powi(2) + 0.5 * k[1] * terms[1].value.powi(2) + m.split_energy_offset()
}

pub fn check_split_identity(model: MaterialModel) {
    if model.law().split().is_none() {
        return; // an optional capability the model does not offer
    }
    run((material(model), deformation_with_amplitude(model, 0.6)), |(m, f)| {
        let psi = m.energy_density(&f);
        let split = split_energy(&m, &f);
        let mu = m.lame().mu_pa;
        prop_assert!((psi - split).abs() <= 1e-9 * (psi.abs() + mu), "ψ = {psi}, split = {split}");
        Ok(())
    });
    // Also at rest.
    run(material(model), |m| {
        let split = split_energy(&m, &Mat3::identity());
        prop_assert!(split.abs() <= 1e-12 * m.lame().mu_pa);
        Ok(())
    });
}

pub fn check_split_gradients_fd(model: MaterialModel) {
    if model.law().split().is_none() {
        return; // an optional capability the model does not offer
    }
    run((material(model), deformation(model)), |(m, f)| {
        let [dev, hyd] = m.split_terms(&f);
        // Deviatoric term: sqrt form, scale = C ≥ 0, grad = ∂(C²/2)/∂F.
        prop_assert!(dev.value >= 0.0);
        prop_assert_eq!(dev.scale, dev.value);
        let fd = fd_gradient(&f, |g| 0.5 * m.split_terms(g)[0].value.powi(2));
        prop_assert!(
            (dev.grad_f_scaled - fd).norm() <= FD_RTOL * (fd.norm() + 1.0),
            "deviatoric: {} vs {fd}",
            dev.grad_f_scaled
        );
        // Hydrostatic term: scale = 1, grad = ∂C/∂F.
        prop_assert_eq!(hyd.scale, 1.0);
        let fd = fd_gradient(&f, |g| m.split_terms(g)[1].value);
        prop_assert!(
            (hyd.grad_f_scaled - fd).norm() <= FD_RTOL * (fd.norm() + 1.0),
            "hydrostatic: {} vs {fd}",
            hyd.grad_f_scaled
        );
        Ok(())
    });
}

pub fn check_linearisation_at_rest(model: MaterialModel) {
    run(material(model), |m| {
        let h = m.dpdf(&Mat3::identity());
        let c = linear_elasticity_tensor(m.lame());
        prop_assert!((h - c).norm() <= 1e-12 * c.norm(), "dP/dF(I) = {h}, C = {c}");
        Ok(())
    });
}

pub fn check_energy_and_pk1_consistent(model: MaterialModel) {
    run((material(model), deformation(model)), |(m, f)| {
        let (psi, p) = m.energy_density_and_pk1(&f);
        prop_assert_eq!(psi, m.energy_density(&f));
        prop_assert_eq!(p, m.pk1(&f));
        Ok(())
    });
}

/// A node's share at a point ([`Material::node_force_and_block`], vertex block descent's visit):
/// `P g` and `Σ_{c,d} ∂P_{rc}/∂F_{kd} g_c g_d` contracted from the full `dP/dF`, for any `g`.
pub fn check_node_force_and_block_match_dpdf(model: MaterialModel) {
    let g = prop::array::uniform3(-3.0f64..3.0).prop_map(|a| Vector3::from_column_slice(&a));
    run((material(model), deformation(model), g), |(m, f, g)| {
        let (force, block) = m.node_force_and_block(m.lame(), &f, &g);
        let p = m.pk1(&f);
        prop_assert!((force - p * g).norm() <= 1e-12 * (p.norm() * g.norm()).max(1e-300), "P g = {force}");
        let c = m.dpdf(&f);
        let expected = Mat3::from_fn(|r, k| {
            let mut sum = 0.0;
            for cc in 0..3 {
                for d in 0..3 {
                    sum += c[(r + 3 * cc, k + 3 * d)] * g[cc] * g[d];
                }
            }
            sum
        });
        let scale = (c.norm() * g.norm_squared()).max(1e-300);
        prop_assert!((block - expected).norm() <= 1e-12 * scale, "block {block}, from dP/dF {expected}");
        prop_assert_eq!(block, block.transpose());
        prop_assert_eq!(block, m.node_block(&f, &g));
        Ok(())
    });
}

/// A whole node visit ([`Material::node_visit`], lane-major, a model's own fast path such as
/// StVK's four lanes per AVX2 register) is `Σ_q V_q` of the point-by-point
/// [`Material::node_force_and_block`], on five points (two chunks of four lanes, the second
/// padded) and on one point (one lane).
pub fn check_node_visit_matches_point_sum(model: MaterialModel) {
    let g = prop::array::uniform3(-3.0f64..3.0).prop_map(|a| Vector3::from_column_slice(&a));
    let points = prop::collection::vec((deformation(model), g, 0.01f64..1.0), 5);
    run((material(model), points), |(m, points)| {
        for (width, used) in [(4usize, 5usize), (1, 1)] {
            let chunks = used.div_ceil(width);
            let (mut f, mut grads, mut volumes) =
                (vec![0.0; 9 * chunks * width], vec![0.0; 3 * chunks * width], vec![0.0; chunks * width]);
            for k in 0..chunks {
                for d in [0, 4, 8] {
                    f[(9 * k + d) * width..][..width].fill(1.0);
                }
            }
            let (mut force, mut block) = (Vector3::zeros(), Mat3::zeros());
            for (q, (fq, gq, v)) in points.iter().take(used).enumerate() {
                let (k, j) = (q / width, q % width);
                for r in 0..3 {
                    for c in 0..3 {
                        f[(9 * k + 3 * r + c) * width + j] = fq[(r, c)];
                    }
                    grads[(3 * k + r) * width + j] = gq[r];
                }
                volumes[k * width + j] = *v;
                let (fo, bo) = m.node_force_and_block(m.lame(), fq, gq);
                force += fo * *v;
                block += bo * *v;
            }
            let visit = NodeVisit { width, f: &f, grads: &grads, volumes: &volumes };
            let (got_force, got_block) = m.node_visit(m.lame(), visit);
            let scale = force.norm().max(block.norm()).max(1e-300);
            prop_assert!((got_force - force).norm() <= 1e-12 * scale, "force {got_force} vs {force} (width {width})");
            prop_assert!((got_block - block).norm() <= 1e-12 * scale, "block {got_block} vs {block} (width {width})");
        }
        Ok(())
    });
}

/// ψ ≥ 0 on random F; exactly when λ ≥ 0, up to rounding otherwise.
pub fn check_energy_nonnegative(model: MaterialModel, nu_min: f64) {
    run((material_with_nu(model, nu_min, 0.48), deformation_with_amplitude(model, 0.6)), |(m, f)| {
        let psi = m.energy_density(&f);
        let l = m.lame();
        if l.lambda_pa >= 0.0 {
            prop_assert!(psi >= 0.0, "ψ = {psi}");
        } else {
            prop_assert!(psi >= -1e-12 * l.mu_pa, "ψ = {psi}");
        }
        Ok(())
    });
}

/// At any `f` (inverted and degenerate ones included): P against finite differences of ψ,
/// dP/dF against finite differences of P, and the split terms summing to ψ.
pub fn check_derivatives_and_split_at(m: &Material, f: &Mat3) -> Result<(), TestCaseError> {
    let mu = m.lame().mu_pa;
    let (psi, p) = m.energy_density_and_pk1(f);
    prop_assert!(psi.is_finite());
    let fd = fd_gradient(f, |g| m.energy_density(g));
    prop_assert!((p - fd).norm() <= 1e-6 * (p.norm() + mu), "{p} vs {fd}");
    let h = m.dpdf(f);
    let fd = fd_jacobian(f, |g| m.pk1(g));
    prop_assert!((h - fd).norm() <= 1e-6 * (h.norm() + mu));
    if !m.has_split() {
        return Ok(());
    }
    let k = m.split_stiffness_pa();
    let t = m.split_terms(f);
    let split = 0.5 * k[0] * t[0].value.powi(2) + 0.5 * k[1] * t[1].value.powi(2) + m.split_energy_offset();
    prop_assert!((split - psi).abs() <= 1e-9 * (psi.abs() + mu));
    Ok(())
}

/// `m`'s energy density and first Piola–Kirchhoff stress at `f` equal `psi` and `p` (a model's
/// textbook formulas), to `1e-9` of the Lamé scale `μ + |λ|`.
pub fn check_against_formulas(m: &Material, f: &Mat3, psi: f64, p: Mat3) -> Result<(), TestCaseError> {
    let (psi_got, p_got) = m.energy_density_and_pk1(f);
    let l = m.lame();
    let scale = l.mu_pa + l.lambda_pa.abs();
    prop_assert!((psi - psi_got).abs() <= 1e-9 * scale, "{psi} vs {psi_got}");
    prop_assert!((p - p_got).norm() <= 1e-9 * (p.norm() + scale));
    Ok(())
}

/// ψ, P, dP/dF (plain and projected) and the split terms are all finite at `f`.
pub fn all_finite(m: &Material, f: &Mat3) -> bool {
    let (psi, p) = m.energy_density_and_pk1(f);
    let finite9 = |h: Mat9| h.iter().all(|x| x.is_finite());
    psi.is_finite()
        && p.iter().all(|x| x.is_finite())
        && finite9(m.dpdf(f))
        && finite9(m.dpdf_projected(f))
        && (!m.has_split()
            || m.split_terms(f)
                .iter()
                .all(|t| t.value.is_finite() && t.scale.is_finite() && t.grad_f_scaled.iter().all(|x| x.is_finite())))
}
