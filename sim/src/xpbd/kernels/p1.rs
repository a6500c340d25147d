//! The linear tetrahedron a register at a time: four (AVX2) or eight (AVX-512) consecutive
//! elements of one colour (they share no node) projected together, one element per 64-bit lane.
//!
//! Per lane this is [`super::project_p1`] followed by the scatter and the
//! non-finite check of the scalar sweep: `F = [x₁−x₀, x₂−x₀, x₃−x₀] G` (`D_s D_m⁻¹`: the rest
//! positions are not gathered), `(ψ, P)` by the one
//! point law on lanes ([`BatchLaw`]: StVK written over lanes, any other model lane by lane),
//! `[∇₁U ∇₂U ∇₃U] = V P Gᵀ`, `∇₀U = −Σ`, `C = √(2 max(VΨ, 0))` and the update of
//! [`crate::xpbd::constraint::xpbd_step`] with its guards (no update where `Σ w|∇U|² + α̃C² ≤
//! f64::MIN_POSITIVE` or NaN, or where the step is not finite). An element whose nodes are all
//! pinned is skipped (its multiplier and nodes untouched), as in the scalar sweep. Results equal
//! the scalar colour sweep's up to the order of floating-point operations, and the four-lane
//! and eight-lane batches' bit for bit on the elements both batch.
//!
//! The rest data of a batch (`G` and `V` of its elements) is stored lane-interleaved in
//! [`super::PackedBlock::batches`]: [`super::P1_VALUES_PER_LANE`] doubles per lane, `G[r][c]`
//! (`∂N_{r+1}/∂X_c`) for `r, c < 3` as `WIDTH` lanes each, then the volumes.

use super::lanes::{BatchLaw, finish_batch, gather, scaled};
use super::{Multipliers, NonFiniteElement, P1_VALUES_PER_LANE, Positions};
use crate::Vec3;
use crate::math::wide::Wide;

/// What the batch kernels read and write.
#[derive(Clone, Copy)]
pub struct BatchIo<'a> {
    pub positions: Positions,
    pub rest: &'a [Vec3],
    pub inv_mass: &'a [f64],
    /// `N WIDTH` node indices per batch (`N` per element, element after element).
    pub nodes: &'a [u32],
    /// [`super::batch_values`] per batch.
    pub values: &'a [f64],
    /// Element index (multiplier) of each packed element, `WIDTH` per batch.
    pub element_ids: &'a [u32],
    pub lambdas: Multipliers,
    pub inv_dt2: f64,
    /// The lanes of the last batch that are elements (bit `l`: lane `l`); every lane of the
    /// others. A colour's last batch may be partial: its other lanes repeat an element's nodes
    /// and id and have zero rest data, and are never updated nor written.
    pub last_lanes: u32,
}

impl BatchIo<'_> {
    /// The lanes of batch `b` of `batches` that are elements.
    #[inline(always)]
    pub fn valid(&self, b: usize, batches: usize) -> u32 {
        if b + 1 == batches { self.last_lanes } else { u32::MAX }
    }
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
/// `io.inv_mass.len()`, element ids below `io.lambdas.len()`; the elements of a batch
/// share no node, and no other thread touches these nodes and multipliers meanwhile.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub unsafe fn batches_avx2<L: BatchLaw>(law: &L, io: BatchIo<'_>, batches: usize) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; compiled with AVX2 and FMA.
    unsafe { batches_wide::<super::lanes::F64x4, L>(law, io, batches) }
}

/// [`batches_avx2`] eight elements at a time.
///
/// # Safety
/// As [`batches_avx2`]; the CPU must support AVX-512 F too.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
pub unsafe fn batches_avx512<L: BatchLaw>(law: &L, io: BatchIo<'_>, batches: usize) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; compiled with AVX-512 F, AVX2 and FMA.
    unsafe { batches_wide::<super::lanes::F64x8, L>(law, io, batches) }
}

/// [`batches_avx2`] two elements at a time, in a web page (WebAssembly `simd128`).
///
/// # Safety
/// As [`batches_avx2`] but for the CPU features: the module was compiled with `simd128`.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub unsafe fn batches_simd128<L: BatchLaw>(law: &L, io: BatchIo<'_>, batches: usize) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded; the whole module is compiled with simd128.
    unsafe { batches_wide::<super::lanes::F64x2, L>(law, io, batches) }
}

/// The batches on `W`'s lanes.
///
/// # Safety
/// As [`batches_avx2`], inlined into a function compiled with `W`'s target features.
#[inline(always)]
unsafe fn batches_wide<W: Wide, L: BatchLaw>(
    law: &L,
    io: BatchIo<'_>,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    let width = W::WIDTH;
    let per_batch = P1_VALUES_PER_LANE * width;
    assert!(
        io.nodes.len() >= batches * 4 * width
            && io.values.len() >= batches * per_batch
            && io.element_ids.len() >= batches * width
    );
    let zero = W::zero();
    let mut projected = 0u64;
    for b in 0..batches {
        let nodes = &io.nodes[b * 4 * width..(b + 1) * 4 * width];
        // SAFETY: forwarded from the caller.
        let Some(gathered) =
            (unsafe { gather::<W, 4, false>(io.positions, io.rest, io.inv_mass, nodes, io.valid(b, batches)) })
        else {
            continue;
        };
        let x = &gathered.x;
        let vals = &io.values[b * per_batch..(b + 1) * per_batch];
        let mut g = [[zero; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                // SAFETY: vals holds 10 WIDTH doubles.
                g[r][c] = unsafe { W::load(vals.as_ptr().add((3 * r + c) * width)) };
            }
        }
        let v = unsafe { W::load(vals.as_ptr().add(9 * width)) };
        // the deformed edges dx[a][r] = (x_{r+1} − x_0)_a
        let mut dx = [[zero; 3]; 3];
        for a in 0..3 {
            for r in 0..3 {
                dx[a][r] = x[r + 1][a].sub(x[0][a]);
            }
        }
        // F = dx G (as mul3: ((dx_a0 g_0b) + dx_a1 g_1b) + dx_a2 g_2b)
        let mut f = [[zero; 3]; 3];
        for a in 0..3 {
            for c in 0..3 {
                f[a][c] = dx[a][2].mul_add(g[2][c], dx[a][1].mul_add(g[1][c], dx[a][0].mul(g[0][c])));
            }
        }
        // SAFETY: compiled with W's target features.
        let (psi, p) = unsafe { law.energy_and_pk1(&f) };
        // ∇_{j+1} U = V P g_j (H = (V P) Gᵀ), ∇_0 U = −Σ
        let vp = scaled(&p, v);
        let mut grad = [[zero; 3]; 4];
        for j in 0..3 {
            for a in 0..3 {
                grad[j + 1][a] = vp[a][2].mul_add(g[j][2], vp[a][1].mul_add(g[j][1], vp[a][0].mul(g[j][0])));
            }
        }
        for a in 0..3 {
            grad[0][a] = grad[1][a].add(grad[2][a]).add(grad[3][a]).neg();
        }
        let ids = &io.element_ids[b * width..(b + 1) * width];
        // SAFETY: nodes checked by gather, ids by finish_batch; forwarded from the caller.
        projected += unsafe {
            finish_batch::<W, 4>(&gathered, v.mul(psi), &grad, io.positions, io.lambdas, nodes, ids, io.inv_dt2)
        }?;
    }
    Ok(projected)
}
