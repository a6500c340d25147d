//! `hox record`: a scene, or several configurations of it side by side, to a Rerun .rrd file,
//! headless.

use super::{DelayedBar, SceneArgs, load_scene};
use crate::config::{DisplayArgs, MeshArgs, PhysicsArgs, overrides, parse_compare};
use crate::output::check_writable;
use crate::recording::{Configuration, LogSettings, Recorder, config_label, entity_name};
use anyhow::{Context, Result, bail};
use hox_scenes::{Instance, SceneOverrides};
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// `--compare`'s help: its keys are the parameter table's.
fn compare_help() -> String {
    format!(
        "Record several configurations of the scene side by side (give it two or more times). Each value lists \
         option=value pairs applied on top of the other options, e.g. `--compare element=p1,refine=1 --compare \
         element=p2`. Options: {}",
        hox_scenes::params::compare_keys()
    )
}

#[derive(clap::Args)]
pub struct RecordArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub mesh: MeshArgs,
    #[command(flatten)]
    pub physics: PhysicsArgs,
    /// Simulated time to record, seconds (default: the scene's duration).
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// The Rerun file to write (.rrd). Checked for writability before simulating.
    #[arg(long)]
    pub out: PathBuf,
    /// Record several configurations of the scene side by side (give it two or more times).
    /// Each value lists option=value pairs applied on top of the other options, e.g.
    /// `--compare element=p1,refine=1 --compare element=p2`.
    #[arg(long, value_name = "OPTION=VALUE,...", help = compare_help())]
    pub compare: Vec<String>,
    #[command(flatten)]
    pub display: DisplayArgs,
    #[command(flatten)]
    pub vtk: super::gmsh::VtkArgs,
    #[command(flatten)]
    pub reference: super::reference::ReferenceArgs,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn record(args: &RecordArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let base = overrides(&args.mesh, Some(&args.physics)).merged(&args.display.overrides);
    // every value is checked first, so a mistyped key is named even when only one is given
    let compared: Vec<SceneOverrides> =
        args.compare.iter().map(|spec| parse_compare(spec, &base)).collect::<Result<_>>()?;
    let configurations = match compared.len() {
        0 => vec![base],
        1 => bail!("--compare needs two or more configurations (give it once per configuration)"),
        _ => compared,
    };
    let mut instances = Vec::new();
    for (k, o) in configurations.iter().enumerate() {
        let s = match scene.with_overrides(o) {
            Ok(s) => s,
            // a compared configuration's error names its --compare value
            Err(e) if !args.compare.is_empty() => return Err(e).context(format!("--compare '{}'", args.compare[k])),
            Err(e) => return Err(e.into()),
        };
        let mut instance = Instance::new(s)?;
        super::note_stability(&mut instance);
        instances.push(instance);
    }
    let seconds = args.seconds.unwrap_or(instances[0].scene.params().duration_secs);
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!("--seconds must be a finite, non-negative number of seconds, got {seconds}");
    }
    let fps = instances[0].scene.params().frames_per_second;
    if instances.iter().any(|i| i.scene.params().frames_per_second != fps) {
        bail!("the compared configurations must share one frame rate (fps) so their frames line up");
    }
    check_writable(&args.out)?;

    // the fields to record: the first configuration's list (`--field`, several allowed)
    let fields = crate::display::fields(instances[0].scene.params());
    let with_field = fields.contains(&hox_sim::measure::field::Field::Error);
    if with_field && args.reference.reference == super::reference::When::None {
        bail!("--field error draws the distance from the reference solution, but --reference none turns it off");
    }
    super::reference::check(&args.reference)?;
    let references: Vec<Option<hox_scenes::reference::Reference>> =
        instances.iter().map(|i| super::reference::find_for_record(&args.reference, &i.scene, with_field)).collect();
    if with_field && references.iter().any(|r| r.as_ref().is_none_or(|r| r.field.is_none())) {
        bail!("--field error: no reference displacement field for {} (see the notes above)", instances[0].scene.name());
    }

    let rec = rerun::RecordingStreamBuilder::new("hox")
        .recording_name(format!("hox record {}", instances[0].scene.name()))
        .save(&args.out)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    // one layout and one colour range per field for every configuration, as the app's
    // viewport draws them
    let first_mesh = instances[0].sim.mesh();
    let offsets = crate::display::side_by_side_offsets(first_mesh, instances.len(), crate::display::LayoutAxis::X);
    let mut names = BTreeSet::new();
    let mut configs = Vec::new();
    for (k, inst) in instances.iter().enumerate() {
        let mut name = entity_name(&config_label(inst));
        if !names.insert(name.clone()) {
            name = format!("{name}_{}", k + 1);
            names.insert(name.clone());
        }
        configs.push(Configuration { name, instance: inst, offset_m: offsets[k], reference: references[k].as_ref() });
    }
    let settings = LogSettings::new(instances[0].scene.params());
    let mut recorder = Recorder::new(&rec, &configs, &settings, &fields)?;
    let logger_names: Vec<String> = recorder.names().iter().map(|s| s.to_string()).collect();
    drop(configs);

    // VTK series beside the recording (one folder per configuration when comparing)
    let mut vtk_writers = Vec::new();
    for (inst, name) in instances.iter().zip(&logger_names) {
        let dir = args.vtk.vtk.as_ref().map(|d| if instances.len() > 1 { d.join(name) } else { d.clone() });
        vtk_writers.push(super::gmsh::VtkWriter::create(
            &super::gmsh::VtkArgs { vtk: dir, vtk_every: args.vtk.vtk_every },
            inst,
        )?);
    }

    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)).context("cannot install the Ctrl-C handler")?;
    }
    let frames = (seconds * fps).round() as u64;
    let mut step_ms: Vec<Vec<f64>> = vec![Vec::new(); instances.len()];
    let mut log_ms = Vec::new();
    let mut bar = DelayedBar::new();
    let started = Instant::now();
    recorder.log_frame(&rec, &instances.iter().collect::<Vec<_>>(), &vec![0.0; instances.len()])?;
    let mut failure = None;
    let mut done = 0;
    'frames: for frame in 1..=frames {
        if interrupted.load(Ordering::SeqCst) {
            break;
        }
        let mut ms_now = vec![0.0; instances.len()];
        for (k, (inst, name)) in instances.iter_mut().zip(&logger_names).enumerate() {
            let t0 = Instant::now();
            if let Err(e) = inst.sim.step_frame() {
                failure = Some(anyhow::anyhow!("{}: configuration {name}: {e}", inst.scene.source));
                break 'frames;
            }
            ms_now[k] = t0.elapsed().as_secs_f64() * 1e3;
            step_ms[k].push(ms_now[k]);
            if let Some(w) = &mut vtk_writers[k] {
                w.frame(inst)?;
            }
        }
        // every configuration stepped: log them together, on ranges they share
        let t1 = Instant::now();
        recorder.log_frame(&rec, &instances.iter().collect::<Vec<_>>(), &ms_now)?;
        log_ms.push(t1.elapsed().as_secs_f64() * 1e3 / instances.len() as f64);
        done = frame;
        bar.reveal("{spinner} {bar:40} {percent}% {msg} (eta {eta})");
        bar.bar.set_position(1000 * frame / frames.max(1));
        bar.bar.set_message(format!("frame {frame}/{frames}"));
    }
    bar.bar.finish_and_clear();
    rec.flush_blocking().with_context(|| format!("cannot finish writing {}", args.out.display()))?;
    drop(rec);
    let mut vtk_indexes = Vec::new();
    for (w, inst) in vtk_writers.into_iter().zip(&instances) {
        if let Some(w) = w {
            vtk_indexes.push(w.finish(inst)?.display().to_string());
        }
    }
    let bytes = std::fs::metadata(&args.out).map(|m| m.len()).unwrap_or(0);
    if let Some(e) = failure {
        eprintln!("{}: kept frames 0..={done} before the failure", args.out.display());
        return Err(e);
    }
    if interrupted.load(Ordering::SeqCst) {
        eprintln!("interrupted: {} holds frames 0..={done} ({bytes} bytes) and plays back", args.out.display());
        std::process::exit(130);
    }
    let configs: Vec<serde_json::Value> = instances
        .iter()
        .zip(&logger_names)
        .zip(step_ms.iter_mut())
        .map(|((inst, name), ms)| {
            serde_json::json!({
                "entity": format!("world/{name}"),
                "elements": inst.sim.mesh().num_elements(),
                "nodes": inst.sim.mesh().num_nodes(),
                "probes": inst.probe_displacements().into_iter().collect::<BTreeMap<_, _>>(),
                "ms_per_frame": hox_scenes::median(ms),
            })
        })
        .collect();
    let summary = serde_json::json!({
        "file": args.out,
        "frames": frames + 1,
        "sim_seconds": instances[0].sim.time_secs(),
        "bytes": bytes,
        "log_ms_per_frame": hox_scenes::median(&mut log_ms),
        "wall_seconds": started.elapsed().as_secs_f64(),
        "configurations": configs,
        "fields": fields.iter().map(|f| f.name()).collect::<Vec<_>>(),
        "vtk": vtk_indexes,
    });
    if args.json {
        println!("{summary}");
    } else {
        println!(
            "{}: {} frames of {} configuration(s), {:.2} MB, logging {:.2} ms per frame and configuration",
            args.out.display(),
            frames + 1,
            instances.len(),
            bytes as f64 / 1e6,
            summary["log_ms_per_frame"].as_f64().unwrap_or_default()
        );
        for c in summary["configurations"].as_array().into_iter().flatten() {
            println!(
                "  {}: {} elements, {} nodes, {:.2} ms per frame",
                c["entity"].as_str().unwrap_or_default(),
                c["elements"],
                c["nodes"],
                c["ms_per_frame"].as_f64().unwrap_or_default()
            );
        }
        for index in &vtk_indexes {
            println!("  VTK series for ParaView: {index}");
        }
        println!(
            "play it back with the Rerun viewer {}: scripts/rerun.sh {} (installs the matching viewer on first use)",
            rerun::build_info().version,
            args.out.display()
        );
    }
    Ok(())
}
