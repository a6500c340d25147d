//! The machine's peak, measured rather than assumed: one thread running nothing but independent
//! 256-bit fused multiply–adds (AVX2 + FMA, the instructions the kernels use), so "% of peak" is
//! against what this core really sustains at its current clock (a stated figure from the nominal
//! frequency misses turbo and the spare adder pipes of newer cores).
//!
//! Twelve independent accumulator chains, enough to cover the FMA latency (4–5 cycles) on two
//! FMA pipes, each step `acc ← acc · a + b` on four doubles: 8 flops per instruction. The best of
//! five timed runs of about 0.1 s each is kept.

// the peak is measured on x86-64 only (elsewhere: the nominal figure)
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code, unused_imports))]

use web_time::Instant;

/// Flops per instruction of the loop: four doubles, a multiply and an add each.
const FLOPS_PER_FMA: f64 = 8.0;
/// Independent accumulators.
const CHAINS: usize = 12;

/// The measured AVX2 FMA peak of one core, GFLOP/s; None where the CPU lacks AVX2 or FMA.
pub fn measured_avx2_peak_gflops() -> Option<f64> {
    #[cfg(target_arch = "x86_64")]
    {
        if !(std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")) {
            return None;
        }
        let iterations = 2_000_000u64;
        let mut best = 0.0f64;
        for _ in 0..5 {
            let start = Instant::now();
            // SAFETY: AVX2 and FMA were detected.
            let sink = unsafe { fma_chains(std::hint::black_box(iterations)) };
            let secs = start.elapsed().as_secs_f64();
            std::hint::black_box(sink);
            best = best.max(iterations as f64 * CHAINS as f64 * FLOPS_PER_FMA / secs / 1e9);
        }
        Some(best)
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
}

/// `iterations` steps of [`CHAINS`] independent 256-bit FMA chains; returns their sum (so the
/// work is not optimised away).
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn fma_chains(iterations: u64) -> f64 {
    use std::arch::x86_64::*;
    let a = _mm256_set1_pd(0.999_999_9);
    let b = _mm256_set1_pd(1e-9);
    let mut acc = [_mm256_set1_pd(1.0); CHAINS];
    for _ in 0..iterations {
        for chain in &mut acc {
            *chain = _mm256_fmadd_pd(*chain, a, b);
        }
    }
    let mut out = [0.0; 4];
    let mut sum = _mm256_setzero_pd();
    for chain in acc {
        sum = _mm256_add_pd(sum, chain);
    }
    // SAFETY: out holds four doubles.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), sum) };
    out.iter().sum()
}

#[cfg(test)]
mod tests {
    /// The measurement runs and gives a finite positive rate where the CPU has AVX2 and FMA
    /// (its value is the machine's, so no bound on it is asserted).
    #[test]
    fn the_peak_is_measured_where_the_cpu_has_avx2() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            let peak = super::measured_avx2_peak_gflops().expect("measured");
            assert!(peak.is_finite() && peak > 0.0, "{peak}");
        }
    }
}
