//! Eight doubles per 512-bit register (AVX-512 F): the lane type [`F64x8`], a [`Lane`] so that
//! the point laws written over lanes ([`crate::math::lane`]) run eight at a time on it, a
//! [`Wide`] so that the XPBD batches (`crate::xpbd::kernels`) are compiled for it, and the one
//! runtime check that the CPU has AVX-512 F besides AVX2 and FMA ([`available`]).
//!
//! Every method is `#[inline(always)]` and only called from functions compiled with
//! `#[target_feature(enable = "avx512f,avx2,fma")]`, which run only where [`available`] said
//! yes. Results per lane are those of [`super::f64x4::F64x4`] bit for bit: the same IEEE
//! operations, fused where that type fuses, in the same order.

use super::f64x4::{F64x4, store_rows};
use super::lane::{Lane, M3};
use super::wide::Wide;
use std::arch::x86_64::*;

/// Whether this CPU has AVX-512 F, AVX2 and FMA, which every function of this module needs.
#[inline]
pub fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f") && super::f64x4::available()
}

/// Eight doubles, one per element.
#[derive(Clone, Copy)]
pub struct F64x8(pub __m512d);

impl F64x8 {
    /// The low and high four lanes.
    #[inline(always)]
    fn halves(self) -> [F64x4; 2] {
        unsafe { [F64x4(_mm512_castpd512_pd256(self.0)), F64x4(_mm512_extractf64x4_pd::<1>(self.0))] }
    }
}

impl Lane for F64x8 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self(unsafe { _mm512_set1_pd(v) })
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(unsafe { _mm512_add_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(unsafe { _mm512_sub_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(unsafe { _mm512_mul_pd(self.0, o.0) })
    }
    /// Fused.
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Self(unsafe { _mm512_fmadd_pd(self.0, b.0, c.0) })
    }
    /// One chain of fused multiply–adds, column by column, as [`F64x4`]'s.
    #[inline(always)]
    fn sum_of_squares(m: &M3<Self>) -> Self {
        let mut sum = <Self as Wide>::zero();
        for c in 0..3 {
            for r in 0..3 {
                sum = m[r][c].mul_add(m[r][c], sum);
            }
        }
        sum
    }
}

impl Wide for F64x8 {
    const WIDTH: usize = 8;
    type Mask = __mmask8;
    #[inline]
    fn available() -> bool {
        available()
    }
    #[inline(always)]
    fn zero() -> Self {
        Self(unsafe { _mm512_setzero_pd() })
    }
    #[inline(always)]
    unsafe fn load(v: *const f64) -> Self {
        Self(unsafe { _mm512_loadu_pd(v) })
    }
    #[inline(always)]
    unsafe fn store(self, out: *mut f64) {
        unsafe { _mm512_storeu_pd(out, self.0) }
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Self(unsafe { _mm512_div_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // vmaxpd returns its second operand when either is NaN, as on AVX2
        Self(unsafe { _mm512_max_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Self::zero().sub(self)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> __mmask8 {
        unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, o.0) }
    }
    #[inline(always)]
    fn ne(self, o: Self) -> __mmask8 {
        unsafe { _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(self.0, o.0) }
    }
    #[inline(always)]
    fn finite(self) -> __mmask8 {
        // x·0 is 0 for a finite x and NaN otherwise
        let zero = Self::zero();
        unsafe { _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.mul(zero).0, zero.0) }
    }
    #[inline(always)]
    fn mask_and(a: __mmask8, b: __mmask8) -> __mmask8 {
        a & b
    }
    #[inline(always)]
    fn mask_or(a: __mmask8, b: __mmask8) -> __mmask8 {
        a | b
    }
    #[inline(always)]
    fn mask_bits(m: __mmask8) -> u32 {
        u32::from(m)
    }
    #[inline(always)]
    fn mask_none() -> __mmask8 {
        0
    }
    #[inline(always)]
    fn select(mask: __mmask8, a: Self, other: Self) -> Self {
        Self(unsafe { _mm512_mask_blend_pd(mask, other.0, a.0) })
    }
    /// One masked eight-lane gather.
    #[inline(always)]
    unsafe fn gather_f64(base: *const f64, index: &[usize], valid: u32) -> Self {
        unsafe {
            let vindex = _mm512_loadu_si512(index.as_ptr().cast());
            Self(_mm512_mask_i64gather_pd::<8>(_mm512_setzero_pd(), valid as __mmask8, vindex, base))
        }
    }
    /// Three eight-lane gathers (`3 index[l] + axis`): fewer cycles than two four-row
    /// transposes joined on the Sapphire Rapids measured (r1 beam, 8 lanes: 0.92–0.94× in
    /// three alternating pairs).
    #[inline(always)]
    unsafe fn gather_rows(base: *const crate::Vec3, index: &[usize]) -> [Self; 3] {
        unsafe {
            let vindex = _mm512_loadu_si512(index.as_ptr().cast());
            let three = _mm512_add_epi64(_mm512_add_epi64(vindex, vindex), vindex);
            let b: *const f64 = base.cast();
            [
                Self(_mm512_i64gather_pd::<8>(three, b)),
                Self(_mm512_i64gather_pd::<8>(three, b.add(1))),
                Self(_mm512_i64gather_pd::<8>(three, b.add(2))),
            ]
        }
    }
    /// Two halves through [`F64x4`]'s row stores (an eight-lane scatter was slower: 1,280 beam,
    /// 1.01–1.14× in four alternating pairs).
    #[inline(always)]
    unsafe fn scatter_rows(v: [Self; 3], base: *mut crate::Vec3, index: &[usize], lanes: u32) {
        let [x, y, z] = [v[0].halves(), v[1].halves(), v[2].halves()];
        for h in 0..2 {
            let idx = &index[4 * h..4 * h + 4];
            // SAFETY: forwarded from the caller.
            unsafe {
                store_rows(
                    [x[h], y[h], z[h]],
                    [base.add(idx[0]), base.add(idx[1]), base.add(idx[2]), base.add(idx[3])],
                    (lanes >> (4 * h)) & 0b1111,
                )
            }
        }
    }
}
