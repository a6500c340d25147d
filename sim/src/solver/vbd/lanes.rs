//! What a VBD node visit reads of each element, kept lane-major and in step with the positions
//! ([`PointLanes`]): the nodes' material gradients, the volumes and the elements' `F_q`, moved
//! with each node ([`carry_points`]) and mixed by the Chebyshev step ([`Snapshots`]); the fused
//! AVX2 + FMA paths and their one runtime check ([`Fused`]).

use crate::Vec3;
use crate::fem::energy::element_grads;
use crate::fem::geometry::BlockGeometry;
use crate::material::{Material, NodeVisitKernel};
use crate::math::shared::SharedMut;
use crate::mesh::Mesh;

/// What a node visit reads of each element, lane-major ([`NodeVisit`]): per block, the points
/// in chunks of `width` (4 where the element has several points, one AVX2 register per chunk; 1
/// for one-point elements), the nodes' `∇_X N_a(r_q)` and the volumes `V_q` (padding: zero), and
/// the elements' `F_q`, kept in step with the positions: refreshed from them at the start of a
/// step and after a projection moved them ([`PointLanes::refresh`]), moved by `Δ ⊗ ∇_X N_a(r_q)`
/// when node `a` of the element moves by `Δ` ([`carry_points`]; `F` is affine in the positions)
/// and mixed as the positions are by the Chebyshev step ([`Snapshots`]), so a node visit reads
/// its elements' `F_q` instead of gathering their nodes.
#[derive(Default)]
pub(super) struct PointLanes {
    pub(super) blocks: Vec<LaneBlock>,
}

/// One block's lane-major data ([`PointLanes`]); element `e`'s entries start at `e ·` the
/// per-element lengths.
#[derive(Clone, Default)]
pub(super) struct LaneBlock {
    pub(super) nodes: usize,
    pub(super) chunks: usize,
    pub(super) width: usize,
    /// Element `e`, node `a`, chunk `k`, coordinate `c`, lane `j`: `(((e·nodes + a)·chunks + k)·3 + c)·width + j`.
    pub(super) grads: Vec<f64>,
    /// Element `e`, chunk `k`, lane `j`: `(e·chunks + k)·width + j`.
    pub(super) volumes: Vec<f64>,
    /// Element `e`, chunk `k`, entry `(r, c)`, lane `j`: `((e·chunks + k)·9 + 3r + c)·width + j`.
    pub(super) f: Vec<f64>,
}

/// Fewest elements per parallel task of [`PointLanes::refresh`].
pub(super) const MIN_ELEMENTS_PER_TASK: usize = 256;

impl LaneBlock {
    pub(super) fn new(block: &crate::mesh::ElementBlock, g: &BlockGeometry) -> Self {
        let (nodes, points) = (g.nodes_per_element, g.points_per_element);
        let width = if points > 1 { 4 } else { 1 };
        let chunks = points.div_ceil(width);
        let elements = block.len();
        let mut lanes = LaneBlock {
            nodes,
            chunks,
            width,
            grads: vec![0.0; elements * nodes * chunks * 3 * width],
            volumes: vec![0.0; elements * chunks * width],
            f: Vec::new(),
        };
        for e in 0..elements {
            let (grads, volumes) = (element_grads(g, e), g.volumes(e));
            for (q, &v) in volumes.iter().enumerate() {
                let (k, j) = (q / width, q % width);
                lanes.volumes[(e * chunks + k) * width + j] = v;
                for a in 0..nodes {
                    for c in 0..3 {
                        lanes.grads[(((e * nodes + a) * chunks + k) * 3 + c) * width + j] = grads[q * nodes + a][c];
                    }
                }
            }
        }
        lanes
    }
    /// The read-only part and `F_q`.
    pub(super) fn split(&mut self) -> (LaneGeometry<'_>, &mut Vec<f64>) {
        let LaneBlock { nodes, chunks, width, grads, volumes, f } = self;
        let geometry = LaneGeometry { nodes: *nodes, chunks: *chunks, width: *width, grads, volumes };
        (geometry, f)
    }
}

/// `f += Σ_r Σ_c d_r ∇N_c` into entry `(r, c)` of every chunk, `W` lanes wide (`F_q += d ⊗ ∇N`);
/// `FMA`: fused multiply-adds, on AVX2 registers when `W` is 4.
///
/// # Safety
/// With `FMA`, the CPU has AVX2 and FMA (the [`Fused`] paths).
#[inline(always)]
pub(super) unsafe fn add_outer<const W: usize, const FMA: bool>(f: &mut [f64], d: &Vec3, grads: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    if W == 4 && FMA {
        use crate::math::f64x4::F64x4;
        let dr = [F64x4::splat(d[0]), F64x4::splat(d[1]), F64x4::splat(d[2])];
        for (fk, gk) in f.chunks_exact_mut(36).zip(grads.chunks_exact(12)) {
            // SAFETY: in bounds (chunks of 36 and 12); the caller's promise for the instructions
            unsafe {
                let g = [F64x4::load(gk.as_ptr()), F64x4::load(gk.as_ptr().add(4)), F64x4::load(gk.as_ptr().add(8))];
                for (r, dr) in dr.iter().enumerate() {
                    for (c, g) in g.iter().enumerate() {
                        let p = fk.as_mut_ptr().add(4 * (3 * r + c));
                        dr.fma(*g, F64x4::load(p)).store(p);
                    }
                }
            }
        }
        return;
    }
    for (fk, gk) in f.chunks_exact_mut(9 * W).zip(grads.chunks_exact(3 * W)) {
        for r in 0..3 {
            for c in 0..3 {
                let (dst, src) = (&mut fk[(3 * r + c) * W..][..W], &gk[c * W..][..W]);
                for j in 0..W {
                    dst[j] = if FMA { d[r].mul_add(src[j], dst[j]) } else { dst[j] + d[r] * src[j] };
                }
            }
        }
    }
}

/// [`add_outer`] at the block's width.
///
/// # Safety
/// [`add_outer`]'s.
#[inline(always)]
pub(super) unsafe fn add_outer_any<const FMA: bool>(width: usize, f: &mut [f64], d: &Vec3, grads: &[f64]) {
    // SAFETY: the caller's promise
    unsafe {
        match width {
            4 => add_outer::<4, FMA>(f, d, grads),
            _ => add_outer::<1, FMA>(f, d, grads),
        }
    }
}

/// Whether the CPU has AVX2 and FMA: the sweep's node updates and `F_q` refreshes are then
/// compiled for them (four-lane `F_q` moves in one fused instruction per entry).
#[derive(Clone, Copy)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct Fused(pub(super) bool);

impl Fused {
    pub(super) fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            Fused(crate::math::f64x4::available())
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Fused(false)
        }
    }
}

/// What an `F_q` refresh reads.
pub(super) struct RefreshInput<'a> {
    pub(super) lanes: LaneGeometry<'a>,
    pub(super) mesh: &'a Mesh,
    pub(super) positions: &'a [Vec3],
}

/// Element `e`'s `F_q` from the positions (`out`: its lane-major entries).
///
/// # Safety
/// [`add_outer`]'s.
#[inline(always)]
pub(super) unsafe fn refresh_element<const FMA: bool>(
    input: &RefreshInput<'_>,
    e: usize,
    nodes: &[u32],
    out: &mut [f64],
) {
    let w = input.lanes.width;
    out.fill(0.0);
    for k in 0..input.lanes.chunks {
        for diagonal in [0, 4, 8] {
            out[(9 * k + diagonal) * w..][..w].fill(1.0);
        }
    }
    for (a, &node) in nodes.iter().enumerate() {
        let u = input.positions[node as usize] - input.mesh.rest_positions[node as usize];
        // SAFETY: the caller's promise
        unsafe { add_outer_any::<FMA>(w, out, &u, input.lanes.node_grads(e, a)) };
    }
}

/// [`refresh_element`] compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU has AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn refresh_element_fused(input: &RefreshInput<'_>, e: usize, nodes: &[u32], out: &mut [f64]) {
    // SAFETY: the CPU has AVX2 and FMA (the caller's promise)
    unsafe { refresh_element::<true>(input, e, nodes, out) }
}

/// What a block's lane-major data holds besides `F_q` (read-only during a sweep).
#[derive(Clone, Copy)]
pub(super) struct LaneGeometry<'a> {
    pub(super) nodes: usize,
    pub(super) chunks: usize,
    pub(super) width: usize,
    pub(super) grads: &'a [f64],
    pub(super) volumes: &'a [f64],
}

impl<'a> LaneGeometry<'a> {
    pub(super) fn grads_len(&self) -> usize {
        self.chunks * 3 * self.width
    }
    pub(super) fn volumes_len(&self) -> usize {
        self.chunks * self.width
    }
    pub(super) fn f_len(&self) -> usize {
        self.chunks * 9 * self.width
    }
    /// Node `a` of element `e`: its gradients.
    #[inline(always)]
    pub(super) fn node_grads(&self, e: usize, a: usize) -> &'a [f64] {
        let len = self.grads_len();
        &self.grads[(e * self.nodes + a) * len..][..len]
    }
    #[inline(always)]
    pub(super) fn volumes(&self, e: usize) -> &'a [f64] {
        let len = self.volumes_len();
        &self.volumes[e * len..][..len]
    }
}

impl PointLanes {
    /// (Tests.) The carried and mixed `F_q` are those of the positions, to rounding.
    #[cfg(test)]
    pub(super) fn assert_in_step_with(&self, mesh: &Mesh, positions: &[Vec3]) {
        let mut fresh = PointLanes { blocks: self.blocks.clone() };
        fresh.refresh(mesh, positions, Fused(false));
        for (kept, fresh) in self.blocks.iter().zip(&fresh.blocks) {
            for (a, b) in kept.f.iter().zip(&fresh.f) {
                assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "kept F_q entry {a}, from the positions {b}");
            }
        }
    }

    pub(super) fn new(mesh: &Mesh, geometry: &[BlockGeometry]) -> Self {
        Self { blocks: mesh.blocks.iter().zip(geometry).map(|(block, g)| LaneBlock::new(block, g)).collect() }
    }

    /// `F_q = I + Σ_a (x_a − X_a) ⊗ ∇_X N_a(r_q)` of every element from the positions.
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    pub(super) fn refresh(&mut self, mesh: &Mesh, positions: &[Vec3], fused: Fused) {
        use rayon::prelude::*;
        for (lanes, block) in self.blocks.iter_mut().zip(&mesh.blocks) {
            let (geometry, f) = lanes.split();
            let len = geometry.f_len();
            let input = RefreshInput { lanes: geometry, mesh, positions };
            f.resize(block.len() * len, 0.0);
            f.par_chunks_mut(len).with_min_len(MIN_ELEMENTS_PER_TASK).enumerate().for_each(|(e, out)| {
                let nodes = block.element(e);
                #[cfg(target_arch = "x86_64")]
                if fused.0 {
                    // SAFETY: the CPU has AVX2 and FMA (detected)
                    return unsafe { refresh_element_fused(&input, e, nodes, out) };
                }
                // SAFETY: no fused instructions
                unsafe { refresh_element::<false>(&input, e, nodes, out) }
            });
        }
    }
}

/// One block of [`PointLanes`] as the sweep uses it: `F_q` written by the node updates of a
/// colour in parallel, the rest read.
#[derive(Clone, Copy)]
pub(super) struct LaneView<'a> {
    pub(super) geometry: LaneGeometry<'a>,
    /// The material's kernel for this width, resolved once ([`Material::node_visit_kernel`]).
    pub(super) kernel: Option<NodeVisitKernel>,
    pub(super) f_len: usize,
    pub(super) f: SharedMut<f64>,
}

impl<'a> LaneView<'a> {
    pub(super) fn of(lanes: &'a mut PointLanes, material: &Material) -> Vec<LaneView<'a>> {
        lanes
            .blocks
            .iter_mut()
            .map(|b| {
                let (geometry, f) = b.split();
                let kernel = material.node_visit_kernel(geometry.width);
                LaneView { geometry, kernel, f_len: geometry.f_len(), f: SharedMut::new(f) }
            })
            .collect()
    }

    /// Element `e`'s `F_q`.
    ///
    /// # Safety
    /// No other thread may access them while the slice lives.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)] // one element per task of a colour: the point of SharedMut
    pub(super) unsafe fn f_mut(&self, e: usize) -> &mut [f64] {
        // SAFETY: the caller's promise
        unsafe { self.f.slice_mut(e * self.f_len, self.f_len) }
    }
}

/// The `F_q` of every block at sweeps `k − 2` and `k − 1` of the Chebyshev acceleration, mixed
/// as the positions are: `F⁽ᵏ⁾ = ω_k (F̄⁽ᵏ⁾ − F⁽ᵏ⁻²⁾) + F⁽ᵏ⁻²⁾`.
#[derive(Default)]
pub(super) struct Snapshots {
    pub(super) prev_prev: Vec<Vec<f64>>,
    pub(super) prev_iter: Vec<Vec<f64>>,
}

impl Snapshots {
    /// Both snapshots at the current `F_q`.
    pub(super) fn start(&mut self, lanes: &PointLanes) {
        for snapshot in [&mut self.prev_prev, &mut self.prev_iter] {
            snapshot.resize_with(lanes.blocks.len(), Vec::new);
            for (to, from) in snapshot.iter_mut().zip(&lanes.blocks) {
                to.clear();
                to.extend_from_slice(&from.f);
            }
        }
    }

    /// After a sweep: mixes the `F_q` with factor `omega` (when accelerating), then moves the
    /// snapshots on.
    pub(super) fn advance(&mut self, lanes: &mut PointLanes, omega: Option<f64>) {
        for ((block, prev_prev), prev_iter) in lanes.blocks.iter_mut().zip(&mut self.prev_prev).zip(&mut self.prev_iter)
        {
            if let Some(omega) = omega {
                for (f, &p) in block.f.iter_mut().zip(prev_prev.iter()) {
                    *f = (*f - p) * omega + p;
                }
            }
            std::mem::swap(prev_prev, prev_iter);
            prev_iter.copy_from_slice(&block.f);
        }
    }
}
