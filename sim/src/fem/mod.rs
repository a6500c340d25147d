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

/// **The node counts with specialised kernels**, the one list: P1, pyramid, prism, Q1, P2, P3 and
/// Q2, each with its node rows' length padded to four lanes (`(n, p)`, `p` = `n` rounded up to a
/// multiple of 4). Every dispatch from a run-time node count to a kernel compiled for it expands
/// this list into its `match` (`$callback!((4, 4), (5, 8), …)`): the element energy's mesh pass
/// (`energy/fixed.rs`), XPBD's sweep, its batches and its `SPECIALISED_NODE_COUNTS`.
/// A new node count is one pair here; a count without one takes the generic kernel.
macro_rules! specialised_node_counts {
    ($callback:ident) => {
        $callback!((4, 4), (5, 8), (6, 8), (8, 8), (10, 12), (20, 20), (27, 28))
    };
}
pub(crate) use specialised_node_counts;

pub mod energy;
pub mod geometry;
pub mod mass;
pub mod quadrature;
