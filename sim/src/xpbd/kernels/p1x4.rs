//! The linear tetrahedron four at a time: four consecutive elements of one colour (they share
//! no node) projected together, one element per 64-bit lane of a 256-bit register (AVX2 + FMA).
//!
//! Per lane this is [`super::project_p1`] with [`super::Stvk`] followed by the scatter and the
//! non-finite check of the scalar sweep: `F = I + [u₁−u₀, u₂−u₀, u₃−u₀] G`, `(ψ, P)` by the one
//! StVK point law ([`crate::material::stvk::energy_and_pk1`] on the four-lane [`Lane`] type),
//! `[∇₁U ∇₂U ∇₃U] = V P Gᵀ`, `∇₀U = −Σ`, `C = √(2 max(VΨ, 0))` and the update of
//! [`crate::xpbd::constraint::xpbd_step`] with its guards (no update where `Σ w|∇U|² + α̃C² ≤
//! f64::MIN_POSITIVE` or NaN, or where the step is not finite). An element whose nodes are all
//! pinned is skipped (its multiplier and nodes untouched), as in the scalar sweep. Results equal
//! the scalar colour sweep's up to the order of floating-point operations.
//!
//! The rest data of a batch (`G` and `V` of its four elements) is stored lane-interleaved in
//! [`super::PackedBlock::p1x4`]: [`BATCH_VALUES`] doubles per batch, `G[r][c]` (`∂N_{r+1}/∂X_c`)
//! for `r, c < 3` as four lanes each, then the four volumes.

use super::{BATCH_VALUES, Multipliers, NonFiniteElement, Positions, Stvk};
use crate::Vec3;
use crate::material::lane::{Lane, M3};
use crate::material::stvk;
use std::arch::x86_64::*;

/// Four doubles, one per element.
#[derive(Clone, Copy)]
struct F64x4(__m256d);

// Every method is inlined into `batches_avx2`, which is compiled with AVX2 and FMA and only
// called where the CPU has both.
impl F64x4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self(unsafe { _mm256_set1_pd(v) })
    }
    #[inline(always)]
    fn zero() -> Self {
        Self(unsafe { _mm256_setzero_pd() })
    }
    /// `[a, b, c, d]` in lanes 0..3.
    #[inline(always)]
    fn new(a: f64, b: f64, c: f64, d: f64) -> Self {
        Self(unsafe { _mm256_set_pd(d, c, b, a) })
    }
    /// # Safety
    /// `p` points to four doubles.
    #[inline(always)]
    unsafe fn load(p: *const f64) -> Self {
        Self(unsafe { _mm256_loadu_pd(p) })
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(unsafe { _mm256_add_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(unsafe { _mm256_sub_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(unsafe { _mm256_mul_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Self(unsafe { _mm256_div_pd(self.0, o.0) })
    }
    /// `self · b + c`, one rounding.
    #[inline(always)]
    fn fma(self, b: Self, c: Self) -> Self {
        Self(unsafe { _mm256_fmadd_pd(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }
    /// `f64::max` per lane for a non-NaN `o` (a NaN `self` gives `o`, as `f64::max`).
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // maxpd returns its second operand when either is NaN
        Self(unsafe { _mm256_max_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Self::zero().sub(self)
    }
    /// All-ones lanes where `self > o` (false for NaN).
    #[inline(always)]
    fn gt(self, o: Self) -> Self {
        Self(unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, o.0) })
    }
    /// All-ones lanes where `self != o` or either is NaN.
    #[inline(always)]
    fn ne(self, o: Self) -> Self {
        Self(unsafe { _mm256_cmp_pd::<_CMP_NEQ_UQ>(self.0, o.0) })
    }
    /// All-ones lanes where `self` is finite.
    #[inline(always)]
    fn finite(self) -> Self {
        // x·0 is 0 for a finite x and NaN otherwise
        Self(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(self.mul(Self::zero()).0, _mm256_setzero_pd()) })
    }
    #[inline(always)]
    fn and(self, o: Self) -> Self {
        Self(unsafe { _mm256_and_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn or(self, o: Self) -> Self {
        Self(unsafe { _mm256_or_pd(self.0, o.0) })
    }
    /// Bit `l` set where lane `l`'s sign bit is (an all-ones mask lane).
    #[inline(always)]
    fn mask_bits(self) -> u32 {
        unsafe { _mm256_movemask_pd(self.0) as u32 }
    }
    /// `self` where `mask`, else `other`.
    #[inline(always)]
    fn select(mask: Self, a: Self, other: Self) -> Self {
        Self(unsafe { _mm256_blendv_pd(other.0, a.0, mask.0) })
    }
    #[inline(always)]
    fn lanes(self) -> [f64; 4] {
        let mut out = [0.0; 4];
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }
}

impl Lane for F64x4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self::splat(v)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::add(self, o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::sub(self, o)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::mul(self, o)
    }
    /// Fused.
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        self.fma(b, c)
    }
    /// One chain of fused multiply–adds, column by column: `m₂₂ m₂₂ + (… + (m₀₀ m₀₀ + 0))`.
    #[inline(always)]
    fn sum_of_squares(m: &M3<Self>) -> Self {
        let mut sum = Self::zero();
        for c in 0..3 {
            for r in 0..3 {
                sum = m[r][c].fma(m[r][c], sum);
            }
        }
        sum
    }
}

/// A 3-vector of lanes.
type V3 = [F64x4; 3];

/// `[x, y, z, 0]` of node `p` (reads three doubles only).
///
/// # Safety
/// `p` points to a `Vec3`.
#[inline(always)]
unsafe fn load_row(p: *const Vec3) -> __m256d {
    unsafe { _mm256_maskload_pd(p.cast(), _mm256_set_epi64x(0, -1, -1, -1)) }
}

/// Four rows `[x, y, z, ·]` (one per lane) into `[x, y, z]` lanes.
#[inline(always)]
fn transpose(r: [__m256d; 4]) -> V3 {
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
unsafe fn store_rows(v: V3, out: [*mut Vec3; 4], lanes: u32) {
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

/// Projects `batches` batches of four P1 elements with StVK. Returns the number of elements
/// projected (with a free node), or the first element (in packed order) whose corrections came
/// out non-finite; as the scalar sweep, the elements before it are projected and scattered, its
/// multiplier is updated, its nodes are not written, and the elements after it are untouched.
///
/// # Safety
/// The CPU must support AVX2 and FMA; `io.nodes`, `io.values`, `io.element_ids` must hold
/// `batches` batches; node indices below `io.positions.len()` and `io.rest.len()` and
/// `io.inv_mass.len()`, element ids below `io.lambdas.len()`; the four elements of a batch
/// share no node, and no other thread touches these nodes and multipliers meanwhile.
#[target_feature(enable = "avx2,fma")]
pub unsafe fn batches_avx2(material: &Stvk, io: BatchIo<'_>, batches: usize) -> Result<u64, NonFiniteElement> {
    assert!(
        io.nodes.len() >= batches * 16
            && io.values.len() >= batches * BATCH_VALUES
            && io.element_ids.len() >= batches * 4
    );
    let (nx, rx, wx) = (io.positions.len(), io.rest.len(), io.inv_mass.len());
    let (mu, lambda_pa) = (F64x4::splat(material.mu_pa), F64x4::splat(material.lambda_pa));
    let (one, two, zero) = (F64x4::splat(1.0), F64x4::splat(2.0), F64x4::zero());
    let inv_dt2 = F64x4::splat(io.inv_dt2);
    let tiny = F64x4::splat(f64::MIN_POSITIVE);
    let mut projected = 0u64;
    for b in 0..batches {
        let nodes: &[u32; 16] = io.nodes[b * 16..(b + 1) * 16].try_into().expect("16 nodes");
        for &n in nodes {
            let n = n as usize;
            assert!(n < nx && n < rx && n < wx);
        }
        // node i of lane l is nodes[4 l + i]
        let node = |l: usize, i: usize| nodes[4 * l + i] as usize;
        let w: [F64x4; 4] = std::array::from_fn(|i| {
            F64x4::new(
                io.inv_mass[node(0, i)],
                io.inv_mass[node(1, i)],
                io.inv_mass[node(2, i)],
                io.inv_mass[node(3, i)],
            )
        });
        // the scalar sweep skips an element whose nodes are all pinned
        let free = w[0].ne(zero).or(w[1].ne(zero)).or(w[2].ne(zero)).or(w[3].ne(zero));
        let free_bits = free.mask_bits();
        if free_bits == 0 {
            continue;
        }
        // SAFETY: indices checked above.
        let (x, u): ([V3; 4], [V3; 4]) = unsafe {
            let mut x = [[zero; 3]; 4];
            let mut u = [[zero; 3]; 4];
            for i in 0..4 {
                let xr: [__m256d; 4] = std::array::from_fn(|l| load_row(io.positions.ptr().add(node(l, i))));
                let rr: [__m256d; 4] = std::array::from_fn(|l| load_row(io.rest.as_ptr().add(node(l, i))));
                x[i] = transpose(xr);
                u[i] = transpose(std::array::from_fn(|l| _mm256_sub_pd(xr[l], rr[l])));
            }
            (x, u)
        };
        let vals = &io.values[b * BATCH_VALUES..(b + 1) * BATCH_VALUES];
        // SAFETY: vals holds 40 doubles.
        let g: [[F64x4; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|c| unsafe { F64x4::load(vals.as_ptr().add((3 * r + c) * 4)) })
        });
        let v = unsafe { F64x4::load(vals.as_ptr().add(36)) };
        // du[a][r] = (u_{r+1} − u_0)_a
        let du: [[F64x4; 3]; 3] = std::array::from_fn(|a| std::array::from_fn(|r| u[r + 1][a].sub(u[0][a])));
        // F = I + du G (as mul3: ((du_a0 g_0b) + du_a1 g_1b) + du_a2 g_2b, then + I)
        let f: [[F64x4; 3]; 3] = std::array::from_fn(|a| {
            std::array::from_fn(|c| {
                let m = du[a][2].fma(g[2][c], du[a][1].fma(g[1][c], du[a][0].mul(g[0][c])));
                if a == c { one.add(m) } else { m }
            })
        });
        // the one StVK point law, four elements at a time
        let (psi, p) = stvk::energy_and_pk1(mu, lambda_pa, &f);
        // ∇_{j+1} U = V P g_j (H = (V P) Gᵀ), ∇_0 U = −Σ
        let vp: [[F64x4; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| p[r][c].mul(v)));
        let mut grad = [[zero; 3]; 4];
        for j in 0..3 {
            for a in 0..3 {
                grad[j + 1][a] = vp[a][2].fma(g[j][2], vp[a][1].fma(g[j][1], vp[a][0].mul(g[j][0])));
            }
        }
        for a in 0..3 {
            grad[0][a] = grad[1][a].add(grad[2][a]).add(grad[3][a]).neg();
        }
        let energy = v.mul(psi).max(zero);
        let c = two.mul(energy).sqrt();
        let mut sum_w_grad2 = zero;
        for i in 0..4 {
            let n2 = grad[i][2].fma(grad[i][2], grad[i][1].fma(grad[i][1], grad[i][0].mul(grad[i][0])));
            sum_w_grad2 = w[i].fma(n2, sum_w_grad2);
        }
        // xpbd_step(c, c, Σ w|∇U|², α̃ = 1/h², λ): a = Σ + α̃ c c, b = −(c + α̃ λ) c, step = b / a,
        // None (no update) unless a > MIN_POSITIVE and the step is finite
        let ids: &[u32; 4] = io.element_ids[b * 4..(b + 1) * 4].try_into().expect("4 ids");
        for &id in ids {
            assert!((id as usize) < io.lambdas.len());
        }
        // SAFETY: ids checked above; no other thread touches these multipliers.
        let lam_ptr = |l: usize| unsafe { io.lambdas.ptr().add(ids[l] as usize) };
        let lambda = unsafe { F64x4::new(*lam_ptr(0), *lam_ptr(1), *lam_ptr(2), *lam_ptr(3)) };
        let a = sum_w_grad2.add(inv_dt2.mul(c).mul(c));
        let rhs = c.add(inv_dt2.mul(lambda)).neg().mul(c);
        let step = rhs.div(a);
        let update = a.gt(tiny).and(step.finite()).and(free);
        let step = F64x4::select(update, step, zero);
        let new_lambda = F64x4::select(update, lambda.add(c.mul(step)), lambda).lanes();
        let mut check = zero;
        let mut out = x;
        for i in 0..4 {
            let s = step.mul(w[i]);
            for a in 0..3 {
                out[i][a] = F64x4::select(update, x[i][a].add(grad[i][a].mul(s)), x[i][a]);
                check = out[i][a].mul(zero).add(check);
            }
        }
        // lanes whose new positions are not all finite (pinned elements are not checked)
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
            // SAFETY: indices checked above; the lanes' nodes are distinct.
            unsafe { store_rows(*oi, std::array::from_fn(|l| io.positions.ptr().add(node(l, i))), done) };
        }
        if bad != 0 {
            let l = bad.trailing_zeros() as usize;
            let i = (0..4).find(|&i| out[i].iter().any(|v| !v.lanes()[l].is_finite())).unwrap_or(0);
            return Err(NonFiniteElement { element: ids[l] as usize, node: nodes[4 * l + i] });
        }
        projected += u64::from(free_bits.count_ones());
    }
    Ok(projected)
}
