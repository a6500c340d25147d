//! What can stop a simulation ([`SimError`]) and the counters of the work it did
//! ([`SolverCounters`]).

use super::method::Method;
use crate::fem::geometry::GeometryError;
use crate::mesh::MeshError;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    #[error("invalid solver settings: {0}")]
    Settings(String),
    #[error("the {solver} solver cannot honour the effect '{effect}' (supported by: {supported_by})")]
    Unsupported { solver: &'static str, effect: &'static str, supported_by: String },
    #[error("effect '{effect}' refers to node {node}, but the mesh has {num_nodes} nodes")]
    EffectNode { effect: &'static str, node: u32, num_nodes: usize },
    #[error("node {node}: {reason}")]
    Mass { node: usize, reason: String },
    #[error(
        "the {solver} simulation blew up at frame {frame}, {} {substep_in_frame} of {substeps_per_frame} (t = {time_secs:.6} s): {origin} element {element} of block {block} ({element_type}), at its node {node}; the last finite state is kept — reset, or use {}",
        step_word(solver),
        remedy(solver)
    )]
    NonFinite {
        /// The solver that was running ("xpbd", "vbd", "newton").
        solver: &'static str,
        /// Element block and index within it.
        block: usize,
        element: usize,
        element_type: String,
        /// A non-finite node of that element (global index).
        node: usize,
        /// What went wrong: "the projection of" (the kernel's output) or "a non-finite position
        /// or velocity in" (found after the substep).
        origin: &'static str,
        /// The frame being advanced, counted from 1.
        frame: u64,
        /// The substep within that frame, counted from 1, and the substeps per frame.
        substep_in_frame: u32,
        substeps_per_frame: u32,
        /// Substeps taken since the start (or the last reset), the failing one included.
        substep: u64,
        time_secs: f64,
    },
    #[error(
        "the {solver} simulation diverged at frame {frame} (t = {time_secs:.6} s): in one {span} node {node} moved {moved_m:.3e} m against the body's mean motion, more than the body's size and what its effects carry ({size_m:.3e} m), and {} halvings of the {} (down to {h_secs:.3e} s) did not help; the last sound state is kept — reset, or use {}",
        halvings,
        step_word(solver),
        remedy(solver)
    )]
    Diverged {
        solver: &'static str,
        /// The node that moved most against the body's mean motion (global index).
        node: usize,
        moved_m: f64,
        /// The bound: the body's size plus the effects' reach ([`crate::effect::Effect::reach_m`]).
        size_m: f64,
        /// What was watched: a "step" of an implicit solver, a "frame" of XPBD's substeps.
        span: &'static str,
        frame: u64,
        time_secs: f64,
        /// How many times the step was halved, and the shortest step tried.
        halvings: u32,
        h_secs: f64,
    },
    #[error(
        "the {solver} simulation could not take its step at frame {frame} (t = {time_secs:.6} s): {why}, and {halvings} halvings of the step (down to {h_secs:.3e} s) did not help; the last sound state is kept — reset, or use {}",
        remedy(solver)
    )]
    Unsolved {
        solver: &'static str,
        frame: u64,
        time_secs: f64,
        /// What the step watch found: the unbalanced force left, or the energy gained.
        why: String,
        halvings: u32,
        h_secs: f64,
    },
}

/// Counters of the work done, for tests and the status line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolverCounters {
    pub substeps: u64,
    pub element_projections: u64,
    pub effect_hook_calls: u64,
    /// VBD sweeps or Newton iterations.
    pub solver_iterations: u64,
    /// VBD's node block updates.
    pub node_updates: u64,
    /// VBD's coarse-grid corrections that moved the nodes ([`vbd_coarse`]).
    pub coarse_corrections: u64,
    /// Newton's numeric factorisations of the stiffness.
    pub factorizations: u64,
    /// Iterations of an iterative linear solver inside a Newton-type solver (conjugate-gradient
    /// iterations; 0 under a direct one: `newton_core::LinearSolver`).
    pub linear_iterations: u64,
    /// Newton steps that reached their iteration limit before the tolerance (VBD's under Newmark
    /// that reached its most rounds of sweeps).
    pub unconverged_steps: u64,
    /// Steps the step watch rejected and took again in halves ([`super::Simulation`]).
    pub rejected_steps: u64,
}

/// What the NaN guard calls a step of `solver` ("substep" for XPBD, "step" for the implicit ones).
fn step_word(solver: &str) -> &'static str {
    Method::from_name(solver).map_or("step", |m| m.info().step_word)
}

/// What the NaN guard suggests after a blow-up under `solver`.
fn remedy(solver: &str) -> &'static str {
    Method::from_name(solver).map_or("a softer material", |m| m.info().remedy)
}
