//! The solver room: what a step solves and the one trait every solver implements.
//!
//! Every solver takes the same step skeleton ([`super::Simulation::substep`]): effects add
//! accelerations, positions are predicted `y = x_n + h v_n` (gravity's `h g` already in `v_n`,
//! so a free node's `y = x_n + h v_n + h² g`), effects place pinned and driven nodes, then **the
//! solver** moves the free nodes ([`StepSolver::solve_step`]), velocities follow `v = (x − x_n)/h`,
//! and effects damp them. The solvers differ only in how they move the free nodes:
//! - [`Method::Xpbd`] (the paper's, `xpbd.rs`): `iterations` Gauss–Seidel sweeps over the element
//!   constraints of extended position-based dynamics, each followed by the effects' own
//!   projections; small steps (Macklin et al. 2019).
//! - [`Method::Vbd`] (`vbd.rs`): vertex block descent (Chen, Liu, Yang, Yuksel, "Vertex Block
//!   Descent", ACM TOG 43(4), 2024) on the incremental potential of implicit Euler,
//!   `G(x) = Σ_i m_i/(2h²)|x_i − y_i|² + Σ_e U_e(x) + Σ_k Φ_k(x)`.
//! - [`Method::Newton`] (`newton.rs`): the same potential minimised by Newton's method with a
//!   sparse Cholesky factorisation and a line search, to a stated tolerance.
//!
//! Effects declare how an implicit solver is to honour them ([`ImplicitRole`]); an effect an
//! implicit solver cannot honour refuses the scene by name ([`check_effects`]).

use super::SimError;
use super::settings::SolverSettings;
use crate::Vec3;
use crate::effect::{Effect, EffectState, ImplicitRole, NodeSpring};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;

/// The solver moving the free nodes within a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Extended position-based dynamics with small steps (the paper's).
    #[default]
    Xpbd,
    /// Vertex block descent on implicit Euler's incremental potential.
    Vbd,
    /// Newton's method on implicit Euler's incremental potential (sparse Cholesky).
    Newton,
}

impl Method {
    pub const ALL: [Method; 3] = [Method::Xpbd, Method::Vbd, Method::Newton];
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Vbd => "vbd",
            Method::Newton => "newton",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
    /// Whether the method solves implicit Euler's incremental potential (VBD, Newton).
    pub fn is_implicit(self) -> bool {
        self != Method::Xpbd
    }
    /// Whether the method can honour an effect of this role.
    pub fn honours(self, role: ImplicitRole) -> bool {
        match (self, role) {
            (Method::Xpbd, _) => true,
            (_, ImplicitRole::Unsupported) => false,
            (Method::Newton, ImplicitRole::Projection) => false,
            _ => true,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Refuses effects `method` cannot honour, naming the first one and the methods that can.
pub(crate) fn check_effects<'e>(
    method: Method,
    effects: impl IntoIterator<Item = &'e dyn Effect>,
) -> Result<(), SimError> {
    for e in effects {
        let role = e.implicit_role();
        if !method.honours(role) {
            let supported_by: Vec<&str> =
                Method::ALL.into_iter().filter(|m| m.honours(role)).map(Method::name).collect();
            return Err(SimError::Unsupported {
                solver: method.name(),
                effect: e.name(),
                supported_by: supported_by.join(", "),
            });
        }
    }
    Ok(())
}

/// What a step solver reads (everything but the positions it moves).
pub(crate) struct StepInput<'a> {
    pub mesh: &'a Mesh,
    pub geometry: &'a [BlockGeometry],
    pub material: &'a Material,
    pub masses_kg: &'a [f64],
    /// 0 for pinned and driven nodes: the solver leaves them where the effects put them.
    pub inv_mass: &'a [f64],
    /// `x_n`, the positions at the start of the step.
    pub prev_positions: &'a [Vec3],
    /// The body acceleration every free node feels (gravity), m/s² — already in the prediction.
    pub body_acceleration: Vec3,
    /// The step, seconds.
    pub h: f64,
    pub settings: &'a SolverSettings,
    /// Changes whenever the pinned nodes, the masses or the material may have changed.
    pub model_version: u64,
}

/// The effects' hooks a solver may call within a step, and their potentials.
pub(crate) struct Hooks<'a> {
    pub effects: &'a mut [Box<dyn Effect>],
    pub velocities: &'a mut [Vec3],
    pub prev_positions: &'a [Vec3],
    pub rest: &'a [Vec3],
    pub inv_mass: &'a [f64],
    pub time_secs: f64,
    pub h: f64,
    pub calls: &'a mut u64,
}

impl Hooks<'_> {
    /// Runs the effects' projections: every effect's (`only` = None, XPBD), or only those of
    /// one role (contact under VBD).
    pub fn after_projection(&mut self, positions: &mut [Vec3], only: Option<ImplicitRole>) {
        for e in self.effects.iter_mut() {
            if only.is_some_and(|role| e.implicit_role() != role) {
                continue;
            }
            *self.calls += 1;
            e.after_projection(&mut EffectState {
                time_secs: self.time_secs,
                dt_secs: self.h,
                rest_positions: self.rest,
                positions,
                prev_positions: self.prev_positions,
                velocities: self.velocities,
                inv_mass: self.inv_mass,
            });
        }
    }

    /// The node springs of the effects that are potentials (a dragged node's attachment).
    pub fn springs(&self) -> Vec<NodeSpring> {
        self.effects.iter().filter_map(|e| e.spring()).collect()
    }
}

/// A solver of the step: moves the free nodes from the prediction to `x_{n+1}`.
pub(crate) trait StepSolver: Send {
    fn method(&self) -> Method;
    /// At the start of a step, before any hook: `velocities` are `v_n`.
    fn begin_step(&mut self, _velocities: &[Vec3]) {}
    /// The history is gone (`warm`: a warm start at rest; otherwise a reset).
    fn reset_history(&mut self, _warm: bool, _num_nodes: usize) {}
    /// `positions` enter holding the prediction `y` (pinned and driven nodes already placed) and
    /// leave holding `x_{n+1}`. Runs the effects' projections as the method allows.
    fn solve_step(
        &mut self,
        input: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut super::SolverCounters,
    ) -> Result<(), super::nan_guard::BadElement>;
    /// The settings changed (the method did not); `geometry_changed`: so did the quadrature.
    fn rebuild(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings, geometry_changed: bool);
    fn as_xpbd(&self) -> Option<&super::xpbd::Xpbd> {
        None
    }
    fn as_xpbd_mut(&mut self) -> Option<&mut super::xpbd::Xpbd> {
        None
    }
    /// The relative residual of each iteration of the last step (Newton; for tests).
    fn last_step_residuals(&self) -> &[f64] {
        &[]
    }
}

/// Makes the solver `settings.method` asks for.
pub(crate) fn make(mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings) -> Box<dyn StepSolver> {
    match settings.method {
        Method::Xpbd => Box::new(super::xpbd::Xpbd::new(mesh, geometry, settings)),
        Method::Vbd => Box::new(super::vbd::Vbd::new(mesh, geometry, settings)),
        Method::Newton => Box::new(super::newton::Newton::new(mesh)),
    }
}
