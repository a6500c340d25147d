//! Lessons: guided classroom demonstrations as data (`assets/lessons/*.toml`, issue #21).
//!
//! A lesson has a title, a goal and steps. Each step sets one or two configurations of a scene
//! (`a`, and `b` to compare: any parameter of the table, [`crate::params`], by its command-line
//! key), how far to run them (`run`: simulated seconds, `"settle"` to rest, or `"static"`:
//! the static equilibrium), says what to look at (`text`), asks the class a `question`, and
//! names the measurement that answers it (`measure`, [`Measure`]), shown live beside the text;
//! the `answer` is revealed on demand. `camera` and `view` set the view.
//!
//! ```toml
//! title = "Why high order"
//! goal = "Fewer, curved elements beat many flat ones: P2 (160) against P1 (1,280) on bending."
//!
//! [[steps]]
//! title = "Same beam, two meshes"
//! scene = "bending"
//! a = { element = "p1", refine = 1 }
//! b = { element = "p2" }
//! run = "settle"                     # or 2.5 (simulated seconds), or "static"
//! measure = "settled-error"          # see Measure
//! camera = "front"                   # iso | front | side | top
//! text = "…"
//! question = "Which beam is nearer the reference?"
//! answer = "…"
//! ```
//!
//! Unknown keys, unknown scenes, parameters or measurements, and values a parameter does not
//! accept are errors naming the file, the step and the key. [`run_step`] runs a step headlessly
//! and measures it: the CLI's recordings, the app and the tests share it.

use crate::error::SceneError;
use crate::instance::Instance;
use crate::params::SceneOverrides;
use crate::params::{PARAMS, Param, Value};
use crate::scene::Scene;
use serde::Deserialize;

/// The built-in lessons, in teaching order: (name, TOML text).
pub const BUILTIN: &[(&str, &str)] = &[
    ("why-high-order", include_str!("../../../assets/lessons/why-high-order.toml")),
    ("locking", include_str!("../../../assets/lessons/locking.toml")),
    ("mesh-bias", include_str!("../../../assets/lessons/mesh-bias.toml")),
    ("quadrature", include_str!("../../../assets/lessons/quadrature.toml")),
    ("shape-functions", include_str!("../../../assets/lessons/shape-functions.toml")),
    ("accuracy-cost", include_str!("../../../assets/lessons/accuracy-cost.toml")),
    ("stability", include_str!("../../../assets/lessons/stability.toml")),
    ("materials", include_str!("../../../assets/lessons/materials.toml")),
    ("curved-boundaries", include_str!("../../../assets/lessons/curved-boundaries.toml")),
];

/// The camera presets a step may name (the app's).
pub const CAMERAS: [&str; 4] = ["iso", "front", "side", "top"];

/// What a step measures, shown live beside its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    /// The probes' error against the reference of the physics, at the end of the run, m.
    SettledError,
    /// The probes' distance from the static equilibrium of the same mesh: what the solver
    /// adds to the mesh's own error, m.
    SolverError,
    /// The first probe's vertical displacement u_z at the end, m.
    TipUz,
    /// The first probe's sideways displacement u_y at the end, m.
    TipUy,
    /// Median wall time of a frame, ms.
    MsPerFrame,
    /// The smallest det F over every quadrature point during the run.
    MinDetF,
    /// Substeps per frame the solver took (the stability guard may raise them).
    Substeps,
    /// The largest node displacement at the end, m.
    MaxDisplacement,
    /// How far the second probe's displacement is from the first's turned half a turn about
    /// the x axis, `|u₂ − diag(1, −1, −1) u₁|`, m: zero when a beam twisted about its axis
    /// responds symmetrically (probes at opposite corners of a cross-section).
    Asymmetry,
    /// The most negative value of the element's shape functions over the reference element.
    ShapeMinimum,
    /// The body's rest volume, m³: `Σ w_q det J` over every quadrature point, the volume the
    /// elements enclose (P1's flat facets cut inside a curved surface; P2's and P3's curved
    /// faces follow it).
    Volume,
}

impl Measure {
    pub const ALL: [Measure; 11] = [
        Measure::SettledError,
        Measure::SolverError,
        Measure::TipUz,
        Measure::TipUy,
        Measure::MsPerFrame,
        Measure::MinDetF,
        Measure::Substeps,
        Measure::MaxDisplacement,
        Measure::Asymmetry,
        Measure::ShapeMinimum,
        Measure::Volume,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Measure::SettledError => "settled-error",
            Measure::SolverError => "solver-error",
            Measure::TipUz => "tip-uz",
            Measure::TipUy => "tip-uy",
            Measure::MsPerFrame => "ms-per-frame",
            Measure::MinDetF => "min-det-f",
            Measure::Substeps => "substeps",
            Measure::MaxDisplacement => "max-displacement",
            Measure::Asymmetry => "asymmetry",
            Measure::ShapeMinimum => "shape-minimum",
            Measure::Volume => "volume",
        }
    }

    /// What it is, for a caption: "settled probe error against the reference".
    pub fn title(self) -> &'static str {
        match self {
            Measure::SettledError => "probe error against the reference",
            Measure::SolverError => "probe distance from this mesh's static equilibrium",
            Measure::TipUz => "probe u_z",
            Measure::TipUy => "probe u_y (sideways)",
            Measure::MsPerFrame => "milliseconds per frame",
            Measure::MinDetF => "smallest det F",
            Measure::Substeps => "substeps per frame",
            Measure::MaxDisplacement => "largest node displacement",
            Measure::Asymmetry => "asymmetry of the twist (opposite corners)",
            Measure::ShapeMinimum => "most negative shape-function value",
            Measure::Volume => "volume of the body at rest",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Measure::SettledError
            | Measure::SolverError
            | Measure::TipUz
            | Measure::TipUy
            | Measure::MaxDisplacement
            | Measure::Asymmetry => "m",
            Measure::MsPerFrame => "ms",
            Measure::Volume => "m³",
            Measure::MinDetF | Measure::Substeps | Measure::ShapeMinimum => "",
        }
    }

    pub fn from_name(name: &str) -> Option<Measure> {
        Measure::ALL.into_iter().find(|m| m.name() == name)
    }

    fn names() -> String {
        Measure::ALL.map(Measure::name).join(", ")
    }
}

/// How far a step runs its configurations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Run {
    /// This many simulated seconds.
    Seconds(f64),
    /// To rest (the scene's settle damping, as `simulate --settle`).
    Settle,
    /// The static equilibrium (hox's static solver), shown at rest.
    Static,
}

/// One step of a lesson.
#[derive(Clone, Debug)]
pub struct Step {
    pub title: String,
    /// The configurations: A, and B when comparing (each the scene with its overrides).
    pub configurations: Vec<Scene>,
    pub run: Run,
    pub measure: Measure,
    pub camera: Option<String>,
    /// Show the reference element's view (of configuration A's element) instead of the model.
    pub reference_element: bool,
    pub text: String,
    pub question: String,
    pub answer: String,
    /// What the answer claims of the numbers, judged beside it as measured.
    pub claim: Option<crate::lab::claim::Claim>,
}

/// A lesson.
#[derive(Clone, Debug)]
pub struct Lesson {
    pub name: String,
    pub title: String,
    pub goal: String,
    pub steps: Vec<Step>,
    /// Where it was read from ("builtin:locking", a path).
    pub source: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LessonFile {
    title: String,
    goal: String,
    steps: Vec<StepFile>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RunFile {
    Seconds(f64),
    Named(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StepFile {
    title: String,
    scene: String,
    #[serde(default)]
    a: toml::Table,
    b: Option<toml::Table>,
    run: Option<RunFile>,
    measure: String,
    camera: Option<String>,
    view: Option<String>,
    text: String,
    question: String,
    answer: String,
    claim: Option<crate::lab::claim::Claim>,
}

/// Names of the built-in lessons, comma-separated.
pub fn names() -> String {
    BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// A built-in lesson by name.
pub fn by_name(name: &str) -> Result<Lesson, SceneError> {
    let (n, text) = BUILTIN.iter().find(|(n, _)| *n == name).ok_or_else(|| SceneError::Parse {
        source_name: format!("lesson '{name}'"),
        message: format!("no such lesson (lessons: {})", names()),
    })?;
    Lesson::from_toml(n, text, &format!("builtin:{n}"))
}

/// Every built-in lesson, parsed and checked.
pub fn registry() -> Result<Vec<Lesson>, SceneError> {
    BUILTIN.iter().map(|(n, text)| Lesson::from_toml(n, text, &format!("builtin:{n}"))).collect()
}

/// A teacher's lesson file.
pub fn from_file(path: &std::path::Path) -> Result<Lesson, SceneError> {
    let source = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::Parse { source_name: source.clone(), message: format!("cannot read it: {e}") })?;
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("lesson");
    Lesson::from_toml(name, &text, &source)
}

impl Lesson {
    /// Parses and checks a lesson: every step's scene exists, its overrides are parameters
    /// with values they accept, its measure and camera are known. Errors name `source`, the
    /// step and the key.
    pub fn from_toml(name: &str, text: &str, source: &str) -> Result<Lesson, SceneError> {
        let bad = |message: String| SceneError::Parse { source_name: source.to_string(), message };
        let file: LessonFile = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        if file.steps.is_empty() {
            return Err(bad("a lesson needs at least one [[steps]]".into()));
        }
        let mut steps = Vec::new();
        for (k, s) in file.steps.into_iter().enumerate() {
            let at = |key: &str, message: String| bad(format!("step {} ('{}'): {key}: {message}", k + 1, s.title));
            let base = crate::scene::builtin::by_name(&s.scene).map_err(|e| at("scene", e.to_string()))?;
            let mut configurations = Vec::new();
            for (label, table) in std::iter::once(("a", &s.a)).chain(s.b.as_ref().map(|b| ("b", b))) {
                let overrides = overrides_from(table).map_err(|(key, m)| at(&format!("{label}.{key}"), m))?;
                let scene = base.with_overrides(&overrides).map_err(|e| at(label, e.to_string()))?;
                configurations.push(scene);
            }
            let run = match &s.run {
                None => Run::Seconds(base.params().duration_secs),
                Some(RunFile::Seconds(secs)) if secs.is_finite() && *secs > 0.0 => Run::Seconds(*secs),
                Some(RunFile::Seconds(secs)) => {
                    return Err(at("run", format!("{secs} is not a positive number of seconds")));
                }
                Some(RunFile::Named(n)) if n == "settle" => Run::Settle,
                Some(RunFile::Named(n)) if n == "static" => Run::Static,
                Some(RunFile::Named(n)) => {
                    return Err(at("run", format!("'{n}' is not \"settle\", \"static\" or a number of seconds")));
                }
            };
            let measure = Measure::from_name(&s.measure)
                .ok_or_else(|| at("measure", format!("unknown '{}' (measures: {})", s.measure, Measure::names())))?;
            if let Some(c) = &s.camera
                && !CAMERAS.contains(&c.as_str())
            {
                return Err(at("camera", format!("unknown '{c}' (cameras: {})", CAMERAS.join(", "))));
            }
            if let Some(c) = &s.claim {
                c.check(configurations.len()).map_err(|m| at("claim", m))?;
            }
            let reference_element = match s.view.as_deref() {
                None | Some("model") => false,
                Some("reference-element") => true,
                Some(v) => return Err(at("view", format!("unknown '{v}' (views: model, reference-element)"))),
            };
            steps.push(Step {
                title: s.title.clone(),
                configurations,
                run,
                measure,
                camera: s.camera.clone(),
                reference_element,
                text: reflow(&s.text),
                question: reflow(&s.question),
                answer: reflow(&s.answer),
                claim: s.claim.clone(),
            });
        }
        Ok(Lesson {
            name: name.to_string(),
            title: file.title,
            goal: file.goal.trim().to_string(),
            steps,
            source: source.to_string(),
        })
    }

    /// The lesson as JSON for `hox lessons --json`.
    pub fn summary_json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.name,
            "title": self.title,
            "goal": self.goal,
            "steps": self.steps.iter().map(|s| serde_json::json!({
                "title": s.title,
                "scene": s.configurations[0].name(),
                "configurations": s.configurations.len(),
                "measure": s.measure.name(),
                "question": s.question,
            })).collect::<Vec<_>>(),
        })
    }
}

/// Text as written in a TOML multi-line string, as paragraphs: single line breaks become spaces
/// (the app and the viewer wrap to their width), blank lines stay.
fn reflow(text: &str) -> String {
    text.trim()
        .split("\n\n")
        .map(|p| p.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect::<Vec<_>>()
        .join("\n\n")
}

/// The overrides a step's `a` or `b` table sets, by the parameter table's command-line keys;
/// Err((key, message)).
fn overrides_from(table: &toml::Table) -> Result<SceneOverrides, (String, String)> {
    let mut o = SceneOverrides::default();
    for (key, value) in table {
        let p = PARAMS
            .iter()
            .find(|p| p.key == key && p.surfaces.cli)
            .ok_or_else(|| (key.clone(), format!("not a parameter (parameters: {})", crate::params::compare_keys())))?;
        let v = match (&p.kind, value) {
            // a grid may be written as in --grid ("16x4x4")
            (crate::params::Kind::Grid { .. }, toml::Value::String(s)) => p.kind.parse(s),
            _ => p.kind.from_toml(value),
        }
        .map_err(|m| (key.clone(), m))?;
        p.check_value(&v).map_err(|m| (key.clone(), format!("{v}: {m}")))?;
        (p.set_override)(&mut o, v);
    }
    Ok(o)
}

/// One configuration's measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    pub value: f64,
    /// The value in words, with its unit: "5.38e-2 m (16.81 %)".
    pub text: String,
}

/// A step's configurations run side by side, frame by frame (the recording logs them together):
/// for its seconds, to rest, or solved statically and shown at rest. A configuration whose
/// simulation fails (a blow-up) stops there and says so in its measurement.
pub struct StepRunner {
    pub instances: Vec<Instance>,
    run: Run,
    measure: Measure,
    settlers: Vec<Option<crate::run::Settler>>,
    done: Vec<bool>,
    failures: Vec<Option<String>>,
    min_det_f: Vec<f64>,
    frame_ms: Vec<Vec<f64>>,
    references: Vec<Option<crate::lab::reference::Reference>>,
}

impl StepRunner {
    /// Builds the configurations (a `"static"` step solves them first; `progress(what,
    /// fraction)` meanwhile) and, for the error measure, finds their references.
    pub fn start(step: &Step, progress: &mut dyn FnMut(&str, f64)) -> Result<StepRunner, SceneError> {
        let mut instances = Vec::new();
        let mut settlers = Vec::new();
        let mut references = Vec::new();
        for (k, scene) in step.configurations.iter().enumerate() {
            let mut instance = Instance::new(scene.clone())?;
            let what = format!("{} ({})", step.title, ["A", "B"][k.min(1)]);
            if step.run == Run::Static {
                let mesh = instance.sim.mesh().clone();
                let solution =
                    crate::instance::solve_static(&instance.scene, &mesh, 1e-9, 10, &mut |f, _, _| progress(&what, f))?;
                instance.sim.warm_start(&solution.positions, 0.0);
            }
            settlers.push(match step.run {
                Run::Settle => Some(crate::run::Settler::start(&mut instance, crate::run::SETTLE_CAP_SECS)?),
                _ => None,
            });
            references
                .push(reference_for(step.measure, &instance.scene, &mut |w, f| progress(&format!("{what}: {w}"), f))?);
            instances.push(instance);
        }
        let n = instances.len();
        let mut runner = StepRunner {
            instances,
            run: step.run,
            measure: step.measure,
            settlers,
            done: vec![step.run == Run::Static; n],
            failures: vec![None; n],
            min_det_f: vec![f64::INFINITY; n],
            frame_ms: vec![Vec::new(); n],
            references,
        };
        for k in 0..n {
            runner.watch(k);
        }
        Ok(runner)
    }

    fn watch(&mut self, k: usize) {
        if self.measure == Measure::MinDetF {
            let sim = &self.instances[k].sim;
            if let Some(m) = hox_sim::measure::min_det_f(sim.mesh(), sim.geometry(), &sim.positions) {
                self.min_det_f[k] = self.min_det_f[k].min(m.det_f);
            }
        }
    }

    /// Whether every configuration has finished.
    pub fn finished(&self) -> bool {
        self.done.iter().all(|d| *d)
    }

    /// One frame of every configuration still running; whether any still runs.
    pub fn advance(&mut self) -> bool {
        for k in 0..self.instances.len() {
            if self.done[k] {
                continue;
            }
            let t0 = web_time::Instant::now();
            let result = self.instances[k].sim.step_frame();
            self.frame_ms[k].push(t0.elapsed().as_secs_f64() * 1e3);
            if let Err(e) = result {
                self.failures[k] = Some(e.to_string());
                self.done[k] = true;
                continue;
            }
            self.watch(k);
            let instance = &mut self.instances[k];
            self.done[k] = match (self.run, &mut self.settlers[k]) {
                (Run::Seconds(secs), _) => instance.sim.time_secs() >= secs - 1e-9,
                (_, Some(settler)) => settler.check(instance) != crate::run::SettleState::Running,
                _ => true,
            };
            if self.done[k]
                && let Some(settler) = self.settlers[k].take()
            {
                settler.stop(&mut self.instances[k]);
            }
        }
        !self.finished()
    }

    /// Runs to the end (`progress` with the simulated time of configuration A).
    pub fn finish(&mut self, progress: &mut dyn FnMut(&str, f64)) {
        while self.advance() {
            let t = self.instances[0].sim.time_secs();
            let fraction = match self.run {
                Run::Seconds(secs) => t / secs,
                _ => t / crate::run::SETTLE_CAP_SECS,
            };
            progress("running", fraction.min(1.0));
        }
    }

    /// The measurement of every configuration now.
    pub fn measured(&self) -> Vec<Measured> {
        (0..self.instances.len())
            .map(|k| match &self.failures[k] {
                Some(e) => Measured { value: f64::INFINITY, text: format!("failed: {e}") },
                None => {
                    let mut ms = self.frame_ms[k].clone();
                    let ms = if ms.is_empty() { f64::NAN } else { crate::run::median(&mut ms) };
                    measure(self.measure, &self.instances[k], self.references[k].as_ref(), ms, self.min_det_f[k])
                }
            })
            .collect()
    }

    /// Why configuration `k` stopped early, if it failed.
    pub fn failure(&self, k: usize) -> Option<&str> {
        self.failures[k].as_deref()
    }
}

/// What `measure` is measured against for `scene`: the reference of its physics (the error),
/// the static solution of its own mesh (the solver's error), or nothing.
pub fn reference_for(
    measure: Measure,
    scene: &Scene,
    progress: crate::lab::reference::Progress<'_>,
) -> Result<Option<crate::lab::reference::Reference>, SceneError> {
    Ok(match measure {
        Measure::SettledError => Some(crate::lab::reference::Lookup::default().for_scene(scene, progress)?),
        Measure::SolverError => Some(crate::lab::reference::own_mesh(scene, progress)?),
        _ => None,
    })
}

/// Runs `step` to its end headlessly and measures it (tests and `hox lesson`).
pub fn run_step(step: &Step, progress: &mut dyn FnMut(&str, f64)) -> Result<(StepRunner, Vec<Measured>), SceneError> {
    let mut runner = StepRunner::start(step, progress)?;
    runner.finish(progress);
    let measured = runner.measured();
    Ok((runner, measured))
}

/// The measurement `measure` of `instance` now: against `reference` (the error), with the
/// run's median `ms_per_frame` and smallest `min_det_f`.
pub fn measure(
    measure: Measure,
    instance: &Instance,
    reference: Option<&crate::lab::reference::Reference>,
    ms_per_frame: f64,
    min_det_f: f64,
) -> Measured {
    let probe = instance.probe_displacements().first().map(|p| p.1);
    let metres = |v: f64| Measured { value: v, text: metres_text(v) };
    match measure {
        Measure::SettledError | Measure::SolverError => {
            let now = instance.probe_displacements();
            match reference {
                Some(r) => {
                    let (m, pct) = (r.error_m(&now).unwrap_or(f64::NAN), r.error_pct(&now).unwrap_or(f64::NAN));
                    // the readout's format (issue #57: "5.521e-2 m" beside "0.05521 m")
                    let metres = crate::present::colour::format_value(m, "m");
                    Measured { value: m, text: format!("{metres} ({pct:.2} %)") }
                }
                None => Measured { value: f64::NAN, text: "no reference".into() },
            }
        }
        Measure::TipUz => metres(probe.map_or(f64::NAN, |u| u[2])),
        Measure::TipUy => metres(probe.map_or(f64::NAN, |u| u[1])),
        Measure::MsPerFrame => Measured { value: ms_per_frame, text: format!("{ms_per_frame:.2} ms per frame") },
        Measure::MinDetF => {
            let now =
                hox_sim::measure::min_det_f(instance.sim.mesh(), instance.sim.geometry(), &instance.sim.positions)
                    .map_or(f64::INFINITY, |m| m.det_f);
            let v = min_det_f.min(now);
            Measured { value: v, text: format!("min det F {v:.3}") }
        }
        Measure::Substeps => {
            let n = instance.sim.substeps_per_frame() as f64;
            let noun = if n == 1.0 { "substep" } else { "substeps" };
            Measured { value: n, text: format!("{n} {noun} per frame") }
        }
        Measure::MaxDisplacement => metres(instance.sim.displacements().iter().map(|u| u.norm()).fold(0.0, f64::max)),
        Measure::Asymmetry => {
            let p = instance.probe_displacements();
            match (p.first(), p.get(1)) {
                (Some((_, a)), Some((_, b))) => {
                    metres(((b[0] - a[0]).powi(2) + (b[1] + a[1]).powi(2) + (b[2] + a[2]).powi(2)).sqrt())
                }
                _ => Measured { value: f64::NAN, text: "needs two probes".into() },
            }
        }
        Measure::Volume => {
            let v = hox_sim::fem::geometry::total_volume_m3(instance.sim.geometry());
            Measured { value: v, text: format!("{v:.6} m³") }
        }
        Measure::ShapeMinimum => {
            let v = shape_minimum(instance.sim.mesh().blocks[0].element_type);
            // no "−0.0000" for a minimum that is zero up to rounding
            let shown = if v.abs() < 5e-5 { 0.0 } else { v };
            Measured { value: v, text: format!("min N_i = {shown:.4}") }
        }
    }
}

/// `v` in metres to the tenth of a millimetre, as a lesson shows it; a value that rounds to zero
/// is "0.0000 m" whatever its sign (issue #59: mesh-bias's sideways tip, ±1e-17 m, read
/// "-0.0000 m" in the page and "0.0000 m" on the desktop).
pub fn metres_text(v: f64) -> String {
    let shown = if v.abs() < 5e-5 { 0.0 } else { v };
    format!("{shown:.4} m")
}

/// The most negative value any shape function of `element` takes on a fine lattice of its
/// reference element (0 for linear elements; −1/8 for P2's vertex functions).
pub fn shape_minimum(element: hox_sim::element::ElementType) -> f64 {
    let e = element.reference();
    let shape = e.shape();
    let n = 24;
    let mut values = vec![0.0; e.num_nodes()];
    let mut lowest = 0.0f64;
    // the bounding box of the reference element, sampled where it contains the point
    let vertices = shape.vertices();
    let lo: [f64; 3] = std::array::from_fn(|k| vertices.iter().map(|v| v[k]).fold(f64::INFINITY, f64::min));
    let hi: [f64; 3] = std::array::from_fn(|k| vertices.iter().map(|v| v[k]).fold(f64::NEG_INFINITY, f64::max));
    for i in 0..=n {
        for j in 0..=n {
            for l in 0..=n {
                let r = [i, j, l].map(|c| c as f64 / n as f64);
                let r: [f64; 3] = std::array::from_fn(|k| lo[k] + r[k] * (hi[k] - lo[k]));
                if !shape.contains(&r, 1e-12) {
                    continue;
                }
                e.shape_functions(&r, &mut values);
                lowest = values.iter().copied().filter(|v| v.is_finite()).fold(lowest, f64::min);
            }
        }
    }
    lowest
}

impl Lesson {
    /// The parameters its steps change: every key of the parameter table whose value differs
    /// between any two configurations of the lesson (A and B, or one step and the next), in
    /// the table's order (issue #35: the locking lesson never showed ν, its one parameter).
    pub fn parameters_changed(&self) -> Vec<&'static Param> {
        let scenes: Vec<&Scene> = self.steps.iter().flat_map(|s| &s.configurations).collect();
        PARAMS
            .iter()
            .filter(|p| p.surfaces.app)
            .filter(|p| scenes.windows(2).any(|w| (p.get)(w[0].params()) != (p.get)(w[1].params())))
            .collect()
    }

    /// One line per configuration of step `k`: its values of [`Lesson::parameters_changed`],
    /// "Element P1 · Poisson ratio ν 0.49".
    pub fn step_parameters(&self, k: usize) -> Vec<String> {
        let changed = self.parameters_changed();
        self.steps[k]
            .configurations
            .iter()
            .map(|scene| {
                changed
                    .iter()
                    .map(|p| format!("{} {}", p.label, parameter(scene, p.key)))
                    .collect::<Vec<_>>()
                    .join(" · ")
            })
            .collect()
    }
}

/// The value of parameter `key` in `scene` as text (for captions): "p2", "0.49".
pub fn parameter(scene: &Scene, key: &str) -> String {
    PARAMS
        .iter()
        .find(|p| p.key == key)
        .map(|p| (p.get)(scene.params()))
        .map_or_else(String::new, |v: Value| v.to_string())
}

#[cfg(test)]
mod tests;
