//! The linear tetrahedron four at a time: four consecutive elements of one colour (they share
//! no node) projected together, one element per 64-bit lane of a 256-bit register (AVX2 + FMA).
//!
//! Per lane this is [`super::project_p1`] followed by the scatter and the
//! non-finite check of the scalar sweep: `F = I + [u₁−u₀, u₂−u₀, u₃−u₀] G`, `(ψ, P)` by the one
//! point law on four lanes ([`BatchLaw`]: StVK written over lanes, any other model lane by lane),
//! `[∇₁U ∇₂U ∇₃U] = V P Gᵀ`, `∇₀U = −Σ`, `C = √(2 max(VΨ, 0))` and the update of
//! [`crate::xpbd::constraint::xpbd_step`] with its guards (no update where `Σ w|∇U|² + α̃C² ≤
//! f64::MIN_POSITIVE` or NaN, or where the step is not finite). An element whose nodes are all
//! pinned is skipped (its multiplier and nodes untouched), as in the scalar sweep. Results equal
//! the scalar colour sweep's up to the order of floating-point operations.
//!
//! The rest data of a batch (`G` and `V` of its four elements) is stored lane-interleaved in
//! [`super::PackedBlock::p1x4`]: [`BATCH_VALUES`] doubles per batch, `G[r][c]` (`∂N_{r+1}/∂X_c`)
//! for `r, c < 3` as four lanes each, then the four volumes.

use super::lanes4::{BatchLaw, F64x4, finish_batch, gather, scaled};
use super::{BATCH_VALUES, Multipliers, NonFiniteElement, Positions};
use crate::Vec3;

/// What [`batches_avx2`] reads and writes.
#[derive(Clone, Copy)]
pub struct BatchIo<'a> {
    pub positions: Positions,
    pub rest: &'a [Vec3],
    pub inv_mass: &'a [f64],
    /// 16 node indices per batch (four per element, element after element).
    pub nodes: &'a [u32],
    /// [`BATCH_VALUES`] per batch.
    pub values: &'a [f64],
    /// Element index (multiplier) of each packed element, 4 per batch.
    pub element_ids: &'a [u32],
    pub lambdas: Multipliers,
    pub inv_dt2: f64,
}

/// Projects `batches` batches of four P1 elements with the point law `law`. Returns the number of
/// elements projected (with a free node), or the first element (in packed order) whose
/// corrections came out non-finite; as the scalar sweep, the elements before it are projected and
/// scattered, its multiplier is updated, its nodes are not written, and the elements after it are
/// untouched.
///
/// # Safety
/// The CPU must support AVX2 and FMA; `io.nodes`, `io.values`, `io.element_ids` must hold
/// `batches` batches; node indices below `io.positions.len()` and `io.rest.len()` and
/// `io.inv_mass.len()`, element ids below `io.lambdas.len()`; the four elements of a batch
/// share no node, and no other thread touches these nodes and multipliers meanwhile.
#[target_feature(enable = "avx2,fma")]
pub unsafe fn batches_avx2<L: BatchLaw>(law: &L, io: BatchIo<'_>, batches: usize) -> Result<u64, NonFiniteElement> {
    assert!(
        io.nodes.len() >= batches * 16
            && io.values.len() >= batches * BATCH_VALUES
            && io.element_ids.len() >= batches * 4
    );
    let (one, zero) = (F64x4::splat(1.0), F64x4::zero());
    let mut projected = 0u64;
    for b in 0..batches {
        let nodes = &io.nodes[b * 16..(b + 1) * 16];
        // SAFETY: forwarded from the caller.
        let Some(gathered) = (unsafe { gather::<4>(io.positions, io.rest, io.inv_mass, nodes) }) else {
            continue;
        };
        let u = &gathered.u;
        let vals = &io.values[b * BATCH_VALUES..(b + 1) * BATCH_VALUES];
        let mut g = [[zero; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                // SAFETY: vals holds 40 doubles.
                g[r][c] = unsafe { F64x4::load(vals.as_ptr().add((3 * r + c) * 4)) };
            }
        }
        let v = unsafe { F64x4::load(vals.as_ptr().add(36)) };
        // du[a][r] = (u_{r+1} − u_0)_a
        let mut du = [[zero; 3]; 3];
        for a in 0..3 {
            for r in 0..3 {
                du[a][r] = u[r + 1][a].sub(u[0][a]);
            }
        }
        // F = I + du G (as mul3: ((du_a0 g_0b) + du_a1 g_1b) + du_a2 g_2b, then + I)
        let mut f = [[zero; 3]; 3];
        for a in 0..3 {
            for c in 0..3 {
                let m = du[a][2].fma(g[2][c], du[a][1].fma(g[1][c], du[a][0].mul(g[0][c])));
                f[a][c] = if a == c { one.add(m) } else { m };
            }
        }
        // SAFETY: compiled with AVX2 and FMA.
        let (psi, p) = unsafe { law.energy_and_pk1(&f) };
        // ∇_{j+1} U = V P g_j (H = (V P) Gᵀ), ∇_0 U = −Σ
        let vp = scaled(&p, v);
        let mut grad = [[zero; 3]; 4];
        for j in 0..3 {
            for a in 0..3 {
                grad[j + 1][a] = vp[a][2].fma(g[j][2], vp[a][1].fma(g[j][1], vp[a][0].mul(g[j][0])));
            }
        }
        for a in 0..3 {
            grad[0][a] = grad[1][a].add(grad[2][a]).add(grad[3][a]).neg();
        }
        let ids: &[u32; 4] = io.element_ids[b * 4..(b + 1) * 4].try_into().expect("4 ids");
        // SAFETY: nodes checked by gather, ids by finish_batch; forwarded from the caller.
        projected += unsafe {
            finish_batch::<4>(&gathered, v.mul(psi), &grad, io.positions, io.lambdas, nodes, ids, io.inv_dt2)
        }?;
    }
    Ok(projected)
}
