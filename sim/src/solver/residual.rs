//! How far a state is from static equilibrium: the unbalanced force on the free nodes relative
//! to the load, the measure `hox static` converges on and `--settle` stops on.
//!
//! With `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i`, the residual is `r = ‖∇Π‖` over the free degrees of
//! freedom, the reactions `‖∇Π‖` over the held ones, and the load scale
//! `max(Σ_i m_i |a|, reactions)` (the body force, or what holds the body if that is larger, as
//! when a drive loads it). Forces of contact and of attachments are not counted.

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

/// The residual of a state whose elastic energy gradient is `grad_elastic`, under the body
/// acceleration `a` acting on the lumped masses; `is_free(i)`: node `i` is free.
pub(crate) fn static_residual(
    grad_elastic: &[Vec3],
    masses_kg: &[f64],
    a: Vec3,
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
    let scale_n = load_scale(body, reactions_n);
    StaticResidual { relative: free_n / scale_n, free_n, reactions_n, scale_n }
}
