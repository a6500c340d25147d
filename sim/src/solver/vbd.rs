//! Vertex block descent (Chen, Liu, Yang, Yuksel, "Vertex Block Descent", ACM Transactions on
//! Graphics 43(4), 2024): implicit Euler's incremental potential
//!
//! `G(x) = Σ_i m_i/(2h²) |x_i − y_i|² + Σ_e U_e(x) + Σ_k k_k/2 |x_{n_k} − t_k|²`
//!
//! minimised by block Gauss–Seidel over the nodes. Each free node `i` takes one 3×3 Newton step
//! on `G` with every other node fixed:
//!
//! `f_i = −(m_i/h²)(x_i − y_i) − Σ_{(e,a) ∋ i} Σ_q V_q P(F_q) ∇_X N_a(r_q) − Σ_k k_k (x_i − t_k)`,
//! `H_i = (m_i/h²) I + Σ_{(e,a) ∋ i} Π_PSD(B_{e,a}) + Σ_k k_k I`, `x_i ← x_i + H_i⁻¹ f_i`,
//!
//! the sums running over every element holding the node with the element's own quadrature and
//! material (a P3 node sums every quadrature point of every P3 element around it), `B_{e,a}` the
//! diagonal block of the element Hessian ([`crate::fem::energy::element_node_gradient_and_block`])
//! projected to positive semi-definite ([`crate::material::project_psd3`]), so `H_i` is positive
//! definite and the update a descent step. Nodes are coloured so that nodes of one colour share no
//! element ([`crate::mesh::adjacency::colour_nodes`]): colours run in order, the nodes of one
//! colour in parallel; each node reads only the others and writes only itself, so serial and
//! parallel sweeps, on any thread count, give the same bits.
//!
//! - **Initialisation** (§3.5 of the paper, [`super::VbdInit`]): by default
//!   `x⁰ = x_n + h v_n + h² ã ĝ` with `ã` the body's acceleration along gravity `ĝ` over the
//!   last step clamped to `[0, |g|]`, so a body at rest in equilibrium starts — and stays —
//!   exactly there: VBD's fixed point is the static equilibrium for any iteration count.
//! - **Acceleration** (§3.7): Chebyshev semi-iteration with spectral radius estimate `ρ`,
//!   `x⁽ᵏ⁾ = ω_k (x̄⁽ᵏ⁾ − x⁽ᵏ⁻²⁾) + x⁽ᵏ⁻²⁾`, `ω_1 = 1`, `ω_2 = 2/(2 − ρ²)`,
//!   `ω_k = 4/(4 − ρ² ω_{k−1})`; `ρ = 0.9` by default (measured: half the sweeps to settle the
//!   bending beam; the authors' code ships it off; 0.95 at 5 sweeps per step diverged).
//! - **Two-level correction** (ours, not the paper's; [`super::vbd_coarse`], on by default,
//!   `coarse_cells = 0` turns it off): before the sweeps, the step's `G` is minimised over
//!   smooth displacements — trilinear functions on a coarse grid over the body — by one Galerkin
//!   coarse-grid correction with a secant line search. The sweeps barely move smooth error (a
//!   beam's slow bending falls by about 0.5 % per sweep on Gmsh's P2 beam), so without it the
//!   steps stay far from converged there: with it that beam settles in 122 frames, as Newton,
//!   instead of 707, and each step costs two gradient evaluations more (plus the coarse matrix
//!   every ten steps). Chebyshev starts after it.
//! - Effects: contact's projection runs after every sweep; attachments are springs in `G`.
//!
//! **Cost.** A sweep visits every (node, element holding it) pair with the element's whole
//! quadrature, so it is kept to what the visit cannot avoid: the elements' `F_q` are cached
//! lane-major (four points per AVX2 register, [`PointLanes`]) and moved with each node and each
//! acceleration step instead of gathered and summed per visit; `P g` and the block come from one
//! call that shares their work ([`crate::material::Material::node_visit`], closed form for StVK
//! on four lanes); a block is tested positive definite by its leading minors before any
//! eigen-decomposition ([`crate::material::project_psd3`]); the node update and the `F_q` moves
//! are compiled for AVX2 and FMA where the CPU has them ([`Fused`]), and the 3 × 3 solve is a
//! hand-written Cholesky.
//! Measured on Gmsh's P2 beam (1,471 elements, docs/PERFORMANCE.md): about 530 instructions
//! per node-element visit, half of them the StVK law.

use super::SolverCounters;
use super::method::{Hooks, Method, StepInput, StepSolver};
use super::nan_guard::{BadElement, ORIGIN_VBD};
use super::settings::{SolverSettings, VbdInit};
use super::vbd_coarse::{CoarseSpace, coarse_cells};
use crate::Vec3;
use crate::effect::{ImplicitRole, NodeSpring};
use crate::fem::energy::element_grads;
use crate::fem::geometry::BlockGeometry;
use crate::material::{Lame, Material, NodeVisit, NodeVisitKernel, project_psd3};
use crate::mesh::Mesh;
use crate::mesh::adjacency::{NodeIncidence, colour_nodes};
use crate::xpbd::kernels::SharedMut;
use nalgebra::Matrix3;

/// Fewest nodes per parallel task within a colour.
const MIN_NODES_PER_TASK: usize = 16;
/// Below this, the adaptive initialisation's acceleration along gravity counts as zero, m/s².
const ADAPTIVE_ACCELERATION_FLOOR_M_S2: f64 = 1e-5;

pub(crate) struct Vbd {
    incidence: NodeIncidence,
    colours: Vec<Vec<u32>>,
    /// `v_n` and `v_{n−1}`, snapshots at the start of the last two steps.
    v_start: Vec<Vec3>,
    v_before: Vec<Vec3>,
    /// Snapshots held (0 after a reset, up to 2).
    history: u8,
    y: Vec<Vec3>,
    prev_iter: Vec<Vec3>,
    prev_prev: Vec<Vec3>,
    lanes: PointLanes,
    /// The `F_q` at the last two sweeps, for the acceleration.
    f_snapshots: Snapshots,
    fused: Fused,
    /// The two-level correction ([`super::vbd_coarse`]); None when `coarse_cells` is 0.
    coarse: Option<CoarseSpace>,
}

impl Vbd {
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings) -> Self {
        let incidence = NodeIncidence::new(mesh);
        let colours = colour_nodes(mesh, &incidence);
        Self {
            incidence,
            colours,
            v_start: Vec::new(),
            v_before: Vec::new(),
            history: 0,
            y: Vec::new(),
            prev_iter: Vec::new(),
            prev_prev: Vec::new(),
            lanes: PointLanes::new(mesh, geometry),
            f_snapshots: Snapshots::default(),
            fused: Fused::detect(),
            coarse: CoarseSpace::for_settings(mesh, settings),
        }
    }
}

/// What a node visit reads of each element, lane-major ([`NodeVisit`]): per block, the points
/// in chunks of `width` (4 where the element has several points, one AVX2 register per chunk; 1
/// for one-point elements), the nodes' `∇_X N_a(r_q)` and the volumes `V_q` (padding: zero), and
/// the elements' `F_q`, kept in step with the positions: refreshed from them at the start of a
/// step and after a projection moved them ([`PointLanes::refresh`]), moved by `Δ ⊗ ∇_X N_a(r_q)`
/// when node `a` of the element moves by `Δ` ([`carry_points`]; `F` is affine in the positions)
/// and mixed as the positions are by the Chebyshev step ([`Snapshots`]), so a node visit reads
/// its elements' `F_q` instead of gathering their nodes.
#[derive(Default)]
struct PointLanes {
    blocks: Vec<LaneBlock>,
}

/// One block's lane-major data ([`PointLanes`]); element `e`'s entries start at `e ·` the
/// per-element lengths.
#[derive(Clone, Default)]
struct LaneBlock {
    nodes: usize,
    chunks: usize,
    width: usize,
    /// Element `e`, node `a`, chunk `k`, coordinate `c`, lane `j`: `(((e·nodes + a)·chunks + k)·3 + c)·width + j`.
    grads: Vec<f64>,
    /// Element `e`, chunk `k`, lane `j`: `(e·chunks + k)·width + j`.
    volumes: Vec<f64>,
    /// Element `e`, chunk `k`, entry `(r, c)`, lane `j`: `((e·chunks + k)·9 + 3r + c)·width + j`.
    f: Vec<f64>,
}

/// Fewest elements per parallel task of [`PointLanes::refresh`].
const MIN_ELEMENTS_PER_TASK: usize = 256;

impl LaneBlock {
    fn new(block: &crate::mesh::ElementBlock, g: &BlockGeometry) -> Self {
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
    fn split(&mut self) -> (LaneGeometry<'_>, &mut Vec<f64>) {
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
unsafe fn add_outer<const W: usize, const FMA: bool>(f: &mut [f64], d: &Vec3, grads: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    if W == 4 && FMA {
        use crate::xpbd::kernels::lanes4::F64x4;
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
unsafe fn add_outer_any<const FMA: bool>(width: usize, f: &mut [f64], d: &Vec3, grads: &[f64]) {
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
struct Fused(bool);

impl Fused {
    fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            Fused(crate::xpbd::kernels::lanes4::available())
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Fused(false)
        }
    }
}

/// What an `F_q` refresh reads.
struct RefreshInput<'a> {
    lanes: LaneGeometry<'a>,
    mesh: &'a Mesh,
    positions: &'a [Vec3],
}

/// Element `e`'s `F_q` from the positions (`out`: its lane-major entries).
///
/// # Safety
/// [`add_outer`]'s.
#[inline(always)]
unsafe fn refresh_element<const FMA: bool>(input: &RefreshInput<'_>, e: usize, nodes: &[u32], out: &mut [f64]) {
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
unsafe fn refresh_element_fused(input: &RefreshInput<'_>, e: usize, nodes: &[u32], out: &mut [f64]) {
    // SAFETY: the CPU has AVX2 and FMA (the caller's promise)
    unsafe { refresh_element::<true>(input, e, nodes, out) }
}

/// What a block's lane-major data holds besides `F_q` (read-only during a sweep).
#[derive(Clone, Copy)]
struct LaneGeometry<'a> {
    nodes: usize,
    chunks: usize,
    width: usize,
    grads: &'a [f64],
    volumes: &'a [f64],
}

impl<'a> LaneGeometry<'a> {
    fn grads_len(&self) -> usize {
        self.chunks * 3 * self.width
    }
    fn volumes_len(&self) -> usize {
        self.chunks * self.width
    }
    fn f_len(&self) -> usize {
        self.chunks * 9 * self.width
    }
    /// Node `a` of element `e`: its gradients.
    #[inline(always)]
    fn node_grads(&self, e: usize, a: usize) -> &'a [f64] {
        let len = self.grads_len();
        &self.grads[(e * self.nodes + a) * len..][..len]
    }
    #[inline(always)]
    fn volumes(&self, e: usize) -> &'a [f64] {
        let len = self.volumes_len();
        &self.volumes[e * len..][..len]
    }
}

impl PointLanes {
    /// (Tests.) The carried and mixed `F_q` are those of the positions, to rounding.
    #[cfg(test)]
    fn assert_in_step_with(&self, mesh: &Mesh, positions: &[Vec3]) {
        let mut fresh = PointLanes { blocks: self.blocks.clone() };
        fresh.refresh(mesh, positions, Fused(false));
        for (kept, fresh) in self.blocks.iter().zip(&fresh.blocks) {
            for (a, b) in kept.f.iter().zip(&fresh.f) {
                assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "kept F_q entry {a}, from the positions {b}");
            }
        }
    }

    fn new(mesh: &Mesh, geometry: &[BlockGeometry]) -> Self {
        Self { blocks: mesh.blocks.iter().zip(geometry).map(|(block, g)| LaneBlock::new(block, g)).collect() }
    }

    /// `F_q = I + Σ_a (x_a − X_a) ⊗ ∇_X N_a(r_q)` of every element from the positions.
    fn refresh(&mut self, mesh: &Mesh, positions: &[Vec3], fused: Fused) {
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
struct LaneView<'a> {
    geometry: LaneGeometry<'a>,
    /// The material's kernel for this width, resolved once ([`Material::node_visit_kernel`]).
    kernel: Option<NodeVisitKernel>,
    f_len: usize,
    f: SharedMut<f64>,
}

impl<'a> LaneView<'a> {
    fn of(lanes: &'a mut PointLanes, material: &Material) -> Vec<LaneView<'a>> {
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
    unsafe fn f_mut(&self, e: usize) -> &mut [f64] {
        // SAFETY: the caller's promise
        unsafe { self.f.slice_mut(e * self.f_len, self.f_len) }
    }
}

/// The `F_q` of every block at sweeps `k − 2` and `k − 1` of the Chebyshev acceleration, mixed
/// as the positions are: `F⁽ᵏ⁾ = ω_k (F̄⁽ᵏ⁾ − F⁽ᵏ⁻²⁾) + F⁽ᵏ⁻²⁾`.
#[derive(Default)]
struct Snapshots {
    prev_prev: Vec<Vec<f64>>,
    prev_iter: Vec<Vec<f64>>,
}

impl Snapshots {
    /// Both snapshots at the current `F_q`.
    fn start(&mut self, lanes: &PointLanes) {
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
    fn advance(&mut self, lanes: &mut PointLanes, omega: Option<f64>) {
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

/// What a node update reads.
struct NodeUpdate<'a> {
    input: &'a StepInput<'a>,
    incidence: &'a NodeIncidence,
    y: &'a [Vec3],
    springs: &'a [NodeSpring],
    w: f64,
    lame: Lame,
    fused: Fused,
}

impl NodeUpdate<'_> {
    /// Moves free node `i` by its Newton step on `G` with the others fixed, and the `F_q` of
    /// the elements holding it with it; returns whether it moved (not when it has no
    /// unbalanced force).
    ///
    /// # Safety
    /// No other thread may access node `i` or the `F_q` of an element holding it meanwhile
    /// (nodes of one colour share no element).
    unsafe fn step(&self, i: usize, positions: SharedMut<Vec3>, lanes: &[LaneView<'_>]) -> Result<bool, BadElement> {
        #[cfg(target_arch = "x86_64")]
        if self.fused.0 {
            // SAFETY: the CPU has AVX2 and FMA (detected); the caller's promise
            return unsafe { self.step_fused(i, positions, lanes) };
        }
        // SAFETY: the caller's promise
        unsafe { self.step_in::<false>(i, positions, lanes) }
    }

    /// [`NodeUpdate::step`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// [`NodeUpdate::step`]'s, and the CPU has AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn step_fused(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        lanes: &[LaneView<'_>],
    ) -> Result<bool, BadElement> {
        // SAFETY: the caller's promise
        unsafe { self.step_in::<true>(i, positions, lanes) }
    }

    /// # Safety
    /// [`NodeUpdate::step`]'s; with `FMA`, the CPU has AVX2 and FMA.
    #[inline(always)]
    unsafe fn step_in<const FMA: bool>(
        &self,
        i: usize,
        positions: SharedMut<Vec3>,
        lanes: &[LaneView<'_>],
    ) -> Result<bool, BadElement> {
        let s = self.input;
        // SAFETY: the caller's promise
        let xi = unsafe { positions.read(i) };
        let m_w = s.masses_kg[i] * self.w;
        let mut f = (self.y[i] - xi) * m_w;
        let mut h = Matrix3::identity() * m_w;
        for inc in self.incidence.of(i) {
            let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
            let l = &lanes[b];
            // SAFETY: an element holding node i
            let fq = unsafe { l.f_mut(e) };
            let g = &l.geometry;
            let visit = NodeVisit { width: g.width, f: fq, grads: g.node_grads(e, a), volumes: g.volumes(e) };
            let (force, block) = match l.kernel {
                // SAFETY: the material's kernel for this width on this CPU
                Some(kernel) => unsafe { kernel(self.lame, visit) },
                None => s.material.node_visit(self.lame, visit),
            };
            f -= force;
            h += project_psd3(&block);
        }
        for sp in self.springs.iter().filter(|sp| sp.node as usize == i) {
            f -= (xi - sp.target_m) * sp.stiffness_n_per_m;
            h += Matrix3::identity() * sp.stiffness_n_per_m;
        }
        if f == Vec3::zeros() {
            return Ok(false);
        }
        let Some(d) = solve_spd3(&h, &f) else {
            return Err(BadElement::at_node(s.mesh, i, ORIGIN_VBD));
        };
        // SAFETY: the caller's promise
        unsafe {
            positions.write(i, xi + d);
            carry_points::<FMA>(self.incidence, i, d, lanes);
        }
        Ok(true)
    }
}

/// `H⁻¹ f` for a symmetric positive definite 3 × 3 `H` by its Cholesky factor `L Lᵀ` (lower
/// triangle read); `None` when `H` is not positive definite or the result not finite.
#[inline(always)]
fn solve_spd3(h: &Matrix3<f64>, f: &Vec3) -> Option<Vec3> {
    let l00 = h[(0, 0)].sqrt();
    let (l10, l20) = (h[(1, 0)] / l00, h[(2, 0)] / l00);
    let l11 = (h[(1, 1)] - l10 * l10).sqrt();
    let l21 = (h[(2, 1)] - l20 * l10) / l11;
    let l22 = (h[(2, 2)] - l20 * l20 - l21 * l21).sqrt();
    // L z = f, then Lᵀ d = z
    let z0 = f[0] / l00;
    let z1 = (f[1] - l10 * z0) / l11;
    let z2 = (f[2] - l20 * z0 - l21 * z1) / l22;
    let d2 = z2 / l22;
    let d1 = (z1 - l21 * d2) / l11;
    let d0 = (z0 - l10 * d1 - l20 * d2) / l00;
    // a non-positive pivot's square root is NaN (or zero, dividing to ±∞)
    let d = Vec3::new(d0, d1, d2);
    d.iter().all(|c| c.is_finite()).then_some(d)
}

/// Moves the `F_q` of every element holding node `i` by `Δ ⊗ ∇_X N_a(r_q)` (node `i` moved by `d`).
///
/// # Safety
/// No other thread may access the `F_q` of an element holding node `i` meanwhile; with `FMA`,
/// the CPU has AVX2 and FMA.
#[inline(always)]
unsafe fn carry_points<const FMA: bool>(incidence: &NodeIncidence, i: usize, d: Vec3, lanes: &[LaneView<'_>]) {
    for inc in incidence.of(i) {
        let (b, e, a) = (inc.block as usize, inc.element as usize, inc.local as usize);
        let l = &lanes[b];
        // SAFETY: the caller's promise
        let fq = unsafe { l.f_mut(e) };
        // SAFETY: the caller's promise
        unsafe { add_outer_any::<FMA>(l.geometry.width, fq, &d, l.geometry.node_grads(e, a)) };
    }
}

impl StepSolver for Vbd {
    fn method(&self) -> Method {
        Method::Vbd
    }

    fn begin_step(&mut self, velocities: &[Vec3]) {
        let had = self.history >= 1 && self.v_start.len() == velocities.len();
        if had {
            std::mem::swap(&mut self.v_before, &mut self.v_start);
        }
        self.v_start.clear();
        self.v_start.extend_from_slice(velocities);
        self.history = if had { 2 } else { 1 };
    }

    fn reset_history(&mut self, warm: bool, num_nodes: usize) {
        // a warm start is at rest: its last velocity is zero, so the next step sees ã = 0
        self.history = if warm { 1 } else { 0 };
        self.v_start.clear();
        self.v_start.resize(num_nodes, Vec3::zeros());
    }

    fn rebuild(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings, geometry_changed: bool) {
        if geometry_changed {
            self.lanes = PointLanes::new(mesh, geometry);
        }
        if geometry_changed || self.coarse.as_ref().map(CoarseSpace::target_cells) != coarse_cells(settings) {
            self.coarse = CoarseSpace::for_settings(mesh, settings);
        }
    }

    fn solve_step(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let h = s.h;
        if let Some(i) = super::nan_guard::first_non_finite_position(positions) {
            return Err(BadElement::at_node(s.mesh, i, super::nan_guard::ORIGIN_INPUT));
        }
        self.y.clear();
        self.y.extend_from_slice(positions);
        // the initial guess
        let g = s.body_acceleration;
        let g_norm = g.norm();
        for (i, x) in positions.iter_mut().enumerate() {
            if s.inv_mass[i] == 0.0 {
                continue;
            }
            let (xn, vn) = (s.prev_positions[i], self.v_start[i]);
            *x = match s.settings.vbd.init {
                VbdInit::Inertia => self.y[i],
                VbdInit::Previous => xn,
                VbdInit::Adaptive if g_norm == 0.0 => xn + vn * h,
                VbdInit::Adaptive if self.history < 2 => self.y[i],
                VbdInit::Adaptive => {
                    let dir = g / g_norm;
                    let a = ((vn - self.v_before[i]) / h).dot(&dir).clamp(0.0, g_norm);
                    let a = if a < ADAPTIVE_ACCELERATION_FLOOR_M_S2 { 0.0 } else { a };
                    xn + vn * h + dir * (a * h * h)
                }
            };
        }
        let springs = hooks.springs();
        let update = NodeUpdate {
            input: s,
            incidence: &self.incidence,
            y: &self.y,
            springs: &springs,
            w: 1.0 / (h * h),
            lame: s.material.lame(),
            fused: self.fused,
        };
        let rho = s.settings.vbd.chebyshev_rho;
        let mut omega = 1.0;
        // the two-level correction: the smooth error the sweeps barely touch, first
        if let Some(c) = &mut self.coarse {
            c.begin_step(s, positions, &springs);
            counters.coarse_corrections += u64::from(c.correct(s, positions, &self.y, &springs));
        }
        if rho > 0.0 {
            self.prev_prev.clear();
            self.prev_prev.extend_from_slice(positions);
            self.prev_iter.clear();
            self.prev_iter.extend_from_slice(positions);
        }
        // the initial guess (and the correction) moved the positions as a whole: F_q from them,
        // then in step with each node move, each acceleration (F is affine in the positions, so
        // it mixes as they do) and, after a projection moved the positions, from them again
        let mut stale = true;
        for k in 1..=s.settings.vbd.iterations {
            if stale {
                self.lanes.refresh(s.mesh, positions, self.fused);
            }
            if rho > 0.0 && k == 1 {
                self.f_snapshots.start(&self.lanes);
            }
            let lanes = LaneView::of(&mut self.lanes, s.material);
            for colour in &self.colours {
                counters.node_updates +=
                    sweep_colour(&update, colour, positions, &lanes, s.settings.sweep.is_colour())?;
            }
            if rho > 0.0 {
                omega = match k {
                    1 => 1.0,
                    2 => 2.0 / (2.0 - rho * rho),
                    _ => 4.0 / (4.0 - rho * rho * omega),
                };
                let mix = k >= 2 && omega > 1.0;
                if mix {
                    for (i, x) in positions.iter_mut().enumerate() {
                        if s.inv_mass[i] > 0.0 {
                            *x = (*x - self.prev_prev[i]) * omega + self.prev_prev[i];
                        }
                    }
                }
                std::mem::swap(&mut self.prev_prev, &mut self.prev_iter);
                self.prev_iter.copy_from_slice(positions);
                self.f_snapshots.advance(&mut self.lanes, mix.then_some(omega));
            }
            let projections = *hooks.calls;
            hooks.after_projection(positions, Some(ImplicitRole::Projection));
            stale = *hooks.calls != projections;
            #[cfg(test)]
            if !stale {
                self.lanes.assert_in_step_with(s.mesh, positions);
            }
            counters.solver_iterations += 1;
        }
        Ok(())
    }
}

/// Updates the free nodes of one colour; returns how many moved.
fn sweep_colour(
    update: &NodeUpdate<'_>,
    colour: &[u32],
    positions: &mut [Vec3],
    lanes: &[LaneView<'_>],
    parallel: bool,
) -> Result<u64, BadElement> {
    let inv_mass = update.input.inv_mass;
    let shared = SharedMut::new(positions);
    // SAFETY: nodes of one colour share no element, so each task touches only its node and the
    // F_q of elements no other task of this colour touches.
    let node = |&i: &u32| -> Result<u64, BadElement> {
        let i = i as usize;
        if inv_mass[i] == 0.0 {
            return Ok(0);
        }
        Ok(u64::from(unsafe { update.step(i, shared, lanes) }?))
    };
    if !parallel {
        return colour.iter().map(node).sum();
    }
    use rayon::prelude::*;
    colour.par_iter().with_min_len(MIN_NODES_PER_TASK).map(node).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::fem::geometry::{deformation_gradient, precompute};

    /// [`carry_points`] on the fused path where `fused` says the CPU has it.
    ///
    /// # Safety
    /// [`carry_points`]'s; `fused` from [`Fused::detect`].
    unsafe fn carry_on_this_cpu(fused: Fused, incidence: &NodeIncidence, i: usize, d: Vec3, lanes: &[LaneView<'_>]) {
        #[cfg(target_arch = "x86_64")]
        if fused.0 {
            #[target_feature(enable = "avx2,fma")]
            unsafe fn carry_fused(incidence: &NodeIncidence, i: usize, d: Vec3, lanes: &[LaneView<'_>]) {
                // SAFETY: the caller's promise
                unsafe { carry_points::<true>(incidence, i, d, lanes) }
            }
            // SAFETY: the caller's promise
            return unsafe { carry_fused(incidence, i, d, lanes) };
        }
        // SAFETY: the caller's promise
        unsafe { carry_points::<false>(incidence, i, d, lanes) }
    }

    /// `H⁻¹ f` of the hand-written 3 × 3 Cholesky is nalgebra's on random SPD matrices, and not
    /// positive definite (a zero or negative pivot) or non-finite input gives `None`.
    #[test]
    fn solve_spd3_matches_a_cholesky_solve_and_refuses_what_is_not_positive_definite() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..200 {
            let a = Matrix3::from_fn(|_, _| next());
            let h = a * a.transpose() + Matrix3::identity() * 0.01;
            let f = Vec3::new(next(), next(), next());
            let want = h.cholesky().unwrap().solve(&f);
            let got = solve_spd3(&h, &f).unwrap();
            assert!((got - want).norm() <= 1e-10 * want.norm(), "{got} vs {want}");
        }
        let f = Vec3::new(1.0, 2.0, 3.0);
        for bad in [
            Matrix3::from_diagonal(&Vec3::new(1.0, 0.0, 1.0)),
            Matrix3::from_diagonal(&Vec3::new(1.0, 1.0, -2.0)),
            Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0),
            Matrix3::from_diagonal(&Vec3::new(f64::NAN, 1.0, 1.0)),
        ] {
            assert_eq!(solve_spd3(&bad, &f), None, "{bad}");
        }
    }

    /// The cached `F_q` carried along node moves are the `F_q` recomputed from the moved
    /// positions (to rounding), on every element type, a mixed mesh's shared nodes included.
    #[test]
    fn carried_point_gradients_match_recomputed_ones_for_every_element_type() {
        for et in ElementType::all() {
            let mesh = super::super::tests::one_cell_cantilever(et);
            let geometry = precompute(&mesh, None).unwrap();
            let incidence = NodeIncidence::new(&mesh);
            // from a deformed start, refreshed and carried on this CPU's path (fused where it
            // has AVX2 and FMA), against a plain refresh of the end positions
            let mut x: Vec<Vec3> = mesh
                .rest_positions
                .iter()
                .enumerate()
                .map(|(i, p)| p + Vec3::new(0.003 * (i % 5) as f64, 0.002 * (i % 3) as f64, -0.004 * (i % 2) as f64))
                .collect();
            let fused = Fused::detect();
            let material =
                Material::new(crate::material::MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
            let mut cached = PointLanes::new(&mesh, &geometry);
            cached.refresh(&mesh, &x, fused);
            for (k, i) in (0..mesh.num_nodes()).step_by(3).enumerate() {
                let d = Vec3::new(0.01 * k as f64, -0.02, 0.015 * (k % 4) as f64);
                x[i] += d;
                let lanes = LaneView::of(&mut cached, &material);
                // SAFETY: one thread; the fused path only where the CPU has AVX2 and FMA
                unsafe { carry_on_this_cpu(fused, &incidence, i, d, &lanes) };
            }
            let mut fresh = PointLanes::new(&mesh, &geometry);
            fresh.refresh(&mesh, &x, Fused(false));
            // and both are the F_q of the element's own gather (lane-major, padding F = I)
            let mut moved = false;
            for ((lanes, block), g) in fresh.blocks.iter().zip(&mesh.blocks).zip(&geometry) {
                let (n, points) = (g.nodes_per_element, g.points_per_element);
                for e in 0..block.len() {
                    let nodes = block.element(e);
                    let (xe, re): (Vec<_>, Vec<_>) =
                        nodes.iter().map(|&i| (x[i as usize], mesh.rest_positions[i as usize])).unzip();
                    let grads = element_grads(g, e);
                    let len = 9 * lanes.chunks * lanes.width;
                    let f_e = &lanes.f[e * len..][..len];
                    for p in 0..lanes.chunks * lanes.width {
                        let (k, j) = (p / lanes.width, p % lanes.width);
                        let expected = if p < points {
                            deformation_gradient(&xe, &re, &grads[p * n..(p + 1) * n])
                        } else {
                            Matrix3::identity()
                        };
                        moved |= (expected - Matrix3::identity()).norm() > 1e-3;
                        let got = Matrix3::from_fn(|r, c| f_e[(9 * k + 3 * r + c) * lanes.width + j]);
                        assert!((got - expected).norm() < 1e-12, "{et}: lane-major {got} vs gathered {expected}");
                    }
                }
            }
            for (a, b) in cached.blocks.iter().zip(&fresh.blocks) {
                for (u, v) in a.f.iter().zip(&b.f) {
                    assert!((u - v).abs() < 1e-12, "{et}: carried {u} vs recomputed {v}");
                }
            }
            assert!(moved, "{et}: no F_q moved");
        }
    }
}
