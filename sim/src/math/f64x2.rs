//! Two doubles per 128-bit register (WebAssembly's `simd128`, issue #59): the lane type
//! [`F64x2`], a [`Lane`] and a [`Wide`] so that the XPBD batches written over registers
//! (`crate::xpbd::kernels`) run two elements at a time in a web page, as they run four on AVX2
//! and eight on AVX-512.
//!
//! Compiled only for `wasm32` with the `simd128` target feature (`scripts/build-web.sh` turns it
//! on for the whole build: every browser of the last years runs it, and a module with it is
//! validated at load, so there is no runtime check to make: [`Wide::available`] is true).
//! Plain WebAssembly has no fused multiply–add: [`Lane::mul_add`] is a multiply and an add (two
//! roundings), as the scalar kernels compute without FMA.

use super::lane::{Lane, M3};
use super::wide::Wide;
use core::arch::wasm32::*;

/// Two doubles, one per element.
#[derive(Clone, Copy)]
pub struct F64x2(pub v128);

impl F64x2 {
    #[inline(always)]
    fn lane(self, l: usize) -> f64 {
        if l == 0 { f64x2_extract_lane::<0>(self.0) } else { f64x2_extract_lane::<1>(self.0) }
    }
}

impl Lane for F64x2 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self(f64x2_splat(v))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(f64x2_add(self.0, o.0))
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(f64x2_sub(self.0, o.0))
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(f64x2_mul(self.0, o.0))
    }
    /// Not fused: WebAssembly's `simd128` has no fused multiply–add.
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Self(f64x2_add(f64x2_mul(self.0, b.0), c.0))
    }
    /// Column by column, as the scalar law without FMA: `((m₀₀² + m₁₀²) + m₂₀²) + …`.
    #[inline(always)]
    fn sum_of_squares(m: &M3<Self>) -> Self {
        let mut columns = [Self::zero(); 3];
        for c in 0..3 {
            columns[c] = m[0][c].mul(m[0][c]).add(m[1][c].mul(m[1][c])).add(m[2][c].mul(m[2][c]));
        }
        columns[0].add(columns[1]).add(columns[2])
    }
}

impl Wide for F64x2 {
    const WIDTH: usize = 2;
    /// All-ones lanes where true.
    type Mask = v128;
    /// `simd128` is a compile-time feature of the module: a browser without it refuses to load
    /// the page's module at all.
    #[inline]
    fn available() -> bool {
        true
    }
    #[inline(always)]
    fn zero() -> Self {
        Self(f64x2_splat(0.0))
    }
    #[inline(always)]
    unsafe fn load(v: *const f64) -> Self {
        // SAFETY: `v` points to two doubles (the caller's promise); unaligned loads are allowed.
        Self(unsafe { v128_load(v.cast()) })
    }
    #[inline(always)]
    unsafe fn store(self, out: *mut f64) {
        // SAFETY: `out` points to two writable doubles.
        unsafe { v128_store(out.cast(), self.0) }
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Self(f64x2_div(self.0, o.0))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(f64x2_sqrt(self.0))
    }
    /// `pmax(o, self)` is `o < self ? self : o`: `self` where it is larger, `o` where `self` is
    /// NaN, as `f64::max`.
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self(f64x2_pmax(o.0, self.0))
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Self(f64x2_neg(self.0))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> v128 {
        f64x2_gt(self.0, o.0)
    }
    #[inline(always)]
    fn ne(self, o: Self) -> v128 {
        f64x2_ne(self.0, o.0)
    }
    /// `x · 0 == 0` for a finite `x`; NaN otherwise.
    #[inline(always)]
    fn finite(self) -> v128 {
        f64x2_eq(f64x2_mul(self.0, f64x2_splat(0.0)), f64x2_splat(0.0))
    }
    #[inline(always)]
    fn mask_and(a: v128, b: v128) -> v128 {
        v128_and(a, b)
    }
    #[inline(always)]
    fn mask_or(a: v128, b: v128) -> v128 {
        v128_or(a, b)
    }
    #[inline(always)]
    fn mask_bits(m: v128) -> u32 {
        i64x2_bitmask(m) as u32
    }
    #[inline(always)]
    fn mask_none() -> v128 {
        i64x2_splat(0)
    }
    #[inline(always)]
    fn select(mask: v128, a: Self, other: Self) -> Self {
        Self(v128_bitselect(a.0, other.0, mask))
    }
    #[inline(always)]
    unsafe fn gather_f64(base: *const f64, index: &[usize], valid: u32) -> Self {
        // SAFETY: each valid lane's `base + index[l]` points to an f64 (the caller's promise).
        let at = |l: usize| if valid & (1 << l) != 0 { unsafe { *base.add(index[l]) } } else { 0.0 };
        Self(f64x2(at(0), at(1)))
    }
    #[inline(always)]
    unsafe fn gather_rows(base: *const crate::Vec3, index: &[usize]) -> [Self; 3] {
        // SAFETY: each `base + index[l]` points to a Vec3 (the caller's promise).
        let (a, b) = unsafe { (&*base.add(index[0]), &*base.add(index[1])) };
        [Self(f64x2(a.x, b.x)), Self(f64x2(a.y, b.y)), Self(f64x2(a.z, b.z))]
    }
    #[inline(always)]
    unsafe fn scatter_rows(v: [Self; 3], base: *mut crate::Vec3, index: &[usize], lanes: u32) {
        for l in 0..2 {
            if lanes & (1 << l) != 0 {
                // SAFETY: each written `base + index[l]` points to a Vec3 no other thread touches.
                let p = unsafe { &mut *base.add(index[l]) };
                *p = crate::Vec3::new(v[0].lane(l), v[1].lane(l), v[2].lane(l));
            }
        }
    }
}
