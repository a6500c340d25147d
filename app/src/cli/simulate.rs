//! `hox simulate`: run a scene for a time or until it settles and print the probe displacements.

use super::{DelayedBar, SceneArgs, gmsh, load_scene, note_stability, reference};
use crate::config::{MeshArgs, PhysicsArgs, overrides};
use anyhow::{Result, bail};
use hox_scenes::{Instance, RunMode};

pub fn simulate(
    scene: &SceneArgs,
    mesh: &MeshArgs,
    physics: &PhysicsArgs,
    seconds: Option<f64>,
    settle: bool,
    vtk: &gmsh::VtkArgs,
    reference_args: &reference::ReferenceArgs,
    json: bool,
) -> Result<()> {
    reference::check(reference_args)?;
    let scene = load_scene(scene)?.with_overrides(&overrides(mesh, Some(physics)))?;
    let mode = if settle {
        RunMode::SETTLE
    } else {
        let t = seconds.unwrap_or(scene.params().duration_secs);
        if !(t.is_finite() && t >= 0.0) {
            bail!("--seconds must be a finite, non-negative number of seconds, got {t}");
        }
        RunMode::Seconds(t)
    };
    let mut instance = Instance::new(scene)?;
    let stability = note_stability(&mut instance);
    if let Some(advice) = hox_scenes::run::solver_advice(&instance) {
        eprintln!("note: {advice}");
    }
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
    // the error of the state the run ended in when at rest, else of its last-second mean (an
    // instantaneous value of a swinging body says little about its accuracy)
    let found = reference::find(reference_args, &instance.scene, settle);
    let (compared, of) = if report.settled || report.at_rest {
        (&report.probes, if report.settled { "settled state" } else { "state at rest" })
    } else if settle {
        (&report.probes_last_second_mean, "last-second mean (not settled)")
    } else {
        (&report.probes_last_second_mean, "last-second mean (still moving; --settle for the equilibrium)")
    };
    let compared: Vec<(String, [f64; 3])> = compared.iter().map(|(n, u)| (n.clone(), *u)).collect();
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
        reference::json(&mut out, found.as_ref(), &compared, of);
        println!("{out}");
    } else {
        println!(
            "{}: {} frames, {:.3} s simulated in {:.2} s, {}{}",
            instance.scene.name(),
            report.frames,
            report.sim_seconds,
            report.wall_secs,
            // the median of no frame is NaN (JSON null): nothing was timed
            if report.frames > 0 {
                format!("{:.2} ms per frame (95th percentile {:.2})", report.ms_per_frame, report.ms_per_frame_p95)
            } else {
                "no frame timed".into()
            },
            if settle {
                format!(", {}, {}", report.solver, report.settle_summary())
            } else {
                format!(", {}", report.solver)
            }
        );
        if let (Some(policy), Some(why)) = (&report.newton_policy, &report.newton_policy_why) {
            println!("  newton policy: {policy} ({why})");
        }
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
        reference::print(found.as_ref(), &compared, of);
        if let Some(index) = &vtk_index {
            println!("  ParaView series: {}", index.display());
        }
    }
    if settle && !report.settled {
        eprintln!("warning: {}", report.settle_summary());
    }
    let budget = instance.scene.params().newton_iterations;
    let budgeted = instance.scene.params().method.reads_parameter("newton_iterations")
        && budget < hox_sim::solver::NewtonSettings::default().max_iterations as usize;
    if report.unconverged_steps > 0 && budgeted {
        eprintln!(
            "note: {} {} steps ended at their budget of {budget} iterations (--newton-iterations) above the tolerance, their unbalanced force carried into the next step",
            report.unconverged_steps, report.solver
        );
    } else if report.unconverged_steps > 0 {
        eprintln!(
            "warning: {} {} steps reached their iteration limit before the tolerance",
            report.unconverged_steps, report.solver
        );
    }
    if report.rejected_steps > 0 {
        eprintln!(
            "warning: the step watch rejected {} {} steps (a node moved more than the body's size, or the step was left far from solved) and took them again in halves",
            report.rejected_steps, report.solver
        );
    }
    Ok(())
}
