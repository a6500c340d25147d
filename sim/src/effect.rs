//! Effects: opt-in units a scene lists (gravity, clamps, …). The solver runs only the effects
//! it was given, so a scene without gravity does no gravity work and one without contact never
//! tests for contact.
//!
//! An effect may pin nodes (their inverse mass becomes 0: the solver's constraints never move
//! them) and hooks into the substep at three places:
//! 1. [`Effect::before_prediction`]: external accelerations (`v += h a`);
//! 2. [`Effect::after_prediction`]: positions of pinned or driven nodes at the new time;
//! 3. [`Effect::after_projection`]: constraints of its own after each solver iteration (contact);
//! 4. [`Effect::after_velocity_update`]: velocity changes (damping).

use crate::Vec3;
use crate::mesh::Mesh;

/// The part of the solver state an effect may read and change during a substep.
pub struct EffectState<'a> {
    /// Time at the end of the substep being taken, seconds.
    pub time_secs: f64,
    /// Substep length, seconds.
    pub dt_secs: f64,
    pub rest_positions: &'a [Vec3],
    pub positions: &'a mut [Vec3],
    pub prev_positions: &'a [Vec3],
    pub velocities: &'a mut [Vec3],
    pub inv_mass: &'a [f64],
}

/// An opt-in effect. Every hook defaults to doing nothing.
pub trait Effect: Send + Sync {
    /// A short name for counters, logs and error messages ("gravity", "clamp", …).
    fn name(&self) -> &'static str;
    /// Nodes this effect positions itself (clamped or driven): the solver gives them zero
    /// inverse mass.
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        Vec::new()
    }
    fn before_prediction(&mut self, _state: &mut EffectState<'_>) {}
    fn after_prediction(&mut self, _state: &mut EffectState<'_>) {}
    fn after_projection(&mut self, _state: &mut EffectState<'_>) {}
    fn after_velocity_update(&mut self, _state: &mut EffectState<'_>) {}
    /// Work done so far (for example nodes accelerated or contact tests made), for the tests
    /// that show an effect not called for costs nothing.
    fn work_count(&self) -> u64 {
        0
    }
}

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
    fn before_prediction(&mut self, s: &mut EffectState<'_>) {
        let dv = self.acceleration_m_s2 * s.dt_secs;
        for (v, w) in s.velocities.iter_mut().zip(s.inv_mass) {
            if *w > 0.0 {
                *v += dv;
            }
        }
        self.nodes_accelerated += s.velocities.len() as u64;
    }
    fn work_count(&self) -> u64 {
        self.nodes_accelerated
    }
}

/// Clamps nodes at their rest positions.
#[derive(Clone, Debug, PartialEq)]
pub struct Clamp {
    pub nodes: Vec<u32>,
}

impl Effect for Clamp {
    fn name(&self) -> &'static str {
        "clamp"
    }
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        self.nodes.clone()
    }
    fn after_prediction(&mut self, s: &mut EffectState<'_>) {
        for &n in &self.nodes {
            s.positions[n as usize] = s.rest_positions[n as usize];
            s.velocities[n as usize] = Vec3::zeros();
        }
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
    fn after_velocity_update(&mut self, s: &mut EffectState<'_>) {
        let factor = (-self.rate_per_sec * s.dt_secs).exp();
        for v in s.velocities.iter_mut() {
            *v *= factor;
        }
    }
}
