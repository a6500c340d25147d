//! No heap allocation inside a frame: a counting global allocator around `step_frame`, for the
//! serial sweep and for the parallel sweep run inside a rayon pool (issue #7).

use hox_scenes::bench::{CASES, bending_beam};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards to the system allocator, counting.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `frames` frames after two warm-up frames.
fn allocations_per_run(parallel: bool, element: &str) -> u64 {
    allocations_of(CASES.iter().find(|c| c.element == element).expect("case"), parallel)
}

fn allocations_of(case: &hox_scenes::bench::BenchCase, parallel: bool) -> u64 {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| {
        let sweep = if parallel { hox_sim::solver::Sweep::Colour } else { hox_sim::solver::Sweep::Element };
        let mut sim = bending_beam(case, sweep).unwrap();
        for _ in 0..2 {
            sim.step_frame().unwrap();
        }
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..3 {
            sim.step_frame().unwrap();
        }
        ALLOCATIONS.load(Ordering::SeqCst) - before
    })
}

#[test]
fn frames_do_not_allocate() {
    // one test function: the counter is global, and tests run on parallel threads
    for element in ["p1", "p2", "q1", "pyramid"] {
        assert_eq!(allocations_per_run(false, element), 0, "{element}, serial sweep");
        assert_eq!(allocations_per_run(true, element), 0, "{element}, parallel sweep");
    }
    // 10,240 tetrahedra: on two threads the block is cut into slabs (kernels::Partition)
    assert_eq!(allocations_of(&CASES[1], true), 0, "P1 r1, slab sweep");
}
