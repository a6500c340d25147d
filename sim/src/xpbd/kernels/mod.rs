//! The hot loop of the solver, specialised per element node count: the energy-constraint sweep
//! over a block (serial in element order, or one colour's contiguous range in the parallel sweep).
//!
//! It computes exactly what [`crate::xpbd::constraint::project_energy_constraint`] computes — for each
//! element, `F_q = I + Σ_i (x_i − X_i) ⊗ ∇_X N_i(r_q)`, `U_e = Σ_q V_q ψ(F_q)`,
//! `∇_i U_e = Σ_q V_q P(F_q) ∇_X N_i(r_q)`, `C = √(2U_e)` and the XPBD update of
//! [`crate::xpbd::constraint::xpbd_step`] (the paper's `Δλ = −2U / (Σ_i w_i |∇_i U|² + 2U α̃)` with
//! λ = 0, Saillant et al. §3) — but with the node count `N` a compile-time constant, so that
//! every per-node loop is unrolled and every scratch array lives in registers or a fixed-size
//! stack array of exactly `N` entries; and with the material's Lamé parameters computed once per
//! sweep instead of once per quadrature point ([`Stvk`]). Results equal the generic kernel's up
//! to the order of floating-point operations.
//!
//! Both sweeps read the element data from a [`PackedBlock`] copy: connectivity, material
//! gradients (as structure of arrays per element and point, so the loops over the `N` nodes
//! vectorise) and quadrature volumes; for the parallel sweep reordered colour by colour, so that each colour is a
//! contiguous range of memory handed to the threads in contiguous chunks (the elements of a
//! colour keep their increasing element order, so the result is bitwise the one of the
//! element-indexed colour sweep).
//!
//! Files, one concern each: `sweep.rs` the sweep and the per-element projections
//! ([`energy_sweep`], [`colour_sweep`], [`project_p1`], [`project_energy`]); the
//! material law it is generic over ([`PointMaterial`], [`Stvk`]) is `crate::material::point_law`
//! and the lane helpers ([`mul3`], [`LANES`]) `crate::math::soa`, both shared with the element
//! energy and gradient of `crate::fem::energy`; `shared.rs` the raw shared pointers ([`SharedMut`]); `pack.rs` the
//! packed element data ([`PackedBlock`]); `schedule.rs` the parallel schedules and every
//! threshold that cuts work between threads ([`parallel_energy_block`], [`Partition`]);
//! [`p1`] the linear tetrahedron a register at a time, [`batch`] any other type (`lanes.rs`: what
//! both batches share). Each batch kernel is written once over the register type
//! (`crate::math::wide`) and compiled twice, four lanes for AVX2 and eight for AVX-512; the width
//! is chosen at packing ([`PackedBlock::lanes`]: the widest the CPU has, or as asked).

mod pack;
use crate::material::point_law;
use crate::math::soa as simd;
mod schedule;
mod shared;
mod sweep;

#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
pub mod batch;
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
pub(crate) mod lanes;
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
pub mod p1;

/// Whether the batches of `nodes`-node elements read reference gradients and one `J⁻¹` per point
/// (P3, Q2) rather than stored material gradients (see `batch`'s module doc). A layout, not a
/// kernel: the packing reads it on every target.
pub const fn from_reference_gradients(nodes: usize) -> bool {
    nodes >= 20
}

/// Doubles per quadrature point and lane of a batch read from reference gradients: `J⁻¹` (9)
/// and `V`.
pub const POINT_VALUES_PER_LANE: usize = 10;

/// Doubles per batch of `lanes` elements of `nodes` nodes and `points` quadrature points in
/// [`PackedBlock::batches`] (the layouts of [`p1`] and [`batch`]).
pub const fn batch_values(nodes: usize, points: usize, lanes: usize) -> usize {
    lanes
        * if nodes == 4 && points == 1 {
            P1_VALUES_PER_LANE
        } else if from_reference_gradients(nodes) {
            points * POINT_VALUES_PER_LANE
        } else {
            points * (3 * nodes + 1)
        }
}

/// The register widths the colour sweep can batch with: the widest this CPU runs (8 with
/// AVX-512 F, 4 with AVX2 and FMA, 2 in a web page compiled with `simd128`), None without
/// any; and whether a given width runs here.
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
pub use lanes::{lanes_available, widest_available};
/// No batches without x86-64's or the page's registers: the scalar sweep only.
#[cfg(not(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128"))))]
pub fn widest_available() -> Option<usize> {
    None
}
/// No batches without x86-64's or the page's registers.
#[cfg(not(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128"))))]
pub fn lanes_available(_lanes: usize) -> bool {
    false
}

pub use crate::material::point_law::{AnyMaterial, PointMaterial, Stvk};
pub use crate::math::soa::{LANES, mul3, padded};
pub use pack::{BlockData, EIGHT_LANE_BATCH_COST, P1_VALUES_PER_LANE, PackedBlock, SolverData, auto_lanes};
pub use schedule::{
    BlockSweep, ELEMENTS_PER_EXTRA_SLAB, GENERIC_MIN_ELEMENTS_PER_TASK, MAX_SLABS, MIN_SLABS,
    PARTITION_MIN_ELEMENTS_PER_SLAB, Partition, SWEEP_MIN_ELEMENTS_PER_THREAD, flops_per_element, p1_equivalents,
    parallel_energy_block, slab_count,
};
pub use shared::{Multipliers, Positions, SharedMut};
pub use sweep::{NonFiniteElement, SPECIALISED_NODE_COUNTS, colour_sweep, energy_sweep, project_energy, project_p1};

#[cfg(test)]
mod tests;
