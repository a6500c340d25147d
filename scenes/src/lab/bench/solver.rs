//! Timing the implicit solvers (`hox bench --solver vbd|newton`) on the benchmark beams
//! ([`super::CASES`]) and the curved parts ([`super::PART_CASES`], each its own scene with only
//! the element type and the solver changed): the same bending scene, started from rest, with only the solver changed
//! (each solver's own settings are the scene's, i.e. the defaults: VBD 10 sweeps per step with
//! Chebyshev ρ 0.9 after its coarse correction of 32 cells, whose two gradient evaluations per step
//! and coarse matrix every ten steps are in its times per node update and element visit; Newton to 1e-6 of the load, at most 30 iterations; 1 step per frame).
//!
//! Per case, every thread count runs its own simulation in its own rayon pool, **side by side**:
//! the warm-up frames of each, then timed frames taken in turn (frame 1 on 1 thread, frame 1 on 2
//! threads, frame 2 on 1 thread, …), so a change of the machine's load hits every thread count
//! alike and the speed-up over one thread is measured in one run. On one thread VBD runs its
//! serial sweep, on more its parallel colour sweep (the same bits); Newton's element Hessians and
//! gradients run on the pool's threads, its factorisation on one thread.
//!
//! What is reported, besides the median ms per frame and the counts (machine-independent):
//! - **VBD**: µs per node update, the median over timed frames of `frame time / node updates in
//!   that frame` (a node update is one node's 3×3 block step); µs per element visit, the same
//!   divided by the mean number of elements holding a free node. A node update visits every element
//!   holding the node, so the element visits of a frame are `node updates × mean incidence of the
//!   free nodes` (exact when every free node moves in every sweep, as in the sagging beam: only a
//!   node with exactly zero unbalanced force is skipped).
//! - **Newton**: ms per iteration and ms per factorisation, the timed frames' summed time over
//!   their summed iterations or numeric factorisations (not every iteration refactors: the factor
//!   is kept while the residual falls fast, so ms per factorisation is the whole frame's time per
//!   factorisation, an upper bound of one factorisation's cost); iterations per step.

use super::{BenchCase, matching_solver_cases};
use crate::error::SceneError;
use crate::lab::study::solver_axis::opt;
use hox_sim::measure::median;
use hox_sim::solver::{Method, SimError, Simulation, SolverCounters};
use web_time::Instant;

/// The solver named `name` (`xpbd`, `vbd`, `newton`), or an error naming `--solver` and the
/// allowed values.
pub fn parse_solver(name: &str) -> Result<Method, SceneError> {
    Method::from_name(name).ok_or_else(|| SceneError::Invalid {
        source_name: "bench".into(),
        key: "--solver".into(),
        value: format!("'{name}'"),
        reason: format!(
            "unknown solver; allowed values: {}",
            Method::ALL.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
        ),
    })
}

/// The benchmark beam of `case` ([`super::bending_beam`]) solved by `method`; `parallel` selects
/// the colour sweep (VBD's parallel node sweep).
pub fn bending_beam_solved_by(case: &BenchCase, method: Method, parallel: bool) -> Result<Simulation, SceneError> {
    let sweep = if parallel { hox_sim::solver::Sweep::Colour } else { hox_sim::solver::Sweep::Element };
    super::beam(case, sweep, Some(method))
}

/// One measured row: a case, a solver and a thread count.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverBenchRow {
    pub case: BenchCase,
    pub method: Method,
    /// Rayon threads.
    pub threads: usize,
    /// VBD's parallel colour sweep (else its serial sweep).
    pub parallel: bool,
    pub nodes: usize,
    pub elements: usize,
    /// Nodes the solver moves (not held by the clamp).
    pub free_nodes: usize,
    /// Mean number of elements holding a free node.
    pub elements_per_free_node: f64,
    /// Implicit steps per frame.
    pub steps_per_frame: u32,
    pub timed_frames: usize,
    /// Median over the timed frames.
    pub ms_per_frame: f64,
    /// Means over the timed frames (machine-independent).
    pub node_updates_per_frame: f64,
    pub element_visits_per_frame: f64,
    /// VBD sweeps or Newton iterations.
    pub iterations_per_frame: f64,
    pub iterations_per_step: f64,
    pub factorizations_per_frame: f64,
    /// Newton steps of the timed frames that stopped at their iteration limit.
    pub unconverged_steps: u64,
    /// VBD: median over frames of frame time / node updates.
    pub us_per_node_update: Option<f64>,
    /// VBD: [`Self::us_per_node_update`] / [`Self::elements_per_free_node`].
    pub us_per_element_visit: Option<f64>,
    /// A Newton-type solver (one that updates no node): summed frame time / summed iterations.
    pub ms_per_iteration: Option<f64>,
    /// A Newton-type solver: summed frame time / summed factorisations.
    pub ms_per_factorization: Option<f64>,
    /// ms per frame on one thread over this row's, measured side by side (None without a
    /// one-thread row of the same case).
    pub speedup_over_one_thread: Option<f64>,
}

impl SolverBenchRow {
    /// The progress line printed as each row is measured, e.g.
    /// `P2 8x2x2 vbd on 1 thread(s): 20.61 ms/frame, 4.82 µs/node update`.
    pub fn progress_line(&self) -> String {
        let per = match self.us_per_node_update {
            Some(x) => format!(", {x:.2} µs/node update"),
            None => self.ms_per_iteration.map_or(String::new(), |x| format!(", {x:.3} ms/iteration")),
        };
        format!(
            "{} {} on {} thread(s): {:.2} ms/frame{per}",
            self.case.label(),
            self.method,
            self.threads,
            self.ms_per_frame
        )
    }
}

/// What one timed frame did: its time and the solver's counts.
#[derive(Clone, Copy, Debug, Default)]
struct Frame {
    ms: f64,
    steps: u64,
    iterations: u64,
    node_updates: u64,
    factorizations: u64,
    unconverged_steps: u64,
}

impl Frame {
    fn new(ms: f64, after: SolverCounters, before: SolverCounters) -> Frame {
        Frame {
            ms,
            steps: after.substeps - before.substeps,
            iterations: after.solver_iterations - before.solver_iterations,
            node_updates: after.node_updates - before.node_updates,
            factorizations: after.factorizations - before.factorizations,
            unconverged_steps: after.unconverged_steps - before.unconverged_steps,
        }
    }
}

/// Mean number of elements holding a node the solver moves, and how many such nodes there are.
fn free_node_incidence(sim: &Simulation) -> (f64, usize) {
    let mut holding = vec![0usize; sim.mesh().num_nodes()];
    for block in &sim.mesh().blocks {
        for &node in &block.connectivity {
            holding[node as usize] += 1;
        }
    }
    let free: Vec<usize> = (0..holding.len()).filter(|&i| sim.inv_mass()[i] > 0.0).collect();
    let sum: usize = free.iter().map(|&i| holding[i]).sum();
    (if free.is_empty() { 0.0 } else { sum as f64 / free.len() as f64 }, free.len())
}

/// Times `case` solved by `method` on each of `threads`, side by side (see the module doc):
/// `warmup_frames` untimed frames each, then up to `frames` timed frames each, taken in turn and
/// capped by `budget_secs` of timed work in all (at least 3 frames each).
pub fn measure_side_by_side(
    case: &BenchCase,
    method: Method,
    threads: &[usize],
    warmup_frames: usize,
    frames: usize,
    budget_secs: f64,
) -> Result<Vec<SolverBenchRow>, SceneError> {
    let failed = |e: SimError| SceneError::Simulation { source_name: case.label(), message: e.to_string() };
    let mut runs = Vec::with_capacity(threads.len());
    for &t in threads {
        let t = t.max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| SceneError::Simulation { source_name: "bench".into(), message: e.to_string() })?;
        let mut sim = pool.install(|| bending_beam_solved_by(case, method, t > 1))?;
        pool.install(|| (0..warmup_frames).try_for_each(|_| sim.step_frame())).map_err(failed)?;
        runs.push((t, pool, sim, Vec::<Frame>::with_capacity(frames)));
    }
    let start = Instant::now();
    for i in 0..frames.max(1) {
        for (_, pool, sim, timed) in &mut runs {
            let before = sim.counters();
            let clock = Instant::now();
            pool.install(|| sim.step_frame()).map_err(failed)?;
            let ms = clock.elapsed().as_secs_f64() * 1e3;
            timed.push(Frame::new(ms, sim.counters(), before));
        }
        if i >= 2 && start.elapsed().as_secs_f64() > budget_secs {
            break;
        }
    }
    let mut rows: Vec<SolverBenchRow> =
        runs.iter().map(|(t, _, sim, timed)| row(case, method, *t, sim, timed)).collect();
    let one_thread = rows.iter().find(|r| r.threads == 1).map(|r| r.ms_per_frame);
    for r in &mut rows {
        r.speedup_over_one_thread = one_thread.map(|one| one / r.ms_per_frame);
    }
    Ok(rows)
}

fn row(case: &BenchCase, method: Method, threads: usize, sim: &Simulation, timed: &[Frame]) -> SolverBenchRow {
    let n = timed.len() as f64;
    let total = |f: fn(&Frame) -> u64| timed.iter().map(f).sum::<u64>();
    let total_ms: f64 = timed.iter().map(|f| f.ms).sum();
    let (elements_per_free_node, free_nodes) = free_node_incidence(sim);
    let (iterations, steps, updates, factorizations) =
        (total(|f| f.iterations), total(|f| f.steps), total(|f| f.node_updates), total(|f| f.factorizations));
    // a solver that updates no node (a Newton-type one) is measured per iteration and factorisation
    let newton_per = |count: u64| (updates == 0 && count > 0).then(|| total_ms / count as f64);
    let mut per_update: Vec<f64> =
        timed.iter().filter(|f| f.node_updates > 0).map(|f| f.ms * 1e3 / f.node_updates as f64).collect();
    let us_per_node_update = (!per_update.is_empty()).then(|| median(&mut per_update));
    let mut ms: Vec<f64> = timed.iter().map(|f| f.ms).collect();
    SolverBenchRow {
        case: *case,
        method,
        threads,
        parallel: sim.settings().sweep.is_colour(),
        nodes: sim.mesh().num_nodes(),
        elements: sim.mesh().num_elements(),
        free_nodes,
        elements_per_free_node,
        steps_per_frame: sim.substeps_per_frame(),
        timed_frames: timed.len(),
        ms_per_frame: median(&mut ms),
        node_updates_per_frame: updates as f64 / n,
        element_visits_per_frame: updates as f64 * elements_per_free_node / n,
        iterations_per_frame: iterations as f64 / n,
        iterations_per_step: if steps > 0 { iterations as f64 / steps as f64 } else { 0.0 },
        factorizations_per_frame: factorizations as f64 / n,
        unconverged_steps: total(|f| f.unconverged_steps),
        us_per_node_update,
        us_per_element_visit: us_per_node_update
            .filter(|_| elements_per_free_node > 0.0)
            .map(|us| us / elements_per_free_node),
        ms_per_iteration: newton_per(iterations),
        ms_per_factorization: newton_per(factorizations),
        speedup_over_one_thread: None,
    }
}

/// Measures the cases matching `filter` ([`matching_cases`]) solved by `method` (VBD or Newton;
/// XPBD's table is [`super::run`]'s), each on all of `threads` side by side, reporting each row to
/// `progress` (what `hox bench --solver` runs).
pub fn run(
    filter: &str,
    method: Method,
    threads: &[usize],
    frames: usize,
    progress: &mut dyn FnMut(&SolverBenchRow),
) -> Result<Vec<SolverBenchRow>, SceneError> {
    let mut rows = Vec::new();
    for case in matching_solver_cases(filter) {
        for row in measure_side_by_side(case, method, threads, super::WARMUP_FRAMES, frames, super::BUDGET_SECS)? {
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

fn speedup(r: &SolverBenchRow) -> String {
    match r.speedup_over_one_thread {
        Some(_) if r.threads == 1 => "1 (base)".into(),
        Some(s) => format!("{s:.2}×"),
        None => "—".into(),
    }
}

/// The table `hox bench --solver` prints: per case, one row per thread count. Newton-type rows (no
/// node updates) get the iteration and factorisation columns, the others (VBD) the node-update
/// columns; one table each.
pub fn markdown(rows: &[SolverBenchRow]) -> String {
    let (newton, sweeps): (Vec<&SolverBenchRow>, Vec<&SolverBenchRow>) =
        rows.iter().partition(|r| r.node_updates_per_frame == 0.0);
    let mut s = String::new();
    if !sweeps.is_empty() {
        s.push_str(
            "| configuration | solver | nodes | elements | elements per free node | threads | sweep | sweeps/frame | node updates/frame | element visits/frame | ms/frame | µs per node update | µs per element visit | speed-up over 1 thread |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in sweeps {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {:.2} | {} | {} | {:.0} | {:.0} | {:.0} | {:.2} | {} | {} | {} |\n",
                r.case.label(),
                r.method,
                r.nodes,
                r.elements,
                r.elements_per_free_node,
                r.threads,
                if r.parallel { "colour" } else { "serial" },
                r.iterations_per_frame,
                r.node_updates_per_frame,
                r.element_visits_per_frame,
                r.ms_per_frame,
                opt(r.us_per_node_update, 2),
                opt(r.us_per_element_visit, 3),
                speedup(r),
            ));
        }
    }
    if !newton.is_empty() {
        if !s.is_empty() {
            s.push('\n');
        }
        s.push_str(
            "| configuration | solver | nodes | elements | threads | steps/frame | iterations/frame | iterations/step | factorisations/frame | unconverged steps | ms/frame | ms per iteration | ms per factorisation | speed-up over 1 thread |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in newton {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {} | {:.2} | {} | {} | {} |\n",
                r.case.label(),
                r.method,
                r.nodes,
                r.elements,
                r.threads,
                r.steps_per_frame,
                r.iterations_per_frame,
                r.iterations_per_step,
                r.factorizations_per_frame,
                r.unconverged_steps,
                r.ms_per_frame,
                opt(r.ms_per_iteration, 3),
                opt(r.ms_per_factorization, 3),
                speedup(r),
            ));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_solver_names_the_flag_and_the_allowed_values() {
        assert_eq!(parse_solver("vbd").unwrap(), Method::Vbd);
        let message = parse_solver("foo").unwrap_err().to_string();
        for needle in ["--solver", "'foo'", "xpbd, vbd, newton"] {
            assert!(message.contains(needle), "{needle} not in: {message}");
        }
    }

    /// The counts are the solvers' own: VBD updates every free node once per sweep, Newton counts
    /// its iterations and factorisations; the timings are positive and finite.
    #[test]
    fn rows_count_the_solvers_work() {
        let case = BenchCase { scene: "bending", element: "p1", grid: [4, 1, 1], refine: 0, paper_ms_per_frame: None };
        let vbd = measure_side_by_side(&case, Method::Vbd, &[1, 2], 1, 2, 60.0).unwrap();
        assert_eq!(vbd.len(), 2);
        for r in &vbd {
            assert_eq!(r.timed_frames, 2);
            assert_eq!(r.iterations_per_frame, 10.0, "10 sweeps per step, 1 step per frame");
            assert_eq!(r.node_updates_per_frame, 10.0 * r.free_nodes as f64);
            assert!(r.free_nodes > 0 && r.free_nodes < r.nodes, "the clamp holds some nodes");
            assert!(r.elements_per_free_node >= 1.0);
            assert_eq!(r.element_visits_per_frame, r.node_updates_per_frame * r.elements_per_free_node);
            for t in [r.ms_per_frame, r.us_per_node_update.unwrap(), r.us_per_element_visit.unwrap()] {
                assert!(t.is_finite() && t > 0.0, "{t}");
            }
            assert!(r.speedup_over_one_thread.is_some_and(|s| s.is_finite() && s > 0.0));
            assert_eq!(r.ms_per_iteration, None);
        }
        assert!(!vbd[0].parallel && vbd[1].parallel);
        let newton = measure_side_by_side(&case, Method::Newton, &[1], 1, 2, 60.0).unwrap();
        let r = &newton[0];
        assert!(r.iterations_per_frame >= 1.0 && r.iterations_per_step == r.iterations_per_frame);
        assert!(r.factorizations_per_frame <= 2.0 * r.iterations_per_frame);
        assert_eq!(r.node_updates_per_frame, 0.0);
        assert!(r.ms_per_iteration.is_some_and(|t| t.is_finite() && t > 0.0));
        let table = markdown(&[vbd, newton].concat());
        assert!(table.contains("µs per node update") && table.contains("ms per factorisation"), "{table}");
    }

    /// Issue #37: the implicit solvers are timed on the curved parts as on the beams; `--only tube`
    /// picks the tube at each order, an exact label one of them.
    #[test]
    fn the_curved_parts_are_timed_like_the_beams() {
        let labels = |f: &str| super::super::matching_solver_cases(f).iter().map(|c| c.label()).collect::<Vec<_>>();
        assert_eq!(labels("tube"), ["P1 tube", "P2 tube", "P3 tube"]);
        assert_eq!(labels("P2 tube"), ["P2 tube"]);
        assert!(super::super::matching_cases("tube").is_empty(), "XPBD's table is the beams'");
        let case = super::super::PART_CASES[0];
        let rows = measure_side_by_side(&case, Method::Newton, &[1], 1, 2, 60.0).unwrap();
        let r = &rows[0];
        assert_eq!((r.case.label().as_str(), r.nodes, r.elements), ("P1 tube", 829, 2424));
        assert!(r.iterations_per_frame >= 1.0 && r.ms_per_frame.is_finite());
    }
}
