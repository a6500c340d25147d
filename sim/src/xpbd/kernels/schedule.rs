//! Scheduling the parallel sweep: the thresholds that cut the work between threads (all of them
//! here), colour after colour in contiguous chunks ([`parallel_energy_block`]), or one slab per
//! thread ([`Partition`]).

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
