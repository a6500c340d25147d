//! Timing the XPBD loop on the paper's bending beam (Saillant et al., Table 1): the five
//! configurations of Table 1 plus Q1, Q2, prism and pyramid beams, ms per frame as the median of
//! timed frames. The beam is the built-in `bending` scene (`assets/scenes/bending.toml`: StVK
//! E = 3 MPa, ν = 0.35, ρ = 1000 kg/m³, 50 substeps × 1 iteration, 60 fps, energy formulation,
//! gravity, clamped at x = 0) with only the element type, grid, refinement and sweep of each
//! case overridden: change the scene file and the benchmark follows.
//!
//! **Flop count.** Per element and substep, with `N` nodes and `Q` quadrature points, the energy
//! kernel ([`hox_sim::xpbd::kernels`]) does, counting a fused multiply–add as 2 flops:
//! - per point: `F = I + Σ_i u_i ⊗ ∇N_i` (18N), StVK `E`, `S`, `ψ`, `P = F S` (165), and
//!   `∇_i U += V P ∇N_i` (18N + 9);
//! - per element: displacements `u_i = x_i − X_i` (3N), `Σ_i w_i |∇_i U|²` (6N), the update
//!   (10, one square root and one division counted as 1 each) and `x_i += w_i step ∇_i U` (7N).
//!
//! So `flops = Q (36 N + 174) + 16 N + 10`: 392 for P1. Achieved GFLOP/s = flops × elements ×
//! substeps / time. The machine's peak is measured ([`peak`]): one core running nothing but
//! independent 256-bit fused multiply–adds.
//!
//! The implicit solvers (VBD, Newton) on the same beams: [`solver`] (`hox bench --solver`).

pub mod peak;
pub mod solver;

use crate::error::SceneError;
use crate::instance::Instance;
use crate::params::SceneOverrides;
use hox_sim::element::ElementType;
use hox_sim::measure::median;
use hox_sim::solver::{Simulation, Sweep};
use web_time::Instant;

/// The peak rate used when the CPU cannot be measured (no AVX2): 2.7 GHz × 2 FMA units ×
/// 4 doubles × 2 flops per FMA, the nominal figure of the project's first machine. Where AVX2
/// and FMA exist, `hox bench` measures the peak instead ([`peak::measured_avx2_peak_gflops`]).
pub const NOMINAL_PEAK_GFLOPS_PER_CORE: f64 = 2.7 * 2.0 * 4.0 * 2.0;

/// The machine every figure is measured on, as the tables in docs/ name it: `"CPU", N logical
/// cores` (the CPU's model name from /proc/cpuinfo, else the architecture).
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("\"{cpu}\", {cores} logical cores")
}

/// One benchmarked configuration: a bending beam, or a curved part ([`PART_CASES`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchCase {
    /// The built-in scene: `bending` (the beams: element, grid and refinement overridden) or a
    /// curved part (`tube`, `elbow`, `hook`: only the element, which picks the part's file).
    pub scene: &'static str,
    pub element: &'static str,
    pub grid: [usize; 3],
    pub refine: usize,
    /// The paper's Table 1 time, ms per frame (its own machine), where it has one.
    pub paper_ms_per_frame: Option<f64>,
}

impl BenchCase {
    pub fn label(&self) -> String {
        if self.scene != "bending" {
            return format!("{} {}", self.element.to_uppercase(), self.scene);
        }
        let [x, y, z] = self.grid;
        let r = if self.refine > 0 { format!(" r{}", self.refine) } else { String::new() };
        format!("{} {x}x{y}x{z}{r}", self.element.to_uppercase())
    }
}

/// The five rows of Table 1, then Q1, Q2, prism and pyramid beams of comparable node count
/// (the meshes of the study, `scenes/src/lab/study/`), then a large beam of every element type
/// but P1 (whose largest is Table 1's 81,920): 32 cells along the beam (24 for the pyramids),
/// large enough for the colour sweep to cut it into slabs for the threads.
pub const CASES: [BenchCase; 15] = [
    BenchCase { scene: "bending", element: "p1", grid: [16, 4, 4], refine: 0, paper_ms_per_frame: Some(43.6) },
    BenchCase { scene: "bending", element: "p1", grid: [16, 4, 4], refine: 1, paper_ms_per_frame: Some(363.0) },
    BenchCase { scene: "bending", element: "p1", grid: [16, 4, 4], refine: 2, paper_ms_per_frame: Some(3116.0) },
    BenchCase { scene: "bending", element: "p2", grid: [8, 2, 2], refine: 0, paper_ms_per_frame: Some(20.9) },
    BenchCase { scene: "bending", element: "p3", grid: [4, 2, 2], refine: 0, paper_ms_per_frame: Some(28.1) },
    BenchCase { scene: "bending", element: "q1", grid: [16, 4, 4], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "q2", grid: [8, 2, 2], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "prism", grid: [16, 4, 4], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "pyramid", grid: [12, 3, 3], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "p2", grid: [32, 8, 8], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "p3", grid: [32, 8, 8], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "q1", grid: [32, 8, 8], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "q2", grid: [32, 8, 8], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "prism", grid: [32, 8, 8], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "bending", element: "pyramid", grid: [24, 6, 6], refine: 0, paper_ms_per_frame: None },
];

/// The curved parts (issue #37: `assets/parts/`, docs/MESHES.md) the implicit solvers are timed
/// on besides the beams (`hox bench --solver`): the tube at every order, the elbow and the hook at
/// P2, each from rest under its scene's loads.
pub const PART_CASES: [BenchCase; 5] = [
    BenchCase { scene: "tube", element: "p1", grid: [0; 3], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "tube", element: "p2", grid: [0; 3], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "tube", element: "p3", grid: [0; 3], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "elbow", element: "p2", grid: [0; 3], refine: 0, paper_ms_per_frame: None },
    BenchCase { scene: "hook", element: "p2", grid: [0; 3], refine: 0, paper_ms_per_frame: None },
];

/// The paper's bending beam for `case`, at rest: the `bending` scene with the case's element
/// type, grid and refinement, swept in the order `sweep`.
pub fn bending_beam(case: &BenchCase, sweep: Sweep) -> Result<Simulation, SceneError> {
    beam(case, sweep, None)
}

/// [`bending_beam`], solved by `method` if given (else the scene's own solver).
fn beam(case: &BenchCase, sweep: Sweep, method: Option<hox_sim::solver::Method>) -> Result<Simulation, SceneError> {
    let element = ElementType::from_name(case.element).ok_or_else(|| SceneError::Invalid {
        source_name: "bench".into(),
        key: "element".into(),
        value: case.element.into(),
        reason: format!("is not a registered element type ({})", ElementType::names()),
    })?;
    let beam = case.scene == "bending";
    let overrides = SceneOverrides {
        element: Some(element),
        grid: beam.then_some(case.grid),
        refine: beam.then_some(case.refine),
        sweep: Some(sweep),
        method,
        ..SceneOverrides::default()
    };
    Ok(Instance::new(crate::scene::builtin::by_name(case.scene)?.with_overrides(&overrides)?)?.sim)
}

/// Flops of one energy-constraint projection of an element with `nodes` nodes and `points`
/// quadrature points (see the module doc).
pub fn flops_per_element(nodes: usize, points: usize) -> f64 {
    hox_sim::xpbd::kernels::flops_per_element(nodes, points) as f64
}

/// One measured row.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    pub case: BenchCase,
    pub elements: usize,
    pub nodes: usize,
    pub points_per_element: usize,
    /// Rayon threads.
    pub threads: usize,
    /// The sweep's order: colour by colour (the default) or element by element.
    pub sweep: Sweep,
    /// The colour sweep's register width (elements per batch: 4 on AVX2, 8 on AVX-512); None
    /// for the element-order sweep, which has no batches.
    pub lanes: Option<usize>,
    pub ms_per_frame: f64,
    /// `ms_per_frame / (elements × substeps)`, in ns.
    pub ns_per_element_substep: f64,
    pub gflops: f64,
    /// With more than one thread: the median over rounds of the one-thread frame's time over
    /// this row's, the frames timed side by side ([`measure_side_by_side`]); None on one thread
    /// or when no one-thread row of the same sweep and width was timed.
    pub speedup_over_one_thread: Option<f64>,
}

impl BenchRow {
    /// The progress line printed as each row is measured, e.g.
    /// `P2 8x2x2 on 1 thread(s), colour sweep (8 lanes): 2.08 ms/frame`.
    pub fn progress_line(&self) -> String {
        format!(
            "{} on {} thread(s), {} sweep{}: {:.2} ms/frame",
            self.case.label(),
            self.threads,
            self.sweep.name(),
            self.lanes.map_or(String::new(), |l| format!(" ({l} lanes)")),
            self.ms_per_frame
        )
    }

    /// The paper's time over ours.
    pub fn speedup_over_paper(&self) -> Option<f64> {
        self.case.paper_ms_per_frame.map(|p| p / self.ms_per_frame)
    }
}

/// One configuration of a case ([`measure_side_by_side`]): the rayon pool's thread count, the
/// sweep, and the colour sweep's register width (None: the widest the CPU has).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchConfig {
    pub threads: usize,
    pub sweep: Sweep,
    pub lanes: Option<usize>,
}

/// Times `case` in each of `configs` **side by side**: one simulation per configuration, each in
/// its own rayon pool, `warmup_frames` untimed frames each, then rounds of one timed frame per
/// configuration, in turn (the order reversed every other round, so that none always goes
/// first), until `frames` rounds or `budget_secs` of timed work in all (at least 3 rounds).
/// A change in the machine's speed — a shared machine's other work, its clock — then falls on
/// every configuration alike instead of on whichever was timed at that moment. Each row's
/// `ms_per_frame` is the median of its frames; a row with more than one thread also gets
/// `speedup_over_one_thread`, the median over rounds of the one-thread frame's time over its own
/// (the one-thread configuration of the same sweep and width), a ratio of frames timed a fraction
/// of a second apart.
pub fn measure_side_by_side(
    case: &BenchCase,
    configs: &[BenchConfig],
    warmup_frames: usize,
    frames: usize,
    budget_secs: f64,
) -> Result<Vec<BenchRow>, SceneError> {
    let failed =
        |e: hox_sim::solver::SimError| SceneError::Simulation { source_name: case.label(), message: e.to_string() };
    let mut runs = Vec::with_capacity(configs.len());
    for config in configs {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(config.threads.max(1))
            .build()
            .map_err(|e| SceneError::Simulation { source_name: "bench".into(), message: e.to_string() })?;
        let sim = pool.install(|| {
            let mut sim = bending_beam(case, config.sweep)?;
            if let Some(l) = config.lanes
                && !sim.set_simd_lanes(l)
            {
                return Err(SceneError::Simulation {
                    source_name: "bench".into(),
                    message: format!("this CPU cannot run batches of {l} elements (4 needs AVX2 and FMA, 8 AVX-512 F)"),
                });
            }
            for _ in 0..warmup_frames {
                sim.step_frame().map_err(failed)?;
            }
            Ok(sim)
        })?;
        runs.push((pool, sim, Vec::<f64>::with_capacity(frames)));
    }
    let start = Instant::now();
    for round in 0..frames.max(1) {
        let order: Vec<usize> =
            if round % 2 == 0 { (0..runs.len()).collect() } else { (0..runs.len()).rev().collect() };
        for k in order {
            let (pool, sim, times_ms) = &mut runs[k];
            let clock = Instant::now();
            pool.install(|| sim.step_frame()).map_err(failed)?;
            times_ms.push(clock.elapsed().as_secs_f64() * 1e3);
        }
        if round >= 2 && start.elapsed().as_secs_f64() > budget_secs {
            break;
        }
    }
    let mut rows = Vec::with_capacity(runs.len());
    for (k, (config, (_, sim, times_ms))) in configs.iter().zip(&runs).enumerate() {
        let lanes = if config.sweep == Sweep::Colour { sim.simd_lanes().first().copied() } else { None };
        let one_thread = configs
            .iter()
            .position(|c| c.threads <= 1 && c.sweep == config.sweep && c.lanes == config.lanes)
            .filter(|&one| one != k && config.threads > 1);
        let speedup_over_one_thread = one_thread.map(|one| {
            let mut ratios: Vec<f64> = runs[one].2.iter().zip(times_ms).map(|(a, b)| a / b).collect();
            median(&mut ratios)
        });
        let ms_per_frame = median(&mut times_ms.clone());
        let elements = sim.mesh().num_elements();
        let substeps = sim.substeps_per_frame() as f64;
        let g = &sim.geometry()[0];
        let flops = flops_per_element(g.nodes_per_element, g.points_per_element) * elements as f64 * substeps;
        rows.push(BenchRow {
            case: *case,
            elements,
            nodes: sim.mesh().num_nodes(),
            points_per_element: g.points_per_element,
            threads: config.threads.max(1),
            sweep: config.sweep,
            lanes,
            ms_per_frame,
            ns_per_element_substep: ms_per_frame * 1e6 / (elements as f64 * substeps),
            gflops: flops / (ms_per_frame * 1e6),
            speedup_over_one_thread,
        });
    }
    Ok(rows)
}

/// The table `hox bench` prints: per case, one row per thread count and sweep; `peak_gflops`
/// is one core's AVX2 FMA peak ([`peak::measured_avx2_peak_gflops`]), a quarter of it the
/// scalar peak (one double per FMA).
pub fn markdown(rows: &[BenchRow], peak_gflops: f64) -> String {
    let mut s = format!(
        "| configuration | elements | threads | sweep | lanes | paper ms/frame | ours ms/frame | paper / ours | ns per element·substep | GFLOP/s | % of AVX2 peak ({peak_gflops:.1} GFLOP/s per core) | % of scalar peak | over one thread, frame by frame |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let paper = r.case.paper_ms_per_frame.map_or(String::new(), |p| format!("{p}"));
        let ratio = r.speedup_over_paper().map_or(String::new(), |x| format!("{x:.1}×"));
        let peak = peak_gflops * r.threads as f64;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} | {:.1} | {:.2} | {:.1} % | {:.1} % | {} |\n",
            r.case.label(),
            r.elements,
            r.threads,
            r.sweep.name(),
            r.lanes.map_or("–".to_string(), |l| l.to_string()),
            paper,
            r.ms_per_frame,
            ratio,
            r.ns_per_element_substep,
            r.gflops,
            100.0 * r.gflops / peak,
            400.0 * r.gflops / peak,
            r.speedup_over_one_thread.map_or("–".to_string(), |x| format!("{x:.2}×")),
        ));
    }
    s
}

/// One core's AVX2 peak as `hox bench` reports it: measured where the CPU has AVX2 and FMA,
/// else [`NOMINAL_PEAK_GFLOPS_PER_CORE`].
pub fn peak_gflops_per_core() -> f64 {
    peak::measured_avx2_peak_gflops().unwrap_or(NOMINAL_PEAK_GFLOPS_PER_CORE)
}

/// Untimed frames before the timed ones (the beam starts at rest and sags).
pub const WARMUP_FRAMES: usize = 5;
/// Timed work per case (all its configurations together) after which no more rounds are timed
/// (at least 3 are), seconds.
pub const BUDGET_SECS: f64 = 10.0;

/// The case labelled `filter`, or else every case whose label contains it, ignoring case (a whole
/// label picks that case alone: "P1 16x4x4" is also part of its refinements' labels).
pub fn matching_cases(filter: &str) -> Vec<&'static BenchCase> {
    matching(&CASES, filter)
}

/// [`matching_cases`] among the beams and the curved parts ([`PART_CASES`]): what the implicit
/// solvers are timed on.
pub fn matching_solver_cases(filter: &str) -> Vec<&'static BenchCase> {
    if filter.eq_ignore_ascii_case(PARTS) {
        return PART_CASES.iter().collect();
    }
    let mut cases = matching(&CASES, filter);
    cases.extend(matching(&PART_CASES, filter));
    cases
}

fn matching(cases: &'static [BenchCase], filter: &str) -> Vec<&'static BenchCase> {
    let filter = filter.to_uppercase();
    if filter == TABLE1 {
        return cases.iter().filter(|c| c.paper_ms_per_frame.is_some()).collect();
    }
    let exact = cases.iter().any(|c| c.label().to_uppercase() == filter);
    cases
        .iter()
        .filter(|c| if exact { c.label().to_uppercase() == filter } else { c.label().to_uppercase().contains(&filter) })
        .collect()
}

/// The filter that names the paper's Table 1 beams (every case with a paper figure).
const TABLE1: &str = "TABLE1";
/// The `--only` word that picks every curved part ([`PART_CASES`]) for the implicit solvers.
const PARTS: &str = "parts";

/// Measures the case labelled `filter` (`table1`: the paper's Table 1 beams), or else every
/// case whose label contains it (ignoring case), on each of `threads` with each of `sweeps` (the element-order sweep runs on one
/// thread whatever the pool, so it is measured on one thread only; the colour sweep on each of
/// `lanes`, or the CPU's widest when empty), every configuration of a case side by side
/// ([`measure_side_by_side`]), reporting each row to `progress` (what `hox bench` runs).
pub fn run(
    filter: &str,
    threads: &[usize],
    sweeps: &[Sweep],
    lanes: &[usize],
    frames: usize,
    progress: &mut dyn FnMut(&BenchRow),
) -> Result<Vec<BenchRow>, SceneError> {
    let mut rows = Vec::new();
    for case in matching_cases(filter) {
        let mut configs = Vec::new();
        for &t in threads {
            for &sweep in sweeps {
                if sweep == Sweep::Element && t > 1 {
                    continue;
                }
                let widths: Vec<Option<usize>> = if sweep == Sweep::Colour && !lanes.is_empty() {
                    lanes.iter().map(|&l| Some(l)).collect()
                } else {
                    vec![None]
                };
                for l in widths {
                    let config = BenchConfig { threads: t.max(1), sweep, lanes: l };
                    if !configs.contains(&config) {
                        configs.push(config);
                    }
                }
            }
        }
        for row in measure_side_by_side(case, &configs, WARMUP_FRAMES, frames, BUDGET_SECS)? {
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every configuration of a case is timed side by side, one row each in the order given; the
    /// speed-up over one thread is on the rows with more threads only, taken from the
    /// one-thread row of the same sweep, and printed in the table's last column.
    #[test]
    fn configurations_are_timed_side_by_side_with_the_speed_up_frame_by_frame() {
        let case = BenchCase { scene: "bending", element: "p1", grid: [4, 1, 1], refine: 0, paper_ms_per_frame: None };
        let configs = [
            BenchConfig { threads: 1, sweep: Sweep::Colour, lanes: None },
            BenchConfig { threads: 2, sweep: Sweep::Colour, lanes: None },
            BenchConfig { threads: 1, sweep: Sweep::Element, lanes: None },
        ];
        let rows = measure_side_by_side(&case, &configs, 1, 3, 600.0).unwrap();
        let got: Vec<(usize, Sweep)> = rows.iter().map(|r| (r.threads, r.sweep)).collect();
        assert_eq!(got, [(1, Sweep::Colour), (2, Sweep::Colour), (1, Sweep::Element)]);
        assert!(rows.iter().all(|r| r.ms_per_frame > 0.0 && r.elements == 20));
        assert_eq!(rows[0].speedup_over_one_thread, None);
        let speedup = rows[1].speedup_over_one_thread.expect("a two-thread row has its speed-up");
        assert!(speedup.is_finite() && speedup > 0.0, "{speedup}");
        assert_eq!((rows[2].speedup_over_one_thread, rows[2].lanes), (None, None));
        let table = markdown(&rows, 40.0);
        let two = table.lines().find(|l| l.contains("| 2 | colour |")).unwrap();
        assert!(two.trim_end().ends_with(&format!("{speedup:.2}× |")), "{two}");
    }

    /// The benchmark's beam is the bending scene's: its box, material, settings and effects come
    /// from `assets/scenes/bending.toml`; a case changes only the element type, grid, refinement
    /// and sweep.
    #[test]
    fn the_benchmark_beam_is_the_bending_scene_file() {
        let scene = crate::scene::builtin::by_name("bending").unwrap();
        let case = BenchCase { scene: "bending", element: "q1", grid: [4, 1, 1], refine: 0, paper_ms_per_frame: None };
        let sim = bending_beam(&case, Sweep::Element).unwrap();
        assert_eq!(*sim.material(), scene.material());
        assert_eq!(*sim.settings(), hox_sim::solver::SolverSettings { sweep: Sweep::Element, ..scene.settings() });
        let (lo, hi) = sim.mesh().bounding_box();
        assert_eq!([lo, hi].map(|p| [p.x, p.y, p.z]), [scene.params().box_min_m, scene.params().box_max_m]);
        assert_eq!(sim.mesh().num_elements(), 4);
        assert_eq!(sim.mesh().blocks[0].element_type.name(), "q1");
        let effects: Vec<&str> = sim.effects().iter().map(|e| e.name()).collect();
        assert_eq!(effects, ["gravity", "clamp"]);
    }
}
