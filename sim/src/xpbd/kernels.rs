//! The hot loop of the solver, specialised per element node count: the energy-constraint sweep
//! over a block (serial in element order, or one colour's contiguous range in the parallel sweep).
//!
//! It computes exactly what [`crate::xpbd::constraint::project_energy_constraint`] computes — for each
//! element, `F_q = I + Σ_i (x_i − X_i) ⊗ ∇_X N_i(r_q)`, `U_e = Σ_q V_q ψ(F_q)`,
//! `∇_i U_e = Σ_q V_q P(F_q) ∇_X N_i(r_q)`, `C = √(2U_e)` and the XPBD update of
//! [`crate::xpbd::constraint::xpbd_step`] (the paper's `Δλ = −2U / (Σ_i w_i |∇_i U|² + 2U α̃)` with
//! λ = 0, Saillant et al. §3) — but with the node count `N` a compile-time constant, so that
//! every per-node loop is unrolled and every scratch array lives in registers or a fixed-size
//! stack array of exactly `N` entries; and with the material's Lamé parameters computed once per
//! sweep instead of once per quadrature point ([`Stvk`]). Results equal the generic kernel's up
//! to the order of floating-point operations.
//!
//! Both sweeps read the element data from a [`PackedBlock`] copy: connectivity, material
//! gradients (as structure of arrays per element and point, so the loops over the `N` nodes
//! vectorise) and quadrature volumes; for the parallel sweep reordered colour by colour, so that each colour is a
//! contiguous range of memory handed to the threads in contiguous chunks (the elements of a
//! colour keep their increasing element order, so the result is bitwise the one of the
//! element-indexed colour sweep).

use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::material::lane::{self, Scalar, madd};
use crate::material::{Mat3, Material, MaterialModel, stvk};
use crate::mesh::ElementBlock;
use crate::xpbd::constraint::xpbd_step;

/// `(ψ(F), P(F))` at one quadrature point: the material law the kernel is generic over.
pub trait PointMaterial: Sync {
    /// `FMA`: products may use fused multiply–adds ([`mul3`]).
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3);
}

/// `a b` for 3×3 matrices with `madd::<FMA>` (nalgebra's product never fuses).
#[inline(always)]
pub fn mul3<const FMA: bool>(a: &Mat3, b: &Mat3) -> Mat3 {
    Mat3::from_fn(|r, c| madd::<FMA>(a[(r, 2)], b[(2, c)], madd::<FMA>(a[(r, 1)], b[(1, c)], a[(r, 0)] * b[(0, c)])))
}

/// Saint-Venant–Kirchhoff with its Lamé parameters computed once per sweep: the one StVK point
/// law, [`crate::material::stvk::energy_and_pk1`], on one `f64` (fused multiply–adds with `FMA`).
#[derive(Clone, Copy, Debug)]
pub struct Stvk {
    pub mu_pa: f64,
    pub lambda_pa: f64,
}

impl PointMaterial for Stvk {
    #[inline(always)]
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3) {
        let (psi, p) =
            stvk::energy_and_pk1::<Scalar<FMA>>(Scalar(self.mu_pa), Scalar(self.lambda_pa), &lane::from_mat3(f));
        (psi.0, lane::to_mat3(&p))
    }
}

/// Any material, through [`Material::energy_density_and_pk1`].
#[derive(Clone, Copy, Debug)]
pub struct AnyMaterial<'a>(pub &'a Material);

impl PointMaterial for AnyMaterial<'_> {
    #[inline(always)]
    fn energy_and_pk1<const FMA: bool>(&self, f: &Mat3) -> (f64, Mat3) {
        self.0.energy_density_and_pk1(f)
    }
}

/// One block's element data as the sweep reads it (a view of a [`PackedBlock`]).
#[derive(Clone, Copy, Debug)]
pub struct BlockData<'a> {
    /// `N` node indices per element.
    pub nodes: &'a [u32],
    /// Material gradients, structure of arrays per element and point: for packed element `k`
    /// and point `q`, the `3P` values from `(k Q + q) 3P` (`P` = [`padded`]`(N)`) are
    /// `∂N_i/∂X` for `i < P` (zero for `i ≥ N`), then `∂N_i/∂Y`, then `∂N_i/∂Z`, so that the
    /// loops over nodes run in whole vector registers.
    pub grads: &'a [f64],
    /// `Q` quadrature volumes per element.
    pub volumes: &'a [f64],
    pub points: usize,
    /// `element_ids[k]`: the block's element index of packed element `k` (its multiplier and
    /// the name the NaN guard reports). None: packed element `k` is element `k`.
    pub element_ids: Option<&'a [u32]>,
}

/// What the sweep hands back when an element's corrections come out non-finite: its element
/// index in the block and its first non-finite node (nothing was scattered for it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFiniteElement {
    pub element: usize,
    pub node: u32,
}

/// A mutable slice shared across threads through a raw pointer: the parallel sweeps hand one
/// copy to every thread of a colour (or slab), and those threads touch disjoint entries (no two
/// elements of a colour share a node, [`crate::xpbd::colouring`]; each element owns its multipliers).
/// That disjointness, which the type cannot check, is what every `unsafe` access promises.
/// Indices are checked against the length (a panic, never an out-of-bounds access); the hot
/// loops that have already checked an index read and write through [`SharedMut::ptr`].
pub struct SharedMut<T> {
    ptr: *mut T,
    len: usize,
}

impl<T> Clone for SharedMut<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for SharedMut<T> {}

// SAFETY: shared across the threads of one colour, which touch disjoint entries.
unsafe impl<T: Send> Send for SharedMut<T> {}
unsafe impl<T: Send> Sync for SharedMut<T> {}

impl<T> SharedMut<T> {
    pub fn new(slice: &mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len() }
    }

    /// Number of entries.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The first entry's address (for accesses whose index the caller has checked against
    /// [`SharedMut::len`]).
    #[inline(always)]
    pub fn ptr(&self) -> *mut T {
        self.ptr
    }

    /// Entry `i` (panics when `i ≥ len`).
    ///
    /// # Safety
    /// No other thread may write entry `i` meanwhile, and the slice must still be alive.
    #[inline(always)]
    pub unsafe fn read(&self, i: usize) -> T
    where
        T: Copy,
    {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); the caller excludes concurrent writes.
        unsafe { self.ptr.add(i).read() }
    }

    /// Writes entry `i` (panics when `i ≥ len`).
    ///
    /// # Safety
    /// No other thread may access entry `i` meanwhile, and the slice must still be alive.
    #[inline(always)]
    pub unsafe fn write(&self, i: usize, value: T) {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); the caller excludes concurrent access.
        unsafe { self.ptr.add(i).write(value) }
    }

    /// Entries `start..start + len` as a mutable slice (panics when out of bounds).
    ///
    /// # Safety
    /// No other thread may access that range while the returned slice lives, and the slice
    /// must still be alive.
    #[allow(clippy::mut_from_ref)] // disjoint ranges handed to different threads: the point
    #[inline(always)]
    pub unsafe fn slice_mut(&self, start: usize, len: usize) -> &mut [T] {
        assert!(start <= self.len && len <= self.len - start);
        // SAFETY: in bounds (checked); the caller excludes concurrent access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(start), len) }
    }
}

/// Node positions as the sweep reads and writes them.
pub type Positions = SharedMut<Vec3>;
/// Multipliers λ as the sweep writes them (one per element, indexed by the block's element index).
pub type Multipliers = SharedMut<f64>;

/// Node counts with a specialised sweep (P1, pyramid, prism, Q1, P2, P3, Q2).
pub const SPECIALISED_NODE_COUNTS: [usize; 7] = [4, 5, 6, 8, 10, 20, 27];

/// The sweep of the energy formulation over packed elements `range` of `data`, in order.
/// Returns the number of elements projected (those with a free node), or the first element
/// whose corrections came out non-finite. None when `nodes_per_element` has no specialised
/// sweep (the caller falls back to the generic kernel).
///
/// # Safety
/// `positions` and `lambdas` must be valid for the whole sweep, every node index of `data` must
/// be below `positions.len()`, every element id below `lambdas.len()`, and no other thread may
/// touch the nodes and multipliers of the elements in `range` meanwhile.
#[allow(clippy::too_many_arguments)]
pub unsafe fn energy_sweep(
    nodes_per_element: usize,
    material: &Material,
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    data: &BlockData<'_>,
    range: std::ops::Range<usize>,
    lambdas: Multipliers,
    inv_dt2: f64,
) -> Option<Result<u64, NonFiniteElement>> {
    let io = SweepIo { positions, rest, inv_mass, data, lambdas, inv_dt2 };
    #[cfg(target_arch = "x86_64")]
    let wide = std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma");
    macro_rules! dispatch {
        ($(($n:literal, $p:literal)),*) => {
            match nodes_per_element {
                $($n => Some(match material.model {
                    MaterialModel::StVenantKirchhoff => {
                        let l = material.lame();
                        let m = Stvk { mu_pa: l.mu_pa, lambda_pa: l.lambda_pa };
                        #[cfg(target_arch = "x86_64")]
                        if wide {
                            // SAFETY: forwarded from the caller; AVX2 and FMA were detected.
                            return Some(unsafe { sweep_avx2::<$n, $p, _>(&m, io, range) });
                        }
                        // SAFETY: forwarded from the caller.
                        unsafe { sweep::<$n, $p, false, _>(&m, io, range) }
                    }
                    // SAFETY: as above.
                    _ => unsafe { sweep::<$n, $p, false, _>(&AnyMaterial(material), io, range) },
                }),)*
                _ => None,
            }
        };
    }
    dispatch!((4, 4), (5, 8), (6, 8), (8, 8), (10, 12), (20, 20), (27, 28))
}

/// What a sweep reads and writes, besides the material and the range of packed elements.
#[derive(Clone, Copy)]
struct SweepIo<'a> {
    positions: Positions,
    rest: &'a [Vec3],
    inv_mass: &'a [f64],
    data: &'a BlockData<'a>,
    lambdas: Multipliers,
    inv_dt2: f64,
}

/// `acc ← acc + a ∘ b` on [`LANES`] lanes (`a`, `b`: at least `LANES` long): one AVX2 fused
/// multiply–add when `FMA` (set only by [`sweep_avx2`], where the CPU has both).
#[inline(always)]
fn fma_lanes<const FMA: bool>(acc: &mut [f64; LANES], a: &[f64], b: &[f64]) {
    let (a, b): (&[f64; LANES], &[f64; LANES]) =
        (a[..LANES].try_into().expect("LANES"), b[..LANES].try_into().expect("LANES"));
    #[cfg(target_arch = "x86_64")]
    if FMA {
        use std::arch::x86_64::{_mm256_fmadd_pd, _mm256_loadu_pd, _mm256_storeu_pd};
        // SAFETY: FMA is true only under sweep_avx2, which runs where AVX2 and FMA were detected;
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
fn axpy_lanes<const FMA: bool>(acc: &mut [f64; LANES], s: f64, b: &[f64]) {
    fma_lanes::<FMA>(acc, &[s; LANES], b);
}

/// `N` rounded up to a multiple of [`LANES`]: the padded length of the per-node arrays.
pub const fn padded(n: usize) -> usize {
    n.div_ceil(LANES) * LANES
}

/// Width of the partial sums of the node loops (four doubles: one 256-bit register).
pub const LANES: usize = 4;

/// [`sweep`] compiled for AVX2 with FMA (selected at run time).
///
/// # Safety
/// See [`energy_sweep`]; the CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn sweep_avx2<const N: usize, const P: usize, M: PointMaterial>(
    material: &M,
    io: SweepIo<'_>,
    range: std::ops::Range<usize>,
) -> Result<u64, NonFiniteElement> {
    // SAFETY: forwarded.
    unsafe { sweep::<N, P, true, M>(material, io, range) }
}

/// [`energy_sweep`] for `N` nodes per element and material law `M`.
///
/// # Safety
/// See [`energy_sweep`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
unsafe fn sweep<const N: usize, const P: usize, const FMA: bool, M: PointMaterial>(
    material: &M,
    io: SweepIo<'_>,
    range: std::ops::Range<usize>,
) -> Result<u64, NonFiniteElement> {
    let SweepIo { positions, rest, inv_mass, data, lambdas, inv_dt2 } = io;
    let q = data.points;
    let mut projected = 0;
    for k in range {
        let nodes: &[u32; N] = data.nodes[k * N..(k + 1) * N].try_into().expect("N nodes");
        let w: [f64; N] = std::array::from_fn(|i| inv_mass[nodes[i] as usize]);
        if w.iter().all(|&wi| wi == 0.0) {
            continue;
        }
        let e = data.element_ids.map_or(k, |ids| ids[k] as usize);
        assert!(e < lambdas.len());
        // SAFETY: node indices are checked against the length; the caller guarantees no other
        // thread touches these nodes and this multiplier.
        let mut x: [Vec3; N] = std::array::from_fn(|i| unsafe { positions.read(nodes[i] as usize) });
        let d: [Vec3; N] = std::array::from_fn(|i| x[i] - rest[nodes[i] as usize]);
        let lambda = unsafe { &mut *lambdas.ptr().add(e) };
        let grads = &data.grads[k * q * 3 * P..(k + 1) * q * 3 * P];
        let volumes = &data.volumes[k * q..(k + 1) * q];
        if N == 4 && q == 1 {
            // the linear tetrahedron: one point, constant gradients
            let x4: &mut [Vec3; 4] = (&mut x[..]).try_into().expect("4 nodes");
            let (d4, w4): (&[Vec3; 4], &[f64; 4]) =
                (d[..].try_into().expect("4 nodes"), w[..].try_into().expect("4 nodes"));
            project_p1::<FMA, M>(x4, d4, w4, grads, volumes[0], material, inv_dt2, lambda);
        } else {
            let mut u = [[0.0; P]; 3];
            for i in 0..N {
                for a in 0..3 {
                    u[a][i] = d[i][a];
                }
            }
            project_energy::<N, P, FMA, M>(&mut x, &u, &w, grads, volumes, material, inv_dt2, lambda);
        }
        // x·0 is 0 for a finite x and NaN otherwise: one sum checks every coordinate
        let mut check = 0.0;
        for xi in &x {
            check += xi.x * 0.0 + xi.y * 0.0 + xi.z * 0.0;
        }
        if check != 0.0 {
            let i = x.iter().position(|xi| !xi.iter().all(|c| c.is_finite())).unwrap_or(0);
            return Err(NonFiniteElement { element: e, node: nodes[i] });
        }
        for i in 0..N {
            // SAFETY: as above.
            unsafe { positions.ptr().add(nodes[i] as usize).write(x[i]) };
        }
        projected += 1;
    }
    Ok(projected)
}

/// [`project_energy`] for the linear tetrahedron (one quadrature point, constant gradients
/// `g_i = ∇_X N_i`, `Σ_i g_i = 0`): `F = I + Σ_{i=1..3} (u_i − u_0) ⊗ g_i` (the paper's
/// `F = D_s D_m⁻¹` written in displacements), `∇_i U = V P g_i` for `i = 1..3` and
/// `∇_0 U = −Σ_{i≥1} ∇_i U` (Bender et al.'s FEM tetrahedron), all as 3×3 products.
/// `grads` is the point's `3 × 4` structure-of-arrays block; `v` its volume.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn project_p1<const FMA: bool, M: PointMaterial>(
    x: &mut [Vec3; 4],
    u: &[Vec3; 4],
    w: &[f64; 4],
    grads: &[f64],
    v: f64,
    material: &M,
    inv_dt2: f64,
    lambda: &mut f64,
) -> f64 {
    // g[(i − 1, b)] = ∂N_i/∂X_b
    let g = Mat3::new(grads[1], grads[5], grads[9], grads[2], grads[6], grads[10], grads[3], grads[7], grads[11]);
    let du = Mat3::from_columns(&[u[1] - u[0], u[2] - u[0], u[3] - u[0]]);
    let f = Mat3::identity() + mul3::<FMA>(&du, &g);
    let (psi, p) = material.energy_and_pk1::<FMA>(&f);
    // columns: ∇_1 U, ∇_2 U, ∇_3 U
    let h = mul3::<FMA>(&(p * v), &g.transpose());
    let g0 = -(h.column(0) + h.column(1) + h.column(2));
    let grad = [g0, h.column(0).into_owned(), h.column(1).into_owned(), h.column(2).into_owned()];
    let energy = (v * psi).max(0.0);
    let c = (2.0 * energy).sqrt();
    let sum_w_grad2 = w[0] * grad[0].norm_squared()
        + w[1] * grad[1].norm_squared()
        + w[2] * grad[2].norm_squared()
        + w[3] * grad[3].norm_squared();
    if let Some((d_lambda, step)) = xpbd_step(c, c, sum_w_grad2, inv_dt2, *lambda) {
        *lambda += d_lambda;
        for i in 0..4 {
            x[i] += grad[i] * (step * w[i]);
        }
    }
    energy
}

/// Projects one element's energy constraint `C = √(2U_e)` (compliance 1): `x` gathered
/// positions (updated), `u[a][i] = x_ia − X_ia` the displacements (zero for `N ≤ i < P`), `w` inverse masses,
/// `grads` (`points × 3P`, structure of arrays, see [`BlockData::grads`]) and `volumes` its
/// rest data. Returns the element energy before projection.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn project_energy<const N: usize, const P: usize, const FMA: bool, M: PointMaterial>(
    x: &mut [Vec3; N],
    u: &[[f64; P]; 3],
    w: &[f64; N],
    grads: &[f64],
    volumes: &[f64],
    material: &M,
    inv_dt2: f64,
    lambda: &mut f64,
) -> f64 {
    let mut grad = [[0.0; P]; 3];
    let mut energy = 0.0;
    for (gq, v) in grads.chunks_exact(3 * P).zip(volumes) {
        let g: [&[f64; P]; 3] = std::array::from_fn(|b| gq[b * P..(b + 1) * P].try_into().expect("P gradients"));
        // F_ab = δ_ab + Σ_i u_ai g_bi, summed in LANES partial sums (one vector register)
        let mut acc = [[[0.0; LANES]; 3]; 3];
        for c in 0..P / LANES {
            for a in 0..3 {
                for b in 0..3 {
                    let r = c * LANES..(c + 1) * LANES;
                    fma_lanes::<FMA>(&mut acc[a][b], &u[a][r.clone()], &g[b][r]);
                }
            }
        }
        let mut f = Mat3::identity();
        for a in 0..3 {
            for b in 0..3 {
                let s = &acc[a][b];
                f[(a, b)] += (s[0] + s[1]) + (s[2] + s[3]);
            }
        }
        let (psi, p) = material.energy_and_pk1::<FMA>(&f);
        energy += v * psi;
        let vp = p * *v;
        for a in 0..3 {
            let (p0, p1, p2) = (vp[(a, 0)], vp[(a, 1)], vp[(a, 2)]);
            for c in 0..P / LANES {
                let r = c * LANES..(c + 1) * LANES;
                let out: &mut [f64; LANES] = (&mut grad[a][r.clone()]).try_into().expect("LANES");
                for (pb, gb) in [p0, p1, p2].into_iter().zip(g) {
                    axpy_lanes::<FMA>(out, pb, &gb[r.clone()]);
                }
            }
        }
    }
    // as the generic kernel: the stable Neo-Hookean energy can dip below its rest value
    let energy = energy.max(0.0);
    let c = (2.0 * energy).sqrt();
    let mut sum_w_grad2 = 0.0;
    for i in 0..N {
        sum_w_grad2 += w[i] * (grad[0][i] * grad[0][i] + grad[1][i] * grad[1][i] + grad[2][i] * grad[2][i]);
    }
    if let Some((d_lambda, step)) = xpbd_step(c, c, sum_w_grad2, inv_dt2, *lambda) {
        *lambda += d_lambda;
        for i in 0..N {
            let s = step * w[i];
            x[i] += Vec3::new(grad[0][i], grad[1][i], grad[2][i]) * s;
        }
    }
    energy
}

/// Doubles stored per batch of four linear tetrahedra in [`PackedBlock::p1x4`]: 9 gradient
/// entries and the volume, four lanes each.
pub const BATCH_VALUES: usize = 40;

/// The colour sweep over packed range `range` of colour `colour` of `packed` (a colour-ordered
/// block), whose start is a multiple of 4 elements from the colour's start: as [`energy_sweep`],
/// but with `batched` the linear tetrahedra with StVK go four at a time through
/// [`p1x4::batches_avx2`] where the CPU has AVX2 and FMA (the colour's last `len mod 4`
/// elements, and every other case, through the scalar sweep). Which elements are batched
/// depends only on the colour, not on how its range is cut, so the result does not depend on
/// the thread count.
///
/// # Safety
/// As [`energy_sweep`].
#[allow(clippy::too_many_arguments)]
pub unsafe fn colour_sweep(
    nodes_per_element: usize,
    material: &Material,
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    packed: &PackedBlock,
    colour: usize,
    range: std::ops::Range<usize>,
    lambdas: Multipliers,
    inv_dt2: f64,
    batched: bool,
) -> Option<Result<u64, NonFiniteElement>> {
    let data = packed.data();
    let colour_start = packed.colour_starts[colour];
    assert!((range.start - colour_start).is_multiple_of(4) && range.end <= packed.colour_starts[colour + 1]);
    let mut tail = range.clone();
    let mut projected = 0;
    #[cfg(target_arch = "x86_64")]
    if batched
        && nodes_per_element == 4
        && packed.points == 1
        && material.model == MaterialModel::StVenantKirchhoff
        && packed.colour_batches.len() == packed.colour_starts.len()
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
    {
        let first = packed.colour_batches[colour] + (range.start - colour_start) / 4;
        let batches = (range.len() / 4).min(packed.colour_batches[colour + 1] - first);
        let ids = data.element_ids.expect("colour order");
        let io = p1x4::BatchIo {
            positions,
            rest,
            inv_mass,
            nodes: &data.nodes[range.start * 4..(range.start + 4 * batches) * 4],
            values: &packed.p1x4[first * BATCH_VALUES..(first + batches) * BATCH_VALUES],
            element_ids: &ids[range.start..range.start + 4 * batches],
            lambdas,
            inv_dt2,
        };
        let l = material.lame();
        // SAFETY: forwarded from the caller; AVX2 and FMA were detected; the elements of a
        // batch are of one colour.
        match unsafe { p1x4::batches_avx2(&Stvk { mu_pa: l.mu_pa, lambda_pa: l.lambda_pa }, io, batches) } {
            Ok(k) => projected = k,
            Err(bad) => return Some(Err(bad)),
        }
        tail.start += 4 * batches;
    }
    // SAFETY: forwarded from the caller.
    let rest_of =
        unsafe { energy_sweep(nodes_per_element, material, positions, rest, inv_mass, &data, tail, lambdas, inv_dt2) }?;
    Some(rest_of.map(|k| k + projected))
}

// Scheduling thresholds of the parallel sweeps, all in one place. They decide only how the work
// is cut between threads, never the result: the elements of one colour share no node and own
// their multipliers, so projecting them in any grouping and order gives the same positions
// bitwise (the four-lane batches are fixed by the colour's start, not by the cut), and a
// non-finite correction is reported for the first bad element of the colour whatever the cut.
// (The slab partition is the exception that changes the order, hence the result: it depends on
// the thread count, see [`Partition`].)

/// Fewest elements per thread in the specialised sweep ([`parallel_energy_block`]): a colour is
/// cut into at most one contiguous chunk per thread, each at least this long (a colour shorter
/// than twice this runs on one thread). The specialised sweep is cheap per element (540
/// instructions for P1, 2,080 for P2: `docs/PERFORMANCE.md`), so a chunk must be long to
/// outweigh waking a thread.
pub const SWEEP_MIN_ELEMENTS_PER_THREAD: usize = 256;

/// Fewest elements per rayon task in the generic parallel sweep (the split formulation, or a
/// node count without a specialised sweep; `Simulation`'s colour loop): that kernel costs
/// several times more per element, so shorter tasks still pay for themselves.
pub const GENERIC_MIN_ELEMENTS_PER_TASK: usize = 64;

/// Fewest elements per thread for which the parallel sweep cuts a block into slabs
/// ([`Partition`]) instead of synchronising the threads after every colour (the default of
/// `Simulation::set_partition_threshold`).
pub const PARTITION_MIN_ELEMENTS_PER_THREAD: usize = 2048;

/// How [`parallel_energy_block`] sweeps a block.
#[derive(Clone, Copy, Debug)]
pub enum BlockSweep<'a> {
    /// Colour after colour (the block packed in colour order).
    Colours(&'a PackedBlock),
    /// Slab by slab, then the interface ([`Partition`]).
    Slabs(&'a Partition),
}

/// The parallel sweep of the energy formulation over one block, by slabs (see [`Partition`]) or
/// else colour after colour, each
/// colour's packed range cut into one contiguous chunk per thread of rayon's current pool (at
/// least [`SWEEP_MIN_ELEMENTS_PER_THREAD`] elements each, cut at multiples of 4 elements from the
/// colour's start; see [`colour_sweep`] for `batched`). Same-colour elements share no node, so the
/// result is the same for any thread count and scheduling; on a non-finite correction the
/// colour is finished (other chunks may have been scattered) and the error of the first such
/// chunk is returned. None when the node count has no specialised sweep.
pub fn parallel_energy_block(
    nodes_per_element: usize,
    material: &Material,
    positions: &mut [Vec3],
    rest: &[Vec3],
    inv_mass: &[f64],
    sweep: BlockSweep<'_>,
    lambdas: &mut [f64],
    inv_dt2: f64,
    batched: bool,
) -> Option<Result<u64, NonFiniteElement>> {
    use rayon::prelude::*;
    if !SPECIALISED_NODE_COUNTS.contains(&nodes_per_element) {
        return None;
    }
    let (positions, lambdas) = (Positions::new(positions), Multipliers::new(lambdas));
    let packed = match sweep {
        BlockSweep::Colours(packed) => packed,
        BlockSweep::Slabs(partition) => {
            return Some(slab_sweep(
                nodes_per_element,
                material,
                positions,
                rest,
                inv_mass,
                partition,
                lambdas,
                inv_dt2,
                batched,
            ));
        }
    };
    let threads = rayon::current_num_threads().max(1);
    let mut projected = 0;
    for c in 0..packed.num_colours() {
        let range = packed.colour(c);
        let chunks = threads.min(range.len().div_ceil(SWEEP_MIN_ELEMENTS_PER_THREAD)).max(1);
        let fours = range.len().div_ceil(4);
        let cut = |i: usize| range.start + (4 * (fours * i / chunks)).min(range.len());
        let chunk = |i: usize| cut(i)..cut(i + 1);
        // SAFETY: the chunks of a colour are disjoint ranges of elements that share no node
        // (crate::xpbd::colouring) and own their multipliers; node and element indices come from the
        // mesh the positions and multipliers were sized for.
        let run = |i: usize| unsafe {
            colour_sweep(
                nodes_per_element,
                material,
                positions,
                rest,
                inv_mass,
                packed,
                c,
                chunk(i),
                lambdas,
                inv_dt2,
                batched,
            )
            .expect("specialised node count")
        };
        let result = if chunks == 1 {
            run(0)
        } else {
            (0..chunks).into_par_iter().map(|i| (i, run(i))).reduce(|| (usize::MAX, Ok(0)), lowest_error).1
        };
        match result {
            Ok(k) => projected += k,
            Err(bad) => return Some(Err(bad)),
        }
    }
    Some(Ok(projected))
}

/// A block cut for `threads` threads: its nodes split into one slab per thread along the longest
/// axis of the rest shape (cuts at the quantiles of the element centroids, so each slab holds
/// about as many elements); the elements whose nodes all lie in slab `s` are `slabs[s]`, the
/// others (touching two slabs) `interface`, each packed colour by colour (the block's colouring
/// restricted to them, element order kept inside a colour).
///
/// One Gauss–Seidel sweep ([`parallel_energy_block`] with [`BlockSweep::Slabs`]) is then every slab swept colour after
/// colour by its own thread with no synchronisation (no two slabs share a node), one join, and
/// the interface elements swept on one thread: two synchronisations per sweep instead of one per
/// colour. The order (and so the result, bitwise) depends on the thread count, not on the
/// scheduling.
#[derive(Clone, Debug, Default)]
pub struct Partition {
    pub threads: usize,
    pub slabs: Vec<PackedBlock>,
    pub interface: PackedBlock,
}

impl Partition {
    pub fn new(
        block: &ElementBlock,
        geometry: &BlockGeometry,
        colours: &[Vec<u32>],
        rest: &[Vec3],
        threads: usize,
    ) -> Self {
        let threads = threads.max(1);
        let n = block.nodes_per_element();
        let centroid = |e: usize| block.element(e).iter().map(|&i| rest[i as usize]).sum::<Vec3>() / n as f64;
        let (lo, hi) = block
            .elements()
            .flatten()
            .fold((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)), |(lo, hi), &i| {
                (lo.inf(&rest[i as usize]), hi.sup(&rest[i as usize]))
            });
        let axis = (hi - lo).iamax();
        let mut along: Vec<f64> = (0..block.len()).map(|e| centroid(e)[axis]).collect();
        along.sort_by(f64::total_cmp);
        // slab s holds the nodes with cuts[s − 1] ≤ coordinate < cuts[s]
        let cuts: Vec<f64> = (1..threads).map(|s| along[along.len() * s / threads]).collect();
        let slab_of_node = |i: u32| cuts.partition_point(|&c| c <= rest[i as usize][axis]);
        let slab_of_element = |e: u32| {
            let nodes = block.element(e as usize);
            let s = slab_of_node(nodes[0]);
            nodes.iter().all(|&i| slab_of_node(i) == s).then_some(s)
        };
        let owner: Vec<Option<usize>> = (0..block.len() as u32).map(slab_of_element).collect();
        let restricted = |keep: &dyn Fn(Option<usize>) -> bool| -> Vec<Vec<u32>> {
            colours
                .iter()
                .map(|c| c.iter().copied().filter(|&e| keep(owner[e as usize])).collect::<Vec<u32>>())
                .filter(|c| !c.is_empty())
                .collect()
        };
        Self {
            threads,
            slabs: (0..threads)
                .map(|s| PackedBlock::in_colour_order(block, geometry, &restricted(&|o| o == Some(s))))
                .collect(),
            interface: PackedBlock::in_colour_order(block, geometry, &restricted(&|o| o.is_none())),
        }
    }
}

/// Reduces `(chunk, result)` pairs: the counts summed, or the error of the lowest chunk.
fn lowest_error(
    a: (usize, Result<u64, NonFiniteElement>),
    b: (usize, Result<u64, NonFiniteElement>),
) -> (usize, Result<u64, NonFiniteElement>) {
    match (a, b) {
        ((i, Ok(x)), (j, Ok(y))) => (i.min(j), Ok(x + y)),
        ((i, Err(x)), (j, Err(y))) => {
            if i < j {
                (i, Err(x))
            } else {
                (j, Err(y))
            }
        }
        ((i, Err(x)), _) | (_, (i, Err(x))) => (i, Err(x)),
    }
}

/// Every colour of `packed` in turn on the calling thread, as [`colour_sweep`].
///
/// # Safety
/// As [`energy_sweep`], for all of `packed`.
#[allow(clippy::too_many_arguments)]
unsafe fn all_colours(
    nodes_per_element: usize,
    material: &Material,
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    packed: &PackedBlock,
    lambdas: Multipliers,
    inv_dt2: f64,
    batched: bool,
) -> Result<u64, NonFiniteElement> {
    let mut projected = 0;
    for c in 0..packed.num_colours() {
        // SAFETY: forwarded.
        let r = unsafe {
            colour_sweep(
                nodes_per_element,
                material,
                positions,
                rest,
                inv_mass,
                packed,
                c,
                packed.colour(c),
                lambdas,
                inv_dt2,
                batched,
            )
        };
        projected += r.expect("specialised node count")?;
    }
    Ok(projected)
}

/// One Gauss–Seidel sweep of the energy formulation over a block cut by `partition` (see
/// [`Partition`]): the slabs in parallel on rayon's current pool, then the interface. On a
/// non-finite correction the slabs finish, and the error of the lowest slab that had one (or of
/// the interface) is returned.
#[allow(clippy::too_many_arguments)]
fn slab_sweep(
    nodes_per_element: usize,
    material: &Material,
    positions: Positions,
    rest: &[Vec3],
    inv_mass: &[f64],
    partition: &Partition,
    lambdas: Multipliers,
    inv_dt2: f64,
    batched: bool,
) -> Result<u64, NonFiniteElement> {
    use rayon::prelude::*;
    // SAFETY (both sweeps): the slabs' elements touch disjoint nodes (each node is in one slab)
    // and own their multipliers; the interface runs after the join, alone; node and element
    // indices come from the mesh the positions and multipliers were sized for.
    let slab = |s: usize| unsafe {
        all_colours(
            nodes_per_element,
            material,
            positions,
            rest,
            inv_mass,
            &partition.slabs[s],
            lambdas,
            inv_dt2,
            batched,
        )
    };
    let slabs = (0..partition.slabs.len())
        .into_par_iter()
        .with_max_len(1)
        .map(|s| (s, slab(s)))
        .reduce(|| (usize::MAX, Ok(0)), lowest_error)
        .1?;
    // SAFETY: see above.
    let interface = unsafe {
        all_colours(
            nodes_per_element,
            material,
            positions,
            rest,
            inv_mass,
            &partition.interface,
            lambdas,
            inv_dt2,
            batched,
        )
    }?;
    Ok(slabs + interface)
}

/// A block's element data packed for the sweep: in element order (the serial sweep), or
/// reordered colour by colour (the parallel sweep; see the module doc), gradients as structure
/// of arrays ([`BlockData::grads`]). Packed element `k` is element `element_ids[k]`; colour `c`
/// is the packed range `colour_starts[c]..colour_starts[c + 1]` (one range for element order).
#[derive(Clone, Debug, Default)]
pub struct PackedBlock {
    pub nodes: Vec<u32>,
    pub grads: Vec<f64>,
    pub volumes: Vec<f64>,
    /// None in element order.
    pub element_ids: Option<Vec<u32>>,
    pub colour_starts: Vec<usize>,
    pub points: usize,
    /// Linear tetrahedra in colour order only: the gradients and volumes of each colour's
    /// first `4 ⌊len/4⌋` elements in batches of four, lane-interleaved (`p1x4::BATCH_VALUES`
    /// per batch; see [`colour_sweep`]). Empty otherwise.
    pub p1x4: Vec<f64>,
    /// The first batch of colour `c` in [`PackedBlock::p1x4`] (one more entry than colours).
    pub colour_batches: Vec<usize>,
}

impl PackedBlock {
    /// `block`'s data in element order.
    pub fn in_element_order(block: &ElementBlock, geometry: &BlockGeometry) -> Self {
        let all: Vec<u32> = (0..block.len() as u32).collect();
        let mut packed = Self::new(block, geometry, std::slice::from_ref(&all), false);
        packed.element_ids = None;
        packed
    }

    /// `block`'s data in the order of `colours` (element indices per colour).
    pub fn in_colour_order(block: &ElementBlock, geometry: &BlockGeometry, colours: &[Vec<u32>]) -> Self {
        Self::new(block, geometry, colours, true)
    }

    fn new(block: &ElementBlock, geometry: &BlockGeometry, colours: &[Vec<u32>], batches: bool) -> Self {
        let (n, q) = (block.nodes_per_element(), geometry.points_per_element);
        let total: usize = colours.iter().map(Vec::len).sum();
        let mut ids = Vec::with_capacity(total);
        let mut packed = Self {
            nodes: Vec::with_capacity(total * n),
            grads: Vec::with_capacity(total * 3 * padded(n) * q),
            volumes: Vec::with_capacity(total * q),
            element_ids: None,
            colour_starts: Vec::with_capacity(colours.len() + 1),
            points: q,
            p1x4: Vec::new(),
            colour_batches: vec![0],
        };
        packed.colour_starts.push(0);
        for colour in colours {
            for &e in colour {
                let e = e as usize;
                packed.nodes.extend_from_slice(block.element(e));
                for p in 0..q {
                    let g = geometry.gradients(e, p);
                    for axis in 0..3 {
                        packed.grads.extend(g.iter().map(|gi| gi[axis]));
                        packed.grads.extend(std::iter::repeat_n(0.0, padded(n) - n));
                    }
                }
                packed.volumes.extend_from_slice(geometry.volumes(e));
                ids.push(e as u32);
            }
            packed.colour_starts.push(ids.len());
            if batches && n == 4 && q == 1 {
                for four in colour.chunks_exact(4) {
                    for r in 1..4 {
                        for c in 0..3 {
                            packed.p1x4.extend(four.iter().map(|&e| geometry.gradients(e as usize, 0)[r][c]));
                        }
                    }
                    packed.p1x4.extend(four.iter().map(|&e| geometry.volumes(e as usize)[0]));
                }
                packed.colour_batches.push(packed.p1x4.len() / BATCH_VALUES);
            }
        }
        packed.element_ids = Some(ids);
        packed
    }

    pub fn data(&self) -> BlockData<'_> {
        BlockData {
            nodes: &self.nodes,
            grads: &self.grads,
            volumes: &self.volumes,
            points: self.points,
            element_ids: self.element_ids.as_deref(),
        }
    }

    pub fn len(&self) -> usize {
        self.colour_starts.last().copied().unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The packed range of colour `c`.
    pub fn colour(&self, c: usize) -> std::ops::Range<usize> {
        self.colour_starts[c]..self.colour_starts[c + 1]
    }

    pub fn num_colours(&self) -> usize {
        self.colour_starts.len().saturating_sub(1)
    }
}

/// The packed data of every block of a simulation: element order and colour order.
#[derive(Clone, Debug, Default)]
pub struct SolverData {
    pub serial: Vec<PackedBlock>,
    pub colour: Vec<PackedBlock>,
}

impl SolverData {
    pub fn new(blocks: &[ElementBlock], geometry: &[BlockGeometry], colours: &[Vec<Vec<u32>>]) -> Self {
        Self {
            serial: blocks.iter().zip(geometry).map(|(b, g)| PackedBlock::in_element_order(b, g)).collect(),
            colour: blocks
                .iter()
                .zip(geometry)
                .zip(colours)
                .map(|((b, g), c)| PackedBlock::in_colour_order(b, g, c))
                .collect(),
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub mod p1x4;

#[cfg(test)]
mod tests;
