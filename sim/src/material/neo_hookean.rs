//! Compressible Neo-Hookean (`nh`), e.g. Bonet & Wood, *Nonlinear Continuum
//! Mechanics for Finite Element Analysis*, §6.4.3; Sifakis & Barbič, *FEM
//! Simulation of 3D Deformable Solids*, SIGGRAPH 2012 course, §3.4:
//!
//! * ψ(F) = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)², I₁ = ‖F‖²_F, J = det F
//! * P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ
//!
//! **J floor.** ln J is undefined for J ≤ 0. Below
//! [`NEO_HOOKEAN_J_FLOOR`] = J_min = 0.2, ln J is replaced by its first-order
//! Taylor extension L(J) = ln J_min + (J − J_min)/J_min, and F⁻ᵀ = cof F / J
//! by L'(J) cof F = cof F / J_min. ψ and P therefore stay finite and
//! continuous (ψ is C¹) for degenerate and inverted F; below J_min the
//! volumetric term λ/2 L² is a quadratic penalty in J of stiffness
//! λ/J_min² = 25 λ instead of the logarithmic barrier. The floor is a
//! safeguard, chosen by measurement (docs/STABILITY.md, cases 1 and 4): with
//! J_min = 1e-6 an inverted element carried a penalty of ∝ λ 10¹² and P2, P3
//! and Q2 blew up when squashed to 10 % (energies 10⁹–10¹¹ J) and inverted P3
//! starts spiked to 10⁴ × their initial energy; with 0.01–0.1 the P3 squash
//! still overshot its bound; with 0.2 every element type squashes to 10 % and
//! comes back, and inverted starts never exceed their initial energy. Only
//! states compressed below a fifth of their volume differ from the textbook
//! model; stable Neo-Hookean ([`super::stable_neo_hookean`]) remains the model
//! meant for inverting elements. For
//! J ≥ J_min the exact formulas are used. In terms of L:
//!
//! * ψ = μ/2 (I₁ − 3 − 2L) + λ/2 L², P = μF + (λL − μ) L' cof F
//! * dP(F; dF) = μ dF + g'(J) (cof F : dF) cof F + g(J) d cof(F; dF),
//!   with g = (λL − μ) L', g' = λ L'² + (λL − μ) L'' (L'' = −1/J² above the
//!   floor, 0 below), cof F = [f1×f2, f2×f0, f0×f1].
//!
//! I₁ − 3 − 2 ln J ≥ 0 for all F with J > 0 (AM–GM: I₁ ≥ 3 J^{2/3}); its
//! rounding-level negative values are clamped to 0, so ψ ≥ 0 whenever λ ≥ 0.
//!
//! Split (exact, offset 0):
//!
//! * deviatoric C = sqrt(I₁ − 3 − 2 ln J), k = μ; sqrt form: scale = C,
//!   grad_f_scaled = ∂(C²/2)/∂F = F − F⁻ᵀ
//! * hydrostatic C = ln J, k = λ, ∂C/∂F = F⁻ᵀ
//!
//! (with ln J and F⁻ᵀ replaced by L and L' cof F below the floor).

use super::{
    HyperelasticModel, Lame, Mat3, Mat9, SplitModel, SplitTerm, cofactor, cofactor_directional, det_minus_one,
    dpdf_from_directional, first_invariant_minus_three, node_block_from_directional,
};

/// J below which ln J is continued linearly (see the module doc).
pub const NEO_HOOKEAN_J_FLOOR: f64 = 0.2;

/// L(J) with its first two derivatives.
struct LogJ {
    value: f64,
    d1: f64,
    d2: f64,
}

fn log_j(f: &Mat3) -> LogJ {
    let j_minus_1 = det_minus_one(f);
    let j = 1.0 + j_minus_1;
    if j >= NEO_HOOKEAN_J_FLOOR {
        let d1 = 1.0 / j;
        LogJ { value: j_minus_1.ln_1p(), d1, d2: -d1 * d1 }
    } else {
        let d1 = 1.0 / NEO_HOOKEAN_J_FLOOR;
        LogJ { value: NEO_HOOKEAN_J_FLOOR.ln() + (j - NEO_HOOKEAN_J_FLOOR) * d1, d1, d2: 0.0 }
    }
}

/// I₁ − 3 − 2L, clamped at 0.
fn deviatoric_square(f: &Mat3, log: &LogJ) -> f64 {
    (first_invariant_minus_three(f) - 2.0 * log.value).max(0.0)
}

fn energy(l: Lame, f: &Mat3, log: &LogJ) -> f64 {
    0.5 * l.mu_pa * deviatoric_square(f, log) + 0.5 * l.lambda_pa * log.value * log.value
}

/// Compressible Neo-Hookean, as registered in [`super::MaterialModel::ALL`].
#[derive(Clone, Copy, Debug)]
pub struct NeoHookean;

impl HyperelasticModel for NeoHookean {
    fn name(&self) -> &'static str {
        "nh"
    }

    fn long_name(&self) -> &'static str {
        "compressible Neo-Hookean"
    }

    /// Below [`NEO_HOOKEAN_J_FLOOR`] ln J is continued linearly (C¹ only).
    fn smooth_above_det_f(&self) -> f64 {
        NEO_HOOKEAN_J_FLOOR
    }

    fn energy_density(&self, l: Lame, f: &Mat3) -> f64 {
        energy(l, f, &log_j(f))
    }

    fn energy_density_and_pk1(&self, l: Lame, f: &Mat3) -> (f64, Mat3) {
        let log = log_j(f);
        let psi = energy(l, f, &log);
        let p = f * l.mu_pa + cofactor(f) * ((l.lambda_pa * log.value - l.mu_pa) * log.d1);
        (psi, p)
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
impl SplitModel for NeoHookean {
    fn split_terms(&self, _l: Lame, f: &Mat3) -> [SplitTerm; 2] {
        let log = log_j(f);
        let inv_t = cofactor(f) * log.d1;
        let c_dev = deviatoric_square(f, &log).sqrt();
        [
            SplitTerm { value: c_dev, scale: c_dev, grad_f_scaled: f - inv_t },
            SplitTerm { value: log.value, scale: 1.0, grad_f_scaled: inv_t },
        ]
    }

    fn split_stiffness_pa(&self, l: Lame) -> [f64; 2] {
        [l.mu_pa, l.lambda_pa]
    }

    fn split_energy_offset(&self, _l: Lame) -> f64 {
        0.0
    }

    /// `C_h = ln J` (continued linearly below the floor): `d(L' cof F)[dF] = L' d(cof F)[dF] +
    /// L'' (cof F : dF) cof F`.
    fn hydrostatic_hessian(&self, _l: Lame, f: &Mat3) -> Mat9 {
        dpdf_from_directional(hydrostatic_directional(f))
    }

    /// Three directional derivatives where the 9 × 9 takes nine.
    fn hydrostatic_node_block(&self, _l: Lame, f: &Mat3, g: &nalgebra::Vector3<f64>) -> Mat3 {
        node_block_from_directional(hydrostatic_directional(f), g)
    }
}

/// `d(∂C_h/∂F)[dF]` of `C_h = ln J` ([`SplitModel::hydrostatic_hessian`]'s doc).
fn hydrostatic_directional(f: &Mat3) -> impl Fn(&Mat3) -> Mat3 + '_ {
    let log = log_j(f);
    let cof = cofactor(f);
    move |df| cofactor_directional(f, df) * log.d1 + cof * (log.d2 * cof.dot(df))
}

/// `dP[dF] = μ dF + g'(J) (cof F : dF) cof F + g(J) d(cof F)[dF]`, `g = (λ ln J − μ) (ln J)'`.
fn linearisation(l: Lame, f: &Mat3) -> impl Fn(&Mat3) -> Mat3 + '_ {
    let log = log_j(f);
    let cof = cofactor(f);
    let a = l.lambda_pa * log.value - l.mu_pa;
    let g = a * log.d1;
    let dg = l.lambda_pa * log.d1 * log.d1 + a * log.d2;
    move |df| df * l.mu_pa + cof * (dg * cof.dot(df)) + cofactor_directional(f, df) * g
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::super::{Mat3, Material, MaterialModel};
    use super::NEO_HOOKEAN_J_FLOOR;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    const MODEL: MaterialModel = MaterialModel::NeoHookean;

    #[test]
    fn energy_nonnegative() {
        testing::check_energy_nonnegative(MODEL, 0.0);
    }

    #[test]
    fn matches_textbook_formulas() {
        testing::run((testing::material(MODEL), testing::deformation(MODEL)), |(m, f)| {
            let l = m.lame();
            let j = f.determinant();
            let inv_t = f.try_inverse().expect("J > 0.25").transpose();
            let psi = 0.5 * l.mu_pa * (f.norm_squared() - 3.0) - l.mu_pa * j.ln() + 0.5 * l.lambda_pa * j.ln().powi(2);
            let p = (f - inv_t) * l.mu_pa + inv_t * (l.lambda_pa * j.ln());
            testing::check_against_formulas(&m, &f, psi, p)
        });
    }

    #[test]
    fn finite_for_inverted_and_flat_elements() {
        for nu in [-0.3, 0.0, 0.3, 0.49] {
            let m = Material::new(MODEL, 1.0e6, nu, 1000.0).expect("valid");
            for f in [
                Mat3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)),
                Mat3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)),
                Mat3::from_diagonal(&Vector3::new(-2.0, -3.0, -4.0)),
                Mat3::zeros(),
            ] {
                assert!(testing::all_finite(&m, &f), "ν = {nu}, F = {f}");
            }
            // Inverted energy is a steep penalty far above the rest energy.
            let e_inv = m.energy_density(&Mat3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)));
            let e_flat = m.energy_density(&Mat3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0)));
            if nu >= 0.0 {
                assert!(e_inv > e_flat && e_flat > 0.0);
            }
        }
        testing::run((testing::material(MODEL), testing::general_matrix(2.0)), |(m, f)| {
            prop_assert!(testing::all_finite(&m, &f));
            Ok(())
        });
    }

    /// Below the floor the continuation is smooth, so the derivative
    /// identities hold there too.
    #[test]
    fn derivatives_hold_below_the_floor() {
        testing::run(
            (testing::material(MODEL), testing::general_matrix(1.5))
                .prop_filter("clearly inverted", |(_, f)| f.determinant() < -0.05),
            |(m, f)| {
                let mu = m.lame().mu_pa;
                let (psi, p) = m.energy_density_and_pk1(&f);
                let fd = testing::fd_gradient(&f, |g| m.energy_density(g));
                prop_assert!((p - fd).norm() <= 1e-6 * (p.norm() + mu));
                let h = m.dpdf(&f);
                let fd = testing::fd_jacobian(&f, |g| m.pk1(g));
                prop_assert!((h - fd).norm() <= 1e-6 * (h.norm() + mu));
                let k = m.split_stiffness_pa();
                let t = m.split_terms(&f);
                let split = 0.5 * k[0] * t[0].value.powi(2) + 0.5 * k[1] * t[1].value.powi(2);
                prop_assert!((split - psi).abs() <= 1e-9 * (psi.abs() + mu));
                Ok(())
            },
        );
    }

    #[test]
    fn continuous_across_the_floor() {
        let m = Material::new(MODEL, 1.0e6, 0.4, 1000.0).expect("valid");
        let at = |j: f64| Mat3::from_diagonal(&Vector3::new(j, 1.0, 1.0));
        let eps = 1e-9 * NEO_HOOKEAN_J_FLOOR;
        let (psi_lo, p_lo) = m.energy_density_and_pk1(&at(NEO_HOOKEAN_J_FLOOR - eps));
        let (psi_hi, p_hi) = m.energy_density_and_pk1(&at(NEO_HOOKEAN_J_FLOOR + eps));
        assert!((psi_lo - psi_hi).abs() <= 1e-6 * psi_hi.abs(), "{psi_lo} vs {psi_hi}");
        assert!((p_lo - p_hi).norm() <= 1e-6 * p_hi.norm(), "{p_lo} vs {p_hi}");
        let [_, hyd] = m.split_terms(&at(NEO_HOOKEAN_J_FLOOR));
        assert!((hyd.value - NEO_HOOKEAN_J_FLOOR.ln()).abs() < 1e-9);
    }

    #[test]
    fn split_constants() {
        let m = Material::new(MODEL, 2.0e6, 0.3, 1000.0).expect("valid");
        let l = m.lame();
        assert_eq!(m.split_stiffness_pa(), [l.mu_pa, l.lambda_pa]);
        assert_eq!(m.split_energy_offset(), 0.0);
        assert_eq!(NEO_HOOKEAN_J_FLOOR, 0.2);
    }
}
