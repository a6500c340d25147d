//! `hox paper`: the paper's three experiments and Table 1 (supplementary material, Figs. 1–3),
//! run at its settings — StVK, ν 0.35, ρ 1000 kg/m³, E 1 MPa (tension, torsion) and 3 MPa
//! (bending), XPBD with 1 iteration and 50 substeps at 60 fps, the meshes of ERRATA.md — each run
//! settled ([`crate::run`]'s `Settle`, measured by its last-second mean where XPBD's bias keeps it
//! moving), and drawn against a reference: the static solution (`hox static`'s Newton) on a Q2
//! mesh finer than every case (the paper's was a 16,384-element Q1 beam or PolyFEM).
//!
//! The figures sample the displacement field inside the elements, not at their nodes: a grid of
//! rest points is located in its element ([`hox_sim::measure::probe::Probe`]) and carried by the
//! element's own shape functions, so a P2 or P3 element's section is as curved as its field.
//! - **Fig. 1, tension:** the beams' mid-plane `y = 0.25 m` seen from the side, deformed, coloured
//!   by `|u|` on one scale, with the reference's outline of the same plane in red; the measure is
//!   the largest distance from a beam's outline to the reference's (in the view's plane).
//! - **Fig. 2, torsion:** the mid-length section `x = 0.5 m` seen along the axis, deformed,
//!   biased (six tetrahedra per cell) and unbiased (five), the reference's section outline in red;
//!   the same measure.
//! - **Fig. 3, bending:** the top face `z = 0.5 m` of each beam seen from above, undeformed,
//!   coloured by the vertical displacement on one scale, the reference's strip beside them; the
//!   measure is the largest difference of that displacement from the reference's at the same rest
//!   point, over the reference's largest (the colours' offset).
//!
//! The SVG is written here; `hox paper` also rasterises it to PNG.

mod draw;
mod report;

use draw::{draw_deformed, draw_strips};
pub use report::{Claim, claims, paper_markdown, table_markdown};

use crate::error::SceneError;
use crate::instance::Instance;
use crate::lab::study::{PAPER_TABLE_1, StudyConfig};
use crate::params::SceneOverrides;
use crate::run::{RunMode, run};
use hox_sim::Vec3;
use hox_sim::measure::probe::Probe;
use hox_sim::mesh::Mesh;
use hox_sim::mesh::structured::TetSplit;

/// What one settled case gave: its label, mesh size, timing and the sampled field.
#[derive(Clone, Debug)]
pub struct Panel {
    pub label: String,
    pub nodes: usize,
    pub elements: usize,
    /// Median ms per frame, one thread (XPBD at the paper's settings); None for the reference.
    pub ms_per_frame: Option<f64>,
    /// Whether the run settled (or came to rest); the reference is a static solution.
    pub settled: bool,
    /// Deformed positions of the figure's sample grid, row-major (`columns` per row).
    pub deformed: Vec<Vec3>,
    /// The figure's measure for this panel (outline distance in m, or offset in %).
    pub measure: Option<f64>,
}

/// A figure: its panels (the reference last) and the SVG drawn from them.
#[derive(Clone, Debug)]
pub struct Figure {
    pub name: &'static str,
    pub title: String,
    pub panels: Vec<Panel>,
    /// What [`Panel::measure`] is, for the text ("largest distance from the reference outline, m").
    pub measure_name: &'static str,
    pub svg: String,
}

/// One row of Table 1 as hox measures it, beside the paper's.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TableRow {
    pub label: String,
    pub vertices: usize,
    pub elements: usize,
    pub paper_ms_per_frame: f64,
    pub paper_error_m: f64,
    pub xpbd_ms_per_frame: f64,
    pub xpbd_error_m: f64,
    pub xpbd_settled: bool,
    /// (solver, ms per frame, error in m) at the solver's defaults, settled.
    pub solvers: Vec<(String, f64, f64)>,
}

/// Everything `hox paper` writes.
pub struct PaperResult {
    pub figures: Vec<Figure>,
    pub table: Vec<TableRow>,
    pub quick: bool,
}

/// How many rest points per direction the figures sample, and the settle caps (simulated s).
struct Resolution {
    section: usize,
    strip: [usize; 2],
    cap_secs: f64,
    heavy_cap_secs: f64,
}

fn resolution(quick: bool) -> Resolution {
    if quick {
        Resolution { section: 9, strip: [17, 5], cap_secs: 2.0, heavy_cap_secs: 2.0 }
    } else {
        Resolution { section: 21, strip: [41, 11], cap_secs: 20.0, heavy_cap_secs: 8.0 }
    }
}

/// The reference meshes (Q2), and the load steps of their static solve.
fn reference_grid(scene: &str, quick: bool) -> ([usize; 3], usize) {
    match (scene, quick) {
        ("bending", false) => ([32, 8, 8], 1),
        ("bending", true) => ([8, 2, 2], 1),
        ("torsion", false) => ([12, 6, 6], 8),
        ("torsion", true) => ([4, 2, 2], 4),
        (_, false) => ([12, 6, 6], 4),
        (_, true) => ([4, 2, 2], 2),
    }
}

/// The figure a paper scene is drawn as (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureKind {
    Tension,
    Torsion,
    Bending,
}

impl FigureKind {
    /// The figure of a paper scene by its name (`tension`, `torsion`, `bending`).
    pub fn of_scene(name: &str) -> Option<FigureKind> {
        match name {
            "tension" => Some(FigureKind::Tension),
            "torsion" => Some(FigureKind::Torsion),
            "bending" => Some(FigureKind::Bending),
            _ => None,
        }
    }

    /// The file name, without extension.
    pub fn file_name(self) -> &'static str {
        match self {
            FigureKind::Tension => "fig1-tension",
            FigureKind::Torsion => "fig2-torsion",
            FigureKind::Bending => "fig3-bending",
        }
    }

    fn title(self) -> &'static str {
        match self {
            FigureKind::Tension => {
                "Fig. 1 — tension: the mid-plane y = 0.25 m, stretched 0.5 m, coloured by |u|; red: the reference's outline"
            }
            FigureKind::Torsion => {
                "Fig. 2 — torsion: the section x = 0.5 m, end turned 90°, coloured by |u|; red: the reference's outline"
            }
            FigureKind::Bending => {
                "Fig. 3 — bending: the top faces seen from above, undeformed, coloured by the vertical displacement"
            }
        }
    }

    /// The rest points the figure samples on the beam `[lo, hi]`, `nu × nv` of them, row-major:
    /// the mid-plane across the width (tension), the mid-length section (torsion), the top face
    /// (bending). `quick`: fewer.
    pub fn samples(self, lo: Vec3, hi: Vec3, quick: bool) -> (Vec<Vec3>, usize, usize) {
        let res = resolution(quick);
        let d = hi - lo;
        let n = res.section;
        match self {
            FigureKind::Tension => (
                grid(
                    Vec3::new(lo.x, lo.y + 0.5 * d.y, lo.z),
                    Vec3::new(d.x, 0.0, 0.0),
                    Vec3::new(0.0, 0.0, d.z),
                    2 * n - 1,
                    n,
                ),
                2 * n - 1,
                n,
            ),
            FigureKind::Torsion => (
                grid(Vec3::new(lo.x + 0.5 * d.x, lo.y, lo.z), Vec3::new(0.0, d.y, 0.0), Vec3::new(0.0, 0.0, d.z), n, n),
                n,
                n,
            ),
            FigureKind::Bending => {
                let [nu, nv] = res.strip;
                (grid(Vec3::new(lo.x, lo.y, hi.z), Vec3::new(d.x, 0.0, 0.0), Vec3::new(0.0, d.y, 0.0), nu, nv), nu, nv)
            }
        }
    }

    /// How a figure's measure is named.
    fn measure_name(self) -> &'static str {
        match self {
            FigureKind::Bending => "largest offset of the vertical displacement from the reference's, % of its largest",
            _ => "largest distance from the reference outline, m",
        }
    }
}

/// Draws `panels` (the reference's last) sampled at `points` (`nu × nv`) as the figure `kind`,
/// each case measured against the reference (module docs).
pub fn draw_figure(kind: FigureKind, mut panels: Vec<Panel>, points: &[Vec3], nu: usize, nv: usize) -> Figure {
    let title = kind.title();
    let svg = match kind {
        FigureKind::Bending => {
            let uz = |p: &Panel| p.deformed.iter().zip(points).map(|(x, r)| x.z - r.z).collect::<Vec<_>>();
            let ref_uz = panels.last().map(uz).unwrap_or_default();
            let ref_max = ref_uz.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
            for p in panels.iter_mut().rev().skip(1) {
                let gap = uz(p).iter().zip(&ref_uz).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                p.measure = Some(100.0 * gap / ref_max);
            }
            draw_strips(title, &panels, points, nu, nv)
        }
        FigureKind::Tension | FigureKind::Torsion => {
            let project: fn(&Vec3) -> [f64; 2] =
                if kind == FigureKind::Tension { |p| [p.x, p.z] } else { |p| [p.y, p.z] };
            let boundary = ring(nu, nv);
            let outline = |p: &Panel| boundary.iter().map(|&k| project(&p.deformed[k])).collect::<Vec<_>>();
            let ref_outline = panels.last().map(outline).unwrap_or_default();
            for p in panels.iter_mut().rev().skip(1) {
                p.measure = Some(outline_distance(&outline(p), &ref_outline));
            }
            draw_deformed(title, &panels, points, nu, nv, project, &ref_outline, 3)
        }
    };
    Figure { name: kind.file_name(), title: title.into(), panels, measure_name: kind.measure_name(), svg }
}

/// A panel of `label` sampled at the rest `points` from `positions` on `mesh` (a case: its ms
/// per frame and whether it settled; a reference: None).
pub fn panel_of(
    label: String,
    mesh: &Mesh,
    positions: &[Vec3],
    points: &[Vec3],
    timing: Option<(f64, bool)>,
) -> Result<Panel, SceneError> {
    Ok(Panel {
        label,
        nodes: mesh.num_nodes(),
        elements: mesh.num_elements(),
        ms_per_frame: timing.map(|t| t.0),
        settled: timing.is_none_or(|t| t.1),
        deformed: sample(mesh, positions, points)?,
        measure: None,
    })
}

/// The reference panel of `scene` — its physics as they are (another ν, E, …) — at `points`:
/// the static solution on a Q2 mesh of its box, the figure's reference grid (`quick`: the coarse
/// one), solved here.
pub fn reference_panel(
    scene: &crate::scene::Scene,
    kind: FigureKind,
    points: &[Vec3],
    quick: bool,
) -> Result<Panel, SceneError> {
    let name = match kind {
        FigureKind::Tension => "tension",
        FigureKind::Torsion => "torsion",
        FigureKind::Bending => "bending",
    };
    let (cells, load_steps) = reference_grid(name, quick);
    let overrides = SceneOverrides {
        element: hox_sim::element::ElementType::from_name("q2"),
        grid: Some(cells),
        refine: Some(0),
        ..Default::default()
    };
    let built = scene.with_overrides(&overrides)?;
    let instance = Instance::new(built)?;
    let solution =
        crate::instance::solve_static(&instance.scene, instance.sim.mesh(), 1e-9, load_steps, &mut |_, _, _| {})?;
    panel_of(reference_label(name, quick), instance.sim.mesh(), &solution.positions, points, None)
}

/// The reference panel's label: its mesh.
fn reference_label(scene: &str, quick: bool) -> String {
    let (cells, _) = reference_grid(scene, quick);
    format!("reference (Q2 {}×{}×{}, static)", cells[0], cells[1], cells[2])
}

/// Deformed positions at the rest points `points`, by each one's element's shape functions.
pub fn sample(mesh: &Mesh, positions: &[Vec3], points: &[Vec3]) -> Result<Vec<Vec3>, SceneError> {
    points
        .iter()
        .map(|&p| {
            Probe::locate(mesh, "sample", p)
                .map(|probe| probe.position(positions))
                .map_err(|e| SceneError::Simulation { source_name: "paper".into(), message: e.to_string() })
        })
        .collect()
}

/// A rest grid of `nu × nv` points `origin + a·u/(nu−1) + b·v/(nv−1)`, row-major in `u`.
fn grid(origin: Vec3, u: Vec3, v: Vec3, nu: usize, nv: usize) -> Vec<Vec3> {
    (0..nv)
        .flat_map(|j| {
            (0..nu).map(move |i| origin + u * (i as f64 / (nu - 1) as f64) + v * (j as f64 / (nv - 1) as f64))
        })
        .collect()
}

/// The indices of a `nu × nv` grid's boundary, in order round it.
pub fn ring(nu: usize, nv: usize) -> Vec<usize> {
    let mut r: Vec<usize> = (0..nu).collect();
    r.extend((1..nv).map(|j| j * nu + nu - 1));
    r.extend((0..nu - 1).rev().map(|i| (nv - 1) * nu + i));
    r.extend((1..nv - 1).rev().map(|j| j * nu));
    r
}

/// Distance from `p` to the closed polyline `poly`, in 2D.
fn to_polyline(p: [f64; 2], poly: &[[f64; 2]]) -> f64 {
    (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
            ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The largest distance from `outline` (its points) to the closed polyline `reference`.
pub fn outline_distance(outline: &[[f64; 2]], reference: &[[f64; 2]]) -> f64 {
    outline.iter().map(|&p| to_polyline(p, reference)).fold(0.0, f64::max)
}

/// Runs `scene` with `overrides` settled at the paper's settings (XPBD, one thread) and returns
/// the instance and its report.
fn settled(
    scene: &str,
    overrides: &SceneOverrides,
    cap_secs: f64,
) -> Result<(Instance, crate::run::RunReport), SceneError> {
    let built = crate::scene::builtin::by_name(scene)?.with_overrides(overrides)?;
    let mut instance = Instance::new(built)?;
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().map_err(|e| SceneError::Simulation {
        source_name: scene.into(),
        message: format!("cannot make a one-thread pool: {e}"),
    })?;
    let report = one_thread.install(|| run(&mut instance, RunMode::Settle { cap_secs }, &mut |_, _| {}))?;
    Ok((instance, report))
}

/// The state a run is measured by: settled positions, or the last-second mean's stand-in (the
/// final positions of a run still moving, whose report says it did not settle).
fn reference_solution(scene: &str, quick: bool) -> Result<(Instance, Vec<Vec3>), SceneError> {
    let (cells, load_steps) = reference_grid(scene, quick);
    let overrides = SceneOverrides {
        element: hox_sim::element::ElementType::from_name("q2"),
        grid: Some(cells),
        ..Default::default()
    };
    let built = crate::scene::builtin::by_name(scene)?.with_overrides(&overrides)?;
    let instance = Instance::new(built)?;
    let solution =
        crate::instance::solve_static(&instance.scene, instance.sim.mesh(), 1e-9, load_steps, &mut |_, _, _| {})?;
    Ok((instance, solution.positions))
}

fn panel(
    label: String,
    instance: &Instance,
    positions: &[Vec3],
    points: &[Vec3],
    report: Option<&crate::run::RunReport>,
) -> Result<Panel, SceneError> {
    panel_of(label, instance.sim.mesh(), positions, points, report.map(|r| (r.ms_per_frame, r.settled || r.at_rest)))
}

fn case_label(config: &StudyConfig, elements: usize) -> String {
    let split = match config.split {
        TetSplit::Six => " biased",
        TetSplit::Five if config.element.starts_with('p') => " unbiased",
        _ => "",
    };
    format!("{} {elements}{split}", config.element.to_uppercase())
}

/// Runs the paper's experiments (`quick`: coarse references, short runs, the small meshes only)
/// and draws its figures. `progress(message)` says what runs.
pub fn run_paper(quick: bool, progress: &mut dyn FnMut(&str)) -> Result<PaperResult, SceneError> {
    let res = resolution(quick);
    let c = |element: &'static str, grid: [usize; 3], split: TetSplit, refine: usize, heavy: bool| StudyConfig {
        element,
        grid,
        split,
        refine,
        heavy,
    };
    let mut figures = Vec::new();

    // Fig. 1 and 2: the 637-vertex beams (biased: six tetrahedra per cell; unbiased: five)
    let beam = |scene: &str| -> Result<(Vec3, Vec3), SceneError> {
        let built = crate::scene::builtin::by_name(scene)?;
        let params = built.params();
        Ok((Vec3::from(params.box_min_m), Vec3::from(params.box_max_m)))
    };
    for (scene, kind) in [("tension", FigureKind::Tension), ("torsion", FigureKind::Torsion)] {
        progress(&format!("{scene}: reference (static, Q2)"));
        let (reference, ref_positions) = reference_solution(scene, quick)?;
        let (lo, hi) = beam(scene)?;
        let (points, nu, nv) = kind.samples(lo, hi, quick);
        let splits: &[TetSplit] = if scene == "tension" { &[TetSplit::Six] } else { &[TetSplit::Six, TetSplit::Five] };
        let mut panels = Vec::new();
        for &split in splits {
            for (element, cells) in [("p1", [12, 6, 6]), ("p2", [6, 3, 3]), ("p3", [4, 2, 2])] {
                let config = c(element, cells, split, 0, false);
                progress(&format!("{scene}: {} XPBD at 50 substeps", config.label()));
                let (instance, report) = settled(scene, &config.overrides(), res.cap_secs)?;
                let label = case_label(&config, instance.sim.mesh().num_elements());
                panels.push(panel(label, &instance, &instance.sim.positions, &points, Some(&report))?);
            }
        }
        panels.push(panel(reference_label(scene, quick), &reference, &ref_positions, &points, None)?);
        figures.push(draw_figure(kind, panels, &points, nu, nv));
    }

    // Fig. 3 and Table 1: the bending beams
    progress("bending: reference (static, Q2)");
    let (reference, ref_positions) = reference_solution("bending", quick)?;
    let (lo, hi) = beam("bending")?;
    let (top, nu, nv) = FigureKind::Bending.samples(lo, hi, quick);
    let committed = crate::lab::study::reference("bending")?;
    let tip_ref = committed.iter().find(|(n, _)| n == "tip").map(|(_, u)| *u).unwrap_or_default();
    let bending = [
        (c("p1", [16, 4, 4], TetSplit::Five, 0, false), 0),
        (c("p1", [16, 4, 4], TetSplit::Five, 1, true), 1),
        (c("p1", [16, 4, 4], TetSplit::Five, 2, true), 2),
        (c("p2", [8, 2, 2], TetSplit::Five, 0, false), 3),
        (c("p3", [4, 2, 2], TetSplit::Five, 0, false), 4),
    ];
    let mut panels = Vec::new();
    let mut table = Vec::new();
    for (config, row) in bending.iter().filter(|(c, _)| !(quick && c.heavy)) {
        let cap = if config.heavy { res.heavy_cap_secs } else { res.cap_secs };
        progress(&format!("bending: {} XPBD at 50 substeps", config.label()));
        let (instance, report) = settled("bending", &config.overrides(), cap)?;
        let tip = |inst: &Instance| {
            inst.probes
                .iter()
                .find(|p| p.name == "tip")
                .map(|p| p.displacement(&inst.sim.positions, &inst.sim.mesh().rest_positions))
                .unwrap_or_default()
        };
        let xpbd_tip = if report.settled || report.at_rest {
            tip(&instance)
        } else {
            report.probes_last_second_mean.get("tip").map(|u| Vec3::from(*u)).unwrap_or_else(|| tip(&instance))
        };
        let (paper_label, paper_elements, paper_ms, paper_error) = PAPER_TABLE_1[*row];
        let mut solvers = Vec::new();
        for method in ["vbd", "newton", "newton-cg"] {
            progress(&format!("bending: {} {method} at its defaults", config.label()));
            let mut o = config.overrides();
            o.method = hox_sim::solver::Method::from_name(method);
            let (inst, r) = settled("bending", &o, cap)?;
            let u = if r.settled || r.at_rest {
                tip(&inst)
            } else {
                r.probes_last_second_mean.get("tip").map(|u| Vec3::from(*u)).unwrap_or_else(|| tip(&inst))
            };
            solvers.push((method.to_string(), r.ms_per_frame, (u - tip_ref).norm()));
        }
        let elements = instance.sim.mesh().num_elements();
        debug_assert_eq!(format!("P{}", &config.element[1..]), paper_label.to_string());
        table.push(TableRow {
            label: format!("{paper_label} {paper_elements}"),
            vertices: instance.sim.mesh().num_nodes(),
            elements,
            paper_ms_per_frame: paper_ms,
            paper_error_m: paper_error,
            xpbd_ms_per_frame: report.ms_per_frame,
            xpbd_error_m: (xpbd_tip - tip_ref).norm(),
            xpbd_settled: report.settled || report.at_rest,
            solvers,
        });
        let label = format!("{} {elements}", config.element.to_uppercase());
        panels.push(panel(label, &instance, &instance.sim.positions, &top, Some(&report))?);
    }
    panels.push(panel(reference_label("bending", quick), &reference, &ref_positions, &top, None)?);
    figures.push(draw_figure(FigureKind::Bending, panels, &top, nu, nv));
    Ok(PaperResult { figures, table, quick })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_outline_distance_is_zero_on_itself_and_the_offset_otherwise() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(outline_distance(&square, &square), 0.0);
        let moved: Vec<[f64; 2]> = square.iter().map(|p| [p[0] + 0.1, p[1]]).collect();
        assert!((outline_distance(&moved, &square) - 0.1).abs() < 1e-12);
        let r = ring(4, 3);
        assert_eq!(r.len(), 2 * 4 + 2 * 3 - 4);
        assert_eq!(r.iter().collect::<std::collections::BTreeSet<_>>().len(), r.len());
    }
}
