//! Effects: opt-in units a scene lists (gravity, clamps, …). The solver runs only the effects
//! it was given, so a scene without gravity does no gravity work and one without contact never
//! tests for contact.
//!
//! An effect may pin nodes (their inverse mass becomes 0: the solver's constraints never move
//! them) and hooks into the substep at four places:
//! 1. [`Effect::before_prediction`]: external accelerations (`v += h a`);
//! 2. [`Effect::after_prediction`]: positions of pinned or driven nodes at the new time;
//! 3. [`Effect::after_projection`]: constraints of its own after each solver iteration (contact);
//! 4. [`Effect::after_velocity_update`]: velocity changes (damping).
//!
//! The implicit solvers (VBD, Newton) run the same hooks but do not project XPBD constraints:
//! each effect declares its [`ImplicitRole`] (hooks only, a projection, or a potential), and an
//! effect without one is refused by them by name, so nothing is silently ignored.
//!
//! Files: `body.rs` body loads and losses ([`Gravity`], [`Damping`]); `drive.rs` nodes held or
//! moved by prescription ([`Clamp`], [`Prescribed`] with [`smooth_ramp`] and [`AxisRotation`]);
//! `contact.rs` a moving plane with friction ([`ContactPlane`]); `attachment.rs` a node pulled
//! by a compliant XPBD constraint ([`Attachment`], the app's drag).

mod attachment;
mod body;
mod contact;
mod drive;

pub use attachment::{Attachment, MIN_SPRING_COMPLIANCE_M_PER_N};
pub use body::{Damping, Gravity};
pub use contact::ContactPlane;
pub use drive::{AxisRotation, Clamp, Prescribed, smooth_ramp};

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

/// How an implicit solver (VBD, Newton: [`crate::solver::Method`]) honours an effect; XPBD runs
/// every hook whatever the role.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImplicitRole {
    /// Through the step's hooks alone: accelerations before the prediction, pinned or driven
    /// positions after it, velocity changes after the update (gravity, clamps, drives, damping).
    Hooks,
    /// A projection of its own after every solver iteration (contact): VBD runs it after each
    /// sweep; Newton cannot honour it.
    Projection,
    /// A potential added to the step's incremental potential ([`Effect::spring`]).
    Potential,
    /// Not declared: the implicit solvers refuse the scene, naming the effect.
    Unsupported,
}

/// A zero-length spring pulling one node to a target: the potential `Φ = k |x − t|² / 2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeSpring {
    pub node: u32,
    pub target_m: Vec3,
    pub stiffness_n_per_m: f64,
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
    /// How the implicit solvers honour this effect; an effect that does not say is refused by them.
    fn implicit_role(&self) -> ImplicitRole {
        ImplicitRole::Unsupported
    }
    /// The acceleration every free node feels from this effect, m/s² (gravity): the load the
    /// static residual measures.
    fn body_acceleration_m_s2(&self) -> Vec3 {
        Vec3::zeros()
    }
    /// Whether the effect does no work the simulation's energy does not count: gravity (a
    /// potential the energy holds), clamps (held nodes do not move) and damping (takes energy
    /// out). The step watch checks that the energy does not grow only when every effect says so.
    fn does_no_work(&self) -> bool {
        false
    }
    /// The spring this effect is, for the implicit solvers ([`ImplicitRole::Potential`]).
    fn spring(&self) -> Option<NodeSpring> {
        None
    }
    /// How far this effect may carry a node in the step from `time_secs` to `time_secs + dt_secs`,
    /// m: a drive, the path of its nodes; a drag, its node's distance to the target; a moving
    /// plate, its travel. The step watch lets a free node move that much beyond the body's size
    /// (a fast drag across the body is not a blow-up).
    fn reach_m(&self, _positions: &[Vec3], _rest_positions: &[Vec3], _time_secs: f64, _dt_secs: f64) -> f64 {
        0.0
    }
}

/// An [`EffectState`] over the given slices, `dt_secs` = 0.01, for the effects' tests.
#[cfg(test)]
pub(crate) fn test_state<'a>(
    t: f64,
    rest: &'a [Vec3],
    x: &'a mut [Vec3],
    prev: &'a [Vec3],
    v: &'a mut [Vec3],
    w: &'a [f64],
) -> EffectState<'a> {
    EffectState {
        time_secs: t,
        dt_secs: 0.01,
        rest_positions: rest,
        positions: x,
        prev_positions: prev,
        velocities: v,
        inv_mass: w,
    }
}
