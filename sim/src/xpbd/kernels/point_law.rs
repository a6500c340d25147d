//! The material law the sweep is generic over ([`PointMaterial`]): `(ψ(F), P(F))` at one
//! quadrature point. [`Stvk`] is Saint-Venant–Kirchhoff with its Lamé parameters computed once
//! per sweep, through the one StVK point law ([`crate::material::stvk::energy_and_pk1`]); every
//! other model goes through [`AnyMaterial`] (its registered law: one indirect call per point).

use crate::material::lane::{self, Scalar};
use crate::material::{Mat3, Material, stvk};

/// `(ψ(F), P(F))` at one quadrature point: the material law the kernel is generic over.
pub trait PointMaterial: Sync {
    /// `FMA`: products may use fused multiply–adds ([`mul3`](super::mul3)).
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3);
}

/// Saint-Venant–Kirchhoff with its Lamé parameters computed once per sweep: the one StVK point
/// law, [`crate::material::stvk::energy_and_pk1`], on one `f64` (fused multiply–adds with `FMA`).
#[derive(Clone, Copy, Debug)]
pub struct Stvk {
    pub mu_pa: f64,
    pub lambda_pa: f64,
}

impl PointMaterial for Stvk {
    #[inline(always)]
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3) {
        let (psi, p) =
            stvk::energy_and_pk1::<Scalar<FMA>>(Scalar(self.mu_pa), Scalar(self.lambda_pa), &lane::from_mat3(f));
        (psi.0, lane::to_mat3(&p))
    }
}

/// Any material, through [`Material::energy_density_and_pk1`].
#[derive(Clone, Copy, Debug)]
pub struct AnyMaterial<'a>(pub &'a Material);

impl PointMaterial for AnyMaterial<'_> {
    #[inline(always)]
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3) {
        self.0.energy_density_and_pk1(f)
    }
}
