//! What a run is asked to do: the solver ([`Method`]), substeps, iterations, frame rate,
//! formulation, quadrature degree, the sweep's order ([`Sweep`]), the stability guard, and the
//! implicit solvers' integrator ([`Integrator`]) and own settings ([`VbdSettings`],
//! [`NewtonSettings`]) ([`SolverSettings`]).

use super::error::SimError;
use super::integrator::Integrator;
use super::method::Method;
use crate::material::Material;
use crate::xpbd::constraint::Formulation;

/// Time stepping and constraint settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// The solver moving the free nodes within a step (XPBD by default, the paper's).
    pub method: Method,
    /// XPBD's substeps per frame (`substeps`, raised by the stability guard) and iterations.
    pub substeps: u32,
    pub iterations: u32,
    pub frames_per_second: f64,
    pub formulation: Formulation,
    /// Quadrature degree for the elastic energy; None: each element type's default.
    pub quadrature_degree: Option<usize>,
    /// The order of XPBD's Gauss–Seidel sweep ([`Sweep`]): colour by colour (the default) or
    /// element by element.
    pub sweep: Sweep,
    /// The stability guard ([`crate::solver::stability`]): when the requested substep has `h ω_max`
    /// above [`crate::solver::stability::guard_trigger_h_omega`] (3; 1.5 for the energy formulation at
    /// ν ≥ 0.45), take enough substeps for
    /// `h ω_max ≤` [`crate::solver::stability::GUARD_H_OMEGA`]. On by default; the paper's scenes are
    /// below the trigger and unaffected.
    pub stability_guard: bool,
    /// The implicit solvers' (VBD, Newton) steps per frame; XPBD takes `substeps`.
    pub steps_per_frame: u32,
    /// The implicit solvers' time integrator (BDF2 by default: it keeps the motion and damps
    /// what a step cannot resolve); XPBD ignores it.
    pub integrator: Integrator,
    pub vbd: VbdSettings,
    pub newton: NewtonSettings,
}

/// The order in which XPBD's Gauss–Seidel sweep projects the element constraints. Both are
/// Gauss–Seidel sweeps over the same constraints; they differ in order, so their results differ
/// by what the order changes (well below the solver's own bias), never by the thread count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Sweep {
    /// Colour by colour (no two elements of a colour share a node), four same-colour elements per
    /// AVX2 register, each colour cut between rayon's threads; a large block is first cut into
    /// slabs swept side by side, their count set by the block's size alone
    /// ([`crate::xpbd::kernels::slab_count`]). The default: the fastest on one thread and on
    /// many, and the same bits on any thread count.
    #[default]
    Colour,
    /// Element after element in mesh order, on one thread: the order the paper's figures and the
    /// results published before the colour sweep became the default (issue #22) used.
    Element,
}

impl Sweep {
    pub const ALL: [Sweep; 2] = [Sweep::Colour, Sweep::Element];
    pub fn name(self) -> &'static str {
        match self {
            Sweep::Colour => "colour",
            Sweep::Element => "element",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
    /// Whether the sweep goes colour by colour (and may use every thread).
    pub fn is_colour(self) -> bool {
        self == Sweep::Colour
    }
}

/// Vertex block descent's settings ([`crate::solver::Method::Vbd`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VbdSettings {
    /// Gauss–Seidel sweeps over the node colours per step.
    pub iterations: u32,
    /// Chebyshev semi-iterative acceleration's spectral radius estimate `ρ` (0: off). Default
    /// 0.9 with 10 sweeps: on the bending P2 beam it settles in half the sweeps of `ρ = 0`
    /// (572 frames against 1,198), while 0.95 at 5 sweeps diverged (docs/PERFORMANCE.md).
    pub chebyshev_rho: f64,
    /// Where a step's iterations start.
    pub init: VbdInit,
    /// About how many cells the two-level correction's coarse grid has (0: off, the paper's VBD
    /// alone; at most [`VbdSettings::MAX_COARSE_CELLS`]; [`crate::solver`]'s `vbd_coarse`).
    pub coarse_cells: u32,
    /// Under an integrator that damps nothing (Newmark), a step sweeps on, `iterations` at a
    /// time, until its residual is at most this fraction of the load (as Newton measures it).
    pub tolerance: f64,
}

impl VbdSettings {
    /// The coarse grid's largest cell count: its dense matrix of `3 × nodes` rows stays small.
    pub const MAX_COARSE_CELLS: u32 = 256;
    /// The Chebyshev `ρ` lies in `[0, CHEBYSHEV_RHO_BELOW)`: at 1 the acceleration diverges.
    pub const CHEBYSHEV_RHO_BELOW: f64 = 1.0;
}

/// [`VbdSettings::tolerance`]'s default, the settle check's residual: on the bending beam under
/// Newmark 1e-2 already keeps the steps stable (10 sweeps alone blew up within a second) and 1e-3
/// matches Newton's energies to 2e-4 after 15 s, but a run to rest then stops at a residual near
/// the tolerance (4.6e-4 at 1e-3, 5.3e-5 at 1e-4): Newmark keeps what a step leaves. At 1e-5 it
/// settles in 123 frames, as Newton, at about 5× the cost per frame of BDF2's fixed sweeps.
const VBD_TOLERANCE: f64 = 1e-5;

/// Where vertex block descent starts a step (Chen et al. 2024, §3.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum VbdInit {
    /// `x⁰ = x_n + h v_n + h² ã`, the acceleration `ã` the body had along gravity, clamped to
    /// `[0, |g|]` (the paper's adaptive initialisation): a body at rest starts at rest.
    #[default]
    Adaptive,
    /// `x⁰ = y`, the inertial prediction.
    Inertia,
    /// `x⁰ = x_n`.
    Previous,
}

impl VbdInit {
    pub const ALL: [VbdInit; 3] = [VbdInit::Adaptive, VbdInit::Inertia, VbdInit::Previous];
    pub fn name(self) -> &'static str {
        match self {
            VbdInit::Adaptive => "adaptive",
            VbdInit::Inertia => "inertia",
            VbdInit::Previous => "previous",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
}

impl Default for VbdSettings {
    fn default() -> Self {
        Self { iterations: 10, chebyshev_rho: 0.9, init: VbdInit::Adaptive, coarse_cells: 32, tolerance: VBD_TOLERANCE }
    }
}

/// Newton's settings ([`crate::solver::Method::Newton`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// A step has converged when the free residual of its incremental potential is at most this
    /// times the load (the body force, or the reactions if larger): the measure `hox static` uses.
    pub tolerance: f64,
    /// The most Newton iterations a step takes; a step that reaches it keeps its last iterate and
    /// is counted as unconverged.
    pub max_iterations: u32,
    /// Refactor the stiffness at every iteration (pure Newton) instead of reusing the last
    /// factorisation while it keeps converging fast.
    pub refactor_every_iteration: bool,
    /// How the factor is kept between iterations and steps ([`NewtonPolicy`]): by default
    /// chosen by the problem.
    pub policy: NewtonPolicy,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self { tolerance: 1e-6, max_iterations: 30, refactor_every_iteration: false, policy: NewtonPolicy::Auto }
    }
}

/// How Newton keeps its factor (`newton_core.rs`; issue #61: the interactive mode made the
/// default where it pays).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum NewtonPolicy {
    /// Chosen by the problem (`newton.rs`): interactive for a time step whose factorisation costs
    /// at least [`NewtonPolicy::INTERACTIVE_FROM_ITERATIONS`] iterations with the kept factor (a
    /// large part: the P2 tube's costs 17), careful for a smaller one (refreshing is cheap there)
    /// and for a static solve; and careful from the first step the step watch rejects on, for the
    /// rest of the run. Which ran and why is reported ([`crate::solver::Simulation::newton_policy`]).
    #[default]
    Auto,
    /// The interactive mode (issue #37): the factor kept across steps in single precision,
    /// corrected by secant pairs (L-BFGS) and refreshed when keeping it costs more than a
    /// factorisation.
    Interactive,
    /// The factor refreshed whenever the residual falls less than 4× in an iteration, in double
    /// precision.
    Careful,
}

/// The policy a Newton step ran ([`NewtonPolicy::Interactive`] or [`NewtonPolicy::Careful`]) and
/// why, in words (`hox simulate --json`'s `newton_policy` and `newton_policy_why`).
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonPolicyReport {
    pub ran: NewtonPolicy,
    pub why: String,
}

impl NewtonPolicy {
    pub const ALL: [NewtonPolicy; 3] = [NewtonPolicy::Auto, NewtonPolicy::Interactive, NewtonPolicy::Careful];
    /// Auto's threshold: the refresh cost, in iterations with the kept factor, from which a time
    /// step is solved interactively. The P2 8×2×2 beam's costs 4 (careful, as the robustness
    /// suite's small meshes); the P3 8×2×2 beam's 9, P1 refined twice 15, the P2 hook's 14, the
    /// P2 tube's 18 (interactive).
    pub const INTERACTIVE_FROM_ITERATIONS: f64 = 6.0;
    pub fn name(self) -> &'static str {
        match self {
            NewtonPolicy::Auto => "auto",
            NewtonPolicy::Interactive => "interactive",
            NewtonPolicy::Careful => "careful",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            substeps: 50,
            iterations: 1,
            frames_per_second: 60.0,
            formulation: Formulation::Energy,
            quadrature_degree: None,
            sweep: Sweep::Colour,
            stability_guard: true,
            method: Method::Xpbd,
            steps_per_frame: 1,
            integrator: Integrator::default(),
            vbd: VbdSettings::default(),
            newton: NewtonSettings::default(),
        }
    }
}

impl SolverSettings {
    /// The substeps per frame of XPBD.
    pub const SUBSTEPS: Setting = Setting::whole("substeps", "Substeps", 1, 1_000_000, 500);
    /// XPBD's constraint sweeps per substep.
    pub const ITERATIONS: Setting = Setting::whole("iterations", "Iterations", 1, 1_000_000, 20);
    /// Simulated frames per second, > 0 (the slider: 10 to 240).
    pub const FRAMES_PER_SECOND: Setting =
        Setting::number("fps", "Frames per second", (0.0, false), (f64::INFINITY, false), Some((10.0, 240.0)));
    /// The implicit solvers' steps per frame.
    pub const STEPS_PER_FRAME: Setting = Setting::whole("steps", "Steps per frame", 1, 10_000, 20);
    /// VBD's sweeps per step.
    pub const VBD_ITERATIONS: Setting = Setting::whole("vbd-iterations", "VBD iterations", 1, 100_000, 200);
    /// VBD's coarse cells (0: off).
    pub const VBD_COARSE_CELLS: Setting =
        Setting::whole("vbd-coarse-cells", "VBD coarse cells", 0, VbdSettings::MAX_COARSE_CELLS as u64, 128);
    /// The Chebyshev `ρ` of VBD's sweeps, in `[0, 1)`.
    pub const CHEBYSHEV_RHO: Setting =
        Setting::number("chebyshev-rho", "Chebyshev ρ", (0.0, true), (VbdSettings::CHEBYSHEV_RHO_BELOW, false), None);
    /// Newton's tolerance per step, relative to the load, in `(0, 1)`.
    pub const NEWTON_TOLERANCE: Setting =
        Setting::number("newton-tolerance", "Newton tolerance", (0.0, false), (1.0, false), None);
    /// Newton's iterations per step at most.
    pub const NEWTON_ITERATIONS: Setting = Setting::whole("newton-iterations", "Newton iterations", 1, 1000, 50);
    /// **Every numeric setting's declaration**, checked by [`SolverSettings::validate`] and
    /// read by the parameter table (`hox_scenes::params`: its kinds and labels), so a range's
    /// bound and its message are written here once.
    pub const RANGES: [Setting; 9] = [
        Self::SUBSTEPS,
        Self::ITERATIONS,
        Self::FRAMES_PER_SECOND,
        Self::STEPS_PER_FRAME,
        Self::VBD_ITERATIONS,
        Self::VBD_COARSE_CELLS,
        Self::CHEBYSHEV_RHO,
        Self::NEWTON_TOLERANCE,
        Self::NEWTON_ITERATIONS,
    ];

    /// These settings' value of each of [`SolverSettings::RANGES`], in its order.
    pub fn range_values(&self) -> [RangeValue; 9] {
        use RangeValue::{Number, Whole};
        [
            Whole(self.substeps.into()),
            Whole(self.iterations.into()),
            Number(self.frames_per_second),
            Whole(self.steps_per_frame.into()),
            Whole(self.vbd.iterations.into()),
            Whole(self.vbd.coarse_cells.into()),
            Number(self.vbd.chebyshev_rho),
            Number(self.newton.tolerance),
            Whole(self.newton.max_iterations.into()),
        ]
    }

    /// Checks every numeric setting against its declaration ([`SolverSettings::RANGES`]),
    /// naming the first out of range, its range and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        for (setting, value) in Self::RANGES.iter().zip(self.range_values()) {
            setting.check(value)?;
        }
        Ok(())
    }
    /// The material as these settings run it on `mesh`: its hydrostatic term measured where the
    /// formulation says ([`Formulation::volume_measure`]). Refuses what they cannot run: XPBD's
    /// split formulation with a model that offers no split constraints
    /// ([`crate::material::HyperelasticModel::split`], an optional capability; every registered
    /// model has them); the mixed formulation with a model whose split it cannot measure per
    /// element ([`Material::with_volume_measure`]) or on an element type with no stable constant
    /// pressure ([`crate::fem::energy::mixed::refusal`]), named.
    pub fn formulated(&self, material: &Material, mesh: &crate::mesh::Mesh) -> Result<Material, SimError> {
        if !self.method.is_implicit() && self.formulation == Formulation::Split && !material.has_split() {
            return Err(SimError::Settings(format!(
                "the split formulation needs the material's split constraints, which {} does not offer (the energy formulation needs none)",
                material.model.long_name()
            )));
        }
        let refusal = |b: &crate::mesh::ElementBlock| crate::fem::energy::mixed::refusal(b.element_type);
        if let Some(why) = mesh.blocks.iter().find_map(refusal).filter(|_| self.formulation == Formulation::Mixed) {
            return Err(SimError::Settings(why));
        }
        material.with_volume_measure(self.formulation.volume_measure()).map_err(|e| SimError::Settings(e.to_string()))
    }

    /// The substep length `h`, seconds.
    /// `1/(fps · substeps)`: the requested substep; the one taken may be shorter
    /// ([`Simulation::substep_dt_secs`](super::Simulation::substep_dt_secs), the stability guard).
    pub fn substep_dt_secs(&self) -> f64 {
        1.0 / (self.frames_per_second * self.substeps as f64)
    }
}

/// A numeric setting's valid range ([`SolverSettings::RANGES`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// A whole number in `min..=max`; `soft_max` bounds a slider only.
    Whole { min: u64, max: u64, soft_max: u64 },
    /// A finite number between `min` and `max` (each end inclusive or not); `soft` bounds a
    /// slider only (None: a text field).
    Number { min: f64, min_inclusive: bool, max: f64, max_inclusive: bool, soft: Option<(f64, f64)> },
}

/// A value to check against a [`Range`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RangeValue {
    Whole(u64),
    Number(f64),
}

impl Range {
    /// Whether `v` lies in the range (a whole number in a whole range, a finite number in a
    /// number range).
    pub fn contains(&self, v: RangeValue) -> bool {
        match (*self, v) {
            (Range::Whole { min, max, .. }, RangeValue::Whole(n)) => (min..=max).contains(&n),
            (Range::Number { min, min_inclusive, max, max_inclusive, .. }, RangeValue::Number(x)) => {
                x.is_finite()
                    && (if min_inclusive { x >= min } else { x > min })
                    && (if max_inclusive { x <= max } else { x < max })
            }
            _ => false,
        }
    }

    /// What a value in the range looks like, for messages: "a whole number from 1 to 1000",
    /// "a finite number ≥ 0 and < 1".
    pub fn expected(&self) -> String {
        match *self {
            Range::Whole { min, max, .. } => format!("a whole number from {min} to {max}"),
            Range::Number { min, min_inclusive, max, max_inclusive, .. } => {
                let lo = if min == f64::NEG_INFINITY {
                    String::new()
                } else {
                    format!("{} {min}", if min_inclusive { "≥" } else { ">" })
                };
                let hi = if max == f64::INFINITY {
                    String::new()
                } else {
                    format!("{} {max}", if max_inclusive { "≤" } else { "<" })
                };
                let range = [lo, hi].into_iter().filter(|s| !s.is_empty()).collect::<Vec<_>>().join(" and ");
                if range.is_empty() { "a finite number".into() } else { format!("a finite number {range}") }
            }
        }
    }
}

/// One numeric solver setting's declaration: its key in the parameter table (the command
/// line's `--KEY`), its label in messages and menus, and its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    pub key: &'static str,
    pub label: &'static str,
    pub range: Range,
}

impl Setting {
    /// A whole-number setting in `min..=max` (`soft_max`: the slider's top).
    pub const fn whole(key: &'static str, label: &'static str, min: u64, max: u64, soft_max: u64) -> Setting {
        Setting { key, label, range: Range::Whole { min, max, soft_max } }
    }

    /// A number setting between `min` and `max`, each with whether it is inclusive (`soft`: the
    /// slider's ends; None, a text field).
    pub const fn number(
        key: &'static str,
        label: &'static str,
        (min, min_inclusive): (f64, bool),
        (max, max_inclusive): (f64, bool),
        soft: Option<(f64, f64)>,
    ) -> Setting {
        Setting { key, label, range: Range::Number { min, min_inclusive, max, max_inclusive, soft } }
    }

    /// The message of a value outside the range: "{label} must be {expected}" (the parameter
    /// table's wording too), with the value.
    pub fn check(&self, v: RangeValue) -> Result<(), SimError> {
        if self.range.contains(v) {
            return Ok(());
        }
        let got = match v {
            RangeValue::Whole(n) => n.to_string(),
            RangeValue::Number(x) => x.to_string(),
        };
        Err(SimError::Settings(format!("{} must be {}, got {got}", self.label, self.range.expected())))
    }
}
