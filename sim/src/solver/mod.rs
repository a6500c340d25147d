//! The simulation and its solvers. A frame is stepped as in XPBD with small steps (Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke &
//! Müller 2019, "Small steps in physics simulation"): a frame of `1/fps` seconds is `n`
//! substeps of `h = 1/(fps · n)`; each substep
//! 1. applies the effects' accelerations, `v ← v + h a`;
//! 2. predicts `x ← x + h v` (keeping `x_prev`), then lets effects place pinned/driven nodes;
//! 3. resets every multiplier `λ ← 0` and runs `k` Gauss–Seidel iterations over the element
//!    constraints ([`crate::xpbd::constraint`]), each followed by the effects' own projections;
//! 4. updates velocities `v ← (x − x_prev)/h`, then lets effects damp them.
//!
//! Defaults are the paper's: 50 substeps × 1 iteration, 60 frames per second. The solver
//! gathers each element's nodes, calls a pure kernel, and scatters the corrections back.
//!
//! Where things are, in the order each file reads only the ones before it (`tests/tests/rooms.rs`
//! keeps it): `method.rs` (which solvers there are and what each is, [`Method`]) and
//! `integrator.rs` (the implicit solvers' time integrators, [`Integrator`]: registered
//! [`Scheme`]s, one file each in `integrator/`); `error.rs` ([`SimError`], [`SolverCounters`]);
//! `settings.rs` (what a run is asked to do, [`SolverSettings`], each numeric setting's range
//! declared once in [`SolverSettings::RANGES`]); `nan_guard.rs` (naming the element of a blow-up); `step.rs` (what a
//! solver's step reads and the one trait every solver implements); `residual.rs` (the static
//! residual); `sparse.rs` (the sparse stiffness and its Cholesky factor); [`stability`] (the
//! substep guard); `potential.rs` (implicit Euler's incremental potential); `newton_core.rs`
//! (the one Newton's method with line search); the solvers `xpbd/`, `vbd/`, `newton.rs`,
//! `newton_cg.rs`;
//! [`statics`] (the static equilibrium XPBD settles to, by the same Newton); `registry.rs` (the
//! one match naming each solver's type); `simulation.rs` (the stateful [`Simulation`]: the step
//! skeleton below, the NaN and stability guards).
//!
//! **NaN guard.** A kernel whose corrections come out non-finite is not scattered: the substep
//! stops there with [`SimError::NonFinite`] naming that element (block and index), its bad node,
//! the frame, the substep within the frame and the time. After every substep all positions and
//! velocities are checked as well (an effect, or a caller writing `positions`, can also bring a
//! NaN or an infinity in), naming an element that holds the first bad node. On either failure the
//! positions go back to the last finite state (the start of the failing substep, or the rest shape
//! if that was not finite either), velocities to zero, and the simulation refuses to step until
//! [`Simulation::reset`] (or [`Simulation::warm_start`]): a viewer keeps showing the last sound
//! state instead of painting garbage, and offers a reset. See `docs/STABILITY.md`.

mod method;

mod integrator;

mod error;

mod settings;

mod nan_guard;

mod step;

mod residual;

mod sparse;

pub mod stability;

mod potential;

mod newton_core;

mod xpbd;

mod vbd;

mod newton;

mod newton_cg;

pub mod statics;

mod registry;

mod node_loops;

mod simulation;

pub use error::{SimError, SolverCounters};
pub use integrator::{Integrator, IntegratorInfo, Prediction, Scheme, SchemeState, Update};
pub use method::{INFO as METHODS, Method, MethodInfo, SweepsPerStep};
pub use node_loops::NODE_LOOP_MIN_NODES_PER_THREAD;
pub use residual::StaticResidual;
pub use settings::{
    NewtonPolicy, NewtonSettings, Range, RangeValue, Setting, SolverSettings, Sweep, VbdInit, VbdSettings,
};
pub use simulation::Simulation;

#[cfg(test)]
mod implicit_tests;
#[cfg(test)]
mod integrator_tests;
#[cfg(test)]
mod mixed_tests;
#[cfg(test)]
mod tests;
