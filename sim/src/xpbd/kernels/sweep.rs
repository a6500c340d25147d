//! The energy-constraint sweep itself, specialised per node count (see the module doc of
//! [`super`]): [`energy_sweep`] over a packed range in order, [`colour_sweep`] over one colour
//! with the batches of a register of elements, and the per-element projections [`project_p1`] and
//! [`project_energy`] they run.

use super::pack::{BlockData, PackedBlock};
use super::point_law::{AnyMaterial, PointMaterial, Stvk};
use super::shared::{Multipliers, Positions};
use super::simd::mul3;
use crate::Vec3;
use crate::fem::energy::point_energy_and_gradient;
use crate::material::{FastLaw, Mat3, Material};
use crate::xpbd::constraint::xpbd_step;

#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
use super::batch_values;
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
use super::{batch, lanes, p1};

/// What the sweep hands back when an element's corrections come out non-finite: its element
/// index in the block and its first non-finite node (nothing was scattered for it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFiniteElement {
    pub element: usize,
    pub node: u32,
}

/// `[n, …]` of the list's `(n, p)` pairs.
macro_rules! node_counts {
    ($(($n:literal, $p:literal)),*) => {
        [$($n),*]
    };
}

/// Node counts with a specialised sweep: [`crate::fem::specialised_node_counts`]'s list.
pub const SPECIALISED_NODE_COUNTS: &[usize] = &crate::fem::specialised_node_counts!(node_counts);

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
    let wide = super::lanes::lanes_available(4);
    macro_rules! dispatch {
        ($(($n:literal, $p:literal)),*) => {
            match nodes_per_element {
                $($n => Some(if let Some(FastLaw::StVenantKirchhoff(l)) = material.fast_law() {
                        let m = Stvk { mu_pa: l.mu_pa, lambda_pa: l.lambda_pa };
                        #[cfg(target_arch = "x86_64")]
                        if wide {
                            // SAFETY: forwarded from the caller; AVX2 and FMA were detected.
                            return Some(unsafe { sweep_avx2::<$n, $p, _>(&m, io, range) });
                        }
                        // SAFETY: forwarded from the caller.
                        unsafe { sweep::<$n, $p, false, _>(&m, io, range) }
                    } else {
                        // SAFETY: as above.
                        unsafe { sweep::<$n, $p, false, _>(&AnyMaterial(material), io, range) }
                    }),)*
                _ => None,
            }
        };
    }
    crate::fem::specialised_node_counts!(dispatch)
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
        let lambda = unsafe { &mut *lambdas.ptr().add(e) };
        let grads = &data.grads[k * q * 3 * P..(k + 1) * q * 3 * P];
        let volumes = &data.volumes[k * q..(k + 1) * q];
        if N == 4 && q == 1 {
            // the linear tetrahedron: one point, constant gradients
            let x4: &mut [Vec3; 4] = (&mut x[..]).try_into().expect("4 nodes");
            let w4: &[f64; 4] = w[..].try_into().expect("4 nodes");
            project_p1::<FMA, M>(x4, w4, grads, volumes[0], material, inv_dt2, lambda);
        } else {
            let mut u = [[0.0; P]; 3];
            for i in 0..N {
                let d = x[i] - rest[nodes[i] as usize];
                for a in 0..3 {
                    u[a][i] = d[a];
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
/// `g_i = ∇_X N_i`, `Σ_i g_i = 0`): `F = Σ_{i=1..3} (x_i − x_0) ⊗ g_i`, the paper's
/// `F = D_s D_m⁻¹` (the rows `g_i` of `D_m⁻¹`; equal to `I + Σ (u_i − u_0) ⊗ g_i` in
/// displacements, without reading the rest positions), `∇_i U = V P g_i` for `i = 1..3` and
/// `∇_0 U = −Σ_{i≥1} ∇_i U` (Bender et al.'s FEM tetrahedron), all as 3×3 products.
/// `grads` is the point's `3 × 4` structure-of-arrays block; `v` its volume.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn project_p1<const FMA: bool, M: PointMaterial>(
    x: &mut [Vec3; 4],
    w: &[f64; 4],
    grads: &[f64],
    v: f64,
    material: &M,
    inv_dt2: f64,
    lambda: &mut f64,
) -> f64 {
    // g[(i − 1, b)] = ∂N_i/∂X_b
    let g = Mat3::new(grads[1], grads[5], grads[9], grads[2], grads[6], grads[10], grads[3], grads[7], grads[11]);
    let ds = Mat3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
    let f = mul3::<FMA>(&ds, &g);
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
    for (gq, &v) in grads.chunks_exact(3 * P).zip(volumes) {
        let g: [&[f64; P]; 3] = std::array::from_fn(|b| gq[b * P..(b + 1) * P].try_into().expect("P gradients"));
        energy += point_energy_and_gradient::<P, FMA, true, M>(u, g, v, material, &mut grad);
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

/// The colour sweep over packed range `range` of colour `colour` of `packed` (a colour-ordered
/// block), whose start is a multiple of `L` = [`PackedBlock::lanes`] elements from the colour's
/// start: as [`energy_sweep`], but with `batched` `L` elements at a time where the CPU has the
/// register (4: AVX2 and FMA; 8: AVX-512 F too) — the linear tetrahedron at one point through
/// [`p1::batches_avx2`] or [`p1::batches_avx512`], every other specialised node count through
/// [`batch::batches_avx2`] or [`batch::batches_avx512`], StVK as a law over lanes and any other
/// model lane by lane ([`lanes::BatchLaw`]); the colour's last `len mod L` elements in one
/// partial batch, its missing lanes masked out. Which elements share a batch depends only on the
/// colour and `L`, not on how the range is cut, so the result does not depend on the thread
/// count.
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
    #[cfg_attr(
        not(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128"))),
        allow(unused_variables)
    )]
    batched: bool,
) -> Option<Result<u64, NonFiniteElement>> {
    if !SPECIALISED_NODE_COUNTS.contains(&nodes_per_element) {
        return None;
    }
    let data = packed.data();
    let colour_start = packed.colour_starts[colour];
    let width = packed.lanes;
    assert!((range.start - colour_start).is_multiple_of(width) && range.end <= packed.colour_starts[colour + 1]);
    // the batches (x86-64, a web page with simd128) take the first part of the range; the rest
    // goes one by one
    #[cfg_attr(
        not(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128"))),
        allow(unused_mut)
    )]
    let mut tail = range.clone();
    #[cfg_attr(
        not(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128"))),
        allow(unused_mut)
    )]
    let mut projected = 0;
    #[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
    if batched && packed.colour_batches.len() == packed.colour_starts.len() && lanes::lanes_available(width) {
        let (n, q) = (nodes_per_element, packed.points);
        let per_batch = batch_values(n, q, width);
        // every node index and element id of the batches, checked once (the kernels do not)
        assert!(
            packed.node_bound <= positions.len().min(rest.len()).min(inv_mass.len())
                && packed.id_bound <= lambdas.len(),
            "the packed block's indices exceed the positions or multipliers"
        );
        let first = packed.colour_batches[colour] + (range.start - colour_start) / width;
        let stored = packed.colour_batches[colour + 1] - first;
        let full = (range.len() / width).min(stored);
        let ids = data.element_ids.expect("colour order");
        let run = |io: p1::BatchIo<'_>, batches: usize| {
            // SAFETY: forwarded from the caller; the register's features were detected; the
            // elements of a batch are of one colour (a padding lane repeats one but is never
            // written).
            unsafe {
                if let Some(FastLaw::StVenantKirchhoff(l)) = material.fast_law() {
                    let law = Stvk { mu_pa: l.mu_pa, lambda_pa: l.lambda_pa };
                    batches_of(width, n, q, &packed.ref_grads, &law, io, batches)
                } else {
                    batches_of(width, n, q, &packed.ref_grads, &AnyMaterial(material), io, batches)
                }
            }
        };
        let io = p1::BatchIo {
            positions,
            rest,
            inv_mass,
            nodes: &data.nodes[range.start * n..(range.start + width * full) * n],
            values: &packed.batches[first * per_batch..(first + full) * per_batch],
            element_ids: &ids[range.start..range.start + width * full],
            lambdas,
            inv_dt2,
            last_lanes: u32::MAX,
        };
        match run(io, full) {
            Ok(k) => projected = k,
            Err(bad) => return Some(Err(bad)),
        }
        tail.start += width * full;
        // the colour's last, partial batch (only the last chunk of a colour has one): its
        // missing lanes repeat its last element's nodes and id, masked out
        let partial = tail.len();
        if partial > 0 && partial < width && full < stored {
            let mut nodes = [0u32; 8 * 27];
            let mut element_ids = [0u32; 8];
            nodes[..partial * n].copy_from_slice(&data.nodes[tail.start * n..tail.end * n]);
            element_ids[..partial].copy_from_slice(&ids[tail.clone()]);
            for l in partial..width {
                nodes.copy_within((partial - 1) * n..partial * n, l * n);
                element_ids[l] = element_ids[partial - 1];
            }
            let io = p1::BatchIo {
                nodes: &nodes[..width * n],
                values: &packed.batches[(first + full) * per_batch..(first + full + 1) * per_batch],
                element_ids: &element_ids[..width],
                last_lanes: (1 << partial) - 1,
                ..io
            };
            match run(io, 1) {
                Ok(k) => projected += k,
                Err(bad) => return Some(Err(bad)),
            }
            tail.start = tail.end;
        }
    }
    // every element batched (the usual case since the partial batches): no scalar sweep to set up
    if tail.is_empty() {
        return Some(Ok(projected));
    }
    // SAFETY: forwarded from the caller.
    let rest_of =
        unsafe { energy_sweep(nodes_per_element, material, positions, rest, inv_mass, &data, tail, lambdas, inv_dt2) }?;
    Some(rest_of.map(|k| k + projected))
}

/// The batches of `io` for `n` nodes and `q` points on `width` lanes, by the kernel of that
/// node count and width.
///
/// # Safety
/// As [`p1::batches_avx2`] (`width` 4) or `p1::batches_avx512` (8), `p1::batches_simd128` (2,
/// in a web page); `n` one of [`SPECIALISED_NODE_COUNTS`].
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
unsafe fn batches_of<L: lanes::BatchLaw>(
    width: usize,
    n: usize,
    q: usize,
    ref_grads: &[f64],
    law: &L,
    io: p1::BatchIo<'_>,
    batches: usize,
) -> Result<u64, NonFiniteElement> {
    macro_rules! by_node_count {
        ($(($n:literal, $p:literal)),*) => {
            match (width, n) {
                #[cfg(target_arch = "x86_64")]
                (4, 4) if q == 1 => p1::batches_avx2(law, io, batches),
                #[cfg(target_arch = "x86_64")]
                (8, 4) if q == 1 => p1::batches_avx512(law, io, batches),
                #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
                (2, 4) if q == 1 => p1::batches_simd128(law, io, batches),
                $(#[cfg(target_arch = "x86_64")]
                (4, $n) => batch::batches_avx2::<$n, L>(law, io, ref_grads, q, batches),
                #[cfg(target_arch = "x86_64")]
                (8, $n) => batch::batches_avx512::<$n, L>(law, io, ref_grads, q, batches),
                #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
                (2, $n) => batch::batches_simd128::<$n, L>(law, io, ref_grads, q, batches),)*
                (2 | 4 | 8, _) => unreachable!("{n} nodes: no specialised sweep"),
                _ => unreachable!("{width} lanes"),
            }
        };
    }
    // SAFETY: forwarded.
    unsafe { crate::fem::specialised_node_counts!(by_node_count) }
}
