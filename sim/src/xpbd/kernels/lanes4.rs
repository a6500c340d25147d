//! What every four-element batch of the colour sweep shares, one element per lane of the
//! four-lane type ([`F64x4`], `crate::math::f64x4`): reading four elements' node positions as rows and
//! transposing them in registers ([`load_row`], [`transpose`]), writing them back
//! ([`store_rows`]), the material law on four lanes ([`BatchLaw`]), and the end of a projection
//! shared by the P1 batches ([`super::p1x4`]) and the batches of every other element type
//! ([`super::batch`]): the XPBD update with its guards, the non-finite check and the scatter
//! ([`finish_batch`]).
//!
//! Every function is `#[inline(always)]` and only called from functions compiled with
//! `#[target_feature(enable = "avx2,fma")]`, which run only where the CPU has both.

use super::{AnyMaterial, Multipliers, NonFiniteElement, Positions, Stvk};
use crate::Vec3;
use crate::material::{Mat3, stvk};
pub use crate::math::f64x4::{F64x4, available};
use crate::math::lane::M3;
use std::arch::x86_64::*;

/// A 3-vector of lanes.
pub type V3 = [F64x4; 3];

/// `[x, y, z, 0]` of node `p` (reads three doubles only).
///
/// # Safety
/// `p` points to a `Vec3`.
#[inline(always)]
pub unsafe fn load_row(p: *const Vec3) -> __m256d {
    unsafe { _mm256_maskload_pd(p.cast(), _mm256_set_epi64x(0, -1, -1, -1)) }
}

/// Four rows `[x, y, z, ·]` (one per lane) into `[x, y, z]` lanes.
#[inline(always)]
pub fn transpose(r: [__m256d; 4]) -> V3 {
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
/// Each `out[l]` written points to a `Vec3`.
#[inline(always)]
pub unsafe fn store_rows(v: V3, out: [*mut Vec3; 4], lanes: u32) {
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

/// `m v`: every entry of a 3×3 matrix of lanes scaled by the lanes `v` (the quadrature volume
/// times the stress, `V P`, of every batch kernel).
#[inline(always)]
pub fn scaled(m: &M3<F64x4>, v: F64x4) -> M3<F64x4> {
    let mut out = *m;
    for row in &mut out {
        for x in row {
            *x = x.mul(v);
        }
    }
    out
}

/// A point law on four elements at a time: `(ψ(F), P(F))` per lane.
pub trait BatchLaw: Sync {
    /// # Safety
    /// Only called from functions compiled with AVX2 and FMA.
    unsafe fn energy_and_pk1(&self, f: &M3<F64x4>) -> (F64x4, M3<F64x4>);
}

/// StVK written over lanes: the one point law ([`stvk::energy_and_pk1`]) on four elements.
impl BatchLaw for Stvk {
    #[inline(always)]
    unsafe fn energy_and_pk1(&self, f: &M3<F64x4>) -> (F64x4, M3<F64x4>) {
        stvk::energy_and_pk1(F64x4::splat(self.mu_pa), F64x4::splat(self.lambda_pa), f)
    }
}

/// Any other model lane by lane, through its own scalar law (the node loops around it stay four
/// elements wide; the law is what the scalar kernel calls, so per lane the same `P` bit for bit).
impl BatchLaw for AnyMaterial<'_> {
    #[inline(always)]
    unsafe fn energy_and_pk1(&self, f: &M3<F64x4>) -> (F64x4, M3<F64x4>) {
        let mut lanes = [[[0.0; 4]; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                lanes[r][c] = f[r][c].lanes();
            }
        }
        let mut psi = [0.0; 4];
        let mut p_lanes = [[[0.0; 4]; 3]; 3];
        for l in 0..4 {
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
        let mut p = [[F64x4::zero(); 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                let v = &p_lanes[r][c];
                p[r][c] = F64x4::new(v[0], v[1], v[2], v[3]);
            }
        }
        (F64x4::new(psi[0], psi[1], psi[2], psi[3]), p)
    }
}

/// Four elements of `N` nodes gathered: inverse masses `w[i]`, positions `x[i]` and
/// displacements `u[i] = x_i − X_i`, node `i` of lane `l` being `nodes[N l + i]`, and `free`, the
/// lanes with a free node (the scalar sweep skips an element whose nodes are all pinned).
pub struct Gathered<const N: usize> {
    pub w: [F64x4; N],
    pub x: [V3; N],
    pub u: [V3; N],
    pub free: F64x4,
}

/// Gathers the batch whose `4 N` node indices are `nodes`, or None when all four elements are
/// pinned.
///
/// # Safety
/// Only called from functions compiled with AVX2 and FMA; `positions` valid for the call, no
/// other thread writing these nodes.
#[inline(always)]
pub unsafe fn gather<const N: usize>(
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    nodes: &[u32],
) -> Option<Gathered<N>> {
    let nodes: &[u32] = &nodes[..4 * N];
    let (nx, rx, wx) = (positions.len(), rest.len(), inv_mass.len());
    for &n in nodes {
        let n = n as usize;
        assert!(n < nx && n < rx && n < wx);
    }
    let zero = F64x4::zero();
    let mut w = [zero; N];
    let mut free = zero;
    for i in 0..N {
        w[i] = F64x4::new(
            inv_mass[nodes[i] as usize],
            inv_mass[nodes[N + i] as usize],
            inv_mass[nodes[2 * N + i] as usize],
            inv_mass[nodes[3 * N + i] as usize],
        );
        free = free.or(w[i].ne(zero));
    }
    if free.mask_bits() == 0 {
        return None;
    }
    let mut x = [[zero; 3]; N];
    let mut u = [[zero; 3]; N];
    for i in 0..N {
        // SAFETY: indices checked above.
        unsafe {
            let xr = [
                load_row(positions.ptr().add(nodes[i] as usize)),
                load_row(positions.ptr().add(nodes[N + i] as usize)),
                load_row(positions.ptr().add(nodes[2 * N + i] as usize)),
                load_row(positions.ptr().add(nodes[3 * N + i] as usize)),
            ];
            let rr = [
                load_row(rest.as_ptr().add(nodes[i] as usize)),
                load_row(rest.as_ptr().add(nodes[N + i] as usize)),
                load_row(rest.as_ptr().add(nodes[2 * N + i] as usize)),
                load_row(rest.as_ptr().add(nodes[3 * N + i] as usize)),
            ];
            x[i] = transpose(xr);
            u[i] = transpose([
                _mm256_sub_pd(xr[0], rr[0]),
                _mm256_sub_pd(xr[1], rr[1]),
                _mm256_sub_pd(xr[2], rr[2]),
                _mm256_sub_pd(xr[3], rr[3]),
            ]);
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
/// Only called from functions compiled with AVX2 and FMA; `nodes` the batch's `4 N` node indices
/// and `ids` its element ids, checked against `positions` and `lambdas` by the caller
/// ([`gather`] checks the nodes); no other thread touching them.
#[inline(always)]
pub unsafe fn finish_batch<const N: usize>(
    g: &Gathered<N>,
    energy: F64x4,
    grad: &[V3; N],
    positions: Positions,
    lambdas: Multipliers,
    nodes: &[u32],
    ids: &[u32; 4],
    inv_dt2: f64,
) -> Result<u64, NonFiniteElement> {
    let zero = F64x4::zero();
    let (w, x, free) = (&g.w, &g.x, g.free);
    let energy = energy.max(zero);
    let c = F64x4::splat(2.0).mul(energy).sqrt();
    let mut sum_w_grad2 = zero;
    for i in 0..N {
        let n2 = grad[i][2].fma(grad[i][2], grad[i][1].fma(grad[i][1], grad[i][0].mul(grad[i][0])));
        sum_w_grad2 = w[i].fma(n2, sum_w_grad2);
    }
    // xpbd_step(c, c, Σ w|∇U|², α̃ = 1/h², λ): a = Σ + α̃ c c, b = −(c + α̃ λ) c, step = b / a,
    // None (no update) unless a > MIN_POSITIVE and the step is finite
    for &id in ids {
        assert!((id as usize) < lambdas.len());
    }
    // SAFETY: ids checked above; no other thread touches these multipliers.
    let lam_ptr = |l: usize| unsafe { lambdas.ptr().add(ids[l] as usize) };
    let lambda = unsafe { F64x4::new(*lam_ptr(0), *lam_ptr(1), *lam_ptr(2), *lam_ptr(3)) };
    let inv_dt2 = F64x4::splat(inv_dt2);
    let a = sum_w_grad2.add(inv_dt2.mul(c).mul(c));
    let rhs = c.add(inv_dt2.mul(lambda)).neg().mul(c);
    let step = rhs.div(a);
    let update = a.gt(F64x4::splat(f64::MIN_POSITIVE)).and(step.finite()).and(free);
    let step = F64x4::select(update, step, zero);
    let new_lambda = F64x4::select(update, lambda.add(c.mul(step)), lambda).lanes();
    let mut check = zero;
    let mut out = *x;
    for i in 0..N {
        let s = step.mul(w[i]);
        for a in 0..3 {
            out[i][a] = F64x4::select(update, x[i][a].add(grad[i][a].mul(s)), x[i][a]);
            check = out[i][a].mul(zero).add(check);
        }
    }
    // lanes whose new positions are not all finite (pinned elements are not checked)
    let free_bits = free.mask_bits();
    let bad = check.ne(zero).and(free).mask_bits();
    let (done, lambda_lanes) = if bad == 0 {
        (free_bits, 0b1111)
    } else {
        let first = bad.trailing_zeros();
        ((1 << first) - 1, (1 << (first + 1)) - 1)
    };
    for l in 0..4 {
        if lambda_lanes & (1 << l) != 0 {
            // SAFETY: as above.
            unsafe { *lam_ptr(l) = new_lambda[l] };
        }
    }
    for (i, oi) in out.iter().enumerate() {
        // SAFETY: indices checked by gather; the lanes' nodes are distinct (one colour).
        unsafe {
            let p = positions.ptr();
            let rows = [
                p.add(nodes[i] as usize),
                p.add(nodes[N + i] as usize),
                p.add(nodes[2 * N + i] as usize),
                p.add(nodes[3 * N + i] as usize),
            ];
            store_rows(*oi, rows, done)
        };
    }
    if bad != 0 {
        let l = bad.trailing_zeros() as usize;
        let i = (0..N).find(|&i| out[i].iter().any(|v| !v.lanes()[l].is_finite())).unwrap_or(0);
        return Err(NonFiniteElement { element: ids[l] as usize, node: nodes[N * l + i] });
    }
    Ok(u64::from(free_bits.count_ones()))
}
