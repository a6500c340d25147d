//! The element data as the sweeps read it: a block's connectivity, material gradients (structure
//! of arrays per element and point, padded to [`super::LANES`]) and quadrature volumes, copied
//! in element order (the serial sweep) or colour by colour (the parallel sweeps, so that a
//! colour is one contiguous range), plus the lane-interleaved batches of a register of elements
//! each ([`super::p1`], [`super::batch`]; four or eight lanes, [`PackedBlock::lanes`]).

use super::simd::padded;
use crate::fem::geometry::BlockGeometry;
use crate::mesh::ElementBlock;
use nalgebra::Matrix3;

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

/// Doubles stored per lane of a batch of linear tetrahedra in [`PackedBlock::batches`]: 9
/// gradient entries and the volume.
pub const P1_VALUES_PER_LANE: usize = 10;

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
    /// In colour order only: the gradients and volumes of each colour's elements in batches of
    /// `L` = [`PackedBlock::lanes`] (`⌈len/L⌉` per colour, the last one padded with zeros),
    /// lane-interleaved
    /// ([`super::batch_values`] per batch: the layout of [`super::p1`] for the linear
    /// tetrahedron at one point, of [`super::batch`] otherwise; see
    /// [`colour_sweep`](super::colour_sweep)). Empty in element order.
    pub batches: Vec<f64>,
    /// Elements per batch: 4 (AVX2) or 8 (AVX-512).
    pub lanes: usize,
    /// In colour order only: `∂N_i/∂r_b(r_q)` at `(q 3 + b) N + i`, the reference gradients the
    /// batches of [`super::batch`] read (the same for every element of the block).
    pub ref_grads: Vec<f64>,
    /// The first batch of colour `c` in [`PackedBlock::batches`] (one more entry than colours).
    pub colour_batches: Vec<usize>,
    /// One more than the largest node index and element id of the block (0 when empty): what
    /// the colour sweep checks its positions and multipliers against once per call, instead
    /// of every index in every batch.
    pub node_bound: usize,
    pub id_bound: usize,
}

impl PackedBlock {
    /// `block`'s data in element order.
    pub fn in_element_order(block: &ElementBlock, geometry: &BlockGeometry) -> Self {
        let all: Vec<u32> = (0..block.len() as u32).collect();
        let mut packed = Self::new(block, geometry, std::slice::from_ref(&all), false, 4);
        packed.element_ids = None;
        packed
    }

    /// `block`'s data in the order of `colours` (element indices per colour), batched for the
    /// register [`auto_lanes`] picks for these colours.
    pub fn in_colour_order(block: &ElementBlock, geometry: &BlockGeometry, colours: &[Vec<u32>]) -> Self {
        Self::in_colour_order_with_lanes(block, geometry, colours, auto_lanes(colours))
    }

    /// As [`PackedBlock::in_colour_order`], in batches of `lanes` (4 or 8) elements.
    pub fn in_colour_order_with_lanes(
        block: &ElementBlock,
        geometry: &BlockGeometry,
        colours: &[Vec<u32>],
        lanes: usize,
    ) -> Self {
        assert!(lanes == 2 || lanes == 4 || lanes == 8, "{lanes} lanes: 2 (a web page), 4 or 8");
        Self::new(block, geometry, colours, true, lanes)
    }

    fn new(block: &ElementBlock, geometry: &BlockGeometry, colours: &[Vec<u32>], batches: bool, lanes: usize) -> Self {
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
            batches: Vec::new(),
            lanes,
            ref_grads: Vec::new(),
            colour_batches: vec![0],
            node_bound: 0,
            id_bound: 0,
        };
        packed.colour_starts.push(0);
        // the reference gradients at each point, shared by every element of the block
        let ref_grads: Vec<Vec<[f64; 3]>> = geometry
            .quadrature
            .points
            .iter()
            .map(|r| {
                let mut g = vec![[0.0; 3]; n];
                geometry.element_type.shape_gradients(r, &mut g);
                g
            })
            .collect();
        if batches && super::from_reference_gradients(n) {
            for g in &ref_grads {
                for axis in 0..3 {
                    packed.ref_grads.extend(g.iter().map(|gi| gi[axis]));
                }
            }
        }
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
            if batches {
                for batch in colour.chunks(lanes) {
                    // a colour's last batch may be partial: its missing lanes hold zero gradients
                    // and volumes (the sweep masks them out; see colour_sweep)
                    let pad = lanes - batch.len();
                    let mut put = |values: &mut dyn Iterator<Item = f64>| {
                        packed.batches.extend(values);
                        packed.batches.extend(std::iter::repeat_n(0.0, pad));
                    };
                    if n == 4 && q == 1 {
                        for r in 1..4 {
                            for c in 0..3 {
                                put(&mut batch.iter().map(|&e| geometry.gradients(e as usize, 0)[r][c]));
                            }
                        }
                        put(&mut batch.iter().map(|&e| geometry.volumes(e as usize)[0]));
                        continue;
                    }
                    if !super::from_reference_gradients(n) {
                        for p in 0..q {
                            for axis in 0..3 {
                                for i in 0..n {
                                    put(&mut batch.iter().map(|&e| geometry.gradients(e as usize, p)[i][axis]));
                                }
                            }
                            put(&mut batch.iter().map(|&e| geometry.volumes(e as usize)[p]));
                        }
                        continue;
                    }
                    for p in 0..q {
                        let jinv: Vec<Matrix3<f64>> = batch
                            .iter()
                            .map(|&e| inverse_jacobian(&ref_grads[p], geometry.gradients(e as usize, p)))
                            .collect();
                        for r in 0..3 {
                            for c in 0..3 {
                                put(&mut jinv.iter().map(|j| j[(r, c)]));
                            }
                        }
                        put(&mut batch.iter().map(|&e| geometry.volumes(e as usize)[p]));
                    }
                }
                packed.colour_batches.push(packed.batches.len() / super::batch_values(n, q, lanes));
            }
        }
        packed.node_bound = packed.nodes.iter().map(|&i| i as usize + 1).max().unwrap_or(0);
        packed.id_bound = ids.iter().map(|&i| i as usize + 1).max().unwrap_or(0);
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
    /// Batches of `lanes` (4 or 8) elements in the colour order; None: each block's
    /// [`auto_lanes`].
    pub fn new(
        blocks: &[ElementBlock],
        geometry: &[BlockGeometry],
        colours: &[Vec<Vec<u32>>],
        lanes: Option<usize>,
    ) -> Self {
        Self {
            serial: blocks.iter().zip(geometry).map(|(b, g)| PackedBlock::in_element_order(b, g)).collect(),
            colour: blocks
                .iter()
                .zip(geometry)
                .zip(colours)
                .map(|((b, g), c)| {
                    PackedBlock::in_colour_order_with_lanes(b, g, c, lanes.unwrap_or_else(|| auto_lanes(c)))
                })
                .collect(),
        }
    }
}

/// What a batch of eight elements counts for against a batch of four in [`auto_lanes`]. On the
/// AVX-512 core measured (Sapphire Rapids, one thread, `hox bench --lanes 4,8` alternately,
/// three rounds), 1.25 sorts every beam measured onto its faster width: the paper's P3 (35
/// batches of four against 32 of eight: four lanes 0.73–0.75× the time of eight) and Q2 (8
/// against 8: 0.55–0.78×) keep four; its P2 (45 against 35: eight lanes 0.64–1.0×), the prism
/// and pyramid beams (130 against 67, 171 against 96: 0.55–0.74×) and every beam whose colours
/// fill their batches (P1 1,280 to 81,920, the 32×8×8 beams but the pyramid's) take eight.
pub const EIGHT_LANE_BATCH_COST: f64 = 1.25;

/// The register width for a block swept in `colours`: 8 where the CPU has AVX-512 F and the
/// block's batches of eight (`Σ ⌈len/8⌉`, a colour's last batch padded) cost less than its
/// batches of four (`Σ ⌈len/4⌉`), a batch of eight counting [`EIGHT_LANE_BATCH_COST`]; else 4
/// (also where the CPU has no SIMD batches at all: they are then not run); 2 in a web page. Small blocks with
/// short colours (the paper's P3 beam: 80 elements) keep four lanes, where half-empty batches
/// of eight were slower. A function of the colours and the CPU alone, never of the thread count.
pub fn auto_lanes(colours: &[Vec<u32>]) -> usize {
    match super::widest_available() {
        // a web page's register: two lanes (wasm simd128)
        Some(2) => return 2,
        Some(8) => {}
        _ => return 4,
    }
    let batches = |w: usize| colours.iter().map(|c| c.len().div_ceil(w)).sum::<usize>() as f64;
    if EIGHT_LANE_BATCH_COST * batches(8) < batches(4) { 8 } else { 4 }
}

/// `J⁻¹` at a point from the reference gradients `g_r` (`∂N_i/∂r`) and the material gradients
/// `g_x` (`∇_X N_i = J⁻ᵀ ∂N_i/∂r`) of the element there: the least-squares solution of
/// `G_r J⁻¹ = G_x` (rows `g_rᵢᵀ`, `g_xᵢᵀ`), `J⁻¹ = (G_rᵀ G_r)⁻¹ G_rᵀ G_x`, exact up to round-off
/// since every element's reference gradients span the three directions.
fn inverse_jacobian(g_r: &[[f64; 3]], g_x: &[crate::Vec3]) -> Matrix3<f64> {
    let mut gtg = Matrix3::zeros();
    let mut gtx = Matrix3::zeros();
    for (r, x) in g_r.iter().zip(g_x) {
        let r = crate::Vec3::from(*r);
        gtg += r * r.transpose();
        gtx += r * x.transpose();
    }
    gtg.try_inverse().expect("reference gradients span three directions") * gtx
}
