//! The study's solver axis (issue #19): for each paper scene and mesh, each solver at its
//! defaults and XPBD on a grid of substeps × iterations, run from rest on **one thread** until
//! settled (the scene's settle damping; [`crate::run`]).
//!
//! Per row:
//! - **solver error**: settled probes against the static solution of the same mesh
//!   ([`hox_sim::solver::statics`]), % of the static displacement;
//! - **total error**: against the fine Q2 reference, % of the reference displacement; the
//!   **discretisation** error (static on this mesh vs reference) is the part no solver removes;
//! - **ms per frame**: the mean frame while the body moves — the first
//!   [`super::motion::MOTION_SECS`] from rest without damping (bending: the beam released;
//!   tension and torsion: the ramp of their drives) — in a one-thread rayon pool (a settling
//!   run's median would mostly time frames at rest, nearly free for Newton);
//! - **seconds to 1 %**: wall time from rest until the probe error against the static solution
//!   falls under 1 % and stays there until the run ends (none if it never does);
//! - bending, **accuracy in motion** ([`super::motion`]): the same solver and mesh released
//!   from rest without damping for [`super::motion::MOTION_SECS`]; the first period and the
//!   amplitude around 2 s against the reference motion (Newmark on Q2 16×4×4). Their errors mix
//!   the mesh's (a coarse mesh is stiffer: a shorter period) and the time integrator's
//!   (implicit Euler and XPBD's damping shrink the amplitude).
//!
//! XPBD keeps its stability guard: a grid point the guard raises is run, and labelled, at the
//! substeps it took.

use super::motion::{Motion, MotionMetrics, reference_motion};
use super::{StudyConfig, probe_distance, probes_of, reference, settled_probes};
use crate::error::SceneError;
use crate::instance::Instance;
use crate::params::SceneOverrides;
use crate::run::{RunMode, run_observed};
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::{Integrator, Method};
use web_time::Instant;

/// XPBD's grid of (substeps, iterations) per frame: equal sweep budgets of 50 and 100.
pub const XPBD_GRID: [(u32, u32); 5] = [(50, 1), (25, 2), (10, 5), (100, 1), (50, 2)];

/// The error, % of the reference, the study's "cheapest configuration" must reach.
pub const TARGET_ERROR_PCT: f64 = 1.0;

/// The frame budget of real time at 60 frames per second, ms.
pub const REAL_TIME_MS: f64 = 1000.0 / 60.0;

/// One solver at one setting: XPBD at a grid point of substeps × iterations, or an implicit
/// solver of the registry ([`Method::ALL`]) at its defaults with one of the integrators
/// ([`Integrator::ALL`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolverChoice {
    Xpbd { substeps: u32, iterations: u32 },
    Implicit(Method, Integrator),
}

impl SolverChoice {
    /// XPBD's grid, then VBD and Newton at their defaults under each integrator.
    pub fn all() -> Vec<SolverChoice> {
        let mut v: Vec<SolverChoice> =
            XPBD_GRID.iter().map(|&(substeps, iterations)| SolverChoice::Xpbd { substeps, iterations }).collect();
        for m in Method::ALL.into_iter().filter(|m| m.is_implicit()) {
            v.extend(Integrator::ALL.map(|i| SolverChoice::Implicit(m, i)));
        }
        v
    }
    /// "xpbd 50x1", "vbd bdf2", "newton newmark".
    pub fn label(&self) -> String {
        match self {
            SolverChoice::Xpbd { substeps, iterations } => format!("xpbd {substeps}x{iterations}"),
            SolverChoice::Implicit(m, i) => format!("{} {}", m.name(), i.name()),
        }
    }
    pub fn method(&self) -> &'static str {
        self.solver().name()
    }
    fn solver(&self) -> Method {
        match self {
            SolverChoice::Xpbd { .. } => Method::Xpbd,
            SolverChoice::Implicit(m, _) => *m,
        }
    }
    fn overrides(&self) -> SceneOverrides {
        match *self {
            SolverChoice::Xpbd { substeps, iterations } => SceneOverrides {
                method: Some(Method::Xpbd),
                substeps: Some(substeps),
                iterations: Some(iterations),
                ..Default::default()
            },
            SolverChoice::Implicit(m, i) => {
                SceneOverrides { method: Some(m), integrator: Some(i), ..Default::default() }
            }
        }
    }
}

/// The meshes of the solver axis for a scene: one per element type (the paper's five-split
/// meshes and the study's others), and for bending the cheapest meshes whose static
/// discretisation error is under 1 % (issue #19: P3 6×2×2 0.91 %, P3 8×2×2 0.67 %, P2 16×4×4
/// 0.69 %, Q2 12×3×3 0.74 %). `quick`: bending P1 16×4×4 and P2 8×2×2 only.
pub fn solver_configurations(scene: &str, quick: bool) -> Vec<StudyConfig> {
    use TetSplit::Five;
    let c = StudyConfig::new;
    if quick {
        return if scene == "bending" {
            vec![c("p1", [16, 4, 4], Five, 0, false), c("p2", [8, 2, 2], Five, 0, false)]
        } else {
            Vec::new()
        };
    }
    let mut configs: Vec<StudyConfig> =
        super::configurations(scene).into_iter().filter(|c| c.split == Five && c.refine == 0).collect();
    if scene == "bending" {
        configs.extend([
            c("p3", [6, 2, 2], Five, 0, true),
            c("p3", [8, 2, 2], Five, 0, true),
            c("p2", [16, 4, 4], Five, 0, true),
            c("q2", [12, 3, 3], Five, 0, true),
        ]);
    }
    configs
}

/// Simulated-time cap of a settling run on the solver axis, seconds (heavy meshes: shorter).
fn settle_cap_secs(heavy: bool) -> f64 {
    if heavy { 10.0 } else { 20.0 }
}

/// One row of the solver axis.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverRow {
    pub scene: String,
    pub config: String,
    pub element: String,
    pub elements: usize,
    pub nodes: usize,
    /// "xpbd 50x1", "vbd bdf2", "newton newmark" (XPBD at the substeps it took, if the guard
    /// raised them).
    pub solver: String,
    /// Element sweeps per frame: XPBD substeps × iterations, VBD steps × sweeps, Newton the mean
    /// iterations (each a factorisation or a back-substitution) per frame.
    pub sweeps_per_frame: f64,
    /// Mean ms per frame on one thread over the first seconds of motion from rest.
    pub ms_per_frame: f64,
    /// Settled probes against the static solution on this mesh, % of the static displacement.
    pub solver_error_pct: f64,
    /// Settled probes against the reference, m and % of the reference displacement.
    pub error_m: f64,
    pub error_pct: f64,
    /// Static solution on this mesh against the reference, % of the reference displacement.
    pub discretisation_pct: f64,
    pub settled: bool,
    pub at_rest: bool,
    pub residual_rel: f64,
    /// Wall seconds from rest until within 1 % of the static solution for good (None: never).
    pub secs_to_1pct: Option<f64>,
    /// Simulated seconds the settling run took.
    pub sim_secs: f64,
    /// Bending: first period and amplitude around 2 s against the reference motion, %.
    pub period_error_pct: Option<f64>,
    pub amplitude_error_pct: Option<f64>,
    /// Why the row has no numbers (a blow-up), if so.
    pub failure: Option<String>,
}

/// The rows of one mesh of the solver axis (a cell of [`super::shard::Plan`]): its static
/// solution once, then every solver, on one thread.
pub fn mesh_rows(
    scene_name: &str,
    config: &StudyConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<SolverRow>, SceneError> {
    let pool = super::one_thread()?;
    let mut rows = Vec::new();
    config_rows(&pool, scene_name, config, &reference_motion()?.metrics(), progress, &mut rows)?;
    Ok(rows)
}

/// The rows of one mesh: its static solution once, then every solver.
fn config_rows(
    pool: &rayon::ThreadPool,
    scene_name: &str,
    config: &StudyConfig,
    motion_reference: &MotionMetrics,
    progress: &mut dyn FnMut(&str),
    rows: &mut Vec<SolverRow>,
) -> Result<(), SceneError> {
    let reference = reference(scene_name)?;
    let reference_size = reference.iter().map(|(_, u)| u.norm()).fold(0.0, f64::max);
    let scene = crate::scene::builtin::by_name(scene_name)?.with_overrides(&config.overrides())?;
    let label = config.label();
    progress(&format!("solvers: {scene_name} {label}: static solution"));
    let instance = Instance::new(scene.clone())?;
    let mesh = instance.sim.mesh();
    let statics = pool
        .install(|| crate::instance::solve_static(&scene, mesh, 1e-8, 1, &mut |_, _, _| {}))
        .map_err(|e| SceneError::Simulation { source_name: format!("{scene_name} {label}"), message: e.to_string() })?;
    let static_probes = probes_of(&instance, &statics.positions);
    let static_size = static_probes.iter().map(|(_, u)| u.norm()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let discretisation_pct = 100.0 * probe_distance(&static_probes, &reference) / reference_size;
    for choice in SolverChoice::all() {
        progress(&format!("solvers: {scene_name} {label}: {} settling from rest", choice.label()));
        let solver_scene = scene.with_overrides(&choice.overrides())?;
        let mut row = SolverRow {
            scene: scene_name.to_string(),
            config: label.clone(),
            element: config.element.to_string(),
            elements: instance.sim.mesh().num_elements(),
            nodes: instance.sim.mesh().num_nodes(),
            solver: choice.label(),
            sweeps_per_frame: f64::NAN,
            ms_per_frame: f64::NAN,
            solver_error_pct: f64::NAN,
            error_m: f64::NAN,
            error_pct: f64::NAN,
            discretisation_pct,
            settled: false,
            at_rest: false,
            residual_rel: f64::NAN,
            secs_to_1pct: None,
            sim_secs: 0.0,
            period_error_pct: None,
            amplitude_error_pct: None,
            failure: None,
        };
        // settling from rest, timing when the error against the static solution stays under 1 %
        let mut settling = Instance::new(solver_scene.clone())?;
        let started = Instant::now();
        let mut within_since: Option<f64> = None;
        let mut on_frame = |i: &Instance| {
            let error = probe_distance(&probes_of(i, &i.sim.positions), &static_probes) / static_size;
            within_since = if error <= 0.01 { within_since.or(Some(started.elapsed().as_secs_f64())) } else { None };
            Ok(())
        };
        let cap_secs = settle_cap_secs(config.heavy);
        let settle =
            pool.install(|| run_observed(&mut settling, RunMode::Settle { cap_secs }, &mut |_, _| {}, &mut on_frame));
        let report = match settle {
            Ok(r) => r,
            Err(e) => {
                row.failure = Some(e.to_string());
                rows.push(row);
                continue;
            }
        };
        let counters = settling.sim.counters();
        let frames = report.frames.max(1) as f64;
        row.sweeps_per_frame = match choice {
            SolverChoice::Xpbd { iterations, .. } => (settling.sim.substeps_per_frame() * iterations) as f64,
            SolverChoice::Implicit(..) => counters.solver_iterations as f64 / frames,
        };
        if let SolverChoice::Xpbd { substeps, iterations } = choice
            && settling.sim.substeps_per_frame() != substeps
        {
            row.solver = format!("xpbd {}x{iterations} (guard; asked {substeps})", settling.sim.substeps_per_frame());
        }
        let probes = settled_probes(&report);
        row.solver_error_pct = 100.0 * probe_distance(&probes, &static_probes) / static_size;
        row.error_m = probe_distance(&probes, &reference);
        row.error_pct = 100.0 * row.error_m / reference_size;
        row.settled = report.settled;
        row.at_rest = report.at_rest;
        row.residual_rel = report.residual_rel;
        row.secs_to_1pct = within_since;
        row.sim_secs = report.sim_seconds;
        // the cost of motion, and (bending) its accuracy: released from rest, undamped
        progress(&format!("solvers: {scene_name} {label}: {} released from rest", choice.label()));
        let mut moving = Instance::new(solver_scene)?;
        let probe = moving.probes.first().map(|p| p.name.clone()).unwrap_or_default();
        let probe = if scene_name == "bending" { "tip".to_string() } else { probe };
        match pool.install(|| super::motion::record_motion(&mut moving, super::motion::MOTION_SECS, &probe)) {
            Ok(recorded) => {
                row.ms_per_frame = recorded.mean_ms_per_frame;
                if scene_name == "bending" {
                    let (period, amplitude) = motion_errors(&recorded.motion, motion_reference);
                    row.period_error_pct = period;
                    row.amplitude_error_pct = amplitude;
                }
            }
            Err(e) => row.failure = Some(format!("in motion: {e}")),
        }
        rows.push(row);
    }
    Ok(())
}

/// The period and amplitude errors of `motion` against the reference's, %.
pub fn motion_errors(motion: &Motion, reference: &MotionMetrics) -> (Option<f64>, Option<f64>) {
    let m = motion.metrics();
    let rel = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b != 0.0 => Some(100.0 * (a - b) / b),
        _ => None,
    };
    (rel(m.period_secs, reference.period_secs), rel(m.amplitude_m, reference.amplitude_m))
}

/// A row counts for "reaches 1 % of the reference" when it came to rest, its total error is at
/// most 1 % and so is its mesh's discretisation error (a total under 1 % on a mesh whose own
/// error is larger is a cancellation between mesh and solver, not accuracy).
pub fn reaches_target(r: &SolverRow) -> bool {
    r.failure.is_none()
        && (r.settled || r.at_rest)
        && r.error_pct <= TARGET_ERROR_PCT
        && r.discretisation_pct <= TARGET_ERROR_PCT
}

/// The cheapest row (ms per frame on one thread) of `scene` that reaches 1 % of the reference.
pub fn cheapest_within_target<'a>(rows: &'a [SolverRow], scene: &str) -> Option<&'a SolverRow> {
    rows.iter()
        .filter(|r| r.scene == scene && reaches_target(r))
        .min_by(|a, b| a.ms_per_frame.total_cmp(&b.ms_per_frame))
}

/// The Pareto frontier of `scene`'s rows in (ms per frame, total error): the rows no other row
/// beats on both, in order of increasing ms.
pub fn pareto_frontier<'a>(rows: &'a [SolverRow], scene: &str) -> Vec<&'a SolverRow> {
    let mut candidates: Vec<&SolverRow> = rows
        .iter()
        .filter(|r| r.scene == scene && r.failure.is_none() && r.ms_per_frame.is_finite() && r.error_pct.is_finite())
        .collect();
    candidates.sort_by(|a, b| a.ms_per_frame.total_cmp(&b.ms_per_frame).then(a.error_pct.total_cmp(&b.error_pct)));
    let mut best = f64::INFINITY;
    candidates
        .into_iter()
        .filter(|r| {
            let keep = r.error_pct < best;
            best = best.min(r.error_pct);
            keep
        })
        .collect()
}

/// A number with `digits` decimals, or "—".
pub(crate) fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "—".into(), |v| format!("{v:.digits$}"))
}

fn signed(v: Option<f64>) -> String {
    v.map_or_else(|| "—".into(), |v| format!("{v:+.1}"))
}

/// `study.md`'s solver-axis section: a table per scene and the cheapest row within 1 %.
pub fn solver_markdown(rows: &[SolverRow]) -> String {
    let mut s = String::from(
        "## The solver axis: what accuracy costs with each solver\n\nEach mesh with XPBD on a grid of substeps × iterations (equal sweep budgets) and with VBD and Newton at their defaults, from rest on **one thread** until settled (settle damping 10/s; VBD with its coarse correction, `vbd_coarse_cells` 32, as the others). *Solver*: settled probes against the static solution of the same mesh; *total*: against the reference; *mesh*: the static solution's own (discretisation) error, which no solver removes. *ms/frame*: the mean frame over the first 2.5 s of motion from rest (no damping; bending: the beam released, tension and torsion: their drives' ramps). *Sweeps/frame*: XPBD substeps × iterations; VBD sweeps; Newton iterations (factorisations or back-substitutions) per frame while settling. *To 1 %*: wall seconds until the error against the static solution stays under 1 % (— never). *Settles*: in equilibrium (residual ≤ 1e-5 of the load), at rest but not in equilibrium (XPBD's bias), or neither by the cap. Bending also: the first period and the amplitude around 2 s of the beam released from rest without damping, against the reference motion (Newmark, Q2 16×4×4; `assets/reference/bending-motion.json`).\n\n",
    );
    for scene in crate::scene::builtin::PAPER_SCENES {
        let scene_rows: Vec<&SolverRow> = rows.iter().filter(|r| r.scene == scene).collect();
        if scene_rows.is_empty() {
            continue;
        }
        s.push_str(&format!("### {scene}\n\n| configuration | elements | solver | sweeps/frame | ms/frame (1 thread) | solver (%) | total (%) | mesh (%) | settles | to 1 % (s) |"));
        let motion = scene == "bending";
        if motion {
            s.push_str(" period (%) | amplitude at 2 s (%) |");
        }
        s.push_str(&format!("\n|{}\n", "---|".repeat(if motion { 12 } else { 10 })));
        for r in scene_rows {
            let settles = match (&r.failure, r.settled, r.at_rest) {
                (Some(f), _, _) => format!("failed: {f}"),
                (None, true, _) => "yes".into(),
                (None, false, true) => format!("at rest, residual {:.0e}", r.residual_rel),
                (None, false, false) => format!("no ({:.0} s cap)", r.sim_secs),
            };
            s.push_str(&format!(
                "| {} | {} | {} | {:.1} | {:.2} | {:.3} | {:.2} | {:.2} | {} | {} |",
                r.config,
                r.elements,
                r.solver,
                r.sweeps_per_frame,
                r.ms_per_frame,
                r.solver_error_pct,
                r.error_pct,
                r.discretisation_pct,
                settles,
                opt(r.secs_to_1pct, 2),
            ));
            if motion {
                s.push_str(&format!(" {} | {} |", signed(r.period_error_pct), signed(r.amplitude_error_pct)));
            }
            s.push('\n');
        }
        s.push('\n');
        s.push_str(&cheapest_sentence(rows, scene));
        s.push_str("\n\n");
    }
    s
}

/// "Cheapest within 1 % of the reference on bending: … at … ms per frame (… the 16.7 ms of 60 fps)."
pub fn cheapest_sentence(rows: &[SolverRow], scene: &str) -> String {
    match cheapest_within_target(rows, scene) {
        None => format!(
            "**{scene}**: no configuration here reaches {TARGET_ERROR_PCT} % of the reference with a mesh whose own error is under {TARGET_ERROR_PCT} %."
        ),
        Some(r) => {
            let budget = if r.ms_per_frame <= REAL_TIME_MS {
                format!("within the {REAL_TIME_MS:.1} ms of 60 frames per second on one thread")
            } else {
                format!(
                    "{:.1}× the {REAL_TIME_MS:.1} ms of 60 frames per second on one thread",
                    r.ms_per_frame / REAL_TIME_MS
                )
            };
            format!(
                "**{scene}**: the cheapest configuration within {TARGET_ERROR_PCT} % of the reference is **{} with {}** ({} elements): {:.2} % total error ({:.2} % of it the mesh's), {:.2} ms per frame — {budget}; from rest it is within 1 % of its static solution after {} s of wall time.",
                r.config,
                r.solver,
                r.elements,
                r.error_pct,
                r.discretisation_pct,
                r.ms_per_frame,
                opt(r.secs_to_1pct, 2)
            )
        }
    }
}

/// `solvers.csv`: the rows.
pub fn solver_csv(rows: &[SolverRow]) -> String {
    let mut s = String::from(
        "scene,configuration,element,elements,nodes,solver,sweeps_per_frame,ms_per_frame_1_thread,solver_error_pct,error_m,error_pct,discretisation_pct,settled,at_rest,residual_rel,secs_to_1pct,sim_secs,period_error_pct,amplitude_error_pct,failure\n",
    );
    let o = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.scene,
            r.config,
            r.element,
            r.elements,
            r.nodes,
            r.solver,
            r.sweeps_per_frame,
            r.ms_per_frame,
            r.solver_error_pct,
            r.error_m,
            r.error_pct,
            r.discretisation_pct,
            r.settled,
            r.at_rest,
            r.residual_rel,
            o(r.secs_to_1pct),
            r.sim_secs,
            o(r.period_error_pct),
            o(r.amplitude_error_pct),
            r.failure.as_deref().unwrap_or("").replace([',', '\n'], ";"),
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::pareto::{dummy_row, pareto_svg};
    use super::*;

    fn row(config: &str, solver: &str, ms: f64, error_pct: f64, mesh_pct: f64) -> SolverRow {
        SolverRow {
            scene: "bending".into(),
            config: config.into(),
            element: "p2".into(),
            solver: solver.into(),
            ms_per_frame: ms,
            error_pct,
            discretisation_pct: mesh_pct,
            settled: true,
            at_rest: true,
            ..dummy_row()
        }
    }

    #[test]
    fn the_pareto_frontier_keeps_only_rows_no_other_beats_on_time_and_error() {
        let rows = vec![
            row("a", "xpbd 50x1", 2.0, 1.5, 1.8),
            row("b", "xpbd 50x2", 4.0, 0.4, 0.2),
            row("c", "vbd", 5.0, 0.9, 0.2), // slower and worse than b
            row("d", "newton", 1.0, 3.0, 1.8),
            row("e", "newton", 9.0, 0.1, 0.05),
        ];
        let f: Vec<&str> = pareto_frontier(&rows, "bending").iter().map(|r| r.config.as_str()).collect();
        assert_eq!(f, ["d", "a", "b", "e"]);
    }

    #[test]
    fn the_cheapest_row_within_one_percent_ignores_cancellations_and_unsettled_runs() {
        let mut unsettled = row("u", "vbd", 0.5, 0.3, 0.3);
        (unsettled.settled, unsettled.at_rest) = (false, false);
        let rows = vec![
            row("cancel", "xpbd 50x1", 1.0, 0.04, 1.4), // total under 1 % only by cancellation
            unsettled,
            row("honest", "newton", 3.0, 0.7, 0.69),
            row("dearer", "xpbd 50x2", 6.0, 0.6, 0.69),
        ];
        assert_eq!(cheapest_within_target(&rows, "bending").unwrap().config, "honest");
        let sentence = cheapest_sentence(&rows, "bending");
        assert!(sentence.contains("honest with newton") && sentence.contains("within the 16.7 ms"), "{sentence}");
        assert!(cheapest_sentence(&rows, "torsion").contains("no configuration"));
    }

    #[test]
    fn the_chart_draws_every_solver_marker_and_the_frontier() {
        let rows = vec![
            row("a", "xpbd 50x1", 2.0, 1.5, 1.8),
            row("b", "vbd", 4.0, 0.4, 0.2),
            row("c", "newton", 9.0, 0.1, 0.05),
        ];
        let svg = pareto_svg(&rows, "bending");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("class=\"pareto\"") && svg.contains("<rect x=") && svg.contains(" Z\""));
        assert!(svg.contains("16.7 ms (60 fps)"));
    }

    #[test]
    fn the_grid_has_the_issues_budgets_and_every_solver() {
        let labels: Vec<String> = SolverChoice::all().iter().map(SolverChoice::label).collect();
        for want in [
            "xpbd 50x1",
            "xpbd 25x2",
            "xpbd 10x5",
            "xpbd 100x1",
            "xpbd 50x2",
            "vbd euler",
            "vbd newmark",
            "vbd bdf2",
            "newton euler",
            "newton newmark",
            "newton bdf2",
        ] {
            assert!(labels.iter().any(|l| l == want), "{want} missing from {labels:?}");
        }
        let bending = solver_configurations("bending", false);
        for want in ["P3 6x2x2 five", "P3 8x2x2 five", "P2 16x4x4 five", "Q2 12x3x3"] {
            assert!(bending.iter().any(|c| c.label() == want), "{want} missing");
        }
    }
}
