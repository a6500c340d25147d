//! Measuring a deformed body: material points followed through the deformation and whether any
//! element is inverted.
//!
//! - [`probe`]: material points located once in the rest mesh by inverting an element's map
//!   `X(r) = Σ_i N_i(r) X_i` (Newton's method), then moving as `x(p) = Σ_i N_i(r) x_i`.
//! - [`surface`]: the boundary tessellated for display (curved faces follow the elements' own
//!   maps) and quadrature points as material points.
//! - [`field`]: scalar fields on the display surface (displacement, von Mises stress, strain,
//!   det F, energy density, error), evaluated at each element's own points.
//! - [`min_det_f`]: the smallest `det F` over every quadrature point ([`MinDetF`]).
//! - [`median`]: the one median (frame timings, run reports; empty input is NaN).
//!
//! It reads meshes and the finite-element model; the solvers do not read it.

pub mod field;
mod inversion;
mod median;
pub mod probe;
pub mod surface;

pub use inversion::{MinDetF, min_det_f};
pub use median::{median, quantile};
