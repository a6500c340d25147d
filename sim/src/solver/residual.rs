//! How far a state is from static equilibrium: the unbalanced force on the free nodes relative
//! to the load, the measure `hox static` converges on and `--settle` stops on.
//!
//! With `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i`, the residual is `r = ‖∇Π‖` over the free degrees of
//! freedom, the reactions `‖∇Π‖` over the held ones, and the load scale
//! `max(Σ_i m_i |a|, reactions, ε μ L²)` (the body force, or what holds the body if that is
//! larger, as when a drive loads it; never below [`load_floor_n`]). Forces of contact and of
//! attachments are not counted.

use crate::Vec3;

/// The static residual of a state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticResidual {
    /// `free_n / scale_n`.
    pub relative: f64,
    /// The unbalanced force on the free nodes, newtons (Euclidean norm over their components).
    pub free_n: f64,
    /// The force the held nodes take, newtons.
    pub reactions_n: f64,
    /// The load the residual is relative to, newtons.
    pub scale_n: f64,
}

/// The load scale: the body force or the reactions, whichever is larger (never zero).
pub(crate) fn load_scale(body_force_n: f64, reactions_n: f64) -> f64 {
    body_force_n.max(reactions_n).max(f64::MIN_POSITIVE)
}

/// The strain of [`load_floor_n`].
pub const LOAD_FLOOR_STRAIN: f64 = 1e-8;

/// The least load a residual is measured against, N: the elastic force of a strain of
/// [`LOAD_FLOOR_STRAIN`] over the body's size squared, `ε μ L²` (μ the shear modulus, L the rest
/// bounding-box diagonal). A body left with no load (gravity removed, a drive released) comes to
/// rest with reactions that decay to round-off; measured against them, the residual of a solved
/// step is round-off over round-off, and the step watch read it as a step left unsolved (the
/// stiff cantilever released, issue #36). The floor is far above the gradient's round-off
/// (about `10⁻¹⁶ μ L²` per node) and far below any load a scene applies (a 1 GPa beam's own
/// weight is 140 times its floor).
pub fn load_floor_n(mu_pa: f64, body_size_m: f64) -> f64 {
    LOAD_FLOOR_STRAIN * mu_pa * body_size_m * body_size_m
}

/// The residual of a state whose elastic energy gradient is `grad_elastic`, under the body
/// acceleration `a` acting on the lumped masses; `is_free(i)`: node `i` is free.
pub(crate) fn static_residual(
    grad_elastic: &[Vec3],
    masses_kg: &[f64],
    a: Vec3,
    floor_n: f64,
    is_free: impl Fn(usize) -> bool,
) -> StaticResidual {
    let (mut free, mut reactions, mut body) = (0.0, 0.0, 0.0);
    for (i, (g, m)) in grad_elastic.iter().zip(masses_kg).enumerate() {
        let r = (g - a * *m).norm_squared();
        if is_free(i) {
            free += r;
        } else {
            reactions += r;
        }
        body += m * a.norm();
    }
    let (free_n, reactions_n) = (free.sqrt(), reactions.sqrt());
    let scale_n = load_scale(body.max(floor_n), reactions_n);
    StaticResidual { relative: free_n / scale_n, free_n, reactions_n, scale_n }
}
