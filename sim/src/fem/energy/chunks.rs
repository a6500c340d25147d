//! The gradient pass over a large block in chunks, on every thread (issue #61: both cores for
//! large parts; Newton's and the static solver's iterations each evaluate `U` and `∇U` at least
//! once). The block's elements are cut into contiguous ranges by the block's size alone — never
//! by the thread count — each range's `Σ U_e` and `∇U` go into a buffer of its own, and the
//! buffers are then added node by node in range order: the same bits on any number of threads.
//! The buffers are kept between passes (a frame allocates nothing once they have grown).

use super::fixed::Pass;
use crate::Vec3;
use rayon::prelude::*;
use std::sync::Mutex;

/// The fewest elements in a range: a block below twice this is one range (the plain pass).
pub const MIN_ELEMENTS_PER_RANGE: usize = 384;
/// The most ranges a block is cut into.
pub const MAX_RANGES: usize = 8;
/// Nodes per task of the node-by-node sum.
const NODES_PER_TASK: usize = 2048;

/// Buffers kept between passes (one per range; taken by one pass at a time, a concurrent pass
/// makes its own).
static PARTIALS: Mutex<Vec<Vec<Vec3>>> = Mutex::new(Vec::new());

/// The number of ranges a block of `elements` is cut into.
pub fn ranges_for(elements: usize) -> usize {
    (elements / MIN_ELEMENTS_PER_RANGE).clamp(1, MAX_RANGES)
}

/// `Σ U_e` over `pass`'s elements with `∇U` added to `grad_out`, `block_pass` running one range
/// into a zeroed buffer as long as `grad_out`; `ranges` ≥ 2.
pub(super) fn energy_and_gradient_in_ranges(
    pass: Pass<'_>,
    ranges: usize,
    grad_out: &mut [Vec3],
    block_pass: &(dyn Fn(Pass<'_>, &mut [Vec3]) -> f64 + Sync),
) -> f64 {
    let mut buffers = std::mem::take(&mut *PARTIALS.lock().unwrap_or_else(|e| e.into_inner()));
    if buffers.len() < ranges {
        buffers.resize_with(ranges, Vec::new);
    }
    let (start, len) = (pass.elements.start, pass.elements.len());
    let mut energies = [0.0; MAX_RANGES];
    let n = grad_out.len();
    energies[..ranges].par_iter_mut().zip(buffers[..ranges].par_iter_mut()).enumerate().for_each(|(k, (e, buf))| {
        buf.clear();
        buf.resize(n, Vec3::zeros());
        let elements = start + k * len / ranges..start + (k + 1) * len / ranges;
        *e = block_pass(Pass { elements, ..pass }, buf);
    });
    let partials = &buffers[..ranges];
    grad_out.par_chunks_mut(NODES_PER_TASK).enumerate().for_each(|(c, g)| {
        for (i, v) in g.iter_mut().enumerate() {
            let node = c * NODES_PER_TASK + i;
            for p in partials {
                *v += p[node];
            }
        }
    });
    let total = energies[..ranges].iter().sum();
    let mut pool = PARTIALS.lock().unwrap_or_else(|e| e.into_inner());
    if pool.len() < buffers.len() {
        *pool = buffers;
    }
    total
}
