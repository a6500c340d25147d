//! What a run is asked to do: substeps, iterations, frame rate, formulation, quadrature degree,
//! serial or parallel sweep, and the stability guard ([`SolverSettings`]).

use super::SimError;
use crate::xpbd::constraint::Formulation;

/// Time stepping and constraint settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    pub substeps: u32,
    pub iterations: u32,
    pub frames_per_second: f64,
    pub formulation: Formulation,
    /// Quadrature degree for the elastic energy; None: each element type's default.
    pub quadrature_degree: Option<usize>,
    /// Project same-colour elements in parallel (rayon's thread pool); otherwise serially in
    /// element order. Both are Gauss–Seidel sweeps, in different orders. On two or more
    /// threads a large block is cut into one slab per thread instead
    /// ([`Simulation::set_partition_threshold`](super::Simulation::set_partition_threshold)); that order depends on the thread count.
    pub parallel: bool,
    /// The stability guard ([`crate::solver::stability`]): when the requested substep has `h ω_max`
    /// above [`crate::solver::stability::guard_trigger_h_omega`] (3; 1.5 for the energy formulation at
    /// ν ≥ 0.45), take enough substeps for
    /// `h ω_max ≤` [`crate::solver::stability::GUARD_H_OMEGA`]. On by default; the paper's scenes are
    /// below the trigger and unaffected.
    pub stability_guard: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            substeps: 50,
            iterations: 1,
            frames_per_second: 60.0,
            formulation: Formulation::Energy,
            quadrature_degree: None,
            parallel: false,
            stability_guard: true,
        }
    }
}

impl SolverSettings {
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |what: String| Err(SimError::Settings(what));
        if self.substeps == 0 {
            return bad("substeps must be at least 1, got 0".into());
        }
        if self.iterations == 0 {
            return bad("iterations must be at least 1, got 0".into());
        }
        if !(self.frames_per_second.is_finite() && self.frames_per_second > 0.0) {
            return bad(format!("frames per second must be a finite positive number, got {}", self.frames_per_second));
        }
        Ok(())
    }
    /// The substep length `h`, seconds.
    /// `1/(fps · substeps)`: the requested substep; the one taken may be shorter
    /// ([`Simulation::substep_dt_secs`](super::Simulation::substep_dt_secs), the stability guard).
    pub fn substep_dt_secs(&self) -> f64 {
        1.0 / (self.frames_per_second * self.substeps as f64)
    }
}
