//! The time integrators of the implicit solvers ([`Integrator`]): what a step of VBD or Newton
//! minimises and how velocities follow from its minimiser. XPBD's substeps are its own
//! integrator and ignore this choice.
//!
//! Every scheme here minimises one incremental potential ([`super::potential`]),
//!
//! `E(x) = Σ_i m_i/(2 h̄²) |x_i − y_i|² + U(x) + Σ_k Φ_k(x)`,
//!
//! with its own *inertia step* `h̄` and prediction `y`, so VBD's sweeps, its coarse correction and
//! Newton's factorisation serve all of them unchanged: they read `h̄` where implicit Euler has
//! `h` ([`super::step::StepInput::inertia_h`]). With `g` the effects' body acceleration (the
//! velocity kick they add before the prediction, divided by `h`) and free nodes only:
//!
//! | scheme | `h̄` | `y` | after the solve |
//! |---|---|---|---|
//! | implicit Euler | `h` | `x_n + h v_n + h² g` | `v = (x − x_n)/h` |
//! | Newmark, average acceleration | `h/2` | `ỹ + (h²/4) g`, `ỹ = x_n + h v_n + (h²/4) a_n` | `a = 4(x − ỹ)/h²`, `v = v_n + (h/2)(a_n + a)` |
//! | BDF2 | `2h/3` | `x̂ + (2h/3) v̂ + (2h/3)² g` | `v = (x − x̂)/(2h/3)` |
//!
//! with `x̂ = (4x_n − x_{n−1})/3`, `v̂ = (4v_n − v_{n−1})/3`. The minimiser satisfies
//! `M (x − y)/h̄² = f(x)`:
//! - for Newmark (β = 1/4, γ = 1/2; Newmark 1959, "A method of computation for structural
//!   dynamics") that is `M a_{n+1} = f(x_{n+1}) + M g` with
//!   `x_{n+1} = x_n + h v_n + (h²/4)(a_n + a_{n+1})`: the trapezoidal rule, second order, no
//!   numerical damping at any step — on a linear system it conserves the energy exactly
//!   (Hughes, *The Finite Element Method*, 2000, §9.1; on a nonlinear one the energy error stays
//!   bounded, O(h²)). Its start needs `a_0 = g − ∇U(x_0)/m`, computed at the first step after
//!   a reset.
//! - for BDF2 (Hairer & Wanner, *Solving Ordinary Differential Equations II*, §V.1) it is
//!   `(3x_{n+1} − 4x_n + x_{n−1})/(2h) = v_{n+1}`, `(3v_{n+1} − 4v_n + v_{n−1})/(2h) = a_{n+1}`:
//!   second order, L-stable, so it damps the highest frequencies (`h ω ≫ 1`) almost entirely
//!   while the slow modes a scene is about lose little (the damping per period grows as
//!   `(h ω)³`). Its first step, with no `x_{n−1}`, is an implicit Euler step.
//! - implicit Euler is first order and damps every mode by a factor
//!   `1/√(1 + (h ω)²)` per step (Hairer & Wanner II, §IV.3): a beam swinging at `h ω ≈ 0.1`
//!   loses about half its amplitude in a hundred steps (docs/STUDY.md).
//!
//! Held and driven nodes are placed by their effects; their velocity is `(x − x_n)/h` under
//! every scheme and they carry no acceleration. So is a node a projection (contact) moved in the
//! step: the second-order updates would turn the projection's jump into an acceleration and
//! bounce the node back off a plane it should rest on. A change of step, of integrator, a reset or a
//! warm start drops the history: the next step starts the scheme afresh.

//!
//! **The registry.** Each scheme is one file in `integrator/` implementing [`Scheme`] (its
//! [`IntegratorInfo`] entry, its prediction and velocity update) and one entry of
//! [`Integrator::ALL`]; [`super::Simulation`] and the solvers ask the entry (no per-scheme
//! `==` anywhere), so a scheme defined elsewhere (a test's) runs through the same code.

use crate::Vec3;

pub mod bdf2;
pub mod euler;
pub mod newmark;

/// A time integrator of the implicit solvers: its entry and its behaviour. Each lives in one
/// file and is listed once in [`Integrator::ALL`]. The defaults are implicit Euler's.
pub trait Scheme: Sync + Send + 'static {
    /// What the scheme is ([`IntegratorInfo`]).
    fn info(&self) -> &IntegratorInfo;
    /// Whether the scheme keeps a history between steps. False: implicit Euler's step, whose
    /// prediction `x_n + h v'` (every scheme's starting point) and update `v = (x − x_n)/h` the
    /// simulation's node loops make (then [`Scheme::predict`] and [`Scheme::update`] are never
    /// called).
    fn keeps_history(&self) -> bool {
        true
    }
    /// Whether the step that starts the history must be given `∇U(x_n)`
    /// ([`Prediction::start_gradient`]; Newmark's `a_0 = g − ∇U(x_0)/m`).
    fn needs_start_acceleration(&self) -> bool {
        false
    }
    /// Whether the solver is handed the scheme's guess of `x_{n+1}` ([`SchemeState::guess`],
    /// where VBD's adaptive start begins).
    fn offers_guess(&self) -> bool {
        false
    }
    /// Rewrites the free nodes' prediction `y` and returns the inertia step `h̄`. Default:
    /// implicit Euler's (`y = x_n + h v'` as it entered, `h̄ = h`).
    fn predict(&self, _state: &mut SchemeState, step: Prediction<'_>) -> f64 {
        step.h
    }
    /// After the solve: the velocities from the minimiser, and the history kept. Default:
    /// implicit Euler's `v = (x − x_n)/h` for every node.
    fn update(&self, _state: &mut SchemeState, step: Update<'_>) {
        step.euler_all();
    }
}

/// What an integrator is, for everything that lists, describes or runs integrators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorInfo {
    /// The name in scene files, on the command line and in recordings (`newmark`), unique in
    /// the registry: integrators compare equal by it.
    pub name: &'static str,
    /// The name in menus and tables.
    pub long_name: &'static str,
    /// The order of accuracy in the step.
    pub order: u32,
    /// What it does to the motion, in a sentence.
    pub motion: &'static str,
    /// Where the scheme and its behaviour are stated.
    pub source: &'static str,
    /// Whether it damps the motion a scene is about (implicit Euler: a swinging beam loses half
    /// its amplitude in 2 s), which the app marks; BDF2 damps only the modes a step cannot
    /// resolve.
    pub damps_motion: bool,
    /// Whether an iterative solver (VBD) must converge each step instead of taking its fixed
    /// sweeps: a scheme that damps nothing keeps the error the sweeps leave, and Newmark's
    /// update turns it into accelerations that feed the next step (measured: VBD's 10 sweeps
    /// on the bending beam blew up within a second).
    pub needs_converged_steps: bool,
    /// Whether VBD may Chebyshev-accelerate a step's first round of sweeps (not under BDF2:
    /// the extrapolation leaves an unconverged step leaning to overshoot, which BDF2, damping
    /// little and keeping such steps, turned into a steady gain of energy; issue #36).
    pub vbd_chebyshev: bool,
    /// Where VBD's adaptive start puts a node with the acceleration `ã` it had along gravity:
    /// true, the scheme's own prediction with `ã` in place of `g`, `y + (ã − |g|) ĝ h̄²`; false,
    /// implicit Euler's explicit extrapolation `x_n + h v_n + h² ã ĝ` (the same point under
    /// implicit Euler, in other bits).
    pub vbd_start_from_prediction: bool,
}

/// The step a scheme's prediction reads and rewrites ([`Scheme::predict`]).
pub struct Prediction<'a> {
    /// The step, seconds.
    pub h: f64,
    /// `x_n`.
    pub x_n: &'a [Vec3],
    /// The velocities after the effects' kicks, `v'` (`(v' − v_n)/h` is the body acceleration
    /// `g`).
    pub velocities: &'a [Vec3],
    /// Enter holding implicit Euler's `x_n + h v'`, leave holding the scheme's `y`.
    pub positions: &'a mut [Vec3],
    /// 0 for held and driven nodes, which keep their place.
    pub inv_mass: &'a [f64],
    /// `∇U(x_n)` when the history starts under a scheme that asks for it
    /// ([`Scheme::needs_start_acceleration`]).
    pub start_gradient: Option<&'a [Vec3]>,
}

/// The step a scheme's velocity update reads ([`Scheme::update`]).
pub struct Update<'a> {
    /// The step and the inertia step `h̄` the prediction returned, seconds.
    pub h: f64,
    pub inertia_h: f64,
    /// `x_n` and the minimiser `x_{n+1}`.
    pub x_n: &'a [Vec3],
    pub positions: &'a [Vec3],
    /// Written: `v_{n+1}`.
    pub velocities: &'a mut [Vec3],
    pub inv_mass: &'a [f64],
    /// The nodes a projection (contact) moved within the step.
    pub projected: &'a [bool],
}

impl Update<'_> {
    /// Implicit Euler's velocity of node `i`, `(x − x_n)/h`: every scheme's for held, driven and
    /// projected nodes.
    #[inline]
    pub fn euler(&self, i: usize) -> Vec3 {
        (self.positions[i] - self.x_n[i]) / self.h
    }
    /// Whether node `i` keeps implicit Euler's velocity: held, driven or moved by a projection.
    #[inline]
    pub fn keeps_euler(&self, i: usize) -> bool {
        self.inv_mass[i] == 0.0 || self.projected.get(i) == Some(&true)
    }
    /// Implicit Euler's update of every node.
    pub fn euler_all(self) {
        for i in 0..self.velocities.len() {
            self.velocities[i] = self.euler(i);
        }
    }
}

/// What a scheme keeps between steps, in buffers any scheme may use (their size is the node
/// count once used).
#[derive(Default)]
pub struct SchemeState {
    /// Steps taken since the history started (0: the first after a reset or a change).
    pub steps: u64,
    /// `v_n`, the velocities at the start of the step (before any effect).
    pub v_n: Vec<Vec3>,
    /// The acceleration at the end of the last step (Newmark's `a_n`).
    pub a_n: Vec<Vec3>,
    /// `x_{n−1}` and `v_{n−1}` (BDF2).
    pub x_before: Vec<Vec3>,
    pub v_before: Vec<Vec3>,
    /// The step's base, what the update measures from (Newmark's `ỹ`, BDF2's `x̂`); sized to the
    /// nodes before each prediction.
    pub base: Vec<Vec3>,
    /// The scheme's guess of `x_{n+1}` ([`Scheme::offers_guess`]): enters each prediction as a
    /// copy of implicit Euler's prediction.
    pub guess: Vec<Vec3>,
}

/// The time integrator of the implicit solvers, by reference to its registered scheme (compare
/// [`crate::material::MaterialModel`]); what it is: [`Integrator::info`]. Integrators compare
/// and hash by name.
#[derive(Clone, Copy)]
pub struct Integrator(pub &'static dyn Scheme);

// The built-in schemes keep the names they had as enum variants.
#[allow(non_upper_case_globals)]
impl Integrator {
    /// **The registry**: every integrator, in this order (menus, `hox solvers`, the study).
    /// Adding one is its file `integrator/NAME.rs` (a unit struct implementing [`Scheme`]), its
    /// `pub mod NAME;` line and one entry here; the scene files, the command line, the app's
    /// menu and the study read the registry.
    pub const ALL: [Integrator; 3] = [Integrator::Euler, Integrator::Newmark, Integrator::Bdf2];

    /// Backward Euler: first order, damps every mode ([`euler`]).
    pub const Euler: Integrator = Integrator(&euler::Euler);
    /// Newmark's average acceleration (the trapezoidal rule): second order, conserves energy
    /// ([`newmark`]).
    pub const Newmark: Integrator = Integrator(&newmark::Newmark);
    /// The two-step backward differentiation formula: second order, damps the highest modes
    /// ([`bdf2`]). The default: it keeps a swinging beam's motion (docs/STUDY.md) and, unlike
    /// Newmark, lets the modes a step cannot resolve die out (a dragged node's stiff spring, the
    /// solver's own error under VBD).
    pub const Bdf2: Integrator = Integrator(&bdf2::Bdf2);

    /// The scheme's behaviour.
    pub fn scheme(self) -> &'static dyn Scheme {
        self.0
    }
    pub fn info(self) -> &'static IntegratorInfo {
        self.0.info()
    }
    pub fn name(self) -> &'static str {
        self.info().name
    }
    pub fn long_name(self) -> &'static str {
        self.info().long_name
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|i| i.name() == s)
    }
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Bdf2
    }
}

crate::math::by_name!(Integrator);

/// What the simulation keeps of the scheme between steps: the scheme's own state, and where
/// projections mark the nodes they move.
#[derive(Default)]
pub(crate) struct History {
    /// The scheme and step the history was made with.
    made_for: Option<(Integrator, f64)>,
    state: SchemeState,
    /// The step's inertia step `h̄`.
    inertia_h: f64,
    /// The nodes a projection (contact) moved within the step, and a scratch copy of the
    /// positions to find them ([`super::step::Hooks::projected`]).
    projected: Vec<bool>,
    before_projection: Vec<Vec3>,
}

impl History {
    /// Drops the history (reset, warm start, a new step length or scheme).
    pub fn clear(&mut self) {
        self.made_for = None;
        self.state.steps = 0;
    }

    /// Whether the next step must be given the elastic gradient at `x_n` for its starting
    /// acceleration ([`Scheme::needs_start_acceleration`], after a reset or a change).
    pub fn needs_start_acceleration(&self, integrator: Integrator, h: f64) -> bool {
        integrator.scheme().needs_start_acceleration() && self.made_for != Some((integrator, h))
    }

    /// At the start of a step, before any effect: `velocities` are `v_n`. Drops the history if
    /// the scheme or the step changed.
    pub fn begin(&mut self, integrator: Integrator, h: f64, velocities: &[Vec3]) {
        // (a simulation's node count never changes, so the history's buffers keep their size)
        if self.made_for != Some((integrator, h)) {
            self.clear();
        }
        self.state.v_n.clear();
        self.state.v_n.extend_from_slice(velocities);
    }

    /// What the solver reads and writes of the history within the step: the scheme's guess of
    /// `x_{n+1}` when it offers one ([`Scheme::offers_guess`]: Newmark's, the motion with the
    /// last acceleration kept, so a body at rest in equilibrium stays where it is), and where
    /// the step's projections mark the nodes they move (all unmarked at the start) with their
    /// scratch copy of the positions.
    pub fn step_views(
        &mut self,
        integrator: Integrator,
        num_nodes: usize,
    ) -> (Option<&[Vec3]>, (&mut [bool], &mut Vec<Vec3>)) {
        self.projected.clear();
        self.projected.resize(num_nodes, false);
        let guess = integrator.scheme().offers_guess().then_some(self.state.guess.as_slice());
        (guess, (&mut self.projected, &mut self.before_projection))
    }

    /// Rewrites the free nodes' prediction for the scheme and returns the inertia step `h̄`
    /// ([`Scheme::predict`]); also makes the scheme's guess of `x_{n+1}`.
    pub fn predict(&mut self, integrator: Integrator, step: Prediction<'_>) -> f64 {
        let n = step.positions.len();
        self.state.base.resize(n, Vec3::zeros());
        self.state.guess.clear();
        self.state.guess.extend_from_slice(step.positions);
        self.inertia_h = integrator.scheme().predict(&mut self.state, step);
        self.inertia_h
    }

    /// After the solve: the velocities from the minimiser `positions`, and the history kept.
    pub fn update(
        &mut self,
        integrator: Integrator,
        h: f64,
        x_n: &[Vec3],
        positions: &[Vec3],
        velocities: &mut [Vec3],
        inv_mass: &[f64],
    ) {
        let step =
            Update { h, inertia_h: self.inertia_h, x_n, positions, velocities, inv_mass, projected: &self.projected };
        integrator.scheme().update(&mut self.state, step);
        self.made_for = Some((integrator, h));
        self.state.steps += 1;
    }
}
