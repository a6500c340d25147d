//! Saint-Venant–Kirchhoff (`stvk`), the model of Saillant et al.,
//! *High-Order Elements in Position Based Dynamics* (and e.g. Bonet & Wood,
//! *Nonlinear Continuum Mechanics for Finite Element Analysis*, §6.4.2).
//!
//! With the Green–Lagrange strain E = ½(FᵀF − I):
//!
//! * ψ(F) = μ E:E + λ/2 (tr E)²
//! * S = 2μE + λ (tr E) I (second Piola–Kirchhoff), P = F S
//! * dP(F; dF) = dF S + F dS, with dE = ½(dFᵀF + FᵀdF), dS = 2μ dE + λ tr(dE) I
//!
//! Split (exact, offset 0):
//!
//! * deviatoric C = ‖E‖_F, k = 2μ; sqrt form: scale = C, grad_f_scaled = ∂(½E:E)/∂F = F E
//! * hydrostatic C = tr E, k = λ, ∂C/∂F = F
//!
//! ψ ≥ 0 for every valid ν since μ E:E ≥ μ (tr E)²/3 and λ + 2μ/3 > 0.
//! The model softens and eventually inverts under strong compression
//! (its tangent is then indefinite; use [`super::Material::dpdf_projected`]).
//!
//! E is evaluated as ½(H + Hᵀ + HᵀH) with H = F − I, which is exact at rest.

use super::{Lame, Mat3, Mat9, SplitTerm, dpdf_from_directional};

fn green_strain(f: &Mat3) -> Mat3 {
    let h = f - Mat3::identity();
    (h + h.transpose() + h.transpose() * h) * 0.5
}

fn second_piola(l: Lame, e: &Mat3) -> Mat3 {
    e * (2.0 * l.mu_pa) + Mat3::identity() * (l.lambda_pa * e.trace())
}

fn energy_from_strain(l: Lame, e: &Mat3) -> f64 {
    let tr = e.trace();
    l.mu_pa * e.norm_squared() + 0.5 * l.lambda_pa * tr * tr
}

pub(super) fn energy_density(l: Lame, f: &Mat3) -> f64 {
    energy_from_strain(l, &green_strain(f))
}

pub(super) fn energy_density_and_pk1(l: Lame, f: &Mat3) -> (f64, Mat3) {
    let e = green_strain(f);
    (energy_from_strain(l, &e), f * second_piola(l, &e))
}

pub(super) fn dpdf(l: Lame, f: &Mat3) -> Mat9 {
    let s = second_piola(l, &green_strain(f));
    let ft = f.transpose();
    dpdf_from_directional(|df| {
        let de = (df.transpose() * f + ft * df) * 0.5;
        let ds = second_piola(l, &de);
        df * s + f * ds
    })
}

pub(super) fn split_terms(f: &Mat3) -> [SplitTerm; 2] {
    let e = green_strain(f);
    let c_dev = e.norm();
    [
        SplitTerm { value: c_dev, scale: c_dev, grad_f_scaled: f * e },
        SplitTerm { value: e.trace(), scale: 1.0, grad_f_scaled: *f },
    ]
}

pub(super) fn split_stiffness_pa(l: Lame) -> [f64; 2] {
    [2.0 * l.mu_pa, l.lambda_pa]
}

pub(super) fn split_energy_offset(_l: Lame) -> f64 {
    0.0
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::super::{Mat3, Material, MaterialModel};
    use proptest::prelude::*;

    const MODEL: MaterialModel = MaterialModel::StVenantKirchhoff;

    common_model_tests!(MODEL);

    #[test]
    fn energy_nonnegative() {
        testing::check_energy_nonnegative(MODEL, -0.45);
    }

    #[test]
    fn matches_textbook_formulas() {
        testing::run((testing::material(MODEL), testing::deformation(MODEL)), |(m, f)| {
            let l = m.lame();
            let e = (f.transpose() * f - Mat3::identity()) * 0.5;
            let psi = l.mu_pa * (e.transpose() * e).trace() + 0.5 * l.lambda_pa * e.trace().powi(2);
            let s = e * (2.0 * l.mu_pa) + Mat3::identity() * (l.lambda_pa * e.trace());
            let p = f * s;
            let (psi_got, p_got) = m.energy_density_and_pk1(&f);
            prop_assert!((psi - psi_got).abs() <= 1e-10 * (psi.abs() + l.mu_pa));
            prop_assert!((p - p_got).norm() <= 1e-10 * (p.norm() + l.mu_pa));
            Ok(())
        });
    }

    #[test]
    fn split_constants() {
        let m = Material::new(MODEL, 2.0e6, 0.3, 1000.0).expect("valid");
        let l = m.lame();
        assert_eq!(m.split_stiffness_pa(), [2.0 * l.mu_pa, l.lambda_pa]);
        assert_eq!(m.split_energy_offset(), 0.0);
    }

    #[test]
    fn tangent_is_indefinite_under_strong_compression_and_projection_fixes_it() {
        let m = Material::new(MODEL, 1.0e6, 0.3, 1000.0).expect("valid");
        let f = Mat3::identity() * 0.5;
        let h = m.dpdf(&f);
        assert!(testing::min_eigenvalue(&h) < 0.0);
        let p = m.dpdf_projected(&f);
        assert!(testing::min_eigenvalue(&p) >= -1e-9 * p.norm());
        assert!((p - h).norm() > 1e-3 * h.norm());
    }
}
