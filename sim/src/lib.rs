//! # hox-sim — the simulation core of hox
//!
//! Implements the method of *High-Order Elements in Position Based Dynamics* (Saillant, Zara,
//! Damiand, Jaillet): every element type is handled by one mechanism. At each quadrature point
//! `r_q` of the reference element, the rest Jacobian `J(X, r_q) = Σ_i X_i ⊗ ∂N_i/∂r(r_q)` and the
//! deformed one `J(x, r_q)` give the deformation gradient `F_q = J(x, r_q) J(X, r_q)⁻¹`; the
//! element energy `U_e = Σ_q w_q det J(X, r_q) ψ(F_q)` and its gradient
//! `∂U_e/∂x_i = Σ_q w_q det J(X, r_q) P(F_q) ∇_X N_i(r_q)` drive XPBD constraints.
//!
//! Where to find things:
//! - [`element`]: reference elements (P1, P2, P3, Q1, Q2, prism, pyramid), Gmsh node order.
//! - [`quadrature`]: Witherden–Vincent and Gauss rules per reference shape, by degree.
//! - [`material`]: hyperelastic models ψ(F), P(F), dP/dF.
//! - [`mesh`]: meshes (blocks of one element type), structured beams, high-order nodes.
//! - [`geometry`]: per-element, per-quadrature-point precomputed gradients and volumes.
//! - [`mass`]: lumped nodal masses (HRZ).
//! - [`probe`]: material points located in the rest mesh, followed through the deformation.
//! - [`energy`]: total elastic energy, gradient and Hessian of a mesh.
//! - [`constraint`]: pure XPBD constraint kernels (energy and split formulations).
//! - [`kernels`]: the hot loop, specialised per node count, and the colour-packed element data.
//! - [`statics`]: static equilibrium by Newton's method (the reference XPBD must settle to).
//! - [`solver`]: the stateful XPBD solver and the opt-in [`effect`]s it runs.
//! - [`surface`]: the tessellated boundary surface and material points for display.
//! - [`benchmark`]: timing the paper's Table 1 beams (`hox bench`, `sim/benches/`).

pub mod benchmark;
pub mod effect;
pub mod element;
pub mod fem;
pub mod io;
pub mod material;
pub mod measure;
pub mod mesh;
pub mod solver;
pub mod xpbd;

pub use nalgebra;

/// A 3-vector of f64 (positions in metres, unless a name says otherwise).
pub type Vec3 = nalgebra::Vector3<f64>;
