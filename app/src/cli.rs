//! The headless commands: their arguments ([`Command`]) and what each runs, one file per command.
//! JSON goes to stdout (`--json`), progress and messages to stderr.

use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use hox_scenes::{Instance, Scene};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod bench;
mod gmsh;
pub(crate) mod inspect;
mod lesson;
mod list;
mod mesh;
mod paper;
mod record;
mod reference;
mod serve;
mod simulate;
mod statics;
mod study;
use crate::config::{MeshArgs, PhysicsArgs};

// The headless commands; `main.rs` adds `hox app`, the interactive one, beside them. (A plain
// comment: clap's derive reads doc comments as help text, and the help stays as it was.)
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
    /// List the solvers and the implicit solvers' integrators: what each is, the parameters it
    /// reads and what it does to the motion.
    Solvers {
        /// Print JSON instead of text.
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
        #[command(flatten)]
        reference: reference::ReferenceArgs,
        #[arg(long)]
        json: bool,
    },
    /// The paper reproduced: its tension, torsion and bending experiments at its settings, Table 1
    /// beside the paper's rows with a column per solver, Figs. 1–3 as SVG and PNG with the
    /// reference drawn in, and PAPER.md checking each caption's claim, written to --out.
    Paper {
        /// Coarse references, short runs and the small meshes only (under a minute).
        #[arg(long)]
        quick: bool,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// The accuracy-versus-time study over the paper scenes: writes study.md, study.csv,
    /// locking.csv (P1/P2/P3 near incompressibility) and study.svg to --out. For a job array:
    /// `--shard K/N` runs the K-th of N parts into study-part-K-of-N.toml, `hox study merge`
    /// joins the parts into the same files as one run.
    #[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
    Study {
        #[command(subcommand)]
        merge: Option<StudyMerge>,
        /// Only the coarse configurations (minutes instead of an hour).
        #[arg(long)]
        quick: bool,
        /// Only these tables, comma-separated: accuracy, locking, solvers (default: all).
        #[arg(long, value_name = "TABLES")]
        only: Option<String>,
        /// Run part K of N of the study's cells (K from 1; cell i goes to part i mod N + 1) and
        /// write it to --out as study-part-K-of-N.toml, for `hox study merge`.
        #[arg(long, value_name = "K/N", conflicts_with = "summary")]
        shard: Option<String>,
        /// Output folder (created if missing).
        #[arg(long, required_unless_present = "summary", conflicts_with = "summary")]
        out: Option<PathBuf>,
        /// Run nothing: print the figures of the study a `--out DIR` run wrote to DIR, as
        /// docs/STUDY.md shows them (its machine line, the bending beam beside the paper's
        /// Table 1, the cheapest configuration within 1 % per scene, the beam in motion).
        #[arg(long, value_name = "DIR")]
        summary: Option<PathBuf>,
    },
    /// Time the XPBD loop on the paper's Table 1 beams and the other element types: ms per
    /// frame against the paper's, ns per element per substep, GFLOP/s (docs/PERFORMANCE.md);
    /// --solver NAME times an implicit solver of `hox solvers` on the same beams.
    Bench {
        /// Timed frames per configuration (the median is reported); a case's configurations
        /// (thread counts, sweeps, widths) are timed side by side, a frame of each in turn.
        #[arg(long, default_value_t = 20)]
        frames: usize,
        /// Thread counts, comma-separated; with more than one thread a row also shows its
        /// speed-up over one thread, frame by frame.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Only the configurations whose label contains this (e.g. "p1", "r2"; "table1": the
        /// paper's Table 1 beams; "parts": the curved parts, with --solver).
        #[arg(long, default_value = "")]
        only: String,
        /// The sweep orders timed, comma-separated: colour (the default everywhere: a register
        /// of elements at a time, every thread) on each thread count, element (mesh order, one
        /// thread) on one thread. XPBD only.
        #[arg(long, value_delimiter = ',', default_value = "colour,element")]
        sweep: Vec<String>,
        /// The colour sweep's register widths timed side by side, comma-separated: 4 (AVX2) and
        /// 8 (AVX-512). Default: the widest this CPU has. XPBD only.
        #[arg(long, value_delimiter = ',')]
        lanes: Vec<usize>,
        /// The solver timed (`hox solvers`): xpbd (the table above), vbd (µs per node update and
        /// per element visit) or a Newton-type one, newton or newton-cg (ms per iteration and per
        /// factorisation); the thread counts run side by side, with the speed-up over one thread.
        #[arg(long, default_value = "xpbd")]
        solver: String,
        /// Print the beam labelled LABEL (e.g. "P1 16x4x4 r1") as JSON, `positions_m`, `tets`
        /// and `clamped`, and time nothing: the mesh a peer benchmark solves too
        /// (bench/pbd_peer.py times PositionBasedDynamics on it).
        #[arg(long, value_name = "LABEL")]
        beam_json: Option<String>,
        /// Print the stability guard's figures for every built-in scene and benchmark beam at
        /// its own settings, timing nothing: the fastest element mode ω_max, `h·ω_max` at the
        /// substeps asked, and the substeps the guard takes (docs/STABILITY.md).
        #[arg(long, conflicts_with = "beam_json")]
        stability: bool,
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
        #[command(flatten)]
        reference: reference::ReferenceArgs,
        #[arg(long)]
        json: bool,
    },
    /// Record a scene to a Rerun file (.rrd) without a display: the deformed surface coloured by
    /// displacement, element edges, probes and time series; --compare records several
    /// configurations side by side.
    Record(Box<record::RecordArgs>),
    /// Read a Rerun recording back and list its entities, components and frame counts.
    Inspect(inspect::InspectArgs),
    /// List the built-in lessons: guided classroom demonstrations (`hox app --lesson NAME`).
    Lessons {
        #[arg(long)]
        json: bool,
    },
    /// Run a lesson headlessly, step by step, printing each step's measurement; `--record`
    /// writes it as a Rerun file a student plays in the stock viewer.
    Lesson(Box<lesson::LessonArgs>),
    /// Serve a recording (.rrd, e.g. from `hox record`) to browsers: students open the URL it
    /// prints and play it in the Rerun web viewer, nothing to install.
    Serve(Box<serve::ServeFileArgs>),
    /// Serve the app itself to browsers (the site `scripts/build-web.sh` builds): every student
    /// runs hox in their own page, drives it and takes the lessons at their own pace.
    ServeApp(Box<serve::ServeAppArgs>),
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

/// The stability guard's findings for a built scene; a note on stderr when it raised the
/// substeps (docs/STABILITY.md).
pub fn note_stability(instance: &mut Instance) -> hox_sim::solver::stability::StabilityReport {
    let stability = instance.sim.stability();
    if stability.raised() {
        eprintln!("note: {}", stability.summary());
    }
    stability
}

/// `hox study merge`.
#[derive(Subcommand)]
pub enum StudyMerge {
    /// Join the parts of a sharded study (`hox study --shard K/N`) into the files one run
    /// writes; refuses a part missing, given twice or of another study, writing nothing.
    Merge {
        /// Part files, or folders holding study-part-*.toml files.
        #[arg(required = true, value_name = "PART")]
        parts: Vec<PathBuf>,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
}

/// Runs a headless command.
pub fn run(command: Command) -> Result<()> {
    match command {
        Command::Elements { json } => list::elements(json),
        Command::Scenes { json } => list::scenes(json),
        Command::Solvers { json } => list::solvers(json),
        Command::Mesh { scene, mesh, json } => mesh::mesh_command(&scene, &mesh, json),
        Command::Simulate { scene, mesh, physics, seconds, settle, vtk, reference, json } => {
            simulate::simulate(&scene, &mesh, &physics, seconds, settle, &vtk, &reference, json)
        }
        Command::Study { merge: Some(StudyMerge::Merge { parts, out }), .. } => study::merge(&parts, &out),
        Command::Study { quick, only, shard, out, summary, merge: None } => match (summary, out) {
            (Some(dir), _) => study::summary(&dir),
            (None, Some(out)) => study::study(quick, only.as_deref(), shard.as_deref(), &out),
            (None, None) => anyhow::bail!("hox study needs --out DIR (run the study) or --summary DIR (print one)"),
        },
        Command::Paper { quick, out } => paper::paper(quick, &out),
        Command::Bench { beam_json: Some(label), .. } => bench::beam_json(&label),
        Command::Bench { stability: true, .. } => bench::stability(),
        Command::Bench { frames, threads, only, sweep, lanes, solver, beam_json: None, stability: false } => {
            bench::bench(frames, &threads, &only, &sweep, &lanes, &solver)
        }
        Command::Static { scene, mesh, physics, tolerance, load_steps, reference, json } => {
            statics::static_command(&scene, &mesh, &physics, tolerance, load_steps, &reference, json)
        }
        Command::Record(args) => record::record(&args),
        Command::Inspect(args) => inspect::inspect(&args),
        Command::Lessons { json } => lesson::lessons(json),
        Command::Lesson(args) => lesson::lesson(&args),
        Command::Serve(args) => serve::serve(&args),
        Command::ServeApp(args) => serve::serve_app(&args),
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
