//! Structure-of-arrays helpers of the per-element kernels (XPBD's sweep, the element energy and
//! gradient of `crate::fem::energy`): 3×3 products with optional fused multiply–adds ([`mul3`]),
//! and the [`LANES`]-wide partial sums of the per-node loops ([`fma_lanes`], [`axpy_lanes`]; one
//! AVX2 register where the CPU has it) over per-node arrays padded to a multiple of [`LANES`]
//! ([`padded`]).

use super::Mat3;
use super::lane::madd;

/// `a b` for 3×3 matrices with `madd::<FMA>` (nalgebra's product never fuses).
#[inline(always)]
pub fn mul3<const FMA: bool>(a: &Mat3, b: &Mat3) -> Mat3 {
    Mat3::from_fn(|r, c| madd::<FMA>(a[(r, 2)], b[(2, c)], madd::<FMA>(a[(r, 1)], b[(1, c)], a[(r, 0)] * b[(0, c)])))
}

/// `aᵀ b` for 3×3 matrices, as [`mul3`].
#[inline(always)]
pub fn tr_mul3<const FMA: bool>(a: &Mat3, b: &Mat3) -> Mat3 {
    Mat3::from_fn(|r, c| madd::<FMA>(a[(2, r)], b[(2, c)], madd::<FMA>(a[(1, r)], b[(1, c)], a[(0, r)] * b[(0, c)])))
}

/// `acc ← acc + a ∘ b` on [`LANES`] lanes (`a`, `b`: at least `LANES` long): one AVX2 fused
/// multiply–add when `FMA` (set only in functions compiled for AVX2 and FMA and called where the
/// CPU has both, such as the XPBD sweep's `sweep_avx2`).
#[inline(always)]
pub fn fma_lanes<const FMA: bool>(acc: &mut [f64; LANES], a: &[f64], b: &[f64]) {
    let (a, b): (&[f64; LANES], &[f64; LANES]) =
        (a[..LANES].try_into().expect("LANES"), b[..LANES].try_into().expect("LANES"));
    #[cfg(target_arch = "x86_64")]
    if FMA {
        use std::arch::x86_64::{_mm256_fmadd_pd, _mm256_loadu_pd, _mm256_storeu_pd};
        // SAFETY: FMA is true only under a function compiled for AVX2 and FMA, which runs where AVX2 and FMA were detected;
        // each pointer covers four f64. Written here rather than in a `#[target_feature]` helper:
        // such a helper cannot be `#[inline(always)]`, and the dev profile (opt-level 2,
        // incremental) left it out of line, one call per four lanes (82 % of the debug build's
        // `hox study --quick` in it, by perf; 7 min 29 s → 6 min 2 s once inlined, same results).
        unsafe {
            let r = _mm256_fmadd_pd(
                _mm256_loadu_pd(a.as_ptr()),
                _mm256_loadu_pd(b.as_ptr()),
                _mm256_loadu_pd(acc.as_ptr()),
            );
            _mm256_storeu_pd(acc.as_mut_ptr(), r);
        }
        return;
    }
    for l in 0..LANES {
        acc[l] = madd::<FMA>(a[l], b[l], acc[l]);
    }
}

/// `acc ← acc + s b` on [`LANES`] lanes, as [`fma_lanes`].
#[inline(always)]
pub fn axpy_lanes<const FMA: bool>(acc: &mut [f64; LANES], s: f64, b: &[f64]) {
    fma_lanes::<FMA>(acc, &[s; LANES], b);
}

/// `N` rounded up to a multiple of [`LANES`]: the padded length of the per-node arrays.
pub const fn padded(n: usize) -> usize {
    n.div_ceil(LANES) * LANES
}

/// Width of the partial sums of the node loops (four doubles: one 256-bit register).
pub const LANES: usize = 4;
