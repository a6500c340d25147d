//! The SIMD register types the XPBD batches run on, behind one trait: [`Wide`], a [`Lane`] of
//! `WIDTH` doubles with loads, stores, comparisons, masks and the gather/scatter of node
//! positions, so that each batch kernel is written once and compiled per width — four lanes
//! on AVX2 + FMA ([`super::f64x4::F64x4`]), eight on AVX-512 ([`super::f64x8::F64x8`]).
//!
//! Every method is `#[inline(always)]` and only called from functions compiled with the
//! type's target features (`#[target_feature(enable = "avx2,fma")]`, resp.
//! `"avx512f,avx2,fma"`), which run only where [`Wide::available`] said yes.

use super::lane::Lane;
use crate::Vec3;

/// `WIDTH` doubles in one register, one element per lane.
pub trait Wide: Lane {
    /// Lanes per register.
    const WIDTH: usize;
    /// A per-lane truth value (a vector of all-ones lanes on AVX2, a bit mask on AVX-512).
    type Mask: Copy;
    /// Whether this CPU can run the type's instructions (the runtime check before any of them).
    fn available() -> bool;
    fn zero() -> Self;
    /// Lane `l` is `v[l]`.
    ///
    /// # Safety
    /// `v` points to `WIDTH` doubles.
    unsafe fn load(v: *const f64) -> Self;
    /// # Safety
    /// `out` points to `WIDTH` writable doubles.
    unsafe fn store(self, out: *mut f64);
    fn div(self, o: Self) -> Self;
    fn sqrt(self) -> Self;
    /// `f64::max` per lane for a non-NaN `o` (a NaN `self` gives `o`).
    fn max(self, o: Self) -> Self;
    fn neg(self) -> Self;
    /// Lanes where `self > o` (false for NaN).
    fn gt(self, o: Self) -> Self::Mask;
    /// Lanes where `self != o` or either is NaN.
    fn ne(self, o: Self) -> Self::Mask;
    /// Lanes where `self` is finite.
    fn finite(self) -> Self::Mask;
    fn mask_and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    fn mask_or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Bit `l` set where lane `l` is true.
    fn mask_bits(m: Self::Mask) -> u32;
    /// No lane true.
    fn mask_none() -> Self::Mask;
    /// `a` where `mask`, else `other`.
    fn select(mask: Self::Mask, a: Self, other: Self) -> Self;
    /// Lane `l` is `base[index[l]]` where bit `l` of `valid` is set, else 0.
    ///
    /// # Safety
    /// Each `base + index[l]` of a valid lane points to an `f64`.
    unsafe fn gather_f64(base: *const f64, index: &[usize], valid: u32) -> Self;
    /// The `x`, `y`, `z` lanes of `WIDTH` nodes, node `l` at `base + index(l)`.
    ///
    /// # Safety
    /// Each `base + index(l)` points to a `Vec3`.
    unsafe fn gather_rows(base: *const Vec3, index: &[usize]) -> [Self; 3];
    /// Writes lane `l` of `v` to node `base + index(l)` for the lanes set in `lanes`.
    ///
    /// # Safety
    /// Each `base + index(l)` written points to a `Vec3` no other thread touches.
    unsafe fn scatter_rows(v: [Self; 3], base: *mut Vec3, index: &[usize], lanes: u32);
}

/// The lanes `f(0), …, f(WIDTH − 1)` (through memory: a plain loop, no closure of its own
/// without the caller's target features; see [`super::lane`]).
#[inline(always)]
pub fn from_lanes<W: Wide>(v: &[f64; 8]) -> W {
    // SAFETY: 8 ≥ WIDTH doubles.
    unsafe { W::load(v.as_ptr()) }
}

/// Lane `l` of `v` at `out[l]` for `l < WIDTH`.
#[inline(always)]
pub fn to_lanes<W: Wide>(v: W) -> [f64; 8] {
    let mut out = [0.0; 8];
    // SAFETY: 8 ≥ WIDTH doubles.
    unsafe { v.store(out.as_mut_ptr()) };
    out
}
