//! The two-step backward differentiation formula (Hairer & Wanner, *Solving Ordinary
//! Differential Equations II*, 1996, §V.1): `(3x_{n+1} − 4x_n + x_{n−1})/(2h) = v_{n+1}`,
//! `(3v_{n+1} − 4v_n + v_{n−1})/(2h) = a_{n+1}`, as the incremental potential's `h̄ = 2h/3`,
//! `y = x̂ + (2h/3) v̂ + (2h/3)² g` with `x̂ = (4x_n − x_{n−1})/3`, `v̂ = (4v_n − v_{n−1})/3`, and
//! after the solve `v_{n+1} = (x_{n+1} − x̂)/(2h/3)`. Second order and L-stable: it damps the
//! fastest, unresolved modes almost entirely and the slow ones little. Its first step, with no
//! `x_{n−1}`, is an implicit Euler step (the standard start, and a robust one: a Newmark start
//! from a stretched attachment overshot so far that the next steps inverted elements).

use super::{IntegratorInfo, Prediction, Scheme, SchemeState, Update};

/// BDF2 ([`super::Integrator::Bdf2`]).
pub struct Bdf2;

const INFO: IntegratorInfo = IntegratorInfo {
    name: "bdf2",
    long_name: "BDF2 (backward differentiation)",
    order: 2,
    motion: "Second order, L-stable: damps the fastest, unresolved modes almost entirely and the slow ones little (more with a larger step).",
    source: "Hairer & Wanner, Solving ODEs II (1996), §V.1",
    damps_motion: false,
    needs_converged_steps: false,
    vbd_chebyshev: false,
    vbd_start_from_prediction: true,
};

impl Scheme for Bdf2 {
    fn info(&self) -> &IntegratorInfo {
        &INFO
    }
    fn predict(&self, s: &mut SchemeState, p: Prediction<'_>) -> f64 {
        let h = p.h;
        if s.steps == 0 {
            // the implicit Euler start
            return h;
        }
        let beta = 2.0 * h / 3.0;
        for i in 0..p.positions.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let kick = (p.velocities[i] - s.v_n[i]) / h;
            let x_hat = (p.x_n[i] * 4.0 - s.x_before[i]) / 3.0;
            let v_hat = (s.v_n[i] * 4.0 - s.v_before[i]) / 3.0;
            s.base[i] = x_hat;
            p.positions[i] = x_hat + v_hat * beta + kick * (beta * beta);
        }
        beta
    }
    fn update(&self, s: &mut SchemeState, u: Update<'_>) {
        if s.steps == 0 {
            for i in 0..u.velocities.len() {
                u.velocities[i] = u.euler(i);
            }
        } else {
            for i in 0..u.positions.len() {
                u.velocities[i] =
                    if u.keeps_euler(i) { u.euler(i) } else { (u.positions[i] - s.base[i]) / u.inertia_h };
            }
        }
        s.x_before.clear();
        s.x_before.extend_from_slice(u.x_n);
        std::mem::swap(&mut s.v_before, &mut s.v_n);
    }
}
