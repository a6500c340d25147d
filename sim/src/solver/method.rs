//! Which solver moves the free nodes within a step ([`Method`]), and what each one is: one entry
//! per solver in [`INFO`] — its name, long name, whether it solves an implicit step, the effect
//! roles it can honour, the parameters of the table it reads, and how the NaN guard words a
//! failure. Everything that lists or describes solvers (the parameter table, the CLI, the app,
//! recordings, the study and the bench) reads this entry instead of matching on the variant; the
//! one match that names each solver's type is [`super::registry::make`].
//!
//! Every solver takes the same step skeleton ([`super::Simulation::substep`]): effects add
//! accelerations, positions are predicted `y = x_n + h v_n` (gravity's `h g` already in `v_n`,
//! so a free node's `y = x_n + h v_n + h² g`), effects place pinned and driven nodes, then **the
//! solver** moves the free nodes ([`super::step::StepSolver::solve_step`]), velocities follow
//! `v = (x − x_n)/h`, and effects damp them. The solvers differ only in how they move the free
//! nodes:
//! - [`Method::Xpbd`] (the paper's, `xpbd/`): `iterations` Gauss–Seidel sweeps over the element
//!   constraints of extended position-based dynamics, each followed by the effects' own
//!   projections; small steps (Macklin et al. 2019).
//! - [`Method::Vbd`] (`vbd/`): vertex block descent (Chen, Liu, Yang, Yuksel, "Vertex Block
//!   Descent", ACM TOG 43(4), 2024) on the incremental potential of implicit Euler,
//!   `G(x) = Σ_i m_i/(2h²)|x_i − y_i|² + Σ_e U_e(x) + Σ_k Φ_k(x)` ([`super::potential`]).
//! - [`Method::Newton`] (`newton.rs`): the same potential minimised by Newton's method with a
//!   sparse Cholesky factorisation and a line search, to a stated tolerance
//!   ([`super::newton_core`], the one Newton the static solver shares).
//! - [`Method::NewtonCg`] (`newton_cg.rs`): the same Newton with each linear solve by conjugate
//!   gradients on the element Hessians, preconditioned by a Cholesky factor kept across steps (an
//!   inexact Newton).
//!
//! Effects declare how an implicit solver is to honour them ([`ImplicitRole`]); an effect a
//! solver cannot honour refuses the scene by name.
//!
//! **Adding a solver**: its file (a type implementing [`super::step::StepSolver`]), a variant
//! here with its [`INFO`] entry, its line in [`super::registry::make`], and its `mod` line in
//! `solver/mod.rs`.

use crate::effect::ImplicitRole;

/// The solver moving the free nodes within a step; what it is: [`Method::info`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Extended position-based dynamics with small steps (the paper's).
    #[default]
    Xpbd,
    /// Vertex block descent on the implicit step's incremental potential.
    Vbd,
    /// Newton's method on the implicit step's incremental potential (sparse Cholesky).
    Newton,
    /// The same Newton with each linear solve by preconditioned conjugate gradients.
    NewtonCg,
}

/// What a solver is, for everything that lists, describes or checks solvers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodInfo {
    pub method: Method,
    /// The name in scene files, on the command line and in recordings (`xpbd`).
    pub name: &'static str,
    /// The name in menus and tables ("XPBD (the paper's)").
    pub long_name: &'static str,
    /// Whether it solves implicit Euler's incremental potential (one step per frame by default)
    /// rather than taking XPBD's substeps.
    pub implicit: bool,
    /// The effect roles it can honour ([`ImplicitRole`]).
    pub honours: &'static [ImplicitRole],
    /// The keys of the parameter table (`hox_scenes::params`) it reads beyond the common ones.
    pub parameters: &'static [&'static str],
    /// What the NaN guard calls one of its steps ("substep", "step").
    pub step_word: &'static str,
    /// What the NaN guard suggests after a blow-up under it.
    pub remedy: &'static str,
    /// What it does to the motion, in a sentence for the place it is chosen (issue #35: the
    /// implicit solvers looked broken, their beam losing half its swing with nothing said).
    /// The figures are the study's (docs/METHOD.md, docs/STUDY.md: the bending beam, 2 s).
    pub motion: &'static str,
    /// Sweeps over the elements one of its steps (XPBD: substeps) takes, for the app's cost
    /// estimate of a change.
    pub sweeps_per_step: SweepsPerStep,
}

/// How many sweeps over the elements a solver's step takes ([`MethodInfo::sweeps_per_step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SweepsPerStep {
    /// The settings' `iterations` (XPBD's per substep).
    Iterations,
    /// The settings' `vbd.iterations`.
    VbdIterations,
    /// About this many (a Newton-type solver's iterations, each an assembly and a solve).
    About(f64),
}

/// Every solver's entry, in [`Method::ALL`]'s order.
pub const INFO: [MethodInfo; 4] = [
    MethodInfo {
        method: Method::Xpbd,
        name: "xpbd",
        long_name: "XPBD (the paper's)",
        implicit: false,
        honours: &[ImplicitRole::Hooks, ImplicitRole::Projection, ImplicitRole::Potential, ImplicitRole::Unsupported],
        parameters: &["substeps", "iterations", "sweep", "stability_guard"],
        step_word: "substep",
        remedy: "more substeps, a softer material or stable Neo-Hookean",
        motion: "Keeps the motion: its small substeps barely damp the swing (0.1–2.7 % of the amplitude lost by 2 s on P2, P3 and Q2).",
        sweeps_per_step: SweepsPerStep::Iterations,
    },
    MethodInfo {
        method: Method::Vbd,
        name: "vbd",
        long_name: "VBD (vertex block descent)",
        implicit: true,
        honours: &[ImplicitRole::Hooks, ImplicitRole::Projection, ImplicitRole::Potential],
        parameters: &[
            "steps_per_frame",
            "integrator",
            "vbd_iterations",
            "chebyshev_rho",
            "vbd_coarse_cells",
            "vbd_init",
            "vbd_settle_damping_per_sec",
        ],
        step_word: "step",
        remedy: "more steps per frame, a softer material or stable Neo-Hookean",
        motion: "Sweeps the implicit step's potential; the motion is its integrator's (below). Its equilibrium is right: Settle shows it.",
        sweeps_per_step: SweepsPerStep::VbdIterations,
    },
    MethodInfo {
        method: Method::Newton,
        name: "newton",
        long_name: "Newton (implicit step)",
        implicit: true,
        honours: &[ImplicitRole::Hooks, ImplicitRole::Potential],
        parameters: &["steps_per_frame", "integrator", "newton_tolerance", "newton_iterations", "newton_policy"],
        step_word: "step",
        remedy: "more steps per frame, a softer material or stable Neo-Hookean",
        motion: "Solves the implicit step to convergence; the motion is its integrator's (below). Its equilibrium is right: Settle shows it.",
        sweeps_per_step: SweepsPerStep::About(5.0),
    },
    MethodInfo {
        method: Method::NewtonCg,
        name: "newton-cg",
        long_name: "Newton-CG (implicit step, conjugate gradients)",
        implicit: true,
        honours: &[ImplicitRole::Hooks, ImplicitRole::Potential],
        parameters: &["steps_per_frame", "integrator", "newton_tolerance", "newton_iterations"],
        step_word: "step",
        remedy: "more steps per frame, a softer material or stable Neo-Hookean",
        motion: "Solves the implicit step to convergence as Newton does, by conjugate gradients (2–5× Newton's time on the beams); the motion is its integrator's (below).",
        sweeps_per_step: SweepsPerStep::About(20.0),
    },
];

impl Method {
    pub const ALL: [Method; 4] = [Method::Xpbd, Method::Vbd, Method::Newton, Method::NewtonCg];
    /// This solver's entry.
    pub fn info(self) -> &'static MethodInfo {
        &INFO[self as usize]
    }
    pub fn name(self) -> &'static str {
        self.info().name
    }
    pub fn long_name(self) -> &'static str {
        self.info().long_name
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
    /// Whether the method solves implicit Euler's incremental potential (VBD, Newton).
    pub fn is_implicit(self) -> bool {
        self.info().implicit
    }
    /// Whether the method can honour an effect of this role.
    pub fn honours(self, role: ImplicitRole) -> bool {
        self.info().honours.contains(&role)
    }
    /// Whether the method reads the parameter-table entry `key`.
    pub fn reads_parameter(self, key: &str) -> bool {
        self.info().parameters.contains(&key)
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_sits_at_its_variants_index() {
        for (i, m) in Method::ALL.into_iter().enumerate() {
            assert_eq!(INFO[i].method, m);
            assert_eq!(Method::from_name(m.name()), Some(m));
        }
    }

    #[test]
    fn newton_refuses_projections_and_only_xpbd_runs_undeclared_effects() {
        assert!(!Method::Newton.honours(ImplicitRole::Projection));
        assert!(Method::Vbd.honours(ImplicitRole::Projection));
        assert!(Method::Xpbd.honours(ImplicitRole::Unsupported));
        assert!(!Method::Vbd.honours(ImplicitRole::Unsupported));
    }
}
