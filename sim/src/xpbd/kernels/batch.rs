//! Every element type a register at a time: four (AVX2) or eight (AVX-512) consecutive elements
//! of one colour (they share no node) projected together, one element per 64-bit lane, for
//! any node count `N` and any number of quadrature points — the P2, P3, Q1, Q2, prism and
//! pyramid elements and the linear tetrahedron at a raised quadrature degree (at one point it
//! has its own batch, [`super::p1`]).
//!
//! Per lane this is [`super::project_energy`] (Saillant et al. §3: for each point
//! `F_q = I + Σ_i u_i ⊗ ∇_X N_i(r_q)`, `U = Σ_q V_q ψ(F_q)`, `∇_i U = Σ_q V_q P(F_q) ∇_X N_i(r_q)`,
//! then `C = √(2U)` and the XPBD update) followed by the non-finite check and the scatter of the
//! scalar sweep ([`super::lanes::finish_batch`]); the point law runs on lanes
//! ([`super::lanes::BatchLaw`]). Every node loop is a register of elements wide with no horizontal
//! sum: `F` takes `9N` fused multiply–adds per point and batch, `∇U` another `9N`. Results equal the
//! scalar colour sweep's up to the order of floating-point operations (its node loops sum in
//! four partial sums, these in node order).
//!
//! **Stored gradients, or reference gradients and one Jacobian per point.** Elements of up to
//! 10 nodes read their material gradients `∇_X N_i(r_q)` as stored at packing (`3N + 1` doubles
//! per point with the volume). From 20 nodes on ([`from_reference_gradients`]: P3, Q2) they are
//! not stored per element: with `∇_X N_i = J⁻ᵀ ∇_r N_i` (`J` the rest Jacobian at the point), the
//! kernel forms `F = I + (Σ_i u_i ⊗ ∇_r N_i) J⁻¹` and `∇_i U += (V P J⁻ᵀ) ∇_r N_i`, the reference
//! gradients `∇_r N_i(r_q)` being the same for every element of the block (one small table,
//! [`super::PackedBlock::ref_grads`], read as broadcasts from L1) and `J⁻¹`, `V` the element's
//! own: 10 doubles per point and lane instead of `3N + 1`. Two 3×3 products per point more,
//! against a P3 batch at 14 points reading 4.5 kB instead of 27 kB per sweep: on
//! beams larger than the cache the stored gradients made the sweep wait on memory (Q2 32×8×8:
//! 162 → 72 ms per frame), while for Q1 the two extra products cost more than they save (1.36 →
//! 1.72 ms on 256 elements; release `bench_table`, one thread, same machine, one run).
//!
//! The rest data of a batch is stored lane-interleaved in [`super::PackedBlock::batches`]: per
//! quadrature point, `∂N_i/∂X_b` for `b < 3`, `i < N` (index `b N + i`) as `WIDTH` lanes each
//! then the volumes; or, from reference gradients, `(J⁻¹)_{bc}` for `b, c < 3` (index `3b + c`)
//! then the volumes: [`super::batch_values`]`(N, Q, WIDTH)` doubles per batch.

use super::lanes::{BatchLaw, V3, finish_batch, gather, scaled};
use super::p1::BatchIo;
use super::{NonFiniteElement, batch_values};
use crate::math::wide::Wide;

/// Projects `batches` batches of four `N`-node elements with `points` quadrature points and the
/// point law `law`, as [`super::p1::batches_avx2`] does for the linear tetrahedron (same
/// return value, same handling of pinned and non-finite elements). `ref_grads` holds
/// `∂N_i/∂r_b(r_q)` at `(q 3 + b) N + i`.
///
/// # Safety
/// As [`super::p1::batches_avx2`], with `4 N` node indices and [`batch_values`]`(N, points, 4)`
/// values per batch.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub unsafe fn batches_avx2<const N: usize, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    ref_grads: &[f64],
    points: usize,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; compiled with AVX2 and FMA.
    unsafe { batches_wide::<super::lanes::F64x4, N, L>(law, io, ref_grads, points, batches) }
}

/// [`batches_avx2`] eight elements at a time.
///
/// # Safety
/// As [`batches_avx2`] with `8 N` node indices and [`batch_values`]`(N, points, 8)` values per
/// batch; the CPU must support AVX-512 F too.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
pub unsafe fn batches_avx512<const N: usize, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    ref_grads: &[f64],
    points: usize,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; compiled with AVX-512 F, AVX2 and FMA.
    unsafe { batches_wide::<super::lanes::F64x8, N, L>(law, io, ref_grads, points, batches) }
}

/// [`batches_avx2`] two elements at a time, in a web page (WebAssembly `simd128`).
///
/// # Safety
/// As [`batches_avx2`] with `2 N` node indices and [`batch_values`]`(N, points, 2)` values per
/// batch; the module was compiled with `simd128`.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub unsafe fn batches_simd128<const N: usize, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    ref_grads: &[f64],
    points: usize,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; the whole module is compiled with simd128.
    unsafe { batches_wide::<super::lanes::F64x2, N, L>(law, io, ref_grads, points, batches) }
}

/// The batches on `W`'s lanes.
///
/// # Safety
/// As [`batches_avx2`], inlined into a function compiled with `W`'s target features.
#[inline(always)]
unsafe fn batches_wide<W: Wide, const N: usize, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    ref_grads: &[f64],
    points: usize,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    let width = W::WIDTH;
    let per_batch = batch_values(N, points, width);
    assert!(
        !(N == 4 && points == 1)
            && (!from_reference_gradients(N) || ref_grads.len() >= points * 3 * N)
            && io.nodes.len() >= batches * width * N
            && io.values.len() >= batches * per_batch
            && io.element_ids.len() >= batches * width
    );
    let (one, zero) = (W::splat(1.0), W::zero());
    let mut projected = 0u64;
    for b in 0..batches {
        let nodes = &io.nodes[b * width * N..(b + 1) * width * N];
        // SAFETY: forwarded from the caller.
        let Some(gathered) =
            (unsafe { gather::<W, N, true>(io.positions, io.rest, io.inv_mass, nodes, io.valid(b, batches)) })
        else {
            continue;
        };
        let u = &gathered.u;
        let vals = &io.values[b * per_batch..(b + 1) * per_batch];
        let mut grad: [V3<W>; N] = [[zero; 3]; N];
        let mut energy = zero;
        if !from_reference_gradients(N) {
            let per_point = (3 * N + 1) * width;
            for q in 0..points {
                let base = vals[q * per_point..(q + 1) * per_point].as_ptr();
                // F_ab = δ_ab + Σ_i u_ia ∂N_i/∂X_b, node after node
                let mut f = [[zero; 3]; 3];
                for i in 0..N {
                    // SAFETY: base points to this point's (3N + 1) WIDTH doubles.
                    let g: [W; 3] = unsafe { [load(base, i), load(base, N + i), load(base, 2 * N + i)] };
                    for a in 0..3 {
                        for c in 0..3 {
                            f[a][c] = u[i][a].mul_add(g[c], f[a][c]);
                        }
                    }
                }
                for a in 0..3 {
                    f[a][a] = f[a][a].add(one);
                }
                // SAFETY: compiled with W's target features.
                let (psi, p) = unsafe { law.energy_and_pk1(&f) };
                // SAFETY: as above.
                let v: W = unsafe { load(base, 3 * N) };
                energy = v.mul_add(psi, energy);
                let vp = scaled(&p, v);
                // ∇_i U += V P ∇N_i
                for i in 0..N {
                    // SAFETY: as above.
                    let g: [W; 3] = unsafe { [load(base, i), load(base, N + i), load(base, 2 * N + i)] };
                    for a in 0..3 {
                        grad[i][a] = vp[a][2].mul_add(g[2], vp[a][1].mul_add(g[1], vp[a][0].mul_add(g[0], grad[i][a])));
                    }
                }
            }
        } else {
            let per_point = POINT_VALUES_PER_LANE * width;
            for q in 0..points {
                let base = vals[q * per_point..(q + 1) * per_point].as_ptr();
                let table = &ref_grads[q * 3 * N..(q + 1) * 3 * N];
                let gr: [&[f64; N]; 3] = [
                    table[..N].try_into().expect("N"),
                    table[N..2 * N].try_into().expect("N"),
                    table[2 * N..].try_into().expect("N"),
                ];
                // Fr_ab = Σ_i u_ia ∂N_i/∂r_b, node after node
                let mut fr = [[zero; 3]; 3];
                for i in 0..N {
                    let g = [W::splat(gr[0][i]), W::splat(gr[1][i]), W::splat(gr[2][i])];
                    for a in 0..3 {
                        for c in 0..3 {
                            fr[a][c] = u[i][a].mul_add(g[c], fr[a][c]);
                        }
                    }
                }
                let mut jinv = [[zero; 3]; 3];
                for r in 0..3 {
                    for c in 0..3 {
                        // SAFETY: base points to this point's 10 WIDTH doubles.
                        jinv[r][c] = unsafe { load(base, 3 * r + c) };
                    }
                }
                // F = I + Fr J⁻¹
                let mut f = [[zero; 3]; 3];
                for a in 0..3 {
                    for c in 0..3 {
                        let m = fr[a][2].mul_add(jinv[2][c], fr[a][1].mul_add(jinv[1][c], fr[a][0].mul(jinv[0][c])));
                        f[a][c] = if a == c { one.add(m) } else { m };
                    }
                }
                // SAFETY: compiled with W's target features.
                let (psi, p) = unsafe { law.energy_and_pk1(&f) };
                // SAFETY: as above.
                let v: W = unsafe { load(base, 9) };
                energy = v.mul_add(psi, energy);
                // M = V P J⁻ᵀ: M_ab = Σ_c (V P)_ac (J⁻¹)_bc
                let vp = scaled(&p, v);
                let mut m = [[zero; 3]; 3];
                for a in 0..3 {
                    for r in 0..3 {
                        m[a][r] = vp[a][2].mul_add(jinv[r][2], vp[a][1].mul_add(jinv[r][1], vp[a][0].mul(jinv[r][0])));
                    }
                }
                // ∇_i U += M ∇_r N_i
                for i in 0..N {
                    let g = [W::splat(gr[0][i]), W::splat(gr[1][i]), W::splat(gr[2][i])];
                    for a in 0..3 {
                        grad[i][a] = m[a][2].mul_add(g[2], m[a][1].mul_add(g[1], m[a][0].mul_add(g[0], grad[i][a])));
                    }
                }
            }
        }
        let ids = &io.element_ids[b * width..(b + 1) * width];
        // SAFETY: nodes checked by gather, ids by finish_batch; forwarded from the caller.
        projected += unsafe {
            finish_batch::<W, N>(&gathered, energy, &grad, io.positions, io.lambdas, nodes, ids, io.inv_dt2)
        }?;
    }
    Ok(projected)
}

pub use super::{POINT_VALUES_PER_LANE, from_reference_gradients};

/// Lanes `WIDTH k..WIDTH (k + 1)` from `base`.
///
/// # Safety
/// `base` points to at least `WIDTH (k + 1)` doubles; only called under `W`'s target features.
#[inline(always)]
unsafe fn load<W: Wide>(base: *const f64, k: usize) -> W {
    unsafe { W::load(base.add(W::WIDTH * k)) }
}
