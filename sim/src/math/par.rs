//! How a pass over a mesh's nodes (or another per-node array) is cut between the threads of
//! rayon's current pool: one contiguous chunk per thread for a large array, the calling thread
//! alone for a small one. Every item's update is its own in such a pass, so the cut never changes
//! the result; it only decides whether waking the other threads pays.

use rayon::prelude::*;

/// Fewest items per thread for which a per-node pass runs on every thread of rayon's pool:
/// below, one pass on the calling thread costs less than waking the others. A pass costs ≈ 2 ns
/// per node here; during a substep the sweep's threads are usually still awake (they have just
/// finished a phase), so a few thousand nodes per thread pay (on the 16,225-node beam, 8,192 had
/// left the passes serial: docs/PERFORMANCE.md, session 26).
pub const NODE_LOOP_MIN_NODES_PER_THREAD: usize = 4096;

/// How many chunks a pass over `len` items is cut into: one per thread of the current pool, at
/// most one per [`NODE_LOOP_MIN_NODES_PER_THREAD`] items, at least one.
pub fn chunks(len: usize) -> usize {
    rayon::current_num_threads().min(len / NODE_LOOP_MIN_NODES_PER_THREAD).max(1)
}

/// Items per chunk when `len` items are cut into `chunks` (all of them when one).
pub fn chunk_len(len: usize, chunks: usize) -> usize {
    len.div_ceil(chunks.max(1)).max(1)
}

/// `f` on each of `chunks` contiguous chunks of `a` and the matching chunks of `b`, on rayon's
/// pool when `chunks` > 1 (the same cut for both: `a` and `b` as long as each other).
pub fn zip_chunks<A: Send, B: Sync>(a: &mut [A], b: &[B], chunks: usize, f: impl Fn(&mut [A], &[B]) + Sync + Send) {
    if chunks > 1 {
        let c = chunk_len(a.len(), chunks);
        a.par_chunks_mut(c).zip(b.par_chunks(c)).for_each(|(a, b)| f(a, b));
    } else {
        f(a, b);
    }
}

/// `v` filled with `value`, on every thread for a long slice.
pub fn fill(v: &mut [f64], value: f64) {
    let chunks = chunks(v.len());
    if chunks > 1 {
        v.par_chunks_mut(chunk_len(v.len(), chunks)).for_each(|c| c.fill(value));
    } else {
        v.fill(value);
    }
}
