//! Four doubles per 256-bit register (AVX2 + FMA): the lane type [`F64x4`], a [`Lane`] so that
//! the point laws written over lanes ([`crate::math::lane`]) run four at a time on it, and the one
//! runtime check that the CPU has both features ([`available`]).
//!
//! Every method is `#[inline(always)]` and only called from functions compiled with
//! `#[target_feature(enable = "avx2,fma")]`, which run only where [`available`] said yes: the
//! XPBD batches (`crate::xpbd::kernels`), StVK's four-lane node law and VBD's fused paths.

use super::lane::{Lane, M3};
use std::arch::x86_64::*;

/// Whether this CPU has AVX2 and FMA, which every function of this module needs (the runtime
/// check before any of them runs).
#[inline]
pub fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Four doubles, one per element.
#[derive(Clone, Copy)]
pub struct F64x4(pub __m256d);

// Every method is inlined into `batches_avx2`, which is compiled with AVX2 and FMA and only
// called where the CPU has both.
impl F64x4 {
    #[inline(always)]
    pub fn splat(v: f64) -> Self {
        Self(unsafe { _mm256_set1_pd(v) })
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Self(unsafe { _mm256_setzero_pd() })
    }
    /// `[a, b, c, d]` in lanes 0..3.
    #[inline(always)]
    pub fn new(a: f64, b: f64, c: f64, d: f64) -> Self {
        Self(unsafe { _mm256_set_pd(d, c, b, a) })
    }
    /// # Safety
    /// `p` points to four doubles.
    #[inline(always)]
    pub unsafe fn load(p: *const f64) -> Self {
        Self(unsafe { _mm256_loadu_pd(p) })
    }
    /// # Safety
    /// `p` points to four writable doubles.
    #[inline(always)]
    pub unsafe fn store(self, p: *mut f64) {
        unsafe { _mm256_storeu_pd(p, self.0) }
    }
    /// Lane `k` holds the sum of `v[k]`'s four lanes (`(a₀ + a₁) + (a₂ + a₃)`).
    #[inline(always)]
    pub fn horizontal_sums(v: [Self; 4]) -> Self {
        unsafe {
            let h01 = _mm256_hadd_pd(v[0].0, v[1].0); // a0+a1, b0+b1, a2+a3, b2+b3
            let h23 = _mm256_hadd_pd(v[2].0, v[3].0);
            let low = _mm256_permute2f128_pd::<0x20>(h01, h23);
            let high = _mm256_permute2f128_pd::<0x31>(h01, h23);
            Self(_mm256_add_pd(low, high))
        }
    }
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        Self(unsafe { _mm256_add_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub fn sub(self, o: Self) -> Self {
        Self(unsafe { _mm256_sub_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        Self(unsafe { _mm256_mul_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub fn div(self, o: Self) -> Self {
        Self(unsafe { _mm256_div_pd(self.0, o.0) })
    }
    /// `self · b + c`, one rounding.
    #[inline(always)]
    pub fn fma(self, b: Self, c: Self) -> Self {
        Self(unsafe { _mm256_fmadd_pd(self.0, b.0, c.0) })
    }
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }
    /// `f64::max` per lane for a non-NaN `o` (a NaN `self` gives `o`, as `f64::max`).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        // maxpd returns its second operand when either is NaN
        Self(unsafe { _mm256_max_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub fn neg(self) -> Self {
        Self::zero().sub(self)
    }
    /// All-ones lanes where `self > o` (false for NaN).
    #[inline(always)]
    pub fn gt(self, o: Self) -> Self {
        Self(unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, o.0) })
    }
    /// All-ones lanes where `self != o` or either is NaN.
    #[inline(always)]
    pub fn ne(self, o: Self) -> Self {
        Self(unsafe { _mm256_cmp_pd::<_CMP_NEQ_UQ>(self.0, o.0) })
    }
    /// All-ones lanes where `self` is finite.
    #[inline(always)]
    pub fn finite(self) -> Self {
        // x·0 is 0 for a finite x and NaN otherwise
        Self(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(self.mul(Self::zero()).0, _mm256_setzero_pd()) })
    }
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        Self(unsafe { _mm256_and_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        Self(unsafe { _mm256_or_pd(self.0, o.0) })
    }
    /// Bit `l` set where lane `l`'s sign bit is (an all-ones mask lane).
    #[inline(always)]
    pub fn mask_bits(self) -> u32 {
        unsafe { _mm256_movemask_pd(self.0) as u32 }
    }
    /// `self` where `mask`, else `other`.
    #[inline(always)]
    pub fn select(mask: Self, a: Self, other: Self) -> Self {
        Self(unsafe { _mm256_blendv_pd(other.0, a.0, mask.0) })
    }
    #[inline(always)]
    pub fn lanes(self) -> [f64; 4] {
        let mut out = [0.0; 4];
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }
}

impl Lane for F64x4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self::splat(v)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::add(self, o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::sub(self, o)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::mul(self, o)
    }
    /// Fused.
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        self.fma(b, c)
    }
    /// One chain of fused multiply–adds, column by column: `m₂₂ m₂₂ + (… + (m₀₀ m₀₀ + 0))`.
    #[inline(always)]
    fn sum_of_squares(m: &M3<Self>) -> Self {
        let mut sum = Self::zero();
        for c in 0..3 {
            for r in 0..3 {
                sum = m[r][c].fma(m[r][c], sum);
            }
        }
        sum
    }
}
