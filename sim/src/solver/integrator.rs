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

use crate::Vec3;

/// The time integrator of the implicit solvers; what it is: [`Integrator::info`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Integrator {
    /// Backward Euler: first order, damps every mode.
    Euler,
    /// Newmark's average acceleration (the trapezoidal rule): second order, conserves energy.
    Newmark,
    /// The two-step backward differentiation formula: second order, damps the highest modes.
    /// The default: it keeps a swinging beam's motion (docs/STUDY.md) and, unlike Newmark, lets
    /// the modes a step cannot resolve die out (a dragged node's stiff spring, the solver's
    /// own error under VBD).
    #[default]
    Bdf2,
}

/// What an integrator is, for everything that lists or describes integrators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorInfo {
    pub integrator: Integrator,
    /// The name in scene files, on the command line and in recordings (`newmark`).
    pub name: &'static str,
    /// The name in menus and tables.
    pub long_name: &'static str,
    /// The order of accuracy in the step.
    pub order: u32,
    /// What it does to the motion, in a sentence.
    pub motion: &'static str,
    /// Where the scheme and its behaviour are stated.
    pub source: &'static str,
    /// Whether an iterative solver (VBD) must converge each step instead of taking its fixed
    /// sweeps: a scheme that damps nothing keeps the error the sweeps leave, and Newmark's
    /// update turns it into accelerations that feed the next step (measured: VBD's 10 sweeps
    /// on the bending beam blew up within a second).
    pub needs_converged_steps: bool,
}

/// Every integrator's entry, in [`Integrator::ALL`]'s order.
pub const INFO: [IntegratorInfo; 3] = [
    IntegratorInfo {
        integrator: Integrator::Euler,
        name: "euler",
        long_name: "implicit Euler",
        order: 1,
        motion: "First order; damps every mode, the more the larger h·ω: at one step per frame a swinging beam loses about half its amplitude in 2 s.",
        source: "Hairer & Wanner, Solving ODEs II (1996), §IV.3",
        needs_converged_steps: false,
    },
    IntegratorInfo {
        integrator: Integrator::Newmark,
        name: "newmark",
        long_name: "Newmark (average acceleration)",
        order: 2,
        motion: "Second order, no numerical damping: conserves the energy of a linear system exactly and keeps a swinging beam's amplitude.",
        source: "Newmark 1959; Hughes, The Finite Element Method (2000), §9.1",
        needs_converged_steps: true,
    },
    IntegratorInfo {
        integrator: Integrator::Bdf2,
        name: "bdf2",
        long_name: "BDF2 (backward differentiation)",
        order: 2,
        motion: "Second order, L-stable: damps the fastest, unresolved modes almost entirely and the slow ones little (more with a larger step).",
        source: "Hairer & Wanner, Solving ODEs II (1996), §V.1",
        needs_converged_steps: false,
    },
];

impl Integrator {
    pub const ALL: [Integrator; 3] = [Integrator::Euler, Integrator::Newmark, Integrator::Bdf2];
    pub fn info(self) -> &'static IntegratorInfo {
        &INFO[self as usize]
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

impl std::fmt::Display for Integrator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a scheme keeps between steps, and its prediction and velocity update.
#[derive(Default)]
pub(crate) struct History {
    /// The scheme and step the history was made with.
    made_for: Option<(Integrator, f64)>,
    /// Steps taken since the history started.
    steps: u64,
    /// `v_n` at the start of the step.
    v_n: Vec<Vec3>,
    /// Newmark: `a_n`, the acceleration at the end of the last step.
    a_n: Vec<Vec3>,
    /// BDF2: `x_{n−1}` and `v_{n−1}`.
    x_before: Vec<Vec3>,
    v_before: Vec<Vec3>,
    /// The step's `ỹ` (Newmark) or `x̂` (BDF2): what the update measures from.
    base: Vec<Vec3>,
    /// The step's inertia step `h̄`.
    inertia_h: f64,
    /// The nodes a projection (contact) moved within the step, and a scratch copy of the
    /// positions to find them ([`super::step::Hooks::projected`]).
    projected: Vec<bool>,
    before_projection: Vec<Vec3>,
    /// The scheme's guess of `x_{n+1}` ([`History::step_views`]).
    guess: Vec<Vec3>,
}

impl History {
    /// Drops the history (reset, warm start, a new step length or scheme).
    pub fn clear(&mut self) {
        self.made_for = None;
        self.steps = 0;
    }

    /// The scheme this step takes: BDF2 starts with an implicit Euler step (the standard start,
    /// and a robust one: a Newmark start from a stretched attachment overshot so far that the
    /// next steps inverted elements).
    fn this_step(&self, integrator: Integrator) -> Integrator {
        match integrator {
            Integrator::Bdf2 if self.steps == 0 => Integrator::Euler,
            other => other,
        }
    }

    /// Whether the next step must be given the elastic gradient at `x_n` for its starting
    /// acceleration (a Newmark step after a reset or a change).
    pub fn needs_start_acceleration(&self, integrator: Integrator, h: f64) -> bool {
        integrator == Integrator::Newmark && self.made_for != Some((integrator, h))
    }

    /// At the start of a step, before any effect: `velocities` are `v_n`. Drops the history if
    /// the scheme or the step changed.
    pub fn begin(&mut self, integrator: Integrator, h: f64, velocities: &[Vec3]) {
        // (a simulation's node count never changes, so the history's buffers keep their size)
        if self.made_for != Some((integrator, h)) {
            self.clear();
        }
        self.v_n.clear();
        self.v_n.extend_from_slice(velocities);
    }

    /// What the solver reads and writes of the history within the step: Newmark's guess of
    /// `x_{n+1}` ([`History::predict`]: the motion with the last acceleration kept, so a body at
    /// rest in equilibrium stays where it is; the other schemes leave the prediction there), and where the step's projections mark the nodes
    /// they move (all unmarked at the start) with their scratch copy of the positions.
    pub fn step_views(&mut self, num_nodes: usize) -> (&[Vec3], (&mut [bool], &mut Vec<Vec3>)) {
        self.projected.clear();
        self.projected.resize(num_nodes, false);
        (&self.guess, (&mut self.projected, &mut self.before_projection))
    }

    /// Rewrites the free nodes' prediction for the scheme and returns the inertia step `h̄`.
    /// `positions` enter holding implicit Euler's `x_n + h v'` (`v'` the velocities after the
    /// effects' kicks, `velocities`) and leave holding the scheme's `y`. `start_gradient`
    /// is `∇U(x_n)` when a Newmark step starts ([`History::needs_start_acceleration`]), from
    /// which `a_0 = g − ∇U(x_n)/m`. Also makes the scheme's guess of `x_{n+1}`
    /// ([`History::step_views`]).
    #[allow(clippy::too_many_arguments)]
    pub fn predict(
        &mut self,
        integrator: Integrator,
        h: f64,
        x_n: &[Vec3],
        velocities: &[Vec3],
        positions: &mut [Vec3],
        inv_mass: &[f64],
        start_gradient: Option<&[Vec3]>,
    ) -> f64 {
        let n = positions.len();
        self.base.resize(n, Vec3::zeros());
        self.guess.clear();
        self.guess.extend_from_slice(positions);
        let kick = |i: usize| (velocities[i] - self.v_n[i]) / h;
        self.inertia_h = match self.this_step(integrator) {
            Integrator::Euler => h,
            Integrator::Newmark => {
                if let Some(grad) = start_gradient {
                    self.a_n = (0..n)
                        .map(|i| if inv_mass[i] > 0.0 { kick(i) - grad[i] * inv_mass[i] } else { Vec3::zeros() })
                        .collect();
                }
                let q = 0.25 * h * h;
                for i in 0..n {
                    if inv_mass[i] == 0.0 {
                        continue;
                    }
                    let tilde = x_n[i] + self.v_n[i] * h + self.a_n[i] * q;
                    self.base[i] = tilde;
                    positions[i] = tilde + kick(i) * q;
                    // the acceleration goes on as it was
                    self.guess[i] = tilde + self.a_n[i] * q;
                }
                0.5 * h
            }
            Integrator::Bdf2 => {
                let beta = 2.0 * h / 3.0;
                for i in 0..n {
                    if inv_mass[i] == 0.0 {
                        continue;
                    }
                    let x_hat = (x_n[i] * 4.0 - self.x_before[i]) / 3.0;
                    let v_hat = (self.v_n[i] * 4.0 - self.v_before[i]) / 3.0;
                    self.base[i] = x_hat;
                    positions[i] = x_hat + v_hat * beta + kick(i) * (beta * beta);
                }
                beta
            }
        };
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
        let n = positions.len();
        let euler = |i: usize| (positions[i] - x_n[i]) / h;
        let projected = |i: usize| self.projected.get(i) == Some(&true);
        let scheme = self.this_step(integrator);
        match scheme {
            Integrator::Euler => {
                for (i, v) in velocities.iter_mut().enumerate() {
                    *v = euler(i);
                }
            }
            Integrator::Newmark => {
                let four_over_h2 = 4.0 / (h * h);
                for i in 0..n {
                    if inv_mass[i] == 0.0 || projected(i) {
                        velocities[i] = euler(i);
                        self.a_n[i] = Vec3::zeros();
                        continue;
                    }
                    let a = (positions[i] - self.base[i]) * four_over_h2;
                    velocities[i] = self.v_n[i] + (self.a_n[i] + a) * (0.5 * h);
                    self.a_n[i] = a;
                }
            }
            Integrator::Bdf2 => {
                for i in 0..n {
                    velocities[i] = if inv_mass[i] == 0.0 || projected(i) {
                        euler(i)
                    } else {
                        (positions[i] - self.base[i]) / self.inertia_h
                    };
                }
            }
        }
        if integrator == Integrator::Bdf2 {
            self.x_before.clear();
            self.x_before.extend_from_slice(x_n);
            std::mem::swap(&mut self.v_before, &mut self.v_n);
        }
        self.made_for = Some((integrator, h));
        self.steps += 1;
    }
}
