//! What the solver says of its work: a status line's summary, the Newton policy that ran and
//! why, the last step's residuals.

use super::Simulation;

impl Simulation {
    /// A few words on the solver's work for a status line ("xpbd, 1,200 constraints").
    pub fn work_summary(&self) -> String {
        self.solver.work_summary(&self.settings, &self.counters)
    }

    /// The policy the last Newton-type step ran and why ([`crate::solver::NewtonPolicy`]; None for
    /// XPBD, VBD and before the first step).
    pub fn newton_policy(&self) -> Option<&crate::solver::settings::NewtonPolicyReport> {
        self.solver.newton_policy()
    }

    /// The relative residual of each Newton iteration of the last step (empty for the others).
    #[doc(hidden)]
    pub fn last_step_residuals(&self) -> &[f64] {
        self.solver.last_step_residuals()
    }
}
