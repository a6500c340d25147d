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
//!
//! **The point law is written once**, [`energy_and_pk1`], over any [`Lane`]: this module's
//! functions run it on one `f64`, the scalar kernels on one `f64` with fused multiply–adds, and
//! the P1 batches (`crate::xpbd::kernels::p1`) on four or eight elements at a time. Its NaN rule:
//! λ tr(E) is added to the diagonal of S only, so a non-finite tr(E) leaves the off-diagonal
//! (shear) stress as 2μE; a NaN or infinite entry of F otherwise propagates into ψ and P.

use super::{
    FastLaw, HyperelasticModel, Lame, Mat3, Mat9, NodeVisit, NodeVisitKernel, SplitModel, SplitTerm,
    dpdf_from_directional,
};
use crate::math::lane::{Lane, M3, Scalar, from_mat3, to_mat3, tr_mat_mul};
use nalgebra::Vector3;

/// E = ½(H + Hᵀ + HᵀH), H = F − I (Green–Lagrange).
#[inline(always)]
pub fn green_strain<L: Lane>(f: &M3<L>) -> M3<L> {
    // plain loops, no closures: see the note in super::lane
    let one = L::splat(1.0);
    let mut h = *f;
    for i in 0..3 {
        h[i][i] = f[i][i].sub(one);
    }
    let hth = tr_mat_mul(&h, &h);
    let half = L::splat(0.5);
    let mut e = hth;
    for r in 0..3 {
        for c in 0..3 {
            e[r][c] = h[r][c].add(h[c][r]).add(hth[r][c]).mul(half);
        }
    }
    e
}

/// tr E.
#[inline(always)]
fn trace<L: Lane>(e: &M3<L>) -> L {
    e[0][0].add(e[1][1]).add(e[2][2])
}

/// S = 2μE + λ tr(E) I (the λ term on the diagonal only), given `tr` = tr E.
#[inline(always)]
pub fn second_piola<L: Lane>(mu: L, lambda: L, e: &M3<L>, tr: L) -> M3<L> {
    let two_mu = L::splat(2.0).mul(mu);
    let lt = lambda.mul(tr);
    let mut s = *e;
    for r in 0..3 {
        for c in 0..3 {
            s[r][c] = e[r][c].mul(two_mu);
        }
        s[r][r] = s[r][r].add(lt);
    }
    s
}

/// ψ = μ E:E + λ/2 (tr E)², given `tr` = tr E.
#[inline(always)]
pub fn energy_from_strain<L: Lane>(mu: L, lambda: L, e: &M3<L>, tr: L) -> L {
    mu.mul(L::sum_of_squares(e)).add(L::splat(0.5).mul(lambda).mul(tr).mul(tr))
}

/// The StVK point law: `(ψ(F), P(F) = F S)` for Lamé parameters `mu`, `lambda` (Pa).
#[inline(always)]
pub fn energy_and_pk1<L: Lane>(mu: L, lambda: L, f: &M3<L>) -> (L, M3<L>) {
    let e = green_strain(f);
    let tr = trace(&e);
    let s = second_piola(mu, lambda, &e, tr);
    (energy_from_strain(mu, lambda, &e, tr), crate::math::lane::mat_mul(f, &s))
}

/// `Σ_k m_kr m_kc` (columns `r`, `c`: `(mᵀm)_rc`).
#[inline(always)]
fn col_dot<L: Lane>(m: &M3<L>, r: usize, c: usize) -> L {
    m[2][r].mul_add(m[2][c], m[1][r].mul_add(m[1][c], m[0][r].mul(m[0][c])))
}

/// `Σ_k m_rk m_ck` (rows `r`, `c`: `(m mᵀ)_rc`).
#[inline(always)]
fn row_dot<L: Lane>(m: &M3<L>, r: usize, c: usize) -> L {
    m[r][2].mul_add(m[c][2], m[r][1].mul_add(m[c][1], m[r][0].mul(m[c][0])))
}

/// `m v` for a symmetric `m` given by its entries `[m00, m11, m22, m01, m02, m12]`.
#[inline(always)]
fn sym_mul<L: Lane>(m: &[L; 6], v: &[L; 3]) -> [L; 3] {
    let [m00, m11, m22, m01, m02, m12] = *m;
    [
        m02.mul_add(v[2], m01.mul_add(v[1], m00.mul(v[0]))),
        m12.mul_add(v[2], m11.mul_add(v[1], m01.mul(v[0]))),
        m22.mul_add(v[2], m12.mul_add(v[1], m02.mul(v[0]))),
    ]
}

/// `m v` for a full `m`.
#[inline(always)]
fn mat_vec<L: Lane>(m: &M3<L>, v: &[L; 3]) -> [L; 3] {
    let mut out = [v[0]; 3];
    for r in 0..3 {
        out[r] = m[r][2].mul_add(v[2], m[r][1].mul_add(v[1], m[r][0].mul(v[0])));
    }
    out
}

/// One node's share at one point ([`HyperelasticModel::node_force_and_block`]) in closed form,
/// written once over [`Lane`]s (one point on [`Scalar`], four on the AVX2 lanes of
/// [`node_visit_avx2`]): `P g = F (S g)` and `B = (g·S g) I + (μ + λ) u ⊗ u + μ |g|² F Fᵀ`,
/// `u = F g`, on the six independent entries of the symmetric `E`, `S` and `B`
/// (`[b00, b11, b22, b01, b02, b12]`). `E = (H + Hᵀ + HᵀH)/2` with `H = F − I`, as
/// [`green_strain`] forms it.
#[inline(always)]
pub fn node_point<L: Lane>(mu: L, lambda: L, f: &M3<L>, g: &[L; 3]) -> ([L; 3], [L; 6]) {
    let (one, half) = (L::splat(1.0), L::splat(0.5));
    let mut h = *f;
    for i in 0..3 {
        h[i][i] = f[i][i].sub(one);
    }
    let mut e = [one; 6];
    for (k, (r, c)) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
        e[k] = h[r][c].add(h[c][r]).add(col_dot(&h, r, c)).mul(half);
    }
    let (two_mu, lt) = (mu.add(mu), lambda.mul(e[0].add(e[1]).add(e[2])));
    let mut s = e;
    for (k, sk) in s.iter_mut().enumerate() {
        *sk = if k < 3 { two_mu.mul_add(e[k], lt) } else { two_mu.mul(e[k]) };
    }
    let sg = sym_mul(&s, g);
    let u = mat_vec(f, g);
    let c_uu = mu.add(lambda);
    let c_ff = mu.mul(g[2].mul_add(g[2], g[1].mul_add(g[1], g[0].mul(g[0]))));
    let diag = g[2].mul_add(sg[2], g[1].mul_add(sg[1], g[0].mul(sg[0])));
    let mut b = [one; 6];
    for (k, (r, c)) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
        b[k] = c_ff.mul_add(row_dot(f, r, c), c_uu.mul(u[r]).mul(u[c]));
        if k < 3 {
            b[k] = b[k].add(diag);
        }
    }
    (mat_vec(f, &sg), b)
}

/// A symmetric block from its entries `[b00, b11, b22, b01, b02, b12]`.
fn sym_mat3(b: &[f64; 6]) -> Mat3 {
    let [b00, b11, b22, b01, b02, b12] = *b;
    Mat3::new(b00, b01, b02, b01, b11, b12, b02, b12, b22)
}

/// [`HyperelasticModel::node_visit`] four points at a time, one chunk of the lane-major visit
/// per AVX2 register (padding has zero volume).
///
/// # Safety
/// The CPU has AVX2 and FMA; `p.width` is 4.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn node_visit_avx2(l: Lame, p: NodeVisit<'_>) -> (Vector3<f64>, Mat3) {
    use crate::math::f64x4::F64x4;
    assert_eq!(p.width, 4, "a four-lane kernel given a visit {} lanes wide", p.width);
    let (mu, lambda) = (F64x4::splat(l.mu_pa), F64x4::splat(l.lambda_pa));
    let (mut force, mut block) = ([F64x4::zero(); 3], [F64x4::zero(); 6]);
    // whole chunks only, so every load below is in bounds
    let chunks = (p.volumes.len() / 4).min(p.f.len() / 36).min(p.grads.len() / 12);
    for k in 0..chunks {
        // SAFETY: in bounds (whole chunks)
        let at = |s: &[f64], i: usize| unsafe { F64x4::load(s.as_ptr().add(4 * i)) };
        let f: [[F64x4; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| at(p.f, 9 * k + 3 * r + c)));
        let g: [F64x4; 3] = std::array::from_fn(|c| at(p.grads, 3 * k + c));
        let v = at(p.volumes, k);
        let (fo, bo) = node_point(mu, lambda, &f, &g);
        for i in 0..3 {
            force[i] = fo[i].fma(v, force[i]);
        }
        for i in 0..6 {
            block[i] = bo[i].fma(v, block[i]);
        }
    }
    let zero = F64x4::zero();
    let [f0, f1, f2, b0] = F64x4::horizontal_sums([force[0], force[1], force[2], block[0]]).lanes();
    let [b1, b2, b3, b4] = F64x4::horizontal_sums([block[1], block[2], block[3], block[4]]).lanes();
    let [b5, ..] = F64x4::horizontal_sums([block[5], zero, zero, zero]).lanes();
    (Vector3::new(f0, f1, f2), sym_mat3(&[b0, b1, b2, b3, b4, b5]))
}

/// E of an nalgebra F (plain `f64`).
fn strain(f: &Mat3) -> Mat3 {
    to_mat3(&green_strain(&from_mat3::<false>(f)))
}

/// S of an nalgebra E (plain `f64`).
fn stress(l: Lame, e: &Mat3) -> Mat3 {
    let e: M3<Scalar<false>> = from_mat3(e);
    to_mat3(&second_piola(Scalar(l.mu_pa), Scalar(l.lambda_pa), &e, trace(&e)))
}

/// Saint-Venant–Kirchhoff, as registered in [`super::MaterialModel::ALL`].
#[derive(Clone, Copy, Debug)]
pub struct StVenantKirchhoff;

impl HyperelasticModel for StVenantKirchhoff {
    fn fast_law(&self, l: Lame) -> Option<FastLaw> {
        Some(FastLaw::StVenantKirchhoff(l))
    }
    fn name(&self) -> &'static str {
        "stvk"
    }

    fn long_name(&self) -> &'static str {
        "Saint-Venant–Kirchhoff"
    }

    fn energy_density(&self, l: Lame, f: &Mat3) -> f64 {
        let e = green_strain(&from_mat3::<false>(f));
        energy_from_strain(Scalar(l.mu_pa), Scalar(l.lambda_pa), &e, trace(&e)).0
    }

    fn energy_density_and_pk1(&self, l: Lame, f: &Mat3) -> (f64, Mat3) {
        let (psi, p) = energy_and_pk1::<Scalar<false>>(Scalar(l.mu_pa), Scalar(l.lambda_pa), &from_mat3(f));
        (psi.0, to_mat3(&p))
    }

    fn dpdf(&self, l: Lame, f: &Mat3) -> Mat9 {
        dpdf_from_directional(linearisation(l, f))
    }

    fn node_block(&self, l: Lame, f: &Mat3, g: &nalgebra::Vector3<f64>) -> Mat3 {
        self.node_force_and_block(l, f, g).1
    }

    /// Closed form: with `dF = e_k ⊗ g`, `dE = (g ⊗ F_kᵀ + F_kᵀ ⊗ g)/2` (`F_k` row `k`), so
    /// column `k` of `B` is `(g·S g) e_k + (μ + λ)(F g)_k F g + μ |g|² (F Fᵀ) e_k`:
    /// `B = (g·S g) I + (μ + λ) u ⊗ u + μ |g|² F Fᵀ`, `u = F g`, and `P g = F (S g)`.
    fn node_force_and_block(&self, l: Lame, f: &Mat3, g: &Vector3<f64>) -> (Vector3<f64>, Mat3) {
        let g = [Scalar::<false>(g[0]), Scalar(g[1]), Scalar(g[2])];
        let (force, b) = node_point(Scalar(l.mu_pa), Scalar(l.lambda_pa), &from_mat3::<false>(f), &g);
        (Vector3::new(force[0].0, force[1].0, force[2].0), sym_mat3(&b.map(|x| x.0)))
    }

    /// Four points per AVX2 register where the CPU has it and the visit is four lanes wide.
    fn node_visit(&self, l: Lame, points: NodeVisit<'_>) -> (Vector3<f64>, Mat3) {
        if let Some(kernel) = self.node_visit_kernel(points.width) {
            // SAFETY: the kernel is for this width on this CPU
            return unsafe { kernel(l, points) };
        }
        points.sum(|f, g| self.node_force_and_block(l, f, g))
    }

    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    fn node_visit_kernel(&self, width: usize) -> Option<NodeVisitKernel> {
        #[cfg(target_arch = "x86_64")]
        if width == 4 && crate::math::f64x4::available() {
            return Some(node_visit_avx2);
        }
        None
    }

    fn split(&self) -> Option<&dyn SplitModel> {
        Some(self)
    }
}

/// The split formulation's two constraints (XPBD's `Formulation::Split`).
impl SplitModel for StVenantKirchhoff {
    fn split_terms(&self, _l: Lame, f: &Mat3) -> [SplitTerm; 2] {
        let e = strain(f);
        let c_dev = e.norm();
        [
            SplitTerm { value: c_dev, scale: c_dev, grad_f_scaled: f * e },
            SplitTerm { value: e.trace(), scale: 1.0, grad_f_scaled: *f },
        ]
    }

    fn split_stiffness_pa(&self, l: Lame) -> [f64; 2] {
        [2.0 * l.mu_pa, l.lambda_pa]
    }

    fn split_energy_offset(&self, _l: Lame) -> f64 {
        0.0
    }

    /// `C_h = tr E = (F : F − 3)/2`: its second derivative is the identity.
    fn hydrostatic_hessian(&self, _l: Lame, _f: &Mat3) -> Mat9 {
        Mat9::identity()
    }

    /// `|g|² I`.
    fn hydrostatic_node_block(&self, _l: Lame, _f: &Mat3, g: &Vector3<f64>) -> Mat3 {
        Mat3::identity() * g.norm_squared()
    }
}

/// `dP[dF] = dF S + F S(dE)`, `dE = (dFᵀ F + Fᵀ dF)/2`.
fn linearisation(l: Lame, f: &Mat3) -> impl Fn(&Mat3) -> Mat3 + '_ {
    let s = stress(l, &strain(f));
    let ft = f.transpose();
    move |df| {
        let de = (df.transpose() * f + ft * df) * 0.5;
        let ds = stress(l, &de);
        df * s + f * ds
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::super::{Mat3, Material, MaterialModel};
    use proptest::prelude::*;

    const MODEL: MaterialModel = MaterialModel::StVenantKirchhoff;

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

    /// The shared point law on plain `f64`s gives, bit for bit, the nalgebra form it replaced:
    /// `E = (H + Hᵀ + HᵀH) ½`, `ψ = μ E:E + ½λ (tr E)²`, `P = F (2μE + λ tr(E) I)` (for finite F,
    /// where adding `0 · λ tr E` off the diagonal changes nothing).
    #[test]
    fn the_shared_law_is_bitwise_the_nalgebra_form() {
        testing::run((testing::material(MODEL), testing::general_matrix(1.5)), |(m, f)| {
            let l = m.lame();
            let h = f - Mat3::identity();
            let e = (h + h.transpose() + h.transpose() * h) * 0.5;
            let psi = l.mu_pa * e.norm_squared() + 0.5 * l.lambda_pa * e.trace() * e.trace();
            let p = f * (e * (2.0 * l.mu_pa) + Mat3::identity() * (l.lambda_pa * e.trace()));
            let (psi_got, p_got) = m.energy_density_and_pk1(&f);
            prop_assert_eq!(psi.to_bits(), psi_got.to_bits());
            prop_assert_eq!(m.energy_density(&f).to_bits(), psi.to_bits());
            for (a, b) in p.iter().zip(p_got.iter()) {
                prop_assert_eq!(a.to_bits(), b.to_bits(), "P = {} vs {}", p, p_got);
            }
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
