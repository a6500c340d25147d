//! The XPBD projection of element constraints: what one Gauss–Seidel sweep does to one element,
//! and how a sweep over many is scheduled.
//!
//! - [`constraint`]: the pure constraint kernels — the XPBD update (Macklin, Müller & Chentanez
//!   2016) `Δλ = −(C + α̃ λ) / (Σ_i w_i |∇_i C|² + α̃)`, `Δx_i = w_i ∇_i C Δλ`, written once in
//!   [`constraint::xpbd_step`]; the paper's energy constraint `C = √(2 U_e)` (Saillant et al.
//!   §3) and the split deviatoric/hydrostatic constraints (Macklin & Müller 2021);
//!   [`constraint::Formulation`] chooses between them.
//! - [`kernels`]: the hot loop — the energy-constraint sweep specialised per node count, the
//!   packed element data it reads, four linear tetrahedra per AVX2 register, and the parallel
//!   schedules (colour chunks, slabs).
//! - [`patch`]: the node-patch hydrostatic constraints of P1 in the mixed formulation (Bonet &
//!   Burton's averaged nodal pressure), coloured so that patches sharing no node run
//!   concurrently.
//! - [`colouring`]: greedy element colouring (no two elements of a colour share a node), which
//!   makes a colour safe to project in parallel.
//!
//! It reads the finite-element model ([`crate::fem`]), materials and meshes; the stateful
//! solver ([`crate::solver`]) and the effects ([`crate::effect`]) call it.

pub mod colouring;
pub mod constraint;
pub mod kernels;
pub mod patch;
