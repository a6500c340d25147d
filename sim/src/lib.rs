//! # hox-sim — the simulation core of hox
//!
//! Implements the method of *High-Order Elements in Position Based Dynamics* (Saillant, Zara,
//! Damiand, Jaillet): every element type is handled by one mechanism. At each quadrature point
//! `r_q` of the reference element, the rest Jacobian `J(X, r_q) = Σ_i X_i ⊗ ∂N_i/∂r(r_q)` and the
//! deformed one `J(x, r_q)` give the deformation gradient `F_q = J(x, r_q) J(X, r_q)⁻¹`; the
//! element energy `U_e = Σ_q w_q det J(X, r_q) ψ(F_q)` and its gradient
//! `∂U_e/∂x_i = Σ_q w_q det J(X, r_q) P(F_q) ∇_X N_i(r_q)` drive XPBD constraints.
//!
//! Where to find things — one folder ("room") per concern, in this order: each reads only the
//! rooms listed before it (no cycles; `tests/tests/rooms.rs` fails on an import against it, and
//! docs/ARCHITECTURE.md states the same order):
//! - [`math`]: the number types below everything — the lane a point law is written over
//!   ([`math::lane::Lane`]: one `f64` or four SIMD lanes), the AVX2 four-lane type and the one
//!   runtime CPU check, the shared pointer of parallel sweeps.
//! - [`element`]: reference elements (P1, P2, P3, Q1, Q2, prism, pyramid), Gmsh node order.
//! - [`material`]: hyperelastic models ψ(F), P(F), dP/dF and their registry.
//! - [`mesh`]: meshes (blocks of one element type), structured beams, shared high-order nodes.
//! - [`fem`]: the finite-element model of a mesh — quadrature rules, precomputed gradients and
//!   volumes (`geometry`, with the one Jacobian and the one deformation gradient), lumped masses,
//!   element and mesh energy with gradient and Hessian.
//! - [`measure`]: probes, the display surface and the fields drawn on it, min det F, the one
//!   [`measure::median`].
//! - [`io`]: mesh files — Gmsh import, VTK/PVD export (with the fields of [`measure`]).
//! - [`xpbd`]: the XPBD projection — pure constraint kernels (energy and split formulations),
//!   the hot sweep specialised per node count (`xpbd::kernels`), element colouring.
//! - [`effect`]: opt-in effects (gravity, clamps, prescribed motion, contact, damping, drag).
//! - [`solver`]: the stateful [`solver::Simulation`] (the step skeleton, the NaN and stability
//!   guards) and its solvers — XPBD, VBD, Newton — behind one trait and one registry, and
//!   static equilibrium by the same Newton (`solver::statics`).
//!
//! Timing the paper's Table 1 beams (`hox bench`) lives in the scenes crate (`hox_scenes::bench`):
//! the beam is the bending scene file's.

pub mod math;

pub mod element;

pub mod material;

pub mod mesh;

pub mod fem;

pub mod measure;

pub mod io;

pub mod xpbd;

pub mod effect;

pub mod solver;

pub use nalgebra;

/// A 3-vector of f64 (positions in metres, unless a name says otherwise).
pub type Vec3 = nalgebra::Vector3<f64>;
