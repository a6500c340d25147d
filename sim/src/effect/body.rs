//! Body loads and losses: uniform [`Gravity`] (`v += h g`) and velocity [`Damping`]
//! (`v ← v e^{−c h}`).

use super::{Effect, EffectState};
use crate::Vec3;

/// Uniform gravity: `v += h g` for every free node.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    pub acceleration_m_s2: Vec3,
    nodes_accelerated: u64,
}

impl Gravity {
    pub fn new(acceleration_m_s2: Vec3) -> Self {
        Self { acceleration_m_s2, nodes_accelerated: 0 }
    }
}

impl Effect for Gravity {
    fn name(&self) -> &'static str {
        "gravity"
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Hooks
    }
    fn body_acceleration_m_s2(&self) -> Vec3 {
        self.acceleration_m_s2
    }
    fn does_no_work(&self) -> bool {
        true
    }
    fn before_prediction(&mut self, s: &mut EffectState<'_>) {
        let dv = self.acceleration_m_s2 * s.dt_secs;
        let chunks = crate::math::par::chunks(s.velocities.len());
        crate::math::par::zip_chunks(s.velocities, s.inv_mass, chunks, |v, w| {
            for (v, w) in v.iter_mut().zip(w) {
                if *w > 0.0 {
                    *v += dv;
                }
            }
        });
        self.nodes_accelerated += s.velocities.len() as u64;
    }
    fn work_count(&self) -> u64 {
        self.nodes_accelerated
    }
}

/// Velocity damping `v ← v e^{−c h}` with rate `c` (1/s): motion decays as `e^{−c t}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Damping {
    pub rate_per_sec: f64,
}

impl Effect for Damping {
    fn name(&self) -> &'static str {
        "damping"
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Hooks
    }
    fn does_no_work(&self) -> bool {
        true
    }
    fn after_velocity_update(&mut self, s: &mut EffectState<'_>) {
        let factor = (-self.rate_per_sec * s.dt_secs).exp();
        for v in s.velocities.iter_mut() {
            *v *= factor;
        }
    }
}
