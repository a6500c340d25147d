//! The material law the per-element kernels are generic over ([`PointMaterial`]): `(ψ(F), P(F))`
//! at one quadrature point (XPBD's sweep, `crate::xpbd::kernels`; the element energy and
//! gradient, `crate::fem::energy`). [`Stvk`] is Saint-Venant–Kirchhoff with its Lamé parameters
//! computed once per sweep or mesh pass (bit for bit [`crate::material::stvk::energy_and_pk1`], tested); every
//! other model goes through [`AnyMaterial`] (its registered law: one indirect call per point).

use crate::material::{Mat3, Material};

/// `(ψ(F), P(F))` at one quadrature point: the material law the kernel is generic over.
pub trait PointMaterial: Sync {
    /// `FMA`: products may use fused multiply–adds ([`mul3`](crate::math::soa::mul3)).
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3);
}

/// Saint-Venant–Kirchhoff with its Lamé parameters computed once per sweep, in nalgebra's
/// column-major form: `E = ½(H + Hᵀ + HᵀH)`, `H = F − I`, `S = 2μE + λ tr(E) I` (λ on the diagonal
/// only), `ψ = μ E:E + λ/2 tr(E)²`, `P = F S`. The same law as
/// [`crate::material::stvk::energy_and_pk1`] bit for bit (tested), written out here because the
/// lane-generic form, run on one `f64` through row-major arrays, made the Q2 serial sweep 7–8 %
/// slower (release `bench_table`, 3.60–3.71 ms against 3.88–4.00 ms per frame, same machine, one run).
#[derive(Clone, Copy, Debug)]
pub struct Stvk {
    pub mu_pa: f64,
    pub lambda_pa: f64,
}

impl PointMaterial for Stvk {
    #[inline(always)]
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3) {
        let h = f - Mat3::identity();
        let e = (h + h.transpose() + crate::math::soa::tr_mul3::<FMA>(&h, &h)) * 0.5;
        let tr = e.trace();
        let mut s = e * (2.0 * self.mu_pa);
        let lt = self.lambda_pa * tr;
        s[(0, 0)] += lt;
        s[(1, 1)] += lt;
        s[(2, 2)] += lt;
        let psi = self.mu_pa * e.norm_squared() + 0.5 * self.lambda_pa * tr * tr;
        (psi, crate::math::soa::mul3::<FMA>(f, &s))
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
