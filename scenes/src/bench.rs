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

use crate::params::SceneOverrides;
use crate::{Instance, SceneError};
use hox_sim::element::ElementType;
use hox_sim::measure::median;
use hox_sim::solver::{Simulation, Sweep};
use std::time::Instant;

/// The peak rate used when the CPU cannot be measured (no AVX2): 2.7 GHz × 2 FMA units ×
/// 4 doubles × 2 flops per FMA, the nominal figure of the project's first machine. Where AVX2
/// and FMA exist, `hox bench` measures the peak instead ([`peak::measured_avx2_peak_gflops`]).
pub const NOMINAL_PEAK_GFLOPS_PER_CORE: f64 = 2.7 * 2.0 * 4.0 * 2.0;

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
/// (the meshes of the study, `scenes/src/study.rs`), then a large beam of every element type
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
    Ok(Instance::new(crate::by_name(case.scene)?.with_overrides(&overrides)?)?.sim)
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

/// Times `case` with the sweep `sweep` (the colour sweep on `lanes` elements per batch, None:
/// the widest the CPU has), in a rayon pool of
/// `threads`: `warmup_frames` untimed, then the median of `frames` timed frames. Frames are
/// also capped by `budget_secs` of timed work (at least 3 frames).
#[allow(clippy::too_many_arguments)]
pub fn measure(
    case: &BenchCase,
    threads: usize,
    sweep: Sweep,
    lanes: Option<usize>,
    warmup_frames: usize,
    frames: usize,
    budget_secs: f64,
) -> Result<BenchRow, SceneError> {
    let threads = threads.max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| SceneError::Simulation { source_name: "bench".into(), message: e.to_string() })?;
    let failed =
        |e: hox_sim::solver::SimError| SceneError::Simulation { source_name: case.label(), message: e.to_string() };
    pool.install(|| {
        let mut sim = bending_beam(case, sweep)?;
        if let Some(l) = lanes
            && !sim.set_simd_lanes(l)
        {
            return Err(SceneError::Simulation {
                source_name: "bench".into(),
                message: format!("this CPU cannot run batches of {l} elements (4 needs AVX2 and FMA, 8 AVX-512 F)"),
            });
        }
        let lanes = if sweep == Sweep::Colour { sim.simd_lanes().first().copied() } else { None };
        for _ in 0..warmup_frames {
            sim.step_frame().map_err(failed)?;
        }
        let mut times_ms = Vec::with_capacity(frames);
        let start = Instant::now();
        for i in 0..frames.max(1) {
            let clock = Instant::now();
            sim.step_frame().map_err(failed)?;
            times_ms.push(clock.elapsed().as_secs_f64() * 1e3);
            if i >= 2 && start.elapsed().as_secs_f64() > budget_secs {
                break;
            }
        }
        let ms_per_frame = median(&mut times_ms);
        let elements = sim.mesh().num_elements();
        let substeps = sim.substeps_per_frame() as f64;
        let g = &sim.geometry()[0];
        let flops = flops_per_element(g.nodes_per_element, g.points_per_element) * elements as f64 * substeps;
        Ok(BenchRow {
            case: *case,
            elements,
            nodes: sim.mesh().num_nodes(),
            points_per_element: g.points_per_element,
            threads,
            sweep,
            lanes,
            ms_per_frame,
            ns_per_element_substep: ms_per_frame * 1e6 / (elements as f64 * substeps),
            gflops: flops / (ms_per_frame * 1e6),
        })
    })
}

/// The table `hox bench` prints: per case, one row per thread count and sweep; `peak_gflops`
/// is one core's AVX2 FMA peak ([`peak::measured_avx2_peak_gflops`]), a quarter of it the
/// scalar peak (one double per FMA).
pub fn markdown(rows: &[BenchRow], peak_gflops: f64) -> String {
    let mut s = format!(
        "| configuration | elements | threads | sweep | lanes | paper ms/frame | ours ms/frame | paper / ours | ns per element·substep | GFLOP/s | % of AVX2 peak ({peak_gflops:.1} GFLOP/s per core) | % of scalar peak |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let paper = r.case.paper_ms_per_frame.map_or(String::new(), |p| format!("{p}"));
        let ratio = r.speedup_over_paper().map_or(String::new(), |x| format!("{x:.1}×"));
        let peak = peak_gflops * r.threads as f64;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} | {:.1} | {:.2} | {:.1} % | {:.1} % |\n",
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
/// Timed work per configuration after which no more frames are timed (at least 3 are), seconds.
pub const BUDGET_SECS: f64 = 10.0;

/// The case labelled `filter`, or else every case whose label contains it, ignoring case (a whole
/// label picks that case alone: "P1 16x4x4" is also part of its refinements' labels).
pub fn matching_cases(filter: &str) -> Vec<&'static BenchCase> {
    matching(&CASES, filter)
}

/// [`matching_cases`] among the beams and the curved parts ([`PART_CASES`]): what the implicit
/// solvers are timed on.
pub fn matching_solver_cases(filter: &str) -> Vec<&'static BenchCase> {
    let mut cases = matching(&CASES, filter);
    cases.extend(matching(&PART_CASES, filter));
    cases
}

fn matching(cases: &'static [BenchCase], filter: &str) -> Vec<&'static BenchCase> {
    let filter = filter.to_uppercase();
    let exact = cases.iter().any(|c| c.label().to_uppercase() == filter);
    cases
        .iter()
        .filter(|c| if exact { c.label().to_uppercase() == filter } else { c.label().to_uppercase().contains(&filter) })
        .collect()
}

/// Measures the case labelled `filter`, or else every case whose label contains it (ignoring
/// case), on each of `threads` with each of `sweeps` (the element-order sweep runs on one
/// thread whatever the pool, so it is measured on one thread only; the colour sweep on each of
/// `lanes`, or the CPU's widest when empty), reporting each row to `progress` as it is measured
/// (what `hox bench` runs).
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
                    let row = measure(case, t, sweep, l, WARMUP_FRAMES, frames, BUDGET_SECS)?;
                    progress(&row);
                    rows.push(row);
                }
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The benchmark's beam is the bending scene's: its box, material, settings and effects come
    /// from `assets/scenes/bending.toml`; a case changes only the element type, grid, refinement
    /// and sweep.
    #[test]
    fn the_benchmark_beam_is_the_bending_scene_file() {
        let scene = crate::by_name("bending").unwrap();
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
