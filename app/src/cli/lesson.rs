//! `hox lessons` and `hox lesson NAME [--record FILE.rrd]`: the built-in lessons
//! ([`hox_scenes::lesson`]), run headlessly step by step with each step's measurement, and
//! recorded as one Rerun file a student plays in the stock viewer — every step a segment of
//! the timeline, its text (title, what to look at, the question, then the answer and the
//! numbers) a text document, the measurement a time series, laid out by the lesson's
//! blueprint.

use super::DelayedBar;
use crate::output::check_writable;
use crate::recording::{Configuration, LogSettings, Recorder, config_label, entity_name};
use anyhow::{Context, Result};
use hox_scenes::lesson::{Lesson, Measured, Step, StepRunner};
use rerun::blueprint as bp;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct LessonArgs {
    /// A built-in lesson (`hox lessons` lists them).
    #[arg(required_unless_present = "lesson_file", conflicts_with = "lesson_file")]
    pub name: Option<String>,
    /// A lesson file of your own (TOML, see docs/LESSONS.md).
    #[arg(long)]
    pub lesson_file: Option<PathBuf>,
    /// Record the lesson to this Rerun file (.rrd): every step a segment of the timeline.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Print the measurements as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also write every configuration's computed reference (what its error is measured against,
    /// in a step's answer or the app's readout) into this folder, as the cache files the page
    /// reads (`scripts/build-web.sh` puts them in the site's references/); each is computed
    /// once per machine, then read from the cache (~/.cache/hox).
    #[arg(long, value_name = "DIR")]
    pub references_to: Option<PathBuf>,
    /// Serve the lesson to the class's browsers as it runs (the Rerun web viewer): students open
    /// the address printed first and follow the steps live; it stays served until Ctrl-C.
    #[arg(long, conflicts_with = "record")]
    pub serve_web: bool,
    /// With --serve-web: stop serving this many seconds after the last step (default: Ctrl-C).
    #[arg(long, requires = "serve_web")]
    pub serve_secs: Option<f64>,
    #[command(flatten)]
    pub serve: crate::web::ServeArgs,
}

/// `hox lessons`: every built-in lesson, its goal and steps.
pub fn lessons(json: bool) -> Result<()> {
    let all = hox_scenes::lesson::registry()?;
    if json {
        println!("{}", serde_json::Value::Array(all.iter().map(Lesson::summary_json).collect()));
        return Ok(());
    }
    for l in &all {
        println!("{:<18} {} — {} steps", l.name, l.title, l.steps.len());
        println!("{:<18} {}", "", l.goal);
    }
    println!("run one: hox app --lesson NAME (in class), hox lesson NAME --record FILE.rrd (to take home)");
    Ok(())
}

/// The markdown of a step: its title, text and question; with `outcome`, the answer and every
/// configuration's measurement.
pub fn step_markdown(lesson: &Lesson, k: usize, outcome: Option<&[Measured]>) -> String {
    let step = &lesson.steps[k];
    let mut text = format!(
        "# {}\n\n## Step {} of {}: {}\n\n{}\n\n**Question:** {}\n\n",
        lesson.title,
        k + 1,
        lesson.steps.len(),
        step.title,
        step.text,
        step.question
    );
    for (j, scene) in step.configurations.iter().enumerate() {
        // while the step runs its measurement is not yet known: said in words (issue #35: the
        // stock viewer showed "probe u_z = …")
        let what = match outcome.and_then(|o| o.get(j)) {
            Some(m) => m.text.clone(),
            None => "measured when the step ends".into(),
        };
        text += &format!("- **{}** {}: {}: {what}\n", ["A", "B"][j.min(1)], scene_label(scene), step.measure.title());
    }
    if let Some(measured) = outcome {
        text += &format!("\n**Answer:** {}\n", step.answer);
        let values: Vec<f64> = measured.iter().map(|m| m.value).collect();
        if let Some(j) = step.claim.as_ref().and_then(|c| c.judge(&values)) {
            text += &format!("\n*{}*\n", j.text);
        }
    }
    text
}

/// "P1 8×2×2 five r1, ν = 0.49": what distinguishes a configuration.
fn scene_label(scene: &hox_scenes::Scene) -> String {
    let p = scene.params();
    let mut label = match scene.mesh_kind() {
        hox_scenes::params::MeshKind::Box => {
            format!("{} {}×{}×{}", p.element.name().to_uppercase(), p.grid[0], p.grid[1], p.grid[2])
        }
        hox_scenes::params::MeshKind::Files => format!("{} {}", p.element.name().to_uppercase(), scene.name()),
        hox_scenes::params::MeshKind::File => scene.mesh.element_names(),
    };
    if p.refine > 0 {
        label += &format!(" r{}", p.refine);
    }
    label += &format!(", {}, ν = {}, {}", p.material, p.poisson_ratio, p.method);
    label
}

/// `hox lesson`: runs every step headlessly, prints the measurements, and records if asked.
pub fn lesson(args: &LessonArgs) -> Result<()> {
    let lesson = crate::config::load_lesson(args.name.as_deref(), args.lesson_file.as_deref())?;
    if let Some(out) = &args.record {
        check_writable(out)?;
    }
    if let Some(dir) = &args.references_to {
        std::fs::create_dir_all(dir).with_context(|| format!("--references-to: cannot create {}", dir.display()))?;
    }
    if let Some(s) = args.serve_secs
        && !(s.is_finite() && s >= 0.0)
    {
        anyhow::bail!("--serve-secs must be a finite, non-negative number of seconds, got {s}");
    }
    let mut web = None;
    let rec = match &args.record {
        Some(out) => Some(
            rerun::RecordingStreamBuilder::new("hox")
                .recording_name(format!("hox lesson {}", lesson.name))
                .save(out)
                .with_context(|| format!("cannot write {}", out.display()))?,
        ),
        None if args.serve_web => {
            let (rec, server) = crate::web::serve_recording(&format!("hox lesson {}", lesson.name), &args.serve)?;
            if !args.json {
                println!("{}", server.url);
            }
            eprintln!("serving the lesson to the class's browsers: open {}", server.url);
            web = Some(server);
            Some(rec)
        }
        None => None,
    };
    if let Some(rec) = &rec {
        name_series(rec, &lesson)?;
        rec.log_static(
            "lesson/goal",
            &rerun::TextDocument::from_markdown(format!("# {}\n\n{}", lesson.title, lesson.goal)),
        )?;
    }
    let mut offset = (0i64, 0.0f64);
    let mut report = Vec::new();
    for (k, step) in lesson.steps.iter().enumerate() {
        let mut bar = DelayedBar::new();
        let mut progress = |what: &str, fraction: f64| {
            bar.reveal("{spinner} {bar:30} {msg} [{elapsed}]");
            bar.bar.set_position((1000.0 * fraction.clamp(0.0, 1.0)) as u64);
            bar.bar.set_message(format!("step {}: {what}", k + 1));
        };
        let mut runner = StepRunner::start(step, &mut progress)?;
        if let (0, Some(rec)) = (k, &rec) {
            // the layout, its 3D view on the first step's bodies as `record_step` places them
            let first_mesh = runner.instances[0].sim.mesh().clone();
            let offsets = crate::display::side_by_side_offsets(
                &first_mesh,
                runner.instances.len(),
                crate::display::LayoutAxis::X,
            );
            let bounds = crate::recording::bounds_of(runner.instances.iter().zip(offsets.iter().copied()));
            crate::recording::eye::send(rec, blueprint(&lesson), bounds)?;
        }
        let measured = match &rec {
            Some(rec) => record_step(rec, &lesson, k, step, &mut runner, &mut offset, &mut progress)?,
            None => {
                runner.finish(&mut progress);
                runner.measured()
            }
        };
        if let Some(dir) = &args.references_to {
            // every configuration's reference as the app's readout shows it, whether or not the
            // step's measure needs it (computed here once per machine, then cached)
            let lookup = hox_scenes::reference::Lookup::default();
            for instance in &runner.instances {
                // a mesh file's own solution is not cached (the page solves it itself)
                let cached = instance.scene.mesh_kind() != hox_scenes::params::MeshKind::File;
                if cached
                    && hox_scenes::reference::unavailable(&instance.scene).is_none()
                    && let Err(e) = lookup.for_scene(&instance.scene, &mut progress)
                {
                    // the app's readout says the same; the lesson's own measures are unaffected
                    eprintln!("--references-to: {} step {}: no reference to write: {e}", lesson.name, k + 1);
                }
                lookup
                    .export(&instance.scene, dir)
                    .with_context(|| format!("--references-to: cannot write into {}", dir.display()))?;
            }
        }
        bar.bar.finish_and_clear();
        let values: Vec<f64> = measured.iter().map(|m| m.value).collect();
        let judged = step.claim.as_ref().and_then(|c| c.judge(&values));
        if !args.json {
            println!("step {} — {}: {}", k + 1, step.title, step.measure.title());
            for (j, m) in measured.iter().enumerate() {
                println!("  {} {}: {}", ["A", "B"][j.min(1)], scene_label(&step.configurations[j]), m.text);
            }
            if let Some(j) = &judged {
                println!("  {}", j.text);
            }
        }
        report.push(serde_json::json!({
            "step": k + 1,
            "title": step.title,
            "measure": step.measure.name(),
            "unit": step.measure.unit(),
            "values": measured.iter().map(|m| m.value).collect::<Vec<_>>(),
            "texts": measured.iter().map(|m| m.text.clone()).collect::<Vec<_>>(),
            "claim": judged.as_ref().map(|j| serde_json::json!({ "value": j.value, "holds": j.holds, "text": j.text })),
        }));
    }
    if let Some(rec) = &rec {
        rec.flush_blocking().context("cannot finish the recording")?;
    }
    let url = web.as_ref().map(|w| w.url.clone());
    if args.json {
        println!(
            "{}",
            serde_json::json!({ "lesson": lesson.name, "title": lesson.title, "steps": report, "file": args.record, "url": url })
        );
    } else if let Some(out) = &args.record {
        println!("{}: the lesson's {} steps, one after the other on the timeline", out.display(), lesson.steps.len());
        println!("play it with the stock Rerun viewer 0.36.3: scripts/rerun.sh {}", out.display());
    }
    if web.is_some() {
        match args.serve_secs {
            Some(s) => std::thread::sleep(std::time::Duration::from_secs_f64(s)),
            None => crate::web::wait_for_ctrl_c("the lesson is done and still served")?,
        }
    }
    drop(rec);
    Ok(())
}

/// Logs step `k` as a segment starting at `offset` (advanced past it): its configurations side
/// by side frame by frame, its text (question first, the answer and the numbers at the end), and
/// its measurement as a time series; its bodies are cleared when it ends, but for the last
/// step's, which the recording ends on (a page following the lesson live, or opened once it has
/// run, shows them beside the last answer rather than an empty view).
fn record_step(
    rec: &rerun::RecordingStream,
    lesson: &Lesson,
    k: usize,
    step: &Step,
    runner: &mut StepRunner,
    offset: &mut (i64, f64),
    progress: &mut dyn FnMut(&str, f64),
) -> Result<Vec<Measured>> {
    rec.set_time_sequence("frame", offset.0);
    rec.set_duration_secs("sim_time", offset.1);
    rec.log("lesson/step", &rerun::TextDocument::from_markdown(step_markdown(lesson, k, None)))?;
    let first_mesh = runner.instances[0].sim.mesh().clone();
    let offsets =
        crate::display::side_by_side_offsets(&first_mesh, runner.instances.len(), crate::display::LayoutAxis::X);
    let names: Vec<String> = runner
        .instances
        .iter()
        .enumerate()
        .map(|(j, i)| format!("s{}_{}_{}", k + 1, ["a", "b"][j.min(1)], entity_name(&config_label(i))))
        .collect();
    let configs: Vec<Configuration<'_>> = runner
        .instances
        .iter()
        .zip(&names)
        .zip(&offsets)
        .map(|((i, name), o)| Configuration { name: name.clone(), instance: i, offset_m: *o, reference: None })
        .collect();
    let mut settings = LogSettings::new(runner.instances[0].scene.params());
    settings.static_data = false;
    settings.blueprint = false;
    settings.time_offset = *offset;
    let fields = crate::display::fields(runner.instances[0].scene.params());
    let mut recorder = Recorder::new(rec, &configs, &settings, &fields)?;
    drop(configs);
    let log = |recorder: &mut Recorder, runner: &StepRunner| -> Result<()> {
        let instances: Vec<&hox_scenes::Instance> = runner.instances.iter().collect();
        recorder.log_frame(rec, &instances, &vec![0.0; instances.len()])?;
        for (j, m) in runner.measured().iter().enumerate() {
            if m.value.is_finite() {
                rec.log(measure_path(step, k, j), &rerun::Scalars::single(m.value))?;
            }
        }
        Ok(())
    };
    log(&mut recorder, runner)?;
    let total = match step.run {
        hox_scenes::lesson::Run::Seconds(s) => s,
        _ => hox_scenes::SETTLE_CAP_SECS,
    };
    while runner.advance() {
        log(&mut recorder, runner)?;
        progress("recording", runner.instances[0].sim.time_secs() / total);
    }
    log(&mut recorder, runner)?;
    let measured = runner.measured();
    let mut end = runner
        .instances
        .iter()
        .map(|i| (i.sim.frames() as i64, i.sim.time_secs()))
        .fold((0i64, 0.0f64), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    // a step shown at rest (static) holds its question two seconds before the answer
    if end.1 < 1.0 {
        end = (end.0 + 120, end.1 + 2.0);
    }
    // the answer and the numbers close the segment; then the bodies go
    rec.set_time_sequence("frame", offset.0 + end.0);
    rec.set_duration_secs("sim_time", offset.1 + end.1);
    rec.log("lesson/step", &rerun::TextDocument::from_markdown(step_markdown(lesson, k, Some(&measured))))?;
    // a short pause on the answer before the next step
    let pause = (30i64, 0.5f64);
    rec.set_time_sequence("frame", offset.0 + end.0 + pause.0);
    rec.set_duration_secs("sim_time", offset.1 + end.1 + pause.1);
    if k + 1 < lesson.steps.len() {
        recorder.clear(rec)?;
    }
    *offset = (offset.0 + end.0 + pause.0 + 1, offset.1 + end.1 + pause.1 + 1.0 / 60.0);
    Ok(measured)
}

/// The folder of a measurement's series: one per unit, so that one chart never mixes metres and
/// milliseconds (issue #35).
fn unit_folder(measure: hox_scenes::lesson::Measure) -> &'static str {
    match measure.unit() {
        "" => "number",
        unit => unit,
    }
}

/// Where configuration `j`'s measurement of step `k` is logged.
fn measure_path(step: &Step, k: usize, j: usize) -> String {
    format!("lesson/measure/{}/step_{}/{}", unit_folder(step.measure), k + 1, ["a", "b"][j.min(1)])
}

/// Names each step's measurement series with its configuration, what it is and its unit
/// ("step 1 A: probe u_z (m)"), once, as static data.
fn name_series(rec: &rerun::RecordingStream, lesson: &Lesson) -> Result<()> {
    for (k, step) in lesson.steps.iter().enumerate() {
        for j in 0..step.configurations.len() {
            let unit = step.measure.unit();
            let name = format!(
                "step {} {}: {}{}",
                k + 1,
                ["A", "B"][j.min(1)],
                step.measure.title(),
                if unit.is_empty() { String::new() } else { format!(" ({unit})") }
            );
            rec.log_static(measure_path(step, k, j), &rerun::SeriesLines::new().with_names([name]))?;
        }
    }
    Ok(())
}

/// The lesson recording's layout: the 3D view large, the step's text and the measurements
/// beside, one chart per unit.
fn blueprint(lesson: &Lesson) -> bp::Blueprint {
    let view3d = bp::Spatial3DView::new("3D").with_origin("world").with_contents(["+ world/**"]);
    let text = bp::TextDocumentView::new("Step").with_origin("lesson/step").with_contents(["+ lesson/step"]);
    let goal = bp::TextDocumentView::new("Lesson").with_origin("lesson/goal").with_contents(["+ lesson/goal"]);
    let mut units: Vec<&str> = lesson.steps.iter().map(|s| unit_folder(s.measure)).collect();
    units.dedup();
    units.sort_unstable();
    units.dedup();
    let mut column: Vec<bp::ContainerLike> = vec![goal.into(), text.into()];
    let mut shares = vec![0.7, 2.2];
    for unit in &units {
        let title = if *unit == "number" { "Measurement".to_string() } else { format!("Measurement ({unit})") };
        column.push(
            bp::TimeSeriesView::new(title)
                .with_origin(format!("lesson/measure/{unit}"))
                .with_contents([format!("+ lesson/measure/{unit}/**")])
                .into(),
        );
        shares.push(1.0 / units.len() as f32);
    }
    let root = bp::Horizontal::new([
        bp::ContainerLike::from(view3d),
        bp::Vertical::new(column).with_row_shares(shares).into(),
    ])
    .with_column_shares([0.62, 0.38]);
    crate::recording::blueprint_of(root)
}
