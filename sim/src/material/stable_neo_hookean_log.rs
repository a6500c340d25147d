//! Stable Neo-Hookean with the log term (`snh-log`): the full energy of Smith,
//! de Goes & Kim, *Stable Neo-Hookean Flesh Simulation*, ACM TOG 37(2), 2018,
//! §4 (eq. 14, "Ψ_New" with the −μ/2 log(I_C + 1) term), split as in Macklin
//! & Müller, *A Constraint-based Formulation of Stable Neo-Hookean Materials*,
//! MIG 2021:
//!
//! * ψ(F) = μ̂/2 (I_C − 3) + λ̂/2 (J − α)² − μ̂/2 log(I_C + 1) + c,
//!   I_C = ‖F‖²_F, J = det F
//! * α = 1 + 3μ̂/(4λ̂) makes F = I stress-free (P(I) = (3/4)μ̂ I + λ̂(1 − α) I);
//! * μ̂ = 4/3 μ and λ̂ = λ + 5/6 μ make the linearisation at rest exactly the
//!   linear elasticity tensor μ(δik δjl + δil δjk) + λ δij δkl of the given
//!   E, ν (Smith et al. §3.4/§4's re-parametrisation; at F = I the tangent is
//!   (3/4)μ̂ (dF + dFᵀ) + (λ̂ − 5/8 μ̂) tr(dF) I — checked by the shared
//!   `linearisation_at_rest_is_linear_elasticity` test);
//! * c = μ̂ log 2 − 9μ̂²/(32λ̂) = μ̂ log 2 − (3/8) μ̂ r, r = α − 1 = 3μ̂/(4λ̂)
//!   = μ/λ̂, makes ψ(I) = 0.
//! * P = μ̂ (I_C/(I_C + 1)) F + λ̂ (J − α) cof F
//!   = μ̂ (I_C/(I_C + 1)) F + (λ̂ (J − 1) − (3/4)μ̂) cof F,
//!   cof F = det(F) F⁻ᵀ = [f1×f2, f2×f0, f0×f1] (columns f0, f1, f2)
//! * dP(F; dF) = μ̂ (I_C/(I_C + 1)) dF + 2μ̂/(I_C + 1)² (F : dF) F
//!   + λ̂ (cof F : dF) cof F + (λ̂ (J − 1) − (3/4)μ̂) d cof(F; dF)
//!
//! **Why hox has it.** [`super::stable_neo_hookean`] (`snh`) drops the log
//! term, as Macklin & Müller do. Without it the energy has a spurious local
//! minimum at F = 0: along F = sI, dψ/ds = 3μs + 3λ̂ s²(s³ − α) > 0 for small
//! s, so elements squashed past the barrier collapse to a point and stay there
//! (docs/STABILITY.md, case 4, "squash to 10 % between plates"). With the log
//! term, along F = sI,
//! dψ/ds = 9μ̂ s³/(3s² + 1) + 3λ̂ s²(s³ − α) ≈ −3λ̂α s² < 0 near s = 0, and
//! dψ/ds < 0 on the whole of (0, 1) for ν > −0.851 (for more strongly auxetic
//! materials, λ̂/μ̂ < 0.153, a minimum along sI reappears near s ≈ 0.69);
//! along F = diag(s, 1, 1), dψ/ds = μ̂ s (s² + 2)/(s² + 3) + λ̂ (s − α) < 0 on
//! (0, 1) for every valid ν. F = 0 is still a stationary point (P(0) = 0),
//! but a saddle: ψ decreases away from it along sI.
//!
//! Like `snh`, everything is defined for degenerate and inverted elements
//! (J ≤ 0): I_C + 1 ≥ 1, so the log and the divisions never fail.
//!
//! Numerically, with x = I_C − 3, d = J − 1 and r = α − 1, the energy is
//! evaluated as μ̂/2 (x − log1p(x/4)) + λ̂/2 · d (d − 2r), which equals the
//! form above algebraically and is exactly 0 at rest.
//!
//! Split (offset c − 3μ̂/2 = μ̂ (log 2 − 3/2) − (3/8) μ̂ r):
//!
//! * deviatoric C = sqrt(I_C − log(I_C + 1)), k = μ̂ (I_C − log(1 + I_C) ≥ 0
//!   for I_C ≥ 0, zero only at F = 0); sqrt form: scale = C,
//!   grad_f_scaled = ∂(C²/2)/∂F = F · I_C/(I_C + 1)
//! * hydrostatic C = J − α, k = λ̂, ∂C/∂F = cof F

use super::{
    HyperelasticModel, Lame, Mat3, Mat9, SplitModel, SplitTerm, cofactor, cofactor_directional, det_minus_one,
    dpdf_from_directional, first_invariant_minus_three, node_block_from_directional,
};

/// The re-parametrised constants of the model.
#[derive(Clone, Copy, Debug)]
struct Params {
    /// μ̂ = 4/3 μ.
    mu_hat: f64,
    /// λ̂ = λ + 5/6 μ (> 0 for every ν > −1).
    lambda_hat: f64,
    /// r = α − 1 = 3μ̂/(4λ̂) = μ/λ̂.
    r: f64,
}

fn params(l: Lame) -> Params {
    let lambda_hat = l.lambda_pa + (5.0 / 6.0) * l.mu_pa;
    Params { mu_hat: (4.0 / 3.0) * l.mu_pa, lambda_hat, r: l.mu_pa / lambda_hat }
}

/// x − log(1 + x) for x ≥ 0, accurate for small x (where it is ≈ x²/2 and the
/// direct formula cancels): a 16-term alternating series below 0.1
/// (truncation error relative to the value < 2e-16).
fn x_minus_log1p(x: f64) -> f64 {
    if x.abs() < 0.1 {
        // x² Σ_{n≥2} (−x)^{n−2}/n, Horner from n = 16 down to 2.
        let mut acc = 0.0;
        for n in (2..=16).rev() {
            acc = 1.0 / n as f64 - x * acc;
        }
        x * x * acc
    } else {
        x - x.ln_1p()
    }
}

fn energy_from_invariants(p: Params, ic_minus_3: f64, j_minus_1: f64) -> f64 {
    0.5 * p.mu_hat * (ic_minus_3 - (0.25 * ic_minus_3).ln_1p())
        + 0.5 * p.lambda_hat * j_minus_1 * (j_minus_1 - 2.0 * p.r)
}

/// The cofactor coefficient λ̂ (J − α) = λ̂ (J − 1) − (3/4) μ̂ (exactly −(3/4) μ̂ at rest,
/// cancelling μ̂ I_C/(I_C + 1) = (3/4) μ̂ bit for bit).
fn cofactor_coefficient(p: Params, j_minus_1: f64) -> f64 {
    p.lambda_hat * j_minus_1 - 0.75 * p.mu_hat
}

/// Stable Neo-Hookean with the log term, as registered in [`super::MaterialModel::ALL`].
#[derive(Clone, Copy, Debug)]
pub struct StableNeoHookeanLog;

impl HyperelasticModel for StableNeoHookeanLog {
    fn name(&self) -> &'static str {
        "snh-log"
    }

    fn long_name(&self) -> &'static str {
        "stable Neo-Hookean with log term"
    }

    fn energy_density(&self, l: Lame, f: &Mat3) -> f64 {
        energy_from_invariants(params(l), first_invariant_minus_three(f), det_minus_one(f))
    }

    fn energy_density_and_pk1(&self, l: Lame, f: &Mat3) -> (f64, Mat3) {
        let p = params(l);
        let d = det_minus_one(f);
        let psi = energy_from_invariants(p, first_invariant_minus_three(f), d);
        let ic = f.norm_squared();
        let pk1 = f * (p.mu_hat * (ic / (ic + 1.0))) + cofactor(f) * cofactor_coefficient(p, d);
        (psi, pk1)
    }

    fn dpdf(&self, l: Lame, f: &Mat3) -> Mat9 {
        dpdf_from_directional(linearisation(l, f))
    }

    fn node_block(&self, l: Lame, f: &Mat3, g: &nalgebra::Vector3<f64>) -> Mat3 {
        node_block_from_directional(linearisation(l, f), g)
    }

    fn split(&self) -> Option<&dyn SplitModel> {
        Some(self)
    }
}

/// The split formulation's two constraints (XPBD's `Formulation::Split`).
impl SplitModel for StableNeoHookeanLog {
    fn split_terms(&self, l: Lame, f: &Mat3) -> [SplitTerm; 2] {
        let p = params(l);
        let ic = f.norm_squared();
        let c_dev = x_minus_log1p(ic).sqrt();
        [
            SplitTerm { value: c_dev, scale: c_dev, grad_f_scaled: f * (ic / (ic + 1.0)) },
            SplitTerm { value: det_minus_one(f) - p.r, scale: 1.0, grad_f_scaled: cofactor(f) },
        ]
    }

    fn split_stiffness_pa(&self, l: Lame) -> [f64; 2] {
        let p = params(l);
        [p.mu_hat, p.lambda_hat]
    }

    fn split_energy_offset(&self, l: Lame) -> f64 {
        let p = params(l);
        // c − 3μ̂/2, c = μ̂ log 2 − 9μ̂²/(32λ̂) = μ̂ log 2 − (3/8) μ̂ r.
        p.mu_hat * (std::f64::consts::LN_2 - 1.5 - 0.375 * p.r)
    }

    /// `C_h = J − α`: its second derivative is `d(cof F)[dF]`.
    fn hydrostatic_hessian(&self, _l: Lame, f: &Mat3) -> Mat9 {
        dpdf_from_directional(|df| cofactor_directional(f, df))
    }
}

/// `dP[dF] = a dF + a' (F : dF) F + λ̂ (cof F : dF) cof F + g d(cof F)[dF]`.
fn linearisation(l: Lame, f: &Mat3) -> impl Fn(&Mat3) -> Mat3 + '_ {
    let p = params(l);
    let cof = cofactor(f);
    let ic = f.norm_squared();
    let a = p.mu_hat * (ic / (ic + 1.0));
    let da = 2.0 * p.mu_hat / ((ic + 1.0) * (ic + 1.0));
    let g = cofactor_coefficient(p, det_minus_one(f));
    move |df| df * a + f * (da * f.dot(df)) + cof * (p.lambda_hat * cof.dot(df)) + cofactor_directional(f, df) * g
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::super::{Mat3, Material, MaterialModel};
    use super::x_minus_log1p;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    const MODEL: MaterialModel = MaterialModel::StableNeoHookeanLog;

    #[test]
    fn energy_nonnegative() {
        testing::check_energy_nonnegative(MODEL, -0.45);
    }

    /// μ̂, λ̂, α, c of Smith et al., evaluated straight from the paper's form.
    fn paper_constants(m: &Material) -> (f64, f64, f64, f64) {
        let l = m.lame();
        let mu_hat = 4.0 / 3.0 * l.mu_pa;
        let lambda_hat = l.lambda_pa + 5.0 / 6.0 * l.mu_pa;
        let alpha = 1.0 + 3.0 * mu_hat / (4.0 * lambda_hat);
        // ψ(I) = 0: λ̂/2 (1 − α)² − μ̂/2 log 4 + c = 0.
        let c = 0.5 * mu_hat * 4f64.ln() - 0.5 * lambda_hat * (1.0 - alpha).powi(2);
        (mu_hat, lambda_hat, alpha, c)
    }

    #[test]
    fn matches_paper_formulas() {
        testing::run((testing::material(MODEL), testing::deformation(MODEL)), |(m, f)| {
            let (mu_hat, lambda_hat, alpha, c) = paper_constants(&m);
            let ic = f.norm_squared();
            let j = f.determinant();
            let psi =
                0.5 * mu_hat * (ic - 3.0) + 0.5 * lambda_hat * (j - alpha).powi(2) - 0.5 * mu_hat * (ic + 1.0).ln() + c;
            let inv_t = f.try_inverse().expect("invertible").transpose();
            let p = f * (mu_hat * (1.0 - 1.0 / (ic + 1.0))) + inv_t * (lambda_hat * (j - alpha) * j);
            testing::check_against_formulas(&m, &f, psi, p)
        });
    }

    #[test]
    fn split_constants() {
        let m = Material::new(MODEL, 2.0e6, 0.3, 1000.0).expect("valid");
        let (mu_hat, lambda_hat, alpha, c) = paper_constants(&m);
        let k = m.split_stiffness_pa();
        assert!((k[0] - mu_hat).abs() <= 1e-15 * mu_hat);
        assert!((k[1] - lambda_hat).abs() <= 1e-15 * lambda_hat);
        let expected = c - 1.5 * mu_hat;
        assert!((m.split_energy_offset() - expected).abs() <= 1e-12 * expected.abs());
        // c = μ̂ log 2 − 9μ̂²/(32λ̂).
        let c_closed = mu_hat * std::f64::consts::LN_2 - 9.0 * mu_hat * mu_hat / (32.0 * lambda_hat);
        assert!((c - c_closed).abs() <= 1e-12 * c.abs());
        // At rest: C_dev = sqrt(3 − log 4), C_hyd = 1 − α.
        let [dev, hyd] = m.split_terms(&Mat3::identity());
        assert!((dev.value - (3.0 - 4f64.ln()).sqrt()).abs() < 1e-15);
        assert!((hyd.value - (1.0 - alpha)).abs() < 1e-15);
        assert!((dev.grad_f_scaled - Mat3::identity() * 0.75).norm() < 1e-15);
    }

    #[test]
    fn x_minus_log1p_is_accurate() {
        for x in [0.0, 1e-300, 1e-12, 1e-6, 1e-3, 0.05, 0.0999, 0.1, 0.5, 1.0, 3.0, 1e6] {
            let got = x_minus_log1p(x);
            // Reference: the series to many terms where small, else the direct formula.
            let expected = if x < 0.5 {
                (2..60).map(|n| (-x).powi(n - 2) * x * x / n as f64).sum::<f64>()
            } else {
                x - (1.0 + x).ln()
            };
            assert!((got - expected).abs() <= 2e-15 * expected, "x = {x}: {got} vs {expected}");
        }
        // Continuous across the switch at 0.1.
        let below = x_minus_log1p(0.1 - 1e-15);
        let above = x_minus_log1p(0.1);
        assert!((above - below).abs() <= 1e-15);
    }

    /// dψ/ds < 0 for s ∈ [1e-4, 0.999] along F = sI and F = diag(s, 1, 1): the
    /// collapsed state F = 0 is no longer a local minimum; compression always
    /// pushes back towards rest.
    #[test]
    fn no_collapse_minimum_along_uniform_and_uniaxial_compression() {
        const SAMPLES: usize = 20_000;
        for nu in [-0.45, -0.3, 0.0, 0.3, 0.45, 0.49, 0.499] {
            let m = Material::new(MODEL, 1.0e6, nu, 1000.0).expect("valid");
            let (mu_hat, lambda_hat, alpha, _) = paper_constants(&m);
            for i in 0..=SAMPLES {
                let s = 1e-4 + (0.999 - 1e-4) * i as f64 / SAMPLES as f64;
                // F = sI: dψ/ds = P : I.
                let dpsi = m.pk1(&(Mat3::identity() * s)).trace();
                let closed =
                    9.0 * mu_hat * s.powi(3) / (3.0 * s * s + 1.0) + 3.0 * lambda_hat * s * s * (s.powi(3) - alpha);
                assert!(
                    (dpsi - closed).abs() <= 1e-9 * (closed.abs() + mu_hat * s * s),
                    "ν = {nu}, s = {s}: {dpsi} vs {closed}"
                );
                assert!(dpsi < 0.0, "ν = {nu}: dψ/ds = {dpsi} ≥ 0 at F = {s}·I");
                // F = diag(s, 1, 1): dψ/ds = P[0, 0].
                let dpsi = m.pk1(&Mat3::from_diagonal(&Vector3::new(s, 1.0, 1.0)))[(0, 0)];
                let closed = mu_hat * s * (s * s + 2.0) / (s * s + 3.0) + lambda_hat * (s - alpha);
                assert!((dpsi - closed).abs() <= 1e-9 * (closed.abs() + mu_hat));
                assert!(dpsi < 0.0, "ν = {nu}: dψ/ds = {dpsi} ≥ 0 at F = diag({s}, 1, 1)");
            }
            // And ψ decreases monotonically towards rest along sI.
            let psi: Vec<f64> = (0..=100).map(|i| m.energy_density(&(Mat3::identity() * (i as f64 / 100.0)))).collect();
            assert!(psi.windows(2).all(|w| w[1] < w[0]), "ν = {nu}: {psi:?}");
            assert_eq!(psi[100], 0.0);
        }
    }

    /// The reason this model exists: `snh` (no log term) has dψ/ds > 0 at
    /// F = 0.05 I, i.e. a spurious minimum at F = 0 that squashed elements fall
    /// into; `snh-log` pushes them back out.
    #[test]
    fn snh_without_log_term_has_the_collapse_minimum_this_model_removes() {
        let s = 0.05;
        for nu in [0.0, 0.3, 0.45] {
            let old = Material::new(MaterialModel::StableNeoHookean, 1.0e6, nu, 1000.0).expect("valid");
            let l = old.lame();
            let lambda_hat = l.lambda_pa + l.mu_pa;
            let alpha = 1.0 + l.mu_pa / lambda_hat;
            let dpsi_old = old.pk1(&(Mat3::identity() * s)).trace();
            let closed = 3.0 * l.mu_pa * s + 3.0 * lambda_hat * s * s * (s.powi(3) - alpha);
            assert!((dpsi_old - closed).abs() <= 1e-9 * l.mu_pa);
            assert!(dpsi_old > 0.0, "ν = {nu}: snh dψ/ds = {dpsi_old} at s = {s}");
            let new = Material::new(MODEL, 1.0e6, nu, 1000.0).expect("valid");
            let dpsi_new = new.pk1(&(Mat3::identity() * s)).trace();
            assert!(dpsi_new < 0.0, "ν = {nu}: snh-log dψ/ds = {dpsi_new} at s = {s}");
        }
    }

    /// The module doc's limit: for ν below ≈ −0.851 (λ̂/μ̂ < 0.153) a minimum
    /// along sI reappears near s ≈ 0.69.
    #[test]
    fn strongly_auxetic_materials_keep_a_minimum_along_uniform_compression() {
        let slope = |nu: f64, s: f64| {
            let m = Material::new(MODEL, 1.0e6, nu, 1000.0).expect("valid");
            m.pk1(&(Mat3::identity() * s)).trace()
        };
        assert!(slope(-0.9, 0.69) > 0.0);
        assert!(slope(-0.84, 0.69) < 0.0);
    }

    /// Degenerate and inverted elements: F with arbitrary entries, J of any sign.
    #[test]
    fn derivatives_hold_for_inverted_and_degenerate_elements() {
        testing::run((testing::material(MODEL), testing::general_matrix(1.5)), |(m, f)| {
            prop_assert!(testing::all_finite(&m, &f));
            testing::check_derivatives_and_split_at(&m, &f)
        });
        for nu in [-0.45, 0.0, 0.3, 0.45, 0.499] {
            let m = Material::new(MODEL, 1.0e6, nu, 1000.0).expect("valid");
            for f in [
                Mat3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)),
                Mat3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)),
                Mat3::from_diagonal(&Vector3::new(-2.0, -3.0, -4.0)),
                Mat3::identity() * 1e-8,
                Mat3::zeros(),
            ] {
                assert!(testing::all_finite(&m, &f), "ν = {nu}, F = {f}");
                let psi = m.energy_density(&f);
                assert!(psi > 0.0, "ν = {nu}, F = {f}: ψ = {psi}");
            }
            // F = 0: a stationary point (P = 0 exactly) with a finite, positive energy
            // ψ(0) = λ̂/2 + μ̂ (log 2 − 3/4) (from the split form).
            let (psi0, p0) = m.energy_density_and_pk1(&Mat3::zeros());
            assert_eq!(p0, Mat3::zeros());
            let k = m.split_stiffness_pa();
            let expected = 0.5 * k[1] + k[0] * (std::f64::consts::LN_2 - 0.75);
            assert!((psi0 - expected).abs() <= 1e-12 * expected, "{psi0} vs {expected}");
            let [dev, hyd] = m.split_terms(&Mat3::zeros());
            assert_eq!((dev.value, dev.scale), (0.0, 0.0));
            assert_eq!(dev.grad_f_scaled, Mat3::zeros());
            assert_eq!(hyd.grad_f_scaled, Mat3::zeros());
            // Inverting pushes back: P at diag(−0.5, 1, 1) has a restoring component, and
            // the inverted state costs more than the flat one.
            let p = m.pk1(&Mat3::from_diagonal(&Vector3::new(-0.5, 1.0, 1.0)));
            assert!(p[(0, 0)] < 0.0);
            let e_inv = m.energy_density(&Mat3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)));
            let e_flat = m.energy_density(&Mat3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)));
            assert!(e_inv > e_flat);
        }
        // Near F = 0 the deviatoric constraint stays accurate (no cancellation in
        // I_C − log(1 + I_C) ≈ I_C²/2).
        let m = Material::new(MODEL, 1.0e6, 0.3, 1000.0).expect("valid");
        let s = 1e-5;
        let [dev, _] = m.split_terms(&(Mat3::identity() * s));
        let ic = 3.0 * s * s;
        let expected = (ic * ic / 2.0 - ic.powi(3) / 3.0).sqrt();
        assert!((dev.value - expected).abs() <= 1e-14 * expected, "{} vs {expected}", dev.value);
    }

    /// Nearly incompressible: ν = 0.499 (λ ≈ 250 E) is accepted, exactly at rest at F = I,
    /// linearises to linear elasticity, and its derivatives match finite differences.
    #[test]
    fn nearly_incompressible_nu_0_499() {
        let m = Material::new(MODEL, 1.0e6, 0.499, 1000.0).expect("ν = 0.499 is valid");
        assert!(Material::new(MODEL, 1.0e6, 0.5, 1000.0).is_err());
        let i = Mat3::identity();
        assert_eq!(m.energy_density_and_pk1(&i), (0.0, Mat3::zeros()));
        let h = m.dpdf(&i);
        let c = testing::linear_elasticity_tensor(m.lame());
        assert!((h - c).norm() <= 1e-12 * c.norm());
        let k = m.split_stiffness_pa();
        assert!(k[0] > 0.0 && k[1] > 300.0 * k[0]);
        testing::run((testing::material_with_nu(MODEL, 0.49, 0.4999), testing::deformation(MODEL)), |(m, f)| {
            let mu = m.lame().mu_pa;
            let (psi, p) = m.energy_density_and_pk1(&f);
            prop_assert!(psi >= 0.0);
            let fd = testing::fd_gradient(&f, |g| m.energy_density(g));
            prop_assert!((p - fd).norm() <= 1e-6 * (p.norm() + mu), "{p} vs {fd}");
            let h = m.dpdf(&f);
            let fd = testing::fd_jacobian(&f, |g| m.pk1(g));
            prop_assert!((h - fd).norm() <= 1e-6 * (h.norm() + mu));
            let k = m.split_stiffness_pa();
            let t = m.split_terms(&f);
            let split = 0.5 * k[0] * t[0].value.powi(2) + 0.5 * k[1] * t[1].value.powi(2) + m.split_energy_offset();
            prop_assert!((split - psi).abs() <= 1e-9 * (psi.abs() + mu));
            Ok(())
        });
    }
}
