//! `hox static`: a scene's static equilibrium by Newton's method (the reference XPBD settles to).

use super::{DelayedBar, SceneArgs, load_scene, reference};
use crate::config::{MeshArgs, PhysicsArgs, overrides};
use anyhow::{Result, bail};
use std::time::Instant;

pub fn static_command(
    scene: &SceneArgs,
    mesh: &MeshArgs,
    physics: &PhysicsArgs,
    tolerance: f64,
    load_steps: usize,
    reference_args: &reference::ReferenceArgs,
    json: bool,
) -> Result<()> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        bail!("--tolerance must be a finite positive number, got {tolerance}");
    }
    if load_steps == 0 {
        bail!("--load-steps must be at least 1");
    }
    reference::check(reference_args)?;
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
    // a mesh file's reference would be this very solution: its error is the mesh's, unknown here
    let found = if scene.is_box() { reference::find(reference_args, &scene, true) } else { None };
    let compared: Vec<(String, [f64; 3])> = probes.iter().map(|(n, u)| (n.clone(), *u)).collect();
    let of = "static solution (the mesh's discretisation error)";
    let mut out = serde_json::json!({
        "probes": probes,
        "groups": groups,
        "newton_iterations": solution.newton_iterations,
        "residual": solution.relative_residual,
        "seconds": seconds,
        "dofs": dofs,
        "cost": {
            "pattern_secs": solution.cost.pattern_secs,
            "hessian_secs": solution.cost.hessian_secs,
            "factor_secs": solution.cost.factor_secs,
            "solve_secs": solution.cost.solve_secs,
            "other_secs": solution.total_secs
                - (solution.cost.pattern_secs + solution.cost.hessian_secs + solution.cost.factor_secs + solution.cost.solve_secs),
            "factorisations": solution.cost.factorisations,
            "matrix_nonzeros": solution.cost.matrix_nonzeros,
            "factor_nonzeros": solution.cost.factor_nonzeros,
        },
    });
    reference::json(&mut out, found.as_ref(), &compared, of);
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
        reference::print(found.as_ref(), &compared, of);
    }
    Ok(())
}
