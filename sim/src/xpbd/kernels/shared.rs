//! The sweep's views of the positions and multipliers every thread of a parallel sweep writes,
//! each thread its own disjoint entries ([`SharedMut`]).

use crate::Vec3;
pub use crate::math::shared::SharedMut;

/// Node positions as the sweep reads and writes them.
pub type Positions = SharedMut<Vec3>;
/// Multipliers λ as the sweep writes them (one per element, indexed by the block's element index).
pub type Multipliers = SharedMut<f64>;
