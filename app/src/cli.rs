//! The headless command line. JSON goes to stdout (`--json`), progress and messages to stderr.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use hox_scenes::{Instance, RunMode, Scene, SceneOverrides};
use hox_sim::element::ElementType;
use hox_sim::fem::quadrature;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod gmsh;
mod record;
pub use record::check_writable;

#[derive(Parser)]
#[command(name = "hox", version, about = "hox: see, measure and teach high-order finite elements in XPBD")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand)]
pub enum Command {
    /// List the element types: nodes, faces, default quadrature (degree and points).
    Elements {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// List the built-in scenes.
    Scenes {
        #[arg(long)]
        json: bool,
    },
    /// Build a scene's mesh and print its element and node counts and volume.
    Mesh {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        mesh: MeshArgs,
        #[arg(long)]
        json: bool,
    },
    /// Solve a scene's static equilibrium (Newton's method with a sparse Cholesky factorisation,
    /// load stepping) and print the probe displacements.
    Static {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        physics: PhysicsArgs,
        /// Relative residual to stop at.
        #[arg(long, default_value_t = 1e-8)]
        tolerance: f64,
        /// Initial number of load increments (halved automatically where Newton struggles).
        #[arg(long, default_value_t = 1)]
        load_steps: usize,
        #[arg(long)]
        json: bool,
    },
    /// The accuracy-versus-time study over the paper scenes: writes study.md, study.csv,
    /// locking.csv (P1/P2/P3 near incompressibility) and study.svg to --out.
    Study {
        /// Only the coarse configurations (minutes instead of an hour).
        #[arg(long)]
        quick: bool,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Time the XPBD loop on the paper's Table 1 beams and the other element types: ms per
    /// frame against the paper's, ns per element per substep, GFLOP/s (docs/PERFORMANCE.md).
    Bench {
        /// Timed frames per configuration (the median is reported).
        #[arg(long, default_value_t = 20)]
        frames: usize,
        /// Thread counts, comma-separated (1: the serial sweep; more: the parallel colour sweep).
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Only the configurations whose label contains this (e.g. "p1", "r2").
        #[arg(long, default_value = "")]
        only: String,
        /// Also time the colour sweep on one thread (linear tetrahedra four per 256-bit
        /// register; `--colour-on-one false`: the serial sweep only).
        #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
        colour_on_one: bool,
    },
    /// Run a scene (for --seconds, or until it --settle-s) and print the probe displacements.
    Simulate {
        #[command(flatten)]
        scene: SceneArgs,
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        physics: PhysicsArgs,
        /// Simulated time to run, seconds (default: the scene's duration).
        #[arg(long, conflicts_with = "settle", allow_negative_numbers = true)]
        seconds: Option<f64>,
        /// Run with the scene's settle damping until the motion has died out (every node moves
        /// less than 1e-7 × the body's diagonal per frame for 30 frames) or 120 s.
        #[arg(long)]
        settle: bool,
        #[command(flatten)]
        vtk: gmsh::VtkArgs,
        #[arg(long)]
        json: bool,
    },
    /// Record a scene to a Rerun file (.rrd) without a display: the deformed surface coloured by
    /// displacement, element edges, probes and time series; --compare records several
    /// configurations side by side.
    Record(record::RecordArgs),
    /// Read a Rerun recording back and list its entities, components and frame counts.
    Inspect(record::InspectArgs),
    /// Open the interactive app (the default when no command is given).
    App(crate::gui::AppArgs),
}

#[derive(Args)]
pub struct SceneArgs {
    /// A built-in scene (see `hox scenes`).
    #[arg(long, conflicts_with_all = ["scene_file", "mesh_file"], required_unless_present_any = ["scene_file", "mesh_file"])]
    pub scene: Option<String>,
    /// A scene file (TOML, see assets/scenes/).
    #[arg(long, conflicts_with = "mesh_file")]
    pub scene_file: Option<PathBuf>,
    #[command(flatten)]
    pub mesh_file: gmsh::MeshFileArgs,
}

#[derive(Args)]
pub struct MeshArgs {
    /// Element type: p1 p2 p3 q1 q2 prism pyramid.
    #[arg(long)]
    pub element: Option<String>,
    /// Hexahedral cells, NXxNYxNZ (e.g. 16x4x4).
    #[arg(long, value_parser = parse_grid)]
    pub grid: Option<[usize; 3]>,
    /// Tetrahedra per cell: five (unbiased) or six (biased).
    #[arg(long)]
    pub split: Option<String>,
    /// 1-to-8 refinements of the tetrahedra.
    #[arg(long)]
    pub refine: Option<usize>,
}

#[derive(Args)]
pub struct PhysicsArgs {
    /// Material model: stvk, snh (stable Neo-Hookean), snh-log (stable Neo-Hookean with
    /// Smith et al.'s log term) or nh (Neo-Hookean).
    #[arg(long)]
    pub material: Option<String>,
    /// Young's modulus, Pa.
    #[arg(long, allow_negative_numbers = true)]
    pub youngs: Option<f64>,
    /// Poisson ratio.
    #[arg(long, allow_negative_numbers = true)]
    pub poisson: Option<f64>,
    /// Density, kg/m³.
    #[arg(long, allow_negative_numbers = true)]
    pub density: Option<f64>,
    /// Constraint formulation: energy or split.
    #[arg(long)]
    pub formulation: Option<String>,
    /// Quadrature degree (default: each element type's).
    #[arg(long)]
    pub quadrature: Option<usize>,
    /// Substeps per frame.
    #[arg(long)]
    pub substeps: Option<u32>,
    /// Solver iterations per substep.
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Frames per second.
    #[arg(long, allow_negative_numbers = true)]
    pub fps: Option<f64>,
    /// Project elements in parallel (colour by colour, on all threads; RAYON_NUM_THREADS sets
    /// how many).
    #[arg(long)]
    pub parallel: bool,
    /// Keep the requested substeps even where the stiffest element needs more for stability
    /// (above h·ω_max = 3 the stability guard raises them to h·ω_max ≤ 1; see docs/STABILITY.md).
    #[arg(long)]
    pub no_stability_guard: bool,
}

/// The stability guard's findings for a built scene; a note on stderr when it raised the
/// substeps (docs/STABILITY.md).
pub fn note_stability(instance: &mut Instance) -> hox_sim::solver::stability::StabilityReport {
    let stability = instance.sim.stability();
    if stability.raised() {
        eprintln!("note: {}", stability.summary());
    }
    stability
}

fn parse_grid(s: &str) -> Result<[usize; 3], String> {
    let parts: Vec<&str> = s.split(['x', 'X']).collect();
    let bad = || format!("grid '{s}' must look like NXxNYxNZ with positive whole numbers, e.g. 16x4x4");
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut g = [0; 3];
    for (gi, p) in g.iter_mut().zip(parts) {
        *gi = p.trim().parse().map_err(|_| bad())?;
        if *gi == 0 {
            return Err(bad());
        }
    }
    Ok(g)
}

pub fn main(cli: Cli) -> Result<()> {
    match cli.command.unwrap_or(Command::App(crate::gui::AppArgs::default())) {
        Command::Elements { json } => elements(json),
        Command::Scenes { json } => scenes(json),
        Command::Mesh { scene, mesh, json } => mesh_command(&scene, &mesh, json),
        Command::Simulate { scene, mesh, physics, seconds, settle, vtk, json } => {
            simulate(&scene, &mesh, &physics, seconds, settle, &vtk, json)
        }
        Command::Study { quick, out } => study(quick, &out),
        Command::Bench { frames, threads, only, colour_on_one } => bench(frames, &threads, &only, colour_on_one),
        Command::Static { scene, mesh, physics, tolerance, load_steps, json } => {
            static_command(&scene, &mesh, &physics, tolerance, load_steps, json)
        }
        Command::Record(args) => record::record(&args),
        Command::Inspect(args) => record::inspect(&args),
        Command::App(args) => crate::gui::run(args),
    }
}

/// A progress bar (1000 steps) on stderr that appears only once a run has lasted two seconds,
/// so short runs print nothing but their result.
struct DelayedBar {
    bar: ProgressBar,
    started: Instant,
    shown: bool,
}

impl DelayedBar {
    fn new() -> Self {
        Self { bar: ProgressBar::hidden(), started: Instant::now(), shown: false }
    }
    /// Shows the bar with `template` once the delay is over.
    fn reveal(&mut self, template: &str) {
        if !self.shown && self.started.elapsed() > Duration::from_secs(2) {
            self.shown = true;
            self.bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            self.bar.set_length(1000);
            self.bar.set_style(ProgressStyle::with_template(template).expect("valid template"));
        }
    }
}

fn load_scene(args: &SceneArgs) -> Result<Scene> {
    if let Some(scene) = gmsh::scene(&args.mesh_file)? {
        return Ok(scene);
    }
    Ok(match (&args.scene, &args.scene_file) {
        (Some(name), None) => hox_scenes::by_name(name)?,
        (None, Some(path)) => Scene::load(path)?,
        _ => bail!("give exactly one of --scene NAME, --scene-file FILE and --mesh FILE.msh"),
    })
}

fn overrides(mesh: &MeshArgs, physics: Option<&PhysicsArgs>) -> SceneOverrides {
    let mut o = SceneOverrides {
        element: mesh.element.clone(),
        grid: mesh.grid,
        split: mesh.split.clone(),
        refine: mesh.refine,
        ..Default::default()
    };
    if let Some(p) = physics {
        o.material = p.material.clone();
        o.youngs_modulus_pa = p.youngs;
        o.poisson_ratio = p.poisson;
        o.density_kg_m3 = p.density;
        o.formulation = p.formulation.clone();
        o.quadrature_degree = p.quadrature;
        o.substeps = p.substeps;
        o.iterations = p.iterations;
        o.frames_per_second = p.fps;
        o.parallel = p.parallel.then_some(true);
        o.stability_guard = p.no_stability_guard.then_some(false);
    }
    o
}

fn mesh_command(scene: &SceneArgs, mesh: &MeshArgs, json: bool) -> Result<()> {
    let scene = load_scene(scene)?.with_overrides(&overrides(mesh, None))?;
    let m = scene.build_mesh()?;
    let geometry = hox_sim::fem::geometry::precompute(&m, scene.settings.quadrature_degree)
        .with_context(|| format!("{}: the mesh has a bad element", scene.source))?;
    let mut out = serde_json::json!({
        "element": scene.mesh.element_names(),
        "elements": m.num_elements(),
        "nodes": m.num_nodes(),
        "volume_m3": hox_sim::fem::geometry::total_volume_m3(&geometry),
    });
    if let Some(imported) = scene.mesh.imported() {
        out["blocks"] = m
            .blocks
            .iter()
            .map(|b| serde_json::json!({"element": b.element_type.name(), "elements": b.len()}))
            .collect();
        out["groups"] = imported.node_sets.iter().map(|(name, nodes)| (name.clone(), serde_json::json!({"nodes": nodes.len(), "elements": imported.element_sets.get(name).map_or(0, Vec::len)}))).collect();
    }
    if json {
        println!("{out}");
    } else {
        println!(
            "{}: {} {} elements, {} nodes, volume {:.6} m³",
            scene.name(),
            out["elements"],
            out["element"].as_str().unwrap_or_default(),
            out["nodes"],
            out["volume_m3"].as_f64().unwrap_or_default()
        );
        if let Some(imported) = scene.mesh.imported() {
            println!("  physical groups: {}", imported.group_names());
        }
    }
    Ok(())
}

fn simulate(
    scene: &SceneArgs,
    mesh: &MeshArgs,
    physics: &PhysicsArgs,
    seconds: Option<f64>,
    settle: bool,
    vtk: &gmsh::VtkArgs,
    json: bool,
) -> Result<()> {
    let scene = load_scene(scene)?.with_overrides(&overrides(mesh, Some(physics)))?;
    let mode = if settle {
        RunMode::SETTLE
    } else {
        let t = seconds.unwrap_or(scene.file.solver.duration_secs);
        if !(t.is_finite() && t >= 0.0) {
            bail!("--seconds must be a finite, non-negative number of seconds, got {t}");
        }
        RunMode::Seconds(t)
    };
    let mut instance = Instance::new(scene)?;
    let stability = note_stability(&mut instance);
    let mut vtk_writer = gmsh::VtkWriter::create(vtk, &instance)?;
    let mut bar = DelayedBar::new();
    let mut on_frame = |i: &Instance| vtk_writer.as_mut().map_or(Ok(()), |w| w.frame(i));
    let report = hox_scenes::run_observed(
        &mut instance,
        mode,
        &mut |t, fraction| {
            let template = if fraction.is_some() {
                "{spinner} {bar:40} {percent}% {msg} (eta {eta})"
            } else {
                "{spinner} settling… {msg}"
            };
            bar.reveal(template);
            if let Some(f) = fraction {
                bar.bar.set_position((1000.0 * f) as u64);
            }
            bar.bar.set_message(format!("t = {t:.2} s"));
        },
        &mut on_frame,
    )?;
    bar.bar.finish_and_clear();
    let groups = instance.group_displacements();
    let vtk_index = vtk_writer.map(|w| w.finish(&instance)).transpose()?;
    if json {
        let mut out = serde_json::to_value(&report)?;
        if !groups.is_empty() {
            out["groups"] = serde_json::to_value(&groups)?;
        }
        if let Some(index) = &vtk_index {
            out["vtk"] = index.display().to_string().into();
        }
        out["substeps_per_frame"] = stability.substeps.into();
        out["h_omega_max"] = stability.requested_h_omega.into();
        println!("{out}");
    } else {
        println!(
            "{}: {} frames, {:.3} s simulated, {:.2} ms per frame{}",
            instance.scene.name(),
            report.frames,
            report.sim_seconds,
            report.ms_per_frame,
            if settle { if report.settled { ", settled" } else { ", NOT settled (cap reached)" } } else { "" }
        );
        for (name, u) in &report.probes {
            println!("  probe {name}: u = ({:+.6}, {:+.6}, {:+.6}) m", u[0], u[1], u[2]);
        }
        for (name, u) in &groups {
            println!("  group {name}: mean u = ({:+.6}, {:+.6}, {:+.6}) m", u[0], u[1], u[2]);
        }
        println!(
            "  kinetic energy {:.6e} J, elastic energy {:.6e} J",
            report.kinetic_energy_j, report.elastic_energy_j
        );
        if let Some(index) = &vtk_index {
            println!("  ParaView series: {}", index.display());
        }
    }
    if settle && !report.settled {
        eprintln!("warning: the run did not settle within {} s", hox_scenes::SETTLE_CAP_SECS);
    }
    Ok(())
}

fn static_command(
    scene: &SceneArgs,
    mesh: &MeshArgs,
    physics: &PhysicsArgs,
    tolerance: f64,
    load_steps: usize,
    json: bool,
) -> Result<()> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        bail!("--tolerance must be a finite positive number, got {tolerance}");
    }
    if load_steps == 0 {
        bail!("--load-steps must be at least 1");
    }
    let scene = load_scene(scene)?.with_overrides(&overrides(mesh, Some(physics)))?;
    let m = scene.build_mesh()?;
    let started = Instant::now();
    let mut bar = DelayedBar::new();
    let solution =
        hox_scenes::solve_static(&scene, &m, tolerance, load_steps, &mut |fraction, iteration, residual| {
            bar.reveal("{spinner} load {bar:30} {msg} [{elapsed}]");
            bar.bar.set_position((1000.0 * fraction) as u64);
            bar.bar.set_message(format!("Newton iteration {iteration}, residual {residual:.2e}"));
        })?;
    bar.bar.finish_and_clear();
    let dofs = solution.free_dofs;
    let seconds = started.elapsed().as_secs_f64();
    let mut probes = std::collections::BTreeMap::new();
    for p in &scene.file.probes {
        let probe = hox_sim::measure::probe::Probe::locate(&m, &p.name, hox_sim::Vec3::from(p.point_m))?;
        let u = probe.displacement(&solution.positions, &m.rest_positions);
        probes.insert(p.name.clone(), [u.x, u.y, u.z]);
    }
    let groups = scene.group_displacements(&solution.positions);
    let out = serde_json::json!({
        "probes": probes,
        "groups": groups,
        "newton_iterations": solution.newton_iterations,
        "residual": solution.relative_residual,
        "seconds": seconds,
        "dofs": dofs,
    });
    if json {
        println!("{out}");
    } else {
        println!(
            "{}: static equilibrium, {dofs} DOFs, {} Newton iterations, residual {:.2e}, {seconds:.2} s",
            scene.name(),
            solution.newton_iterations,
            solution.relative_residual
        );
        for (name, u) in &probes {
            println!("  probe {name}: u = ({:+.6}, {:+.6}, {:+.6}) m", u[0], u[1], u[2]);
        }
        for (name, u) in &groups {
            println!("  group {name}: mean u = ({:+.6}, {:+.6}, {:+.6}) m", u[0], u[1], u[2]);
        }
    }
    Ok(())
}

fn bench(frames: usize, threads: &[usize], only: &str, colour_on_one: bool) -> Result<()> {
    if frames == 0 || threads.contains(&0) {
        bail!("--frames and every --threads count must be at least 1");
    }
    let rows = hox_sim::benchmark::run(only, threads, colour_on_one, frames, &mut |r| {
        eprintln!(
            "{} on {} thread(s), parallel {}: {:.2} ms/frame",
            r.case.label(),
            r.threads,
            r.parallel,
            r.ms_per_frame
        )
    })?;
    if rows.is_empty() {
        bail!("no configuration matches '{only}'");
    }
    print!("{}", hox_sim::benchmark::markdown(&rows));
    Ok(())
}

fn study(quick: bool, out: &std::path::Path) -> Result<()> {
    // refuse an unwritable folder before spending minutes
    std::fs::create_dir_all(out).with_context(|| format!("cannot create the output folder {}", out.display()))?;
    let probe = out.join(".hox-write-test");
    std::fs::write(&probe, b"").with_context(|| format!("cannot write to the output folder {}", out.display()))?;
    let _ = std::fs::remove_file(&probe);
    let bar = ProgressBar::new_spinner();
    bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed}] {msg}").expect("valid template"));
    bar.enable_steady_tick(Duration::from_millis(200));
    let started = Instant::now();
    let mut report = |message: &str| {
        // a log line per step when stderr is not a terminal (CI), the spinner otherwise
        if bar.is_hidden() {
            eprintln!("[{:>6.1} s] {message}", started.elapsed().as_secs_f64());
        }
        bar.set_message(message.to_string());
    };
    let rows = hox_scenes::study::run_study(quick, &mut report)?;
    let locking = hox_scenes::study::locking(quick, &mut report)?;
    bar.finish_and_clear();
    let files = [
        ("study.md", hox_scenes::study::markdown(&rows, quick) + "\n" + &hox_scenes::study::locking_markdown(&locking)),
        ("study.csv", hox_scenes::study::csv(&rows)),
        ("locking.csv", hox_scenes::study::locking_csv(&locking)),
        ("study.svg", hox_scenes::study::svg(&rows)),
    ];
    for (name, text) in files {
        let path = out.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn scenes(json: bool) -> Result<()> {
    let all = hox_scenes::registry()?;
    if json {
        let rows: Vec<_> = all
            .iter()
            .map(|s| serde_json::json!({"name": s.name(), "description": s.file.description, "effects": s.file.effects.iter().map(|e| e.kind()).collect::<Vec<_>>()}))
            .collect();
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        for s in &all {
            let effects: Vec<&str> = s.file.effects.iter().map(|e| e.kind()).collect();
            println!("{:<8} {} [{}]", s.name(), s.file.description, effects.join(", "));
        }
    }
    Ok(())
}

fn elements(json: bool) -> Result<()> {
    let rows: Vec<serde_json::Value> = ElementType::all()
        .map(|e| -> Result<serde_json::Value> {
            let degree = e.default_quadrature_degree();
            let rule = quadrature::rule(e.shape(), degree)?;
            Ok(serde_json::json!({
                "element": e.name(),
                "description": e.description(),
                "gmsh_type": e.gmsh_type(),
                "nodes": e.num_nodes(),
                "faces": e.faces().len(),
                "quadrature_degree": degree,
                "quadrature_points": rule.len(),
            }))
        })
        .collect::<Result<_>>()?;
    if json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!("{:<8} {:<38} {:>5} {:>5} {:>6} {:>7}", "element", "description", "gmsh", "nodes", "degree", "points");
    for r in &rows {
        println!(
            "{:<8} {:<38} {:>5} {:>5} {:>6} {:>7}",
            r["element"].as_str().unwrap_or(""),
            r["description"].as_str().unwrap_or(""),
            r["gmsh_type"].to_string(),
            r["nodes"].to_string(),
            r["quadrature_degree"].to_string(),
            r["quadrature_points"].to_string()
        );
    }
    Ok(())
}
