//! The finite-element model of a mesh: what the solvers integrate.
//!
//! - [`quadrature`]: Witherden–Vincent and Gauss rules per reference shape, by degree.
//! - [`geometry`]: per element and quadrature point `r_q`, the rest Jacobian
//!   `J(X, r_q) = Σ_i X_i ⊗ ∂N_i/∂r(r_q)`, the material gradients `∇_X N_i = J⁻ᵀ ∂N_i/∂r` and the
//!   volumes `V_q = w_q det J`, precomputed; the deformation gradient
//!   `F_q = I + Σ_i (x_i − X_i) ⊗ ∇_X N_i(r_q)`.
//! - [`energy`]: the elastic energy `U_e = Σ_q V_q ψ(F_q)` of an element and of a mesh, its
//!   gradient `Σ_q V_q P(F_q) ∇_X N_i` and Hessian.
//! - [`mass`]: lumped nodal masses (HRZ).
//!
//! It reads reference elements ([`crate::element`]), meshes ([`crate::mesh`]) and materials
//! ([`crate::material`]), and nothing of the solvers.

pub mod energy;
pub mod geometry;
pub mod mass;
pub mod quadrature;
