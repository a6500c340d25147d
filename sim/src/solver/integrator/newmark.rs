//! Newmark's average acceleration (β = 1/4, γ = 1/2; Newmark 1959, "A method of computation for
//! structural dynamics"): `h̄ = h/2`, `y = ỹ + (h²/4) g` with `ỹ = x_n + h v_n + (h²/4) a_n`, and
//! after the solve `a_{n+1} = 4(x_{n+1} − ỹ)/h²`, `v_{n+1} = v_n + (h/2)(a_n + a_{n+1})`. The
//! trapezoidal rule: second order, no numerical damping (Hughes, *The Finite Element Method*,
//! 2000, §9.1). Its start needs `a_0 = g − ∇U(x_0)/m`; its guess of `x_{n+1}` keeps the last
//! acceleration, `ỹ + (h²/4) a_n`, so a body at rest in equilibrium stays where it is.

use super::{IntegratorInfo, Prediction, Scheme, SchemeState, Update};
use crate::Vec3;

/// Newmark's average acceleration ([`super::Integrator::Newmark`]).
pub struct Newmark;

const INFO: IntegratorInfo = IntegratorInfo {
    name: "newmark",
    long_name: "Newmark (average acceleration)",
    order: 2,
    motion: "Second order, no numerical damping: conserves the energy of a linear system exactly and keeps a swinging beam's amplitude.",
    source: "Newmark 1959; Hughes, The Finite Element Method (2000), §9.1",
    damps_motion: false,
    needs_converged_steps: true,
    vbd_chebyshev: true,
    vbd_start_from_prediction: true,
};

impl Scheme for Newmark {
    fn info(&self) -> &IntegratorInfo {
        &INFO
    }
    fn needs_start_acceleration(&self) -> bool {
        true
    }
    fn offers_guess(&self) -> bool {
        true
    }
    fn predict(&self, s: &mut SchemeState, p: Prediction<'_>) -> f64 {
        let (h, n) = (p.h, p.positions.len());
        let kick = |v_n: &[Vec3], i: usize| (p.velocities[i] - v_n[i]) / h;
        if let Some(grad) = p.start_gradient {
            s.a_n = (0..n)
                .map(|i| if p.inv_mass[i] > 0.0 { kick(&s.v_n, i) - grad[i] * p.inv_mass[i] } else { Vec3::zeros() })
                .collect();
        }
        let q = 0.25 * h * h;
        for i in 0..n {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let tilde = p.x_n[i] + s.v_n[i] * h + s.a_n[i] * q;
            s.base[i] = tilde;
            p.positions[i] = tilde + kick(&s.v_n, i) * q;
            // the acceleration goes on as it was
            s.guess[i] = tilde + s.a_n[i] * q;
        }
        0.5 * h
    }
    fn update(&self, s: &mut SchemeState, u: Update<'_>) {
        let h = u.h;
        let four_over_h2 = 4.0 / (h * h);
        for i in 0..u.positions.len() {
            if u.keeps_euler(i) {
                u.velocities[i] = u.euler(i);
                s.a_n[i] = Vec3::zeros();
                continue;
            }
            let a = (u.positions[i] - s.base[i]) * four_over_h2;
            u.velocities[i] = s.v_n[i] + (s.a_n[i] + a) * (0.5 * h);
            s.a_n[i] = a;
        }
    }
}
