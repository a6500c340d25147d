//! Scheduling the parallel sweep: the thresholds that cut the work between threads (all of them
//! here), colour after colour in contiguous chunks ([`parallel_energy_block`]), or slab by slab in
//! two phases ([`Partition`]).

use super::pack::PackedBlock;
use super::shared::{Multipliers, Positions};
use super::sweep::{NonFiniteElement, SPECIALISED_NODE_COUNTS, colour_sweep};
use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::ElementBlock;

// Scheduling thresholds of the parallel sweeps, all in one place. They decide only how the work
// is cut between threads, never the result: the elements of one colour share no node and own
// their multipliers, so projecting them in any grouping and order gives the same positions
// bitwise (the four-lane batches are fixed by the colour's start, not by the cut), and a
// non-finite correction is reported for the first bad element of the colour whatever the cut.
// The slab partition changes the order, hence the result, but its slab count depends on the
// block's size alone ([`slab_count`]), so the result still does not depend on the thread count.

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

/// Fewest elements per slab, in [`p1_equivalents`] ([`slab_count`]; the default of
/// `Simulation::set_partition_threshold`): a block of at least [`MIN_SLABS`] times this is cut
/// into slabs ([`Partition`]) instead of synchronising the threads after every colour. 1,024
/// linear tetrahedra take ≈ 30 µs per sweep, well above the cost of a join.
pub const PARTITION_MIN_ELEMENTS_PER_SLAB: usize = 1024;

/// Elements per slab, in [`p1_equivalents`], past which a block is cut into more than
/// [`MIN_SLABS`] slabs (up to [`MAX_SLABS`]). More slabs than threads per phase let a thread that
/// finishes early take another slab (rayon's work stealing): two threads of a shared machine do
/// not run at one speed (on the 81,920-tetrahedron beam with two slabs per phase, one thread's
/// slabs took 25 ms per frame and the other's 34 ms, and every phase waited for the slower; with
/// eight per phase both threads finished each phase within a slab's time of each other).
/// 4,096 cuts that beam into 16 slabs of 5,120 tetrahedra, ≈ 100 µs each per sweep, far above a
/// steal's cost (docs/journal/performance.md, session 26).
pub const ELEMENTS_PER_EXTRA_SLAB: usize = 4_096;

/// The fewest slabs a cut block has: two phases of two slabs each.
pub const MIN_SLABS: usize = 4;

/// The most slabs a block is cut into.
pub const MAX_SLABS: usize = 16;

/// Flops of one energy-constraint projection of an element with `nodes` nodes and `points`
/// quadrature points, a fused multiply–add counted as 2: per point `F` (18N), the StVK law (165)
/// and `∇_i U += V P ∇N_i` (18N + 9); per element the displacements (3N), `Σ w|∇U|²` (6N), the
/// update (10) and the scatter (7N). 392 for P1, 31,384 for Q2 at 27 points.
pub const fn flops_per_element(nodes: usize, points: usize) -> usize {
    points * (36 * nodes + 174) + 16 * nodes + 10
}

/// A block's size in linear tetrahedra of equal work: `len` elements of `nodes` nodes and
/// `points` points, weighted by [`flops_per_element`] against P1's — what the slab thresholds
/// are stated in, so that a block of 13 Q2 hexahedra at 27 points counts as much as 1,024 P1
/// tetrahedra.
pub fn p1_equivalents(len: usize, nodes: usize, points: usize) -> usize {
    len.saturating_mul(flops_per_element(nodes, points)) / flops_per_element(4, 1)
}

/// How many slabs the colour sweep cuts a block of `len` elements into, `len` in
/// [`p1_equivalents`]: 1 (no cut: colour by colour) below [`MIN_SLABS`]` min_per_slab`, else the
/// largest power of two at most `len / ELEMENTS_PER_EXTRA_SLAB`, between [`MIN_SLABS`] and
/// [`MAX_SLABS`]. A function of the block alone: the sweep's order, hence its result, never
/// depends on the thread count, and on a machine with fewer threads than slabs per phase a
/// thread sweeps several slabs in turn.
pub fn slab_count(len: usize, min_per_slab: usize) -> usize {
    if len < min_per_slab.saturating_mul(MIN_SLABS) {
        return 1;
    }
    let wanted = (len / ELEMENTS_PER_EXTRA_SLAB).clamp(MIN_SLABS, MAX_SLABS);
    1 << wanted.ilog2()
}

/// How [`parallel_energy_block`] sweeps a block.
#[derive(Clone, Copy, Debug)]
pub enum BlockSweep<'a> {
    /// Colour after colour (the block packed in colour order).
    Colours(&'a PackedBlock),
    /// Slab by slab, the even slabs side by side, then the odd ones ([`Partition`]).
    Slabs(&'a Partition),
}

/// The parallel sweep of the energy formulation over one block, by slabs (see [`Partition`]) or
/// else colour after colour, each
/// colour's packed range cut into one contiguous chunk per thread of rayon's current pool (at
/// least [`SWEEP_MIN_ELEMENTS_PER_THREAD`] elements each, cut at multiples of the batch width from
/// the colour's start; see [`colour_sweep`] for `batched`). Same-colour elements share no node, so the
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
        let width = packed.lanes;
        let batches = range.len().div_ceil(width);
        let cut = |i: usize| range.start + (width * (batches * i / chunks)).min(range.len());
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

/// A block cut into slabs ([`slab_count`]) along the longest axis of its rest shape: element
/// `e` belongs to slab `s` when its centroid lies between cuts `s − 1` and `s`, the cuts at the
/// quantiles of the centroids (so each slab holds about as many elements), and each slab is
/// packed colour by colour (the block's colouring restricted to it, element order kept inside a
/// colour).
///
/// One Gauss–Seidel sweep ([`parallel_energy_block`] with [`BlockSweep::Slabs`]) is then two
/// phases, a red–black ordering of the slabs: the even slabs side by side, one task each, swept
/// colour after colour with no synchronisation, one join, then the odd slabs likewise. Two slabs of
/// one phase share no node, because the slab between them is thicker than an element (checked
/// when the partition is made: a block too thin for its slab count is not cut, [`Partition::new`]
/// gives None). Two synchronisations per sweep instead of one per colour, and no element swept
/// alone. The order (and so the result, bitwise) depends on the slab count, not on the thread
/// count or the scheduling.
#[derive(Clone, Debug, Default)]
pub struct Partition {
    pub slabs: Vec<PackedBlock>,
}

impl Partition {
    /// `block` cut into `slabs` slabs (even, at least 2), each packed in batches of `lanes`
    /// elements ([`PackedBlock::in_colour_order_with_lanes`]), or None when two slabs of one
    /// phase would share a node.
    pub fn new(
        block: &ElementBlock,
        geometry: &BlockGeometry,
        colours: &[Vec<u32>],
        rest: &[Vec3],
        slabs: usize,
        lanes: usize,
    ) -> Option<Self> {
        if slabs < 2 || !slabs.is_multiple_of(2) || block.len() < slabs {
            return None;
        }
        let n = block.nodes_per_element();
        let centroid = |e: usize| block.element(e).iter().map(|&i| rest[i as usize]).sum::<Vec3>() / n as f64;
        let (lo, hi) = block
            .elements()
            .flatten()
            .fold((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)), |(lo, hi), &i| {
                (lo.inf(&rest[i as usize]), hi.sup(&rest[i as usize]))
            });
        let axis = (hi - lo).iamax();
        let along: Vec<f64> = (0..block.len()).map(|e| centroid(e)[axis]).collect();
        let mut sorted = along.clone();
        sorted.sort_by(f64::total_cmp);
        // slab s holds the elements with cuts[s − 1] ≤ centroid < cuts[s]
        let cuts: Vec<f64> = (1..slabs).map(|s| sorted[sorted.len() * s / slabs]).collect();
        let owner: Vec<usize> = along.iter().map(|&c| cuts.partition_point(|&cut| cut <= c)).collect();
        // two slabs of one phase must not share a node
        let mut node_slab = vec![usize::MAX; rest.len()];
        for phase in 0..2 {
            node_slab.fill(usize::MAX);
            for (e, &s) in owner.iter().enumerate() {
                if s % 2 != phase {
                    continue;
                }
                for &i in block.element(e) {
                    let slot = &mut node_slab[i as usize];
                    if *slot != usize::MAX && *slot != s {
                        return None;
                    }
                    *slot = s;
                }
            }
        }
        let restricted = |slab: usize| -> Vec<Vec<u32>> {
            colours
                .iter()
                .map(|c| c.iter().copied().filter(|&e| owner[e as usize] == slab).collect::<Vec<u32>>())
                .filter(|c| !c.is_empty())
                .collect()
        };
        Some(Self {
            slabs: (0..slabs)
                .map(|s| PackedBlock::in_colour_order_with_lanes(block, geometry, &restricted(s), lanes))
                .collect(),
        })
    }

    /// `block` cut into `slabs` slabs ([`Partition::new`]), or, where it is too thin for that
    /// many, into half as many, and so on down to [`MIN_SLABS`]: None only when even that fails.
    /// Still a function of the block alone.
    pub fn largest(
        block: &ElementBlock,
        geometry: &BlockGeometry,
        colours: &[Vec<u32>],
        rest: &[Vec3],
        slabs: usize,
        lanes: usize,
    ) -> Option<Self> {
        let mut count = slabs;
        while count >= MIN_SLABS {
            if let Some(partition) = Self::new(block, geometry, colours, rest, count, lanes) {
                return Some(partition);
            }
            count /= 2;
        }
        None
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
/// [`Partition`]): the even slabs side by side on rayon's current pool, then the odd ones. On a
/// non-finite correction the phase finishes, and the error of its lowest slab that had one is
/// returned (the next phase is not swept).
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
    // SAFETY: the slabs of one phase touch disjoint nodes (checked by Partition::new) and their
    // elements own their multipliers; the phases run one after the other; node and element
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
    let mut projected = 0;
    for phase in 0..2 {
        // (no allocation inside a frame: the phase's slabs are 2k + phase)
        projected += (0..partition.slabs.len() / 2)
            .into_par_iter()
            .with_max_len(1)
            .map(|k| 2 * k + phase)
            .map(|s| (s, slab(s)))
            .reduce(|| (usize::MAX, Ok(0)), lowest_error)
            .1?;
    }
    Ok(projected)
}
