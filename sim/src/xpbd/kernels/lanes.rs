//! What every batch of the colour sweep shares, one element per lane of a SIMD register type
//! ([`Wide`]: four lanes on AVX2, eight on AVX-512, `crate::math::wide`): gathering the
//! elements' node positions into lanes ([`gather`]), the material law on lanes ([`BatchLaw`]),
//! and the end of a projection shared by the P1 batches ([`super::p1`]) and the batches of every
//! other element type ([`super::batch`]): the XPBD update with its guards, the non-finite check
//! and the scatter ([`finish_batch`]).
//!
//! Every function is `#[inline(always)]` and only called from functions compiled with the
//! register type's target features, which run only where the CPU has them.

use super::{AnyMaterial, Multipliers, NonFiniteElement, Positions, Stvk};
use crate::Vec3;
use crate::material::{Mat3, stvk};
use crate::math::lane::M3;
use crate::math::wide::{Wide, from_lanes, to_lanes};

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub use crate::math::f64x2::F64x2;
#[cfg(target_arch = "x86_64")]
pub use crate::math::f64x4::F64x4;
#[cfg(target_arch = "x86_64")]
pub use crate::math::f64x8::F64x8;

/// A 3-vector of lanes.
pub type V3<W> = [W; 3];

/// The register width the colour sweep runs on: the widest this CPU has (eight lanes with
/// AVX-512 F, four with AVX2 and FMA), None without either (the scalar sweep only).
#[cfg(target_arch = "x86_64")]
pub fn widest_available() -> Option<usize> {
    if <F64x8 as Wide>::available() {
        Some(8)
    } else if <F64x4 as Wide>::available() {
        Some(4)
    } else {
        None
    }
}

/// Whether the CPU runs batches of `lanes` elements (4: AVX2 and FMA; 8: AVX-512 F too).
#[cfg(target_arch = "x86_64")]
pub fn lanes_available(lanes: usize) -> bool {
    match lanes {
        4 => <F64x4 as Wide>::available(),
        8 => <F64x8 as Wide>::available(),
        _ => false,
    }
}

/// In a web page: two lanes (`simd128`, a feature the module was compiled with).
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub fn widest_available() -> Option<usize> {
    Some(2)
}

/// In a web page: batches of two.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub fn lanes_available(lanes: usize) -> bool {
    lanes == 2
}

/// `m v`: every entry of a 3×3 matrix of lanes scaled by the lanes `v` (the quadrature volume
/// times the stress, `V P`, of every batch kernel).
#[inline(always)]
pub fn scaled<W: Wide>(m: &M3<W>, v: W) -> M3<W> {
    let mut out = *m;
    for row in &mut out {
        for x in row {
            *x = x.mul(v);
        }
    }
    out
}

/// A point law on a register of elements at a time: `(ψ(F), P(F))` per lane.
pub trait BatchLaw: Sync {
    /// # Safety
    /// Only called from functions compiled with `W`'s target features.
    unsafe fn energy_and_pk1<W: Wide>(&self, f: &M3<W>) -> (W, M3<W>);
}

/// StVK written over lanes: the one point law ([`stvk::energy_and_pk1`]) on every lane.
impl BatchLaw for Stvk {
    #[inline(always)]
    unsafe fn energy_and_pk1<W: Wide>(&self, f: &M3<W>) -> (W, M3<W>) {
        stvk::energy_and_pk1(W::splat(self.mu_pa), W::splat(self.lambda_pa), f)
    }
}

/// Any other model lane by lane, through its own scalar law (the node loops around it stay a
/// register wide; the law is what the scalar kernel calls, so per lane the same `P` bit for bit).
impl BatchLaw for AnyMaterial<'_> {
    #[inline(always)]
    unsafe fn energy_and_pk1<W: Wide>(&self, f: &M3<W>) -> (W, M3<W>) {
        let mut lanes = [[[0.0; 8]; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                lanes[r][c] = to_lanes(f[r][c]);
            }
        }
        let mut psi = [0.0; 8];
        let mut p_lanes = [[[0.0; 8]; 3]; 3];
        for l in 0..W::WIDTH {
            let fl = Mat3::new(
                lanes[0][0][l],
                lanes[0][1][l],
                lanes[0][2][l],
                lanes[1][0][l],
                lanes[1][1][l],
                lanes[1][2][l],
                lanes[2][0][l],
                lanes[2][1][l],
                lanes[2][2][l],
            );
            let (psi_l, p_l) = self.0.energy_density_and_pk1(&fl);
            psi[l] = psi_l;
            for r in 0..3 {
                for c in 0..3 {
                    p_lanes[r][c][l] = p_l[(r, c)];
                }
            }
        }
        let mut p = [[W::zero(); 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                p[r][c] = from_lanes(&p_lanes[r][c]);
            }
        }
        (from_lanes(&psi), p)
    }
}

/// A register of elements of `N` nodes gathered: inverse masses `w[i]`, positions `x[i]` and
/// displacements `u[i] = x_i − X_i`, node `i` of lane `l` being `nodes[N l + i]`, and `free`, the
/// lanes with a free node (the scalar sweep skips an element whose nodes are all pinned).
pub struct Gathered<W: Wide, const N: usize> {
    pub w: [W; N],
    pub x: [V3<W>; N],
    pub u: [V3<W>; N],
    pub free: W::Mask,
}

/// Gathers the batch whose `WIDTH N` node indices are `nodes`, or None when all its elements
/// are pinned. The displacements `u` only with `DISPLACEMENTS` (else zero, and `rest` not read:
/// the P1 batch forms `F` from the positions alone). Only the lanes set in `valid` are elements (a colour's last batch may be
/// partial): the others count as pinned, so they are never updated nor written.
///
/// # Safety
/// Only called from functions compiled with `W`'s target features; every node index below
/// `positions.len()`, `rest.len()` and `inv_mass.len()` (checked once per colour sweep, not
/// here); `positions` valid for the call, no other thread writing these nodes.
#[inline(always)]
pub unsafe fn gather<W: Wide, const N: usize, const DISPLACEMENTS: bool>(
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    nodes: &[u32],
    valid: u32,
) -> Option<Gathered<W, N>> {
    let nodes: &[u32] = &nodes[..W::WIDTH * N];
    let zero = W::zero();
    let mut w = [zero; N];
    let mut free = W::mask_none();
    let mut index = [[0usize; 8]; N];
    for i in 0..N {
        for l in 0..W::WIDTH {
            index[i][l] = nodes[l * N + i] as usize;
        }
        // SAFETY: indices below inv_mass.len() (the caller's promise).
        w[i] = unsafe { W::gather_f64(inv_mass.as_ptr(), &index[i][..W::WIDTH], valid) };
        free = W::mask_or(free, w[i].ne(zero));
    }
    if W::mask_bits(free) == 0 {
        return None;
    }
    let mut x = [[zero; 3]; N];
    let mut u = [[zero; 3]; N];
    for i in 0..N {
        // SAFETY: indices below the lengths (the caller's promise).
        x[i] = unsafe { W::gather_rows(positions.ptr(), &index[i][..W::WIDTH]) };
        if DISPLACEMENTS {
            // SAFETY: as above.
            let ri = unsafe { W::gather_rows(rest.as_ptr(), &index[i][..W::WIDTH]) };
            u[i] = [x[i][0].sub(ri[0]), x[i][1].sub(ri[1]), x[i][2].sub(ri[2])];
        }
    }
    Some(Gathered { w, x, u, free })
}

/// The end of a batch's projection, as the scalar sweep ends each element's: from the element
/// energies `energy` (`Σ_q V_q ψ_q`, before the floor at 0) and gradients `grad[i] = ∇_i U`,
/// `C = √(2 max(U, 0))`, the update of [`crate::xpbd::constraint::xpbd_step`] with its guards
/// (no update where `Σ w|∇U|² + α̃C² ≤ f64::MIN_POSITIVE` or NaN, or where the step is not
/// finite), the multipliers written, the non-finite check and the scatter. Returns the number of
/// elements projected, or the first lane's element whose new positions are not finite (the lanes
/// before it scattered, its multiplier updated, its nodes not written, the lanes after it
/// untouched).
///
/// # Safety
/// Only called from functions compiled with `W`'s target features; `nodes` the batch's
/// `WIDTH N` node indices and `ids` its `WIDTH` element ids, below `positions.len()` and
/// `lambdas.len()` (checked once per colour sweep); no other thread touching them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub unsafe fn finish_batch<W: Wide, const N: usize>(
    g: &Gathered<W, N>,
    energy: W,
    grad: &[V3<W>; N],
    positions: Positions,
    lambdas: Multipliers,
    nodes: &[u32],
    ids: &[u32],
    inv_dt2: f64,
) -> Result<u64, NonFiniteElement> {
    let width = W::WIDTH;
    let zero = W::zero();
    let (w, x, free) = (&g.w, &g.x, g.free);
    let energy = energy.max(zero);
    let c = W::splat(2.0).mul(energy).sqrt();
    let mut sum_w_grad2 = zero;
    for i in 0..N {
        let n2 = grad[i][2].mul_add(grad[i][2], grad[i][1].mul_add(grad[i][1], grad[i][0].mul(grad[i][0])));
        sum_w_grad2 = w[i].mul_add(n2, sum_w_grad2);
    }
    // xpbd_step(c, c, Σ w|∇U|², α̃ = 1/h², λ): a = Σ + α̃ c c, b = −(c + α̃ λ) c, step = b / a,
    // None (no update) unless a > MIN_POSITIVE and the step is finite
    let ids = &ids[..width];
    // SAFETY: ids below lambdas.len() (the caller's promise); no other thread touches these
    // multipliers.
    let lam_ptr = |l: usize| unsafe { lambdas.ptr().add(ids[l] as usize) };
    let mut lambda_lanes = [0.0; 8];
    for l in 0..width {
        // SAFETY: as above.
        lambda_lanes[l] = unsafe { *lam_ptr(l) };
    }
    let lambda: W = from_lanes(&lambda_lanes);
    let inv_dt2 = W::splat(inv_dt2);
    let a = sum_w_grad2.add(inv_dt2.mul(c).mul(c));
    let rhs = c.add(inv_dt2.mul(lambda)).neg().mul(c);
    let step = rhs.div(a);
    let update = W::mask_and(W::mask_and(a.gt(W::splat(f64::MIN_POSITIVE)), step.finite()), free);
    let step = W::select(update, step, zero);
    let new_lambda = to_lanes(W::select(update, lambda.add(c.mul(step)), lambda));
    let mut check = zero;
    let mut out = *x;
    for i in 0..N {
        let s = step.mul(w[i]);
        for a in 0..3 {
            out[i][a] = W::select(update, x[i][a].add(grad[i][a].mul(s)), x[i][a]);
            check = out[i][a].mul(zero).add(check);
        }
    }
    // lanes whose new positions are not all finite (pinned elements are not checked)
    let free_bits = W::mask_bits(free);
    let bad = W::mask_bits(W::mask_and(check.ne(zero), free));
    // the multipliers of the free lanes (a pinned lane's is unchanged; a padding lane repeats
    // an element of the batch, so it must not write)
    let (done, written) = if bad == 0 {
        (free_bits, free_bits)
    } else {
        let first = bad.trailing_zeros();
        (((1 << first) - 1) & free_bits, ((1 << (first + 1)) - 1) & free_bits)
    };
    for l in 0..width {
        if written & (1 << l) != 0 {
            // SAFETY: as above.
            unsafe { *lam_ptr(l) = new_lambda[l] };
        }
    }
    for (i, oi) in out.iter().enumerate() {
        let mut index = [0usize; 8];
        for l in 0..width {
            index[l] = nodes[N * l + i] as usize;
        }
        // SAFETY: indices checked by gather; the lanes' nodes are distinct (one colour).
        unsafe { W::scatter_rows(*oi, positions.ptr(), &index[..width], done) };
    }
    if bad != 0 {
        let l = bad.trailing_zeros() as usize;
        let i = (0..N).find(|&i| out[i].iter().any(|v| !to_lanes(*v)[l].is_finite())).unwrap_or(0);
        return Err(NonFiniteElement { element: ids[l] as usize, node: nodes[N * l + i] });
    }
    Ok(u64::from(free_bits.count_ones()))
}
