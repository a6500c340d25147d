//! Implicit (backward) Euler: `h̄ = h`, `y = x_n + h v_n + h² g`, and after the solve
//! `v_{n+1} = (x_{n+1} − x_n)/h`. First order; it damps every mode by a factor
//! `1/√(1 + (h ω)²)` per step (Hairer & Wanner, *Solving Ordinary Differential Equations II*,
//! 1996, §IV.3). It keeps no history: the simulation's node loops make its prediction and
//! update, the defaults of [`Scheme`].

use super::{IntegratorInfo, Scheme};

/// Implicit Euler ([`super::Integrator::Euler`]).
pub struct Euler;

const INFO: IntegratorInfo = IntegratorInfo {
    name: "euler",
    long_name: "implicit Euler",
    order: 1,
    motion: "First order; damps every mode, the more the larger h·ω: at one step per frame a swinging beam loses about half its amplitude in 2 s.",
    source: "Hairer & Wanner, Solving ODEs II (1996), §IV.3",
    damps_motion: true,
    needs_converged_steps: false,
    vbd_chebyshev: true,
    vbd_start_from_prediction: false,
};

impl Scheme for Euler {
    fn info(&self) -> &IntegratorInfo {
        &INFO
    }
    fn keeps_history(&self) -> bool {
        false
    }
}
