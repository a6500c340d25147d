//! The accuracy-versus-time study: the paper's Table 1, reproduced and extended.
//!
//! For each paper scene and each configuration (element type, grid, split, refinement), with the
//! paper's solver settings (50 substeps × 1 iteration, 60 fps, StVK, energy formulation):
//! 1. the static solution on that mesh ([`hox_sim::solver::statics`]);
//! 2. XPBD settled at the paper's settings, timed (median ms per frame);
//! 3. the substeps that bring the **solver error** (settled XPBD vs the static solution on the
//!    same mesh) under 1 %, found from the measured 1/substeps² law and confirmed by a settled
//!    run warm-started from the previous one, and its ms per frame.
//!
//! Errors are measured at the scene's probes against the committed reference
//! (`assets/reference/*-fine.json`, a fine Q2 static solution): the **total** error of settled
//! XPBD, split into **discretisation** (static on this mesh vs reference) and **solver** (XPBD vs
//! static on this mesh). Each error is the largest probe-displacement difference (m), and in % of
//! the largest reference probe displacement.

pub mod locking;
pub mod motion;
pub mod pareto;
pub mod shard;
pub mod solver_axis;
pub mod summary;

/// An element type's colour in the study's charts (`study.svg` and the app's).
pub use crate::present::colour::element_colour;
pub use locking::{LOCKING_POISSON_RATIOS, LockingRow, locking, locking_at, locking_csv, locking_markdown};

use crate::error::SceneError;
use crate::instance::Instance;
use crate::params::SceneOverrides;
use crate::present::svg::{decades, element_hex, element_legend, plot_frame};
use crate::run::{RunMode, run};
use hox_sim::Vec3;
use hox_sim::element::{ElementType, ReferenceShape};
use hox_sim::mesh::structured::TetSplit;

/// The paper's Table 1 (bending): (label, elements, ms per frame, tip error in m).
pub const PAPER_TABLE_1: [(&str, usize, f64, f64); 5] = [
    ("P1", 1_280, 43.6, 1.5e-1),
    ("P1", 10_240, 363.0, 5.1e-2),
    ("P1", 81_920, 3_116.0, 9.4e-3),
    ("P2", 160, 20.9, 3.1e-3),
    ("P3", 80, 28.1, 1.2e-2),
];

/// The solver error the second point set of the study aims at.
pub const SOLVER_ERROR_TARGET: f64 = 0.01;

/// One mesh configuration of the study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyConfig {
    pub element: &'static str,
    pub grid: [usize; 3],
    pub split: TetSplit,
    pub refine: usize,
    /// Left out of `--quick`.
    pub heavy: bool,
}

impl StudyConfig {
    const fn new(element: &'static str, grid: [usize; 3], split: TetSplit, refine: usize, heavy: bool) -> Self {
        Self { element, grid, split, refine, heavy }
    }
    /// The scene overrides that build this configuration's mesh.
    pub fn overrides(&self) -> SceneOverrides {
        SceneOverrides {
            // the study's own element names, all registered
            element: ElementType::from_name(self.element),
            grid: Some(self.grid),
            split: Some(self.split),
            refine: Some(self.refine),
            ..Default::default()
        }
    }
    pub fn label(&self) -> String {
        let is_tet = ElementType::from_name(self.element).is_some_and(|e| e.shape() == ReferenceShape::Tetrahedron);
        let mut s = format!("{} {}x{}x{}", self.element.to_uppercase(), self.grid[0], self.grid[1], self.grid[2]);
        if is_tet {
            s.push_str(&format!(" {}", self.split.name()));
        }
        if self.refine > 0 {
            s.push_str(&format!(" r{}", self.refine));
        }
        s
    }
}

/// The configurations of a paper scene: the paper's meshes (Table 1 for bending, the biased
/// 637-vertex beams for tension and torsion), their other split, and Q1, Q2, prism and pyramid
/// meshes of comparable node count.
pub fn configurations(scene: &str) -> Vec<StudyConfig> {
    use TetSplit::{Five, Six};
    let c = StudyConfig::new;
    if scene == "bending" {
        vec![
            c("p1", [16, 4, 4], Five, 0, false),
            c("p1", [16, 4, 4], Five, 1, true),
            c("p1", [16, 4, 4], Five, 2, true),
            c("p2", [8, 2, 2], Five, 0, false),
            c("p3", [4, 2, 2], Five, 0, false),
            c("p1", [16, 4, 4], Six, 0, false),
            c("p2", [8, 2, 2], Six, 0, false),
            c("p3", [4, 2, 2], Six, 0, false),
            c("q1", [16, 4, 4], Five, 0, false),
            c("q2", [8, 2, 2], Five, 0, false),
            c("prism", [16, 4, 4], Five, 0, false),
            c("pyramid", [12, 3, 3], Five, 0, false),
        ]
    } else {
        vec![
            c("p1", [12, 6, 6], Six, 0, false),
            c("p2", [6, 3, 3], Six, 0, false),
            c("p3", [4, 2, 2], Six, 0, false),
            c("p1", [12, 6, 6], Five, 0, false),
            c("p2", [6, 3, 3], Five, 0, false),
            c("p3", [4, 2, 2], Five, 0, false),
            c("q1", [12, 6, 6], Five, 0, false),
            c("q2", [6, 3, 3], Five, 0, false),
            c("prism", [12, 6, 6], Five, 0, false),
            c("pyramid", [9, 4, 4], Five, 0, false),
        ]
    }
}

/// One row of the study.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StudyRow {
    pub scene: String,
    pub config: String,
    pub element: String,
    pub split: String,
    pub elements: usize,
    pub nodes: usize,
    pub constraints: usize,
    /// Median ms per frame at the paper's settings, one thread.
    pub ms_per_frame: f64,
    /// Median ms per frame of the parallel sweep on all threads (rayon's pool).
    pub ms_per_frame_all_threads: Option<f64>,
    pub error_m: f64,
    pub error_pct: f64,
    pub discretisation_m: f64,
    pub solver_m: f64,
    pub solver_pct: f64,
    pub substeps_for_1pct: u32,
    pub ms_per_frame_1pct: f64,
    pub error_1pct_m: f64,
    pub settled: bool,
}

/// Probe displacements of a paper scene's committed reference ([`crate::lab::reference::committed`]).
pub fn reference(scene: &str) -> Result<Vec<(String, Vec3)>, SceneError> {
    let unknown = || SceneError::Unknown { name: scene.to_string(), available: "bending, tension, torsion".into() };
    let built = crate::scene::builtin::by_name(scene).map_err(|_| unknown())?;
    let committed = crate::lab::reference::committed(&built)?.ok_or_else(unknown)?;
    Ok(committed.probes.into_iter().map(|(name, u)| (name, Vec3::from(u))).collect())
}

/// Largest distance between two probe sets (matched by name).
fn probe_distance(a: &[(String, Vec3)], b: &[(String, Vec3)]) -> f64 {
    a.iter()
        .map(|(name, u)| b.iter().find(|(n, _)| n == name).map(|(_, v)| (u - v).norm()).unwrap_or(f64::INFINITY))
        .fold(0.0, f64::max)
}

fn probes_of(instance: &Instance, positions: &[Vec3]) -> Vec<(String, Vec3)> {
    instance
        .probes
        .iter()
        .map(|p| (p.name.clone(), p.displacement(positions, &instance.sim.mesh().rest_positions)))
        .collect()
}

/// The settled probe displacements of a run, or, when it never settled (XPBD can keep a small
/// oscillation going), their mean over the last simulated second.
fn settled_probes(report: &crate::run::RunReport) -> Vec<(String, Vec3)> {
    let source = if report.settled || report.at_rest { &report.probes } else { &report.probes_last_second_mean };
    source.iter().map(|(n, u)| (n.clone(), Vec3::from(*u))).collect()
}

/// Simulated-time caps for settling in the study: first run, warm-started runs (heavy meshes
/// get shorter caps; a run that does not settle is measured by its last-second mean).
fn caps(heavy: bool) -> (f64, f64) {
    if heavy { (10.0, 5.0) } else { (30.0, 15.0) }
}

/// Runs one configuration of one scene. `progress(message)` reports what is being done.
pub fn study_one(
    scene_name: &str,
    config: &StudyConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<StudyRow, SceneError> {
    let reference = reference(scene_name)?;
    let reference_size = reference.iter().map(|(_, u)| u.norm()).fold(0.0, f64::max);
    let base = crate::scene::builtin::by_name(scene_name)?;
    let scene = base.with_overrides(&config.overrides())?;
    let label = config.label();
    let fail = |m: String| SceneError::Simulation { source_name: format!("{scene_name} {label}"), message: m };

    // 1. the static solution on this mesh
    progress(&format!("{scene_name} {label}: static solution"));
    let mut instance = Instance::new(scene.clone())?;
    let statics = crate::instance::solve_static(&scene, instance.sim.mesh(), 1e-8, 1, &mut |_, _, _| {})
        .map_err(|e| fail(e.to_string()))?;
    let static_probes = probes_of(&instance, &statics.positions);

    // 2. XPBD settled at the paper's settings
    progress(&format!("{scene_name} {label}: XPBD at 50 substeps"));
    let (first_cap, warm_cap) = caps(config.heavy);
    // timed on one thread (the colour sweep, the default, would otherwise take every thread)
    let one_thread = one_thread()?;
    let report = one_thread.install(|| run(&mut instance, RunMode::Settle { cap_secs: first_cap }, &mut |_, _| {}))?;
    let xpbd_probes = settled_probes(&report);
    let solver_m = probe_distance(&xpbd_probes, &static_probes);
    let static_size = static_probes.iter().map(|(_, u)| u.norm()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let solver_rel = solver_m / static_size;

    // 2b. the same settings on all threads: one simulated second from
    // the settled state, timed
    progress(&format!("{scene_name} {label}: XPBD at 50 substeps, all threads"));
    let mut parallel_scene = scene.clone();
    parallel_scene.file.params.sweep = hox_sim::solver::Sweep::Colour;
    let mut parallel = Instance::new(parallel_scene)?;
    parallel.sim.warm_start(&instance.sim.positions, instance.sim.time_secs());
    let all_threads = run(&mut parallel, RunMode::Seconds(1.0), &mut |_, _| {})?.ms_per_frame;

    // 3. substeps for a solver error under 1 % (bias ∝ 1/substeps²), warm-started
    let (mut substeps, mut ms_1pct, mut error_1pct_m) =
        (instance.sim.substeps_per_frame(), report.ms_per_frame, probe_distance(&xpbd_probes, &reference));
    let mut rel = solver_rel;
    let mut positions = instance.sim.positions.clone();
    let mut time = instance.sim.time_secs();
    let mut tries = 0;
    while rel > SOLVER_ERROR_TARGET && tries < 4 {
        tries += 1;
        let estimate = (substeps as f64 * (rel / (0.8 * SOLVER_ERROR_TARGET)).sqrt()).ceil();
        substeps = ((estimate / 10.0).ceil() * 10.0).max(substeps as f64 + 10.0) as u32;
        progress(&format!("{scene_name} {label}: XPBD at {substeps} substeps"));
        let finer = scene.with_overrides(&SceneOverrides { substeps: Some(substeps), ..Default::default() })?;
        let mut inst = Instance::new(finer)?;
        inst.sim.warm_start(&positions, time);
        let r = one_thread.install(|| run(&mut inst, RunMode::Settle { cap_secs: warm_cap }, &mut |_, _| {}))?;
        let p = settled_probes(&r);
        rel = probe_distance(&p, &static_probes) / static_size;
        ms_1pct = r.ms_per_frame;
        error_1pct_m = probe_distance(&p, &reference);
        positions.copy_from_slice(&inst.sim.positions);
        time = inst.sim.time_secs();
    }
    let error_m = probe_distance(&xpbd_probes, &reference);
    Ok(StudyRow {
        scene: scene_name.to_string(),
        config: label,
        element: config.element.to_string(),
        split: config.split.name().to_string(),
        elements: instance.sim.mesh().num_elements(),
        nodes: instance.sim.mesh().num_nodes(),
        constraints: instance.sim.num_constraints(),
        ms_per_frame: report.ms_per_frame,
        ms_per_frame_all_threads: Some(all_threads),
        error_m,
        error_pct: 100.0 * error_m / reference_size,
        discretisation_m: probe_distance(&static_probes, &reference),
        solver_m,
        solver_pct: 100.0 * solver_rel,
        substeps_for_1pct: substeps,
        ms_per_frame_1pct: ms_1pct,
        error_1pct_m,
        settled: report.settled || report.at_rest,
    })
}

/// Runs the study's accuracy table over the paper scenes (`quick`: without the heavy
/// configurations): its cells ([`shard::Plan`]) one after another.
pub fn run_study(quick: bool, progress: &mut dyn FnMut(&str)) -> Result<Vec<StudyRow>, SceneError> {
    let plan = shard::Plan { quick, tables: vec![shard::Table::Accuracy] };
    Ok(shard::run_all(&plan, progress)?.accuracy)
}

/// `study.md`: one table per scene.
pub fn markdown(rows: &[StudyRow], quick: bool) -> String {
    let mut s = String::from("# Accuracy versus time\n\n");
    s.push_str(&format!(
        "Produced by `hox study{}`. Settings: the paper's (StVK, 50 substeps × 1 iteration, 60 fps, energy formulation), settled; errors at the probes against the fine Q2 reference (`assets/reference/`), in metres and in % of the reference displacement. *Discretisation*: static solution on the mesh vs reference. *Solver*: settled XPBD vs static solution on the same mesh. *Substeps for 1 %*: the substeps that bring the solver error under 1 %, and the ms per frame that costs. Times are medians over frames of the colour sweep (colour by colour, four elements per AVX2 register or eight per AVX-512 one; the same result on any thread count): on one thread and on all threads (rayon's pool; measured over one second from the settled state).\n\n",
        if quick { " --quick" } else { "" }
    ));
    for scene in crate::scene::builtin::PAPER_SCENES {
        let scene_rows: Vec<&StudyRow> = rows.iter().filter(|r| r.scene == scene).collect();
        if scene_rows.is_empty() {
            continue;
        }
        s.push_str(&format!("## {scene}\n\n| configuration | elements | nodes | constraints | ms/frame (1 thread) | ms/frame (all threads) | error (m) | error (%) | discretisation (m) | solver (m) | solver (%) | substeps for 1 % | ms/frame at those | error there (m) | settled at 50 |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"));
        for r in scene_rows {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {:.2} | {} | {:.2e} | {:.2} | {:.2e} | {:.2e} | {:.2} | {} | {:.2} | {:.2e} | {} |\n",
                r.config,
                r.elements,
                r.nodes,
                r.constraints,
                r.ms_per_frame,
                r.ms_per_frame_all_threads.map(|v| format!("{v:.2}")).unwrap_or_else(|| "—".into()),
                r.error_m,
                r.error_pct,
                r.discretisation_m,
                r.solver_m,
                r.solver_pct,
                r.substeps_for_1pct,
                r.ms_per_frame_1pct,
                r.error_1pct_m,
                if r.settled { "yes" } else { "no: oscillates (last-second mean)" },
            ));
        }
        s.push('\n');
    }
    s.push_str("Paper (Table 1, bending; its machine): P1 1,280: 43.6 ms, 1.5e-1 m; P1 10,240: 363 ms, 5.1e-2 m; P1 81,920: 3,116 ms, 9.4e-3 m; P2 160: 20.9 ms, 3.1e-3 m; P3 80: 28.1 ms, 1.2e-2 m.\n");
    s
}

/// `study.csv`: the same rows.
pub fn csv(rows: &[StudyRow]) -> String {
    let mut s = String::from(
        "scene,configuration,element,split,elements,nodes,constraints,ms_per_frame_1_thread,ms_per_frame_all_threads,error_m,error_pct,discretisation_m,solver_m,solver_pct,substeps_for_1pct,ms_per_frame_1pct,error_1pct_m,settled\n",
    );
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.scene,
            r.config,
            r.element,
            r.split,
            r.elements,
            r.nodes,
            r.constraints,
            r.ms_per_frame,
            r.ms_per_frame_all_threads.map(|v| v.to_string()).unwrap_or_default(),
            r.error_m,
            r.error_pct,
            r.discretisation_m,
            r.solver_m,
            r.solver_pct,
            r.substeps_for_1pct,
            r.ms_per_frame_1pct,
            r.error_1pct_m,
            r.settled
        ));
    }
    s
}

/// `study.svg`: bending tip error versus ms per frame, log–log, one colour per element type;
/// filled circles at the paper's settings, rings at the 1 %-solver-error settings, and the
/// paper's Table 1 points as crosses.
pub fn svg(rows: &[StudyRow]) -> String {
    let colour = element_hex;
    let bending: Vec<&StudyRow> = rows.iter().filter(|r| r.scene == "bending").collect();
    let mut xs: Vec<f64> = bending.iter().flat_map(|r| [r.ms_per_frame, r.ms_per_frame_1pct]).collect();
    let mut ys: Vec<f64> = bending.iter().flat_map(|r| [r.error_m, r.error_1pct_m]).collect();
    xs.extend(PAPER_TABLE_1.iter().map(|p| p.2));
    ys.extend(PAPER_TABLE_1.iter().map(|p| p.3));
    let positive = |v: &f64| *v > 0.0 && v.is_finite();
    let (x0, x1) = decades(xs.iter().filter(|v| positive(v)));
    let (y0, y1) = decades(ys.iter().filter(|v| positive(v)));
    let (w, h, left, right, top, bottom) = (760.0, 520.0, 80.0, 170.0, 40.0, 60.0);
    let px = |x: f64| left + (x.max(1e-300).log10() - x0) / (x1 - x0) * (w - left - right);
    let py = |y: f64| top + (y1 - y.max(1e-300).log10()) / (y1 - y0) * (h - top - bottom);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<rect width="{w}" height="{h}" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">Bending: tip error vs time per frame (log–log)</text>
"#,
        w / 2.0
    );
    for d in (x0 as i32)..=(x1 as i32) {
        let x = px(10f64.powi(d));
        s.push_str(&format!(r##"<line x1="{x}" y1="{top}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">1e{d}</text>
"##, h - bottom, h - bottom + 16.0));
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = py(10f64.powi(d));
        s.push_str(&format!(r##"<line x1="{left}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">1e{d}</text>
"##, w - right, left - 6.0, y + 4.0));
    }
    s.push_str(&plot_frame([left, top, right, bottom], [w, h], "ms per frame", "tip error vs reference (m)"));
    for r in &bending {
        let c = colour(&r.element);
        if positive(&r.error_1pct_m) && r.substeps_for_1pct != 50 {
            s.push_str(&format!(
                r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{c}" stroke-dasharray="3,3"/>
"#,
                px(r.ms_per_frame),
                py(r.error_m),
                px(r.ms_per_frame_1pct),
                py(r.error_1pct_m)
            ));
            s.push_str(&format!(r#"<circle cx="{}" cy="{}" r="5" fill="white" stroke="{c}" stroke-width="2"><title>{} at {} substeps: {:.3} ms, {:.2e} m</title></circle>
"#, px(r.ms_per_frame_1pct), py(r.error_1pct_m), r.config, r.substeps_for_1pct, r.ms_per_frame_1pct, r.error_1pct_m));
        }
        s.push_str(&format!(
            r#"<circle cx="{}" cy="{}" r="5" fill="{c}"><title>{} at 50 substeps: {:.3} ms, {:.2e} m</title></circle>
"#,
            px(r.ms_per_frame),
            py(r.error_m),
            r.config,
            r.ms_per_frame,
            r.error_m
        ));
    }
    for (label, elements, ms, err) in PAPER_TABLE_1 {
        let c = colour(&label.to_lowercase());
        let (x, y) = (px(ms), py(err));
        s.push_str(&format!(r#"<path d="M{} {} L{} {} M{} {} L{} {}" stroke="{c}" stroke-width="2"><title>paper {label} {elements}: {ms} ms, {err:.1e} m</title></path>
"#, x - 5.0, y - 5.0, x + 5.0, y + 5.0, x - 5.0, y + 5.0, x + 5.0, y - 5.0));
    }
    // legend
    let lx = w - right + 15.0;
    let mut ly = element_legend(&mut s, ElementType::all().map(|e| e.name()), lx, top + 10.0);
    ly += 8.0;
    s.push_str(&format!(r##"<circle cx="{lx}" cy="{ly}" r="5" fill="#555"/><text x="{}" y="{}">50 substeps</text>
<circle cx="{lx}" cy="{}" r="5" fill="white" stroke="#555" stroke-width="2"/><text x="{}" y="{}">solver error &lt; 1 %</text>
<path d="M{} {} L{} {} M{} {} L{} {}" stroke="#555" stroke-width="2"/><text x="{}" y="{}">paper, Table 1</text>
"##, lx + 10.0, ly + 4.0, ly + 18.0, lx + 10.0, ly + 22.0, lx - 5.0, ly + 31.0, lx + 5.0, ly + 41.0, lx - 5.0, ly + 41.0, lx + 5.0, ly + 31.0, lx + 10.0, ly + 40.0));
    s.push_str("</svg>\n");
    s
}

/// A pool of one thread, for the study's timings (the colour sweep would otherwise take every
/// thread).
pub(crate) fn one_thread() -> Result<rayon::ThreadPool, SceneError> {
    rayon::ThreadPoolBuilder::new().num_threads(1).build().map_err(|e| SceneError::Simulation {
        source_name: "study".into(),
        message: format!("cannot make a one-thread pool: {e}"),
    })
}
