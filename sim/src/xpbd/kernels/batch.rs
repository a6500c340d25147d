//! Every element type four at a time: four consecutive elements of one colour (they share no
//! node) projected together, one element per 64-bit lane of a 256-bit register (AVX2 + FMA), for
//! any node count `N` and any number of quadrature points — the P2, P3, Q1, Q2, prism and
//! pyramid elements and the linear tetrahedron at a raised quadrature degree (at one point it
//! has its own batch, [`super::p1x4`]).
//!
//! Per lane this is [`super::project_energy`] (Saillant et al. §3: for each point
//! `F_q = I + Σ_i u_i ⊗ ∇_X N_i(r_q)`, `U = Σ_q V_q ψ(F_q)`, `∇_i U = Σ_q V_q P(F_q) ∇_X N_i(r_q)`,
//! then `C = √(2U)` and the XPBD update) followed by the non-finite check and the scatter of the
//! scalar sweep ([`super::lanes4::finish_batch`]); the point law runs on four lanes
//! ([`super::lanes4::BatchLaw`]). Every node loop is four elements wide with no horizontal sum:
//! `F` takes `9N` fused multiply–adds per point and batch, `∇U` another `9N`. Results equal the
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
//! own: 10 doubles per point instead of `3N + 1`. Two 3×3 products per point more (54 FMAs on
//! four lanes), against a P3 batch at 14 points reading 4.5 kB instead of 27 kB per sweep: on
//! beams larger than the cache the stored gradients made the sweep wait on memory.
//!
//! beams larger than the cache the stored gradients made the sweep wait on memory (Q2 32×8×8:
//! 162 → 72 ms per frame), while for Q1 the two extra products cost more than they save (1.36 →
//! 1.72 ms on 256 elements; release `bench_table`, one thread, same machine, one run).
//!
//! The rest data of a batch is stored lane-interleaved in [`super::PackedBlock::batches`]: per
//! quadrature point, `∂N_i/∂X_b` for `b < 3`, `i < N` (index `b N + i`) as four lanes each then
//! the four volumes; or, from reference gradients, `(J⁻¹)_{bc}` for `b, c < 3` (index `3b + c`)
//! then the volumes: [`super::batch_values`]`(N, Q)` doubles per batch.

use super::lanes4::{BatchLaw, F64x4, V3, finish_batch, gather, scaled};
use super::p1x4::BatchIo;
use super::{NonFiniteElement, batch_values};

/// Projects `batches` batches of four `N`-node elements with `points` quadrature points and the
/// point law `law`, as [`super::p1x4::batches_avx2`] does for the linear tetrahedron (same
/// return value, same handling of pinned and non-finite elements). `ref_grads` holds
/// `∂N_i/∂r_b(r_q)` at `(q 3 + b) N + i`.
///
/// # Safety
/// As [`super::p1x4::batches_avx2`], with `4 N` node indices and [`batch_values`]`(N, points)`
/// values per batch.
#[target_feature(enable = "avx2,fma")]
pub unsafe fn batches_avx2<const N: usize, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    ref_grads: &[f64],
    points: usize,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    let per_batch = batch_values(N, points);
    assert!(
        !(N == 4 && points == 1)
            && (!from_reference_gradients(N) || ref_grads.len() >= points * 3 * N)
            && io.nodes.len() >= batches * 4 * N
            && io.values.len() >= batches * per_batch
            && io.element_ids.len() >= batches * 4
    );
    let (one, zero) = (F64x4::splat(1.0), F64x4::zero());
    let mut projected = 0u64;
    for b in 0..batches {
        let nodes = &io.nodes[b * 4 * N..(b + 1) * 4 * N];
        // SAFETY: forwarded from the caller.
        let Some(gathered) = (unsafe { gather::<N>(io.positions, io.rest, io.inv_mass, nodes) }) else {
            continue;
        };
        let u = &gathered.u;
        let vals = &io.values[b * per_batch..(b + 1) * per_batch];
        let mut grad: [V3; N] = [[zero; 3]; N];
        let mut energy = zero;
        if !from_reference_gradients(N) {
            let per_point = (3 * N + 1) * 4;
            for q in 0..points {
                let base = vals[q * per_point..(q + 1) * per_point].as_ptr();
                // F_ab = δ_ab + Σ_i u_ia ∂N_i/∂X_b, node after node
                let mut f = [[zero; 3]; 3];
                for i in 0..N {
                    // SAFETY: base points to this point's (3N + 1) × 4 doubles.
                    let g = unsafe { [load(base, i), load(base, N + i), load(base, 2 * N + i)] };
                    for a in 0..3 {
                        for c in 0..3 {
                            f[a][c] = u[i][a].fma(g[c], f[a][c]);
                        }
                    }
                }
                for a in 0..3 {
                    f[a][a] = f[a][a].add(one);
                }
                // SAFETY: compiled with AVX2 and FMA.
                let (psi, p) = unsafe { law.energy_and_pk1(&f) };
                // SAFETY: as above.
                let v = unsafe { load(base, 3 * N) };
                energy = v.fma(psi, energy);
                let vp = scaled(&p, v);
                // ∇_i U += V P ∇N_i
                for i in 0..N {
                    // SAFETY: as above.
                    let g = unsafe { [load(base, i), load(base, N + i), load(base, 2 * N + i)] };
                    for a in 0..3 {
                        grad[i][a] = vp[a][2].fma(g[2], vp[a][1].fma(g[1], vp[a][0].fma(g[0], grad[i][a])));
                    }
                }
            }
        } else {
            for q in 0..points {
                let base = vals[q * POINT_VALUES..(q + 1) * POINT_VALUES].as_ptr();
                let table = &ref_grads[q * 3 * N..(q + 1) * 3 * N];
                let gr: [&[f64; N]; 3] = [
                    table[..N].try_into().expect("N"),
                    table[N..2 * N].try_into().expect("N"),
                    table[2 * N..].try_into().expect("N"),
                ];
                // Fr_ab = Σ_i u_ia ∂N_i/∂r_b, node after node
                let mut fr = [[zero; 3]; 3];
                for i in 0..N {
                    let g = [F64x4::splat(gr[0][i]), F64x4::splat(gr[1][i]), F64x4::splat(gr[2][i])];
                    for a in 0..3 {
                        for c in 0..3 {
                            fr[a][c] = u[i][a].fma(g[c], fr[a][c]);
                        }
                    }
                }
                // SAFETY: base points to this point's 10 × 4 doubles.
                let mut jinv = [[zero; 3]; 3];
                for r in 0..3 {
                    for c in 0..3 {
                        jinv[r][c] = unsafe { load(base, 3 * r + c) };
                    }
                }
                // F = I + Fr J⁻¹
                let mut f = [[zero; 3]; 3];
                for a in 0..3 {
                    for c in 0..3 {
                        let m = fr[a][2].fma(jinv[2][c], fr[a][1].fma(jinv[1][c], fr[a][0].mul(jinv[0][c])));
                        f[a][c] = if a == c { one.add(m) } else { m };
                    }
                }
                // SAFETY: compiled with AVX2 and FMA.
                let (psi, p) = unsafe { law.energy_and_pk1(&f) };
                // SAFETY: as above.
                let v = unsafe { load(base, 9) };
                energy = v.fma(psi, energy);
                // M = V P J⁻ᵀ: M_ab = Σ_c (V P)_ac (J⁻¹)_bc
                let vp = scaled(&p, v);
                let mut m = [[zero; 3]; 3];
                for a in 0..3 {
                    for r in 0..3 {
                        m[a][r] = vp[a][2].fma(jinv[r][2], vp[a][1].fma(jinv[r][1], vp[a][0].mul(jinv[r][0])));
                    }
                }
                // ∇_i U += M ∇_r N_i
                for i in 0..N {
                    let g = [F64x4::splat(gr[0][i]), F64x4::splat(gr[1][i]), F64x4::splat(gr[2][i])];
                    for a in 0..3 {
                        grad[i][a] = m[a][2].fma(g[2], m[a][1].fma(g[1], m[a][0].fma(g[0], grad[i][a])));
                    }
                }
            }
        }
        let ids: &[u32; 4] = io.element_ids[b * 4..(b + 1) * 4].try_into().expect("4 ids");
        // SAFETY: nodes checked by gather, ids by finish_batch; forwarded from the caller.
        projected +=
            unsafe { finish_batch::<N>(&gathered, energy, &grad, io.positions, io.lambdas, nodes, ids, io.inv_dt2) }?;
    }
    Ok(projected)
}

/// Whether the batches of `nodes`-node elements read reference gradients and one `J⁻¹` per point
/// (P3, Q2) rather than stored material gradients (see the module doc).
pub const fn from_reference_gradients(nodes: usize) -> bool {
    nodes >= 20
}

/// Doubles per quadrature point of a batch read from reference gradients: `J⁻¹` (9) and `V`,
/// four lanes each.
pub const POINT_VALUES: usize = 40;

/// Lanes `4k..4k + 4` from `base`.
///
/// # Safety
/// `base` points to at least `4k + 4` doubles; only called under AVX2.
#[inline(always)]
unsafe fn load(base: *const f64, k: usize) -> F64x4 {
    unsafe { F64x4::load(base.add(4 * k)) }
}
