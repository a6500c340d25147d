//! The parameter table: every mesh, material, solver, effect and display parameter of a scene,
//! defined once.
//!
//! Each entry of [`PARAMS`] states a parameter's key (`youngs`: the CLI flag `--youngs`, the
//! `--compare youngs=…` key, the app's link), its scene-file key (`material.youngs_modulus_pa`),
//! type ([`Kind`]), unit, help text, valid range, default, where it appears ([`Surfaces`]) and
//! what a change of it invalidates in a running simulation ([`Invalidates`]). From the table come:
//!
//! - the typed values [`Params`] (one field per entry, persisted by the app) and the typed
//!   [`SceneOverrides`] (the same fields, each optional);
//! - the scene file's `[mesh]`, `[material]`, `[solver]`, `[effect]` and `[display]` keys, their
//!   parsing and their range checks ([`crate::scene`]);
//! - the command line's flags and the `--compare key=value` keys (the app's `cli` room);
//! - the app's controls, their links in compare mode and their rebuild levels (the app's `gui`
//!   room), and the configuration a recording states.
//!
//! **Adding a parameter** is one entry in the `params!` invocation below plus the code that uses
//! the value (e.g. `SolverSettings`); nothing else lists parameters.
//!
//! This file holds the table and the public surface made from it; the rest of the folder: the
//! meta-types `kind` (type and range, group, surfaces, invalidation) and `value` (untyped values
//! and their conversion to the typed fields, the choices' types), `param` (one entry), `options`
//! (the choices' option lists), `applies` (when an entry applies), `size` (the box's size limits)
//! and `suggest` (did-you-mean). A choice's text is parsed into its typed field (e.g.
//! [`MaterialModel`]) where it enters: a scene file, a command-line flag, a `--compare` key, the
//! app's menu or its persisted settings. The solver entries' defaults are sim's
//! ([`SolverSettings::default`]).

use serde::{Deserialize, Serialize};

mod applies;
mod kind;
mod options;
mod param;
mod size;
mod suggest;
#[cfg(test)]
mod tests;
mod value;

pub use applies::is_tetrahedral;
pub use kind::{EVERYWHERE, FILE_ONLY, Group, Invalidates, Kind, Surfaces};
pub use param::{MeshKind, Param};
pub use size::{MAX_BOX_BYTES, MAX_BOX_ELEMENTS, box_bytes, box_elements, thousands};
pub use value::{Choice, ParamType, Value};

use hox_sim::element::ElementType;
use hox_sim::material::{DENSITY_KG_M3, MaterialModel, POISSON_RATIO, YOUNGS_MODULUS_PA};
use hox_sim::measure::field::Field;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::{Integrator, Method, NewtonPolicy, SolverSettings, Sweep, VbdInit};
use hox_sim::xpbd::constraint::Formulation;
use value::as_text;

use options::*;
use param::BASE;
#[cfg(test)]
use size::check_box_size;
use size::{check_grid_size, check_refine_size};

/// sim's solver defaults: the solver entries' defaults are these, written once in
/// [`SolverSettings::default`].
fn solver() -> SolverSettings {
    SolverSettings::default()
}

/// Defines [`Params`], [`SceneOverrides`] and [`PARAMS`] from one list.
macro_rules! params {
    ($( $(#[$attr:meta])* $field:ident : $ty:ty = $default:expr => { $($def:tt)* } )*) => {
        /// Every parameter's value (see the module docs); a scene's resolved configuration and
        /// the app's live controls. Persisted by the app (missing fields take their defaults).
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(default)]
        pub struct Params {
            $( $(#[$attr])* pub $field: $ty, )*
        }

        impl Default for Params {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        /// Changes to a scene's parameters (command line, `--compare`, the app, studies),
        /// applied by [`crate::scene::Scene::with_overrides`]: a field per parameter, `None` = keep.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct SceneOverrides {
            $( pub $field: Option<$ty>, )*
        }

        /// The table, in display order.
        pub static PARAMS: &[Param] = &[
            $( Param {
                field: stringify!($field),
                get: |p| p.$field.to_value(),
                set: |p, v| match <$ty as ParamType>::from_value(v) {
                    Some(x) => { p.$field = x; true }
                    None => false,
                },
                get_override: |o| o.$field.as_ref().map(ParamType::to_value),
                set_override: |o, v| match <$ty as ParamType>::from_value(v) {
                    Some(x) => { o.$field = Some(x); true }
                    None => false,
                },
                $($def)*
            }, )*
        ];
    };
}

params! {
    /// Element type of a box mesh (or the file of a scene with one per type): a registered
    /// element type ([`ElementType::all`]).
    #[serde(with = "as_text")]
    element: ElementType = ElementType::from_name("p2").expect("P2 is registered") => {
        key: "element", group: Group::Mesh, file_key: "element", label: "Element",
        help: "The element type: its shape (tetrahedron, hexahedron, prism, pyramid) and polynomial order; `hox elements` describes each.",
        kind: Kind::Choice(element_options), invalidates: Invalidates::Mesh, required: true, box_only: true, picks_file: true, ..BASE
    }
    /// `five` (unbiased) or `six` (biased) tetrahedra per cell.
    #[serde(with = "as_text")]
    split: TetSplit = TetSplit::Five => {
        key: "split", group: Group::Mesh, file_key: "split", label: "Tet split",
        help: "How each hexahedral cell is cut into tetrahedra: five (unbiased, alternating) or six (biased along one diagonal).",
        kind: Kind::Choice(split_options), invalidates: Invalidates::Mesh, box_only: true, applies: Some(is_tetrahedral), ..BASE
    }
    /// Hexahedral cells per direction of a box mesh.
    grid: [usize; 3] = [8, 2, 2] => {
        key: "grid", group: Group::Mesh, file_key: "grid", label: "Grid",
        help: "Hexahedral cells along x, y and z before any splitting (each 1–64), NXxNYxNZ.",
        kind: Kind::Grid { min: 1, max: 64 }, invalidates: Invalidates::Mesh, required: true, box_only: true,
        check_with: Some(check_grid_size), ..BASE
    }
    /// 1-to-8 refinements of the tetrahedra.
    refine: usize = 0 => {
        key: "refine", group: Group::Mesh, file_key: "refine", label: "Refine",
        help: "1-to-8 refinements of the tetrahedra (each multiplies the element count by 8; tetrahedra only).",
        kind: Kind::Whole { min: 0, max: 3, soft_max: 3 }, invalidates: Invalidates::Mesh, box_only: true,
        applies: Some(is_tetrahedral), check_with: Some(check_refine_size), ..BASE
    }
    /// The box's lower corner, metres.
    box_min_m: [f64; 3] = [0.0; 3] => {
        key: "box-min-m", group: Group::Mesh, file_key: "box_min_m", label: "Box lower corner", unit: "m",
        help: "The box mesh's lower corner, metres.",
        kind: Kind::Point, invalidates: Invalidates::Mesh, surfaces: FILE_ONLY, required: true, box_only: true, ..BASE
    }
    /// The box's upper corner, metres.
    box_max_m: [f64; 3] = [2.0, 0.5, 0.5] => {
        key: "box-max-m", group: Group::Mesh, file_key: "box_max_m", label: "Box upper corner", unit: "m",
        help: "The box mesh's upper corner, metres; beyond the lower corner in every direction.",
        kind: Kind::Point, invalidates: Invalidates::Mesh, surfaces: FILE_ONLY, required: true, box_only: true, ..BASE
    }
    /// A registered material model ([`MaterialModel::ALL`]).
    #[serde(with = "as_text")]
    material: MaterialModel = MaterialModel::StVenantKirchhoff => {
        key: "material", group: Group::Material, file_key: "model", label: "Model",
        help: "The hyperelastic energy model; stvk (Saint-Venant–Kirchhoff) is the paper's.",
        kind: Kind::Choice(material_options), invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Young's modulus, Pa.
    youngs_modulus_pa: f64 = 3e6 => {
        key: "youngs", group: Group::Material, file_key: "youngs_modulus_pa", label: "Young's modulus E", unit: "Pa",
        help: "Stiffness in pascals, > 0 (rubber ~1e6, the paper's beam 3e6).",
        kind: Kind::Number { min: YOUNGS_MODULUS_PA.min, min_inclusive: false, max: YOUNGS_MODULUS_PA.max, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Poisson ratio.
    poisson_ratio: f64 = 0.35 => {
        key: "poisson", group: Group::Material, file_key: "poisson_ratio", label: "Poisson ratio ν",
        help: "Lateral contraction, between −1 and 0.5 (exclusive); near 0.5 is nearly incompressible.",
        kind: Kind::Number { min: POISSON_RATIO.min, min_inclusive: false, max: POISSON_RATIO.max, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Density, kg/m³.
    density_kg_m3: f64 = 1000.0 => {
        key: "density", group: Group::Material, file_key: "density_kg_m3", label: "Density ρ", unit: "kg/m³",
        help: "Mass per volume in kg/m³, > 0 (water 1000).",
        kind: Kind::Number { min: DENSITY_KG_M3.min, min_inclusive: false, max: DENSITY_KG_M3.max, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// A solver of the registry ([`Method::ALL`]).
    #[serde(with = "as_text")]
    method: Method = solver().method => {
        key: "solver", group: Group::Solver, file_key: "method", label: "Solver",
        help: "The solver moving the free nodes (`hox solvers` describes each): xpbd is the paper's extended position-based dynamics (substeps × iterations); the others are implicit, solving each step's incremental potential, whose scheme is --integrator (vbd: vertex block descent, Chen et al. 2024; the Newton-type ones to --newton-tolerance). A solver that cannot honour a scene's effect (contact) refuses it by name.",
        kind: Kind::Choice(method_options), ..BASE
    }
    /// Implicit steps per frame (the implicit solvers).
    steps_per_frame: u32 = solver().steps_per_frame => {
        key: "steps", group: Group::Solver, file_key: "steps_per_frame", label: SolverSettings::STEPS_PER_FRAME.label,
        help: "Steps per frame of the implicit solvers (XPBD takes --substeps); more steps, less numerical damping and phase error.",
        kind: Kind::of_range(SolverSettings::STEPS_PER_FRAME.range), ..BASE
    }
    /// The implicit solvers' time integrator: euler | newmark | bdf2.
    #[serde(with = "as_text")]
    integrator: Integrator = solver().integrator => {
        key: "integrator", group: Group::Solver, file_key: "integrator", label: "Integrator",
        help: "Time integrator of the implicit solvers (XPBD's substeps are its own): bdf2 (default: second order, keeps a swinging beam's motion and damps only the fast modes a frame cannot resolve, so a dragged node settles), newmark (average acceleration: conserves energy exactly, no numerical damping at all, so unresolved fast modes ring on) or euler (implicit Euler: first order, damps the motion, at one step per frame a beam loses half its swing in 2 s). docs/METHOD.md.",
        kind: Kind::Choice(integrator_options), ..BASE
    }
    /// VBD sweeps per step.
    vbd_iterations: u32 = solver().vbd.iterations => {
        key: "vbd-iterations", group: Group::Solver, file_key: "vbd_iterations", label: SolverSettings::VBD_ITERATIONS.label,
        help: "Vertex block descent sweeps over the node colours per step.",
        kind: Kind::of_range(SolverSettings::VBD_ITERATIONS.range), ..BASE
    }
    /// Chebyshev acceleration's ρ for VBD (0: off).
    chebyshev_rho: f64 = solver().vbd.chebyshev_rho => {
        key: "chebyshev-rho", group: Group::Solver, file_key: "chebyshev_rho", label: SolverSettings::CHEBYSHEV_RHO.label,
        help: "Chebyshev acceleration of the VBD sweeps, its spectral radius estimate in [0, 1) (0: off; 0.9 halves the sweeps to settle the bending beam; 0.95 can diverge at few sweeps).",
        kind: Kind::of_range(SolverSettings::CHEBYSHEV_RHO.range),
        ..BASE
    }
    /// VBD's two-level correction: about how many coarse cells (0: off).
    vbd_coarse_cells: u32 = solver().vbd.coarse_cells => {
        key: "vbd-coarse-cells", group: Group::Solver, file_key: "vbd_coarse_cells", label: SolverSettings::VBD_COARSE_CELLS.label,
        help: "VBD's two-level correction: before its sweeps each step solves for the smooth part of the motion on a coarse grid of about this many trilinear cells over the body (0: off, the paper's VBD alone). The sweeps barely move smooth error such as a beam's slow bending; with the correction Gmsh's P2 beam settles in 122 frames (as Newton) instead of 707.",
        kind: Kind::of_range(SolverSettings::VBD_COARSE_CELLS.range), ..BASE
    }
    /// Where a VBD step starts: adaptive | inertia | previous.
    #[serde(with = "as_text")]
    vbd_init: VbdInit = solver().vbd.init => {
        key: "vbd-init", group: Group::Solver, file_key: "vbd_init", label: "VBD start",
        help: "Where a VBD step starts: adaptive (the paper's: the last step's acceleration along gravity, so a body at rest stays at rest), inertia (the inertial prediction) or previous (the last position).",
        kind: Kind::Choice(vbd_init_options), ..BASE
    }
    /// Newton's tolerance per step, relative to the load.
    newton_tolerance: f64 = solver().newton.tolerance => {
        key: "newton-tolerance", group: Group::Solver, file_key: "newton_tolerance", label: SolverSettings::NEWTON_TOLERANCE.label,
        help: "A Newton step has converged when its unbalanced force is at most this fraction of the load (the body force, or the reactions if larger), as `hox static` measures it; in (0, 1).",
        kind: Kind::of_range(SolverSettings::NEWTON_TOLERANCE.range), ..BASE
    }
    /// Newton iterations per step at most.
    newton_iterations: usize = solver().newton.max_iterations as usize => {
        key: "newton-iterations", group: Group::Solver, file_key: "newton_iterations", label: SolverSettings::NEWTON_ITERATIONS.label,
        help: "Newton iterations per step at most (the implicit solvers of the Newton family). The default runs a step to its tolerance; a budget of 2 keeps a large part at the display's rate: a step left above the tolerance carries its unbalanced force into the next, so a swinging body lags slightly and a settled one is as exact as ever (docs/journal/performance.md, session 24).",
        kind: Kind::of_range(SolverSettings::NEWTON_ITERATIONS.range), ..BASE
    }
    /// How Newton keeps its factor: auto | interactive | careful.
    #[serde(with = "as_text")]
    newton_policy: NewtonPolicy = solver().newton.policy => {
        key: "newton-policy", group: Group::Solver, file_key: "newton_policy", label: "Newton's factor",
        help: "How Newton keeps its factor. auto (the default): interactive where a factorisation costs at least 6 iterations with the kept factor (a part of thousands of nodes), careful on smaller meshes, and careful from the first step the step watch rejects; `--json` says which ran and why. interactive: the factor kept across steps in single precision, corrected by secant pairs (L-BFGS) and refreshed only when keeping it costs more than a factorisation. careful: refreshed whenever an iteration reduces the residual less than 4×, in double precision.",
        kind: Kind::Choice(newton_policy_options), ..BASE
    }
    /// energy | split | mixed.
    #[serde(with = "as_text")]
    formulation: Formulation = solver().formulation => {
        key: "formulation", group: Group::Solver, file_key: "formulation", label: "Formulation",
        help: "Energy: one constraint C = √(2U) per element (the paper's); split: deviatoric and hydrostatic constraints per quadrature point (XPBD); mixed: the volume measured once per element (one constant pressure), which cures volumetric locking near ν = 0.5, on every solver (P2, P3, Q2; stvk, nh).",
        kind: Kind::Choice(formulation_options), ..BASE
    }
    /// None: each element type's default degree.
    quadrature_degree: Option<usize> = solver().quadrature_degree => {
        key: "quadrature", group: Group::Solver, file_key: "quadrature_degree", label: "Quadrature",
        help: "Degree of polynomials the element quadrature integrates exactly (default: the element's own).",
        kind: Kind::Degree { max: 21 }, ..BASE
    }
    /// XPBD substeps per frame.
    substeps: u32 = solver().substeps => {
        key: "substeps", group: Group::Solver, file_key: "substeps", label: SolverSettings::SUBSTEPS.label,
        help: "XPBD substeps per frame (the paper: 50); more substeps, less solver bias, more time.",
        kind: Kind::of_range(SolverSettings::SUBSTEPS.range), ..BASE
    }
    /// Constraint sweeps per substep.
    iterations: u32 = solver().iterations => {
        key: "iterations", group: Group::Solver, file_key: "iterations", label: SolverSettings::ITERATIONS.label,
        help: "Constraint sweeps per substep (the paper: 1).",
        kind: Kind::of_range(SolverSettings::ITERATIONS.range), ..BASE
    }
    /// More substeps where the stiffest element needs them (`hox_sim::solver::stability`).
    stability_guard: bool = solver().stability_guard => {
        key: "guard", group: Group::Solver, file_key: "stability_guard", label: "Stability guard",
        help: "More substeps when the stiffest element needs them (when h·ω_max would exceed 3, enough for h·ω_max ≤ 1; just below 3 your substeps are kept); off: exactly the substeps asked for, which may blow up (docs/STABILITY.md).",
        kind: Kind::Flag, switch: Some(("no-stability-guard", false)), ..BASE
    }
    /// Simulated frames per second; each frame is one time step.
    frames_per_second: f64 = solver().frames_per_second => {
        key: "fps", group: Group::Solver, file_key: "frames_per_second", label: SolverSettings::FRAMES_PER_SECOND.label,
        help: "Simulated frames per second of simulated time (the paper: 60); each frame is one time step h = 1/fps.",
        kind: Kind::of_range(SolverSettings::FRAMES_PER_SECOND.range),
        ..BASE
    }
    /// colour | element: the order of XPBD's Gauss–Seidel sweep.
    #[serde(with = "as_text")]
    sweep: Sweep = solver().sweep => {
        key: "sweep", group: Group::Solver, file_key: "sweep", label: "Sweep",
        help: "Order of XPBD's constraint sweep. colour (default): colour by colour, four elements per AVX2 register, on every thread (RAYON_NUM_THREADS sets how many), the same result on any thread count; element: element after element in mesh order on one thread (the order of the paper's figures and of hox's results before the colour sweep became the default).",
        kind: Kind::Choice(sweep_options), ..BASE
    }
    /// Default run length, seconds.
    duration_secs: f64 = 3.0 => {
        key: "duration", group: Group::Solver, file_key: "duration_secs", label: "Duration", unit: "s",
        help: "Simulated time a run lasts by default (`--seconds` overrides it).",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping used by `--settle`, 1/s.
    settle_damping_per_sec: f64 = 10.0 => {
        key: "settle-damping", group: Group::Solver, file_key: "settle_damping_per_sec", label: "Settle damping", unit: "1/s",
        help: "Velocity damping rate a run to rest (--settle) adds, per second.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping used by `--settle` when the solver is VBD, 1/s.
    vbd_settle_damping_per_sec: f64 = 10.0 => {
        key: "vbd-settle-damping", group: Group::Solver, file_key: "vbd_settle_damping_per_sec", label: "VBD settle damping", unit: "1/s",
        help: "Velocity damping rate a run to rest (--settle) adds when the solver is vbd, per second, in place of the settle damping. With the coarse correction (vbd_coarse_cells > 0) VBD's steps are near converged and the 10/s that settles XPBD and Newton fastest does so too (Gmsh's P2 1,471 beam: 122 frames, as Newton); without it the few sweeps per step leave the slow bending modes only part of their stiffness and 2/s settles fastest (707 frames against 2,200 at 10/s).",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping of every node, 1/s (0: none).
    damping_per_sec: f64 = 0.0 => {
        key: "damping", group: Group::Effect, file_key: "damping_per_sec", label: "Damping", unit: "1/s",
        help: "Velocity damping rate of every node per second, on top of any damping effect the scene lists (0: none); a swinging beam comes to rest at a rate of about this many e-foldings per second. A change restarts the run.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Mesh, ..BASE
    }
    /// Pieces per edge of drawn curved and quadrilateral faces.
    tessellation: usize = 4 => {
        key: "tessellation", group: Group::Display, file_key: "tessellation", label: "Face segments",
        help: "Pieces per edge when drawing curved (high-order) and quadrilateral faces: more shows the curvature of P2, P3 and Q2 elements more smoothly, at more drawing cost.",
        kind: Kind::Whole { min: 1, max: 16, soft_max: 12 }, invalidates: Invalidates::Nothing, ..BASE
    }
    /// The fields the surface is coloured by, comma-separated; the first is drawn
    /// ([`hox_sim::measure::field::Field`]).
    #[serde(with = "as_text")]
    field: Vec<Field> = vec![Field::Displacement] => {
        key: "field", group: Group::Display, file_key: "field", label: "Colour by",
        help: "What the surface is coloured by: displacement (|u|, m), von-mises (stress, Pa), strain (equivalent Green–Lagrange strain), det-f (volume ratio), energy-density (J/m³) or error (|u − u_ref| against the reference field, m), evaluated at each element's own points. `hox record` records every field listed (comma-separated or --field repeated), each in its own 3D view; the app draws the first.",
        kind: Kind::Choices(field_options), invalidates: Invalidates::Nothing, ..BASE
    }
    /// Top of the colour range of the metre fields (|u|, error), metres (0: automatic).
    colour_max_m: f64 = 0.0 => {
        key: "colour-max-m", group: Group::Display, file_key: "colour_max_m", label: "Colour top (m)", unit: "m",
        help: "Top of a fixed colour range for displacement and error, metres (larger values are drawn pink, marked saturated); 0: automatic, growing to the largest value seen so nothing saturates. Compared configurations share the first one's range.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, ..BASE
    }
    /// Top of the colour range of the first other field listed, in its unit (0: automatic).
    colour_max: f64 = 0.0 => {
        key: "colour-max", group: Group::Display, file_key: "colour_max", label: "Colour top (field unit)",
        help: "Top of a fixed colour range for the first field listed other than displacement and error, in its unit (Pa for von-mises, J/m³ for energy-density, none for strain and det-f, whose range is then symmetric about 1); larger values are drawn pink, smaller than the bottom light blue. 0: automatic.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, ..BASE
    }
    /// Draw (or record) every quadrature point.
    quadrature_points: bool = false => {
        key: "quadrature-points", group: Group::Display, file_key: "quadrature_points", label: "Quadrature points",
        help: "Also draw (and record) every quadrature point, where the solver samples F.",
        kind: Kind::Flag, switch: Some(("quadrature-points", true)), invalidates: Invalidates::Nothing, ..BASE
    }
}

/// The parameter with command-line / `--compare` / link key `key`.
pub fn by_key(key: &str) -> Option<&'static Param> {
    PARAMS.iter().find(|p| p.key == key)
}

/// The parameters of `group`, in display order.
pub fn in_group(group: Group) -> impl Iterator<Item = &'static Param> {
    PARAMS.iter().filter(move |p| p.group == group)
}

/// The keys `--compare` accepts, comma-separated.
pub fn compare_keys() -> String {
    PARAMS.iter().filter(|p| p.surfaces.cli).map(|p| p.key).collect::<Vec<_>>().join(", ")
}

impl SceneOverrides {
    /// The parameters this sets, with their values.
    pub fn iter(&self) -> impl Iterator<Item = (&'static Param, Value)> + '_ {
        PARAMS.iter().filter_map(move |p| (p.get_override)(self).map(|v| (p, v)))
    }

    /// Sets the parameter `key` from text (`--compare key=value`); errors name the key.
    pub fn set_text(&mut self, key: &str, text: &str) -> Result<(), String> {
        let p = by_key(key).filter(|p| p.surfaces.cli).ok_or_else(|| suggest::unknown_key(key))?;
        let v = p.kind.parse(text).map_err(|e| format!("{key}: {e}"))?;
        p.check_value(&v).map_err(|e| format!("{key} = {v}: {e}"))?;
        (p.set_override)(self, v);
        Ok(())
    }

    /// `self` with every value `other` sets put on top.
    pub fn merged(&self, other: &SceneOverrides) -> SceneOverrides {
        let mut out = self.clone();
        for (p, v) in other.iter() {
            (p.set_override)(&mut out, v);
        }
        out
    }
}

impl Params {
    /// The value of the parameter `key`.
    pub fn value(&self, key: &str) -> Option<Value> {
        by_key(key).map(|p| (p.get)(self))
    }

    /// `self` with `overrides` applied (unchecked; [`crate::scene::Scene::with_overrides`] checks).
    pub fn overridden(&self, overrides: &SceneOverrides) -> Params {
        let mut p = self.clone();
        for (param, v) in overrides.iter() {
            (param.set)(&mut p, v);
        }
        p
    }

    /// Every value as overrides (what the app applies to its scene); a mesh file's scene takes
    /// no box parameters ([`Param::used_with`]).
    pub fn as_overrides(&self, kind: MeshKind) -> SceneOverrides {
        let mut o = SceneOverrides::default();
        for p in PARAMS.iter().filter(|p| p.used_with(kind)) {
            (p.set_override)(&mut o, (p.get)(self));
        }
        o
    }

    /// The keys of the parameters (shown in the app) that differ between `self` and `other`.
    pub fn changed_keys(&self, other: &Params) -> Vec<&'static str> {
        PARAMS.iter().filter(|p| (p.get)(self) != (p.get)(other)).map(|p| p.key).collect()
    }

    /// Copies parameter `key` from `from`.
    pub fn copy_from(&mut self, from: &Params, key: &str) {
        if let Some(p) = by_key(key) {
            (p.set)(self, (p.get)(from));
        }
    }

    /// What changing from `self` to `new` invalidates (Nothing: a display or run-length change,
    /// which a running simulation does not see).
    pub fn invalidated_by(&self, new: &Params) -> Invalidates {
        PARAMS
            .iter()
            .filter(|p| (p.get)(self) != (p.get)(new))
            .map(|p| p.invalidates)
            .max()
            .unwrap_or(Invalidates::Nothing)
    }

    /// A short label of a box configuration, e.g. `P2 8×2×2 five` or `P1 8×2×2 five r1`.
    pub fn box_label(&self) -> String {
        let [x, y, z] = self.grid;
        let tets = is_tetrahedral(self);
        let mut s = format!("{} {x}×{y}×{z}", self.element.name().to_uppercase());
        if tets {
            s += &format!(" {}", self.split.name());
            if self.refine > 0 {
                s += &format!(" r{}", self.refine);
            }
        }
        s
    }

    /// Every parameter as JSON, by scene-file path (`material.youngs_modulus_pa`): what a
    /// recording or a report states about its configuration.
    pub fn to_json(&self, kind: MeshKind) -> serde_json::Value {
        let mut out = serde_json::Map::new();
        for p in PARAMS.iter().filter(|p| p.used_with(kind)) {
            out.insert(p.file_path(), (p.get)(self).to_json());
        }
        serde_json::Value::Object(out)
    }
}
