//! How a pass over a mesh's nodes (or another per-node array) is cut between the threads of
//! rayon's current pool: one contiguous chunk per thread for a large array, the calling thread
//! alone for a small one. Every item's update is its own in such a pass, so the cut never changes
//! the result; it only decides whether waking the other threads pays.

use rayon::prelude::*;

/// Fewest items per thread for which a per-node pass runs on every thread of rayon's pool:
/// below, one pass on the calling thread costs less than waking the others. A pass costs ≈ 2 ns
/// per node here; during a substep the sweep's threads are usually still awake (they have just
/// finished a phase), so a few thousand nodes per thread pay (on the 16,225-node beam, 8,192 had
/// left the passes serial: docs/journal/performance.md, session 26).
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

/// Runs `f` while one other worker of rayon's current pool waits for its jobs awake, taking each
/// job `f` shares out as soon as it is queued, instead of going to sleep between two of `f`'s
/// parallel loops.
///
/// Why: a rayon worker with nothing to do sleeps after a few dozen rounds of looking, and waking
/// it costs a system call and, in a virtual machine, an interrupt between processors; a substep of
/// the colour sweep has about seven parallel loops, and on a shared 2-core machine the wake-ups
/// cost more than the second thread gained (docs/journal/performance.md, session 28). The waiting worker
/// keeps looking (yielding its core to any other thread ready on it between two looks, as rayon
/// does before it sleeps) for as long as `f` runs, so call it around a stretch of many short
/// parallel loops (a frame), not around long serial work.
///
/// How: `rayon::join(f, wait)`. `wait` is queued before any job of `f`, so the first worker to
/// steal from this thread takes it (a thief takes the oldest job) and waits there until `f` ends;
/// it never sits inside one of `f`'s jobs, so `f` never waits for it. If no worker takes it, the
/// calling thread finds it after `f` and it returns at once. Nothing is allocated (a frame must
/// not allocate: `scenes/tests/no_alloc.rs`); a panic in `f` ends the wait and reaches the
/// caller. On a pool of more than two threads the others sleep and wake as before.
pub fn with_pool_awake<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    use std::sync::atomic::{AtomicBool, Ordering};
    if rayon::current_num_threads() < 2 {
        return f();
    }
    struct SetOnDrop<'a>(&'a AtomicBool);
    impl Drop for SetOnDrop<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    let done = AtomicBool::new(false);
    let (result, ()) = rayon::join_context(
        |_| {
            // the waiting worker stops even when f panics (the panic then reaches the caller)
            let _done = SetOnDrop(&done);
            f()
        },
        |ctx| {
            if !ctx.migrated() {
                return; // run by the calling thread after f: nothing to wait for
            }
            while !done.load(Ordering::Acquire) {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::thread::yield_now();
                }
            }
        },
    );
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f`'s result comes back, its own parallel loops run (shared with the waiting worker), and
    /// on any pool size, from a worker of the pool or from a thread outside it.
    #[test]
    fn with_pool_awake_returns_what_f_computes_with_its_parallel_loops() {
        let expected: u64 = (0..100_000u64).map(|i| i * i % 7).sum();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let got = pool.install(|| {
                with_pool_awake(|| {
                    (0..50).map(|_| (0..100_000u64).into_par_iter().map(|i| i * i % 7).sum::<u64>()).max().unwrap()
                })
            });
            assert_eq!(got, expected, "{threads} threads");
        }
        // from a thread outside any pool: a worker of the global pool runs f
        let got = std::thread::spawn(move || {
            with_pool_awake(|| (0..100_000u64).into_par_iter().map(|i| i * i % 7).sum::<u64>())
        })
        .join()
        .unwrap();
        assert_eq!(got, expected);
    }

    /// A panic in `f` reaches the caller, and the waiting worker is let go: the pool runs the
    /// next parallel loop.
    #[test]
    fn a_panic_inside_with_pool_awake_reaches_the_caller_and_frees_the_pool() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let caught = pool.install(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                with_pool_awake(|| {
                    let _: u64 = (0..10_000u64).into_par_iter().sum();
                    panic!("inside the frame")
                })
            }))
        });
        assert!(caught.is_err());
        let after: u64 = pool.install(|| (0..10_000u64).into_par_iter().sum());
        assert_eq!(after, 49_995_000);
    }
}
