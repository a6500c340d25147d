//! The reference motion of the bending beam released from rest (issue #19, item 4).
//!
//! The built-in `bending` scene (StVK E = 3 MPa, ν = 0.35, ρ = 1000 kg/m³, gravity, clamped at
//! x = 0) on Q2 16×4×4 (the `medium` static reference level, 7,776 DOFs), started at rest in the
//! undeformed shape, integrated by the Newton solver with Newmark's average-acceleration rule
//! ([`hox_sim::solver::Integrator::Newmark`], energy-conserving: no numerical damping; the code
//! `--solver newton --integrator newmark` runs) with the step `h`,
//! and again with `h/2`; the tip probe's displacement is sampled every 1/60 s over `SECS`. The
//! file keeps the `h` run and states the largest tip difference between the two runs.
//!
//! `cargo run --release -p hox-scenes --example reference_motion -- [h_secs] [secs] > assets/reference/bending-motion.json`
//! (defaults 1/960 s and 3 s; about 15 minutes on a 2-core machine). `scripts/reference.sh motion`
//! runs it.

use hox_scenes::study::motion::Motion;
use hox_scenes::{Instance, SceneOverrides};
use hox_sim::solver::{Integrator, Method};
use std::time::Instant;

const GRID: [usize; 3] = [16, 4, 4];
const SAMPLE_HZ: f64 = 60.0;
const TOLERANCE: f64 = 1e-10;

fn motion(h_secs: f64, secs: f64) -> Result<(Motion, Vec<[f64; 3]>, f64, u64), Box<dyn std::error::Error>> {
    let scene = hox_scenes::by_name("bending")?.with_overrides(&SceneOverrides {
        element: hox_sim::element::ElementType::from_name("q2"),
        grid: Some(GRID),
        ..Default::default()
    })?;
    let mut instance = Instance::new(scene)?;
    let tip = instance.probes.iter().position(|p| p.name == "tip").ok_or("the bending scene has no tip probe")?;
    let mut settings = *instance.sim.settings();
    settings.method = Method::Newton;
    settings.integrator = Integrator::Newmark;
    settings.frames_per_second = 1.0 / h_secs;
    settings.steps_per_frame = 1;
    settings.newton.tolerance = TOLERANCE;
    instance.sim.set_settings(settings)?;
    let per_sample = (1.0 / (SAMPLE_HZ * h_secs)).round() as usize;
    if (per_sample as f64 * h_secs * SAMPLE_HZ - 1.0).abs() > 1e-9 {
        return Err(format!("the step {h_secs} s must divide 1/{SAMPLE_HZ} s").into());
    }
    let samples = (secs * SAMPLE_HZ).round() as usize;
    let started = Instant::now();
    let probe = |i: &Instance| i.probes[tip].displacement(&i.sim.positions, &i.sim.mesh().rest_positions);
    let mut tip_m = vec![probe(&instance)];
    for k in 0..samples {
        for _ in 0..per_sample {
            instance.sim.step_frame()?;
        }
        tip_m.push(probe(&instance));
        if (k + 1) % 30 == 0 {
            eprintln!(
                "h = {h_secs:.3e} s: {:.2} s simulated, {:.0} s wall",
                instance.sim.time_secs(),
                started.elapsed().as_secs_f64()
            );
        }
    }
    let tip_z_m = tip_m.iter().map(|u| u.z).collect();
    let tip_xyz = tip_m.iter().map(|u| [u.x, u.y, u.z]).collect();
    Ok((
        Motion { sample_secs: 1.0 / SAMPLE_HZ, tip_z_m },
        tip_xyz,
        started.elapsed().as_secs_f64(),
        instance.sim.counters().solver_iterations,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let h_secs: f64 = match args.next() {
        Some(a) => a.parse().map_err(|_| format!("h_secs must be a number, got {a}"))?,
        None => 1.0 / 960.0,
    };
    let secs: f64 = match args.next() {
        Some(a) => a.parse().map_err(|_| format!("secs must be a number, got {a}"))?,
        None => 3.0,
    };
    if !(secs > 0.0 && secs.is_finite()) {
        return Err(format!("secs must be positive, got {secs}").into());
    }
    let (fine, tip_xyz, wall, iterations) = motion(h_secs, secs)?;
    let (half, _, wall_half, _) = motion(0.5 * h_secs, secs)?;
    let difference_m = fine.tip_z_m.iter().zip(&half.tip_z_m).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let (m, m_half) = (fine.metrics(), half.metrics());
    let json = serde_json::json!({
        "scene": "bending",
        "element": "q2",
        "grid": format!("{}x{}x{}", GRID[0], GRID[1], GRID[2]),
        "scheme": "Newmark average acceleration (beta = 1/4, gamma = 1/2), Newton per step",
        "start": "at rest, undeformed, released at t = 0 (gravity and the clamp at x = 0 only; no damping)",
        "dt_secs": h_secs,
        "check_dt_secs": 0.5 * h_secs,
        "newton_tolerance": TOLERANCE,
        "max_tip_z_difference_from_half_step_m": difference_m,
        "period_secs": m.period_secs,
        "period_secs_at_half_step": m_half.period_secs,
        "amplitude_m": m.amplitude_m,
        "amplitude_m_at_half_step": m_half.amplitude_m,
        "amplitude_at_secs": hox_scenes::study::motion::AMPLITUDE_AT_SECS,
        "newton_iterations": iterations,
        "seconds": wall,
        "seconds_at_half_step": wall_half,
        "sample_secs": fine.sample_secs,
        "probe": "tip",
        "tip_z_m": fine.tip_z_m,
        "tip_m": tip_xyz,
    });
    println!("{json}");
    Ok(())
}
