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

/// `[x, y, z, 0]` of node `p` (reads three doubles only).
///
/// # Safety
/// `p` points to a `Vec3`; only called under AVX2.
#[inline(always)]
pub unsafe fn load_row(p: *const crate::Vec3) -> __m256d {
    unsafe { _mm256_maskload_pd(p.cast(), _mm256_set_epi64x(0, -1, -1, -1)) }
}

/// Four rows `[x, y, z, ·]` (one per lane) into `[x, y, z]` lanes.
#[inline(always)]
pub fn transpose(r: [__m256d; 4]) -> [F64x4; 3] {
    unsafe {
        let t0 = _mm256_unpacklo_pd(r[0], r[1]); // x0 x1 z0 z1
        let t1 = _mm256_unpackhi_pd(r[0], r[1]); // y0 y1 ·  ·
        let t2 = _mm256_unpacklo_pd(r[2], r[3]); // x2 x3 z2 z3
        let t3 = _mm256_unpackhi_pd(r[2], r[3]); // y2 y3 ·  ·
        [
            F64x4(_mm256_permute2f128_pd::<0x20>(t0, t2)),
            F64x4(_mm256_permute2f128_pd::<0x20>(t1, t3)),
            F64x4(_mm256_permute2f128_pd::<0x31>(t0, t2)),
        ]
    }
}

/// Writes lane `l` of `v` to `out[l]` for the lanes set in `lanes`.
///
/// # Safety
/// Each `out[l]` written points to a `Vec3`; only called under AVX2.
#[inline(always)]
pub unsafe fn store_rows(v: [F64x4; 3], out: [*mut crate::Vec3; 4], lanes: u32) {
    unsafe {
        let xy_02 = _mm256_unpacklo_pd(v[0].0, v[1].0); // x0 y0 x2 y2
        let xy_13 = _mm256_unpackhi_pd(v[0].0, v[1].0); // x1 y1 x3 y3
        let z_01 = _mm256_castpd256_pd128(v[2].0);
        let z_23 = _mm256_extractf128_pd::<1>(v[2].0);
        let xy = [
            _mm256_castpd256_pd128(xy_02),
            _mm256_castpd256_pd128(xy_13),
            _mm256_extractf128_pd::<1>(xy_02),
            _mm256_extractf128_pd::<1>(xy_13),
        ];
        for (l, p) in out.into_iter().enumerate() {
            if lanes & (1 << l) == 0 {
                continue;
            }
            let p: *mut f64 = p.cast();
            _mm_storeu_pd(p, xy[l]);
            match l {
                0 => _mm_store_sd(p.add(2), z_01),
                1 => _mm_storeh_pd(p.add(2), z_01),
                2 => _mm_store_sd(p.add(2), z_23),
                _ => _mm_storeh_pd(p.add(2), z_23),
            }
        }
    }
}

impl super::wide::Wide for F64x4 {
    const WIDTH: usize = 4;
    type Mask = F64x4;
    #[inline]
    fn available() -> bool {
        available()
    }
    #[inline(always)]
    fn zero() -> Self {
        Self::zero()
    }
    #[inline(always)]
    unsafe fn load(v: *const f64) -> Self {
        unsafe { Self::load(v) }
    }
    #[inline(always)]
    unsafe fn store(self, out: *mut f64) {
        unsafe { Self::store(self, out) }
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Self::div(self, o)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self::sqrt(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::max(self, o)
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Self::neg(self)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self {
        Self::gt(self, o)
    }
    #[inline(always)]
    fn ne(self, o: Self) -> Self {
        Self::ne(self, o)
    }
    #[inline(always)]
    fn finite(self) -> Self {
        Self::finite(self)
    }
    #[inline(always)]
    fn mask_and(a: Self, b: Self) -> Self {
        a.and(b)
    }
    #[inline(always)]
    fn mask_or(a: Self, b: Self) -> Self {
        a.or(b)
    }
    #[inline(always)]
    fn mask_bits(m: Self) -> u32 {
        m.mask_bits()
    }
    #[inline(always)]
    fn mask_none() -> Self {
        Self::zero()
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, other: Self) -> Self {
        Self::select(mask, a, other)
    }
    /// Four scalar loads (AVX2's gather is no faster on the cores measured).
    #[inline(always)]
    unsafe fn gather_f64(base: *const f64, index: &[usize], valid: u32) -> Self {
        let at = |l: usize| if valid & (1 << l) != 0 { unsafe { *base.add(index[l]) } } else { 0.0 };
        Self(unsafe { _mm256_set_pd(at(3), at(2), at(1), at(0)) })
    }
    #[inline(always)]
    unsafe fn gather_rows(base: *const crate::Vec3, index: &[usize]) -> [Self; 3] {
        // SAFETY: forwarded from the caller.
        unsafe {
            transpose([
                load_row(base.add(index[0])),
                load_row(base.add(index[1])),
                load_row(base.add(index[2])),
                load_row(base.add(index[3])),
            ])
        }
    }
    #[inline(always)]
    unsafe fn scatter_rows(v: [Self; 3], base: *mut crate::Vec3, index: &[usize], lanes: u32) {
        // SAFETY: forwarded from the caller.
        unsafe {
            store_rows(v, [base.add(index[0]), base.add(index[1]), base.add(index[2]), base.add(index[3])], lanes)
        }
    }
}
