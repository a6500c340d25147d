//! Running a scene: for a given simulated time, or until it settles.
//!
//! **Settling** (`RunMode::Settle`): velocity damping `v ← v e^{−c h}` with the scene's
//! `settle_damping_per_sec` is added, and the run stops once every node has moved less than
//! `SETTLE_TOLERANCE_REL` × the body's bounding-box diagonal per frame for `SETTLE_FRAMES`
//! consecutive frames, after all prescribed ramps and moving planes have stopped; or after
//! `SETTLE_CAP_SECS` simulated seconds, reported as not settled.

use crate::scene::EffectSpec;
use crate::{Instance, SceneError};
use hox_sim::effect::Damping;
use std::time::Instant;

/// Consecutive quiet frames that count as settled.
pub const SETTLE_FRAMES: usize = 30;
/// Largest per-frame node motion that counts as quiet, relative to the body's diagonal.
pub const SETTLE_TOLERANCE_REL: f64 = 1e-7;
/// Simulated time after which settling gives up.
pub const SETTLE_CAP_SECS: f64 = 120.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunMode {
    Seconds(f64),
    /// Until settled, or for at most `cap_secs` simulated seconds.
    Settle {
        cap_secs: f64,
    },
}

impl RunMode {
    /// Settling with the default cap.
    pub const SETTLE: RunMode = RunMode::Settle { cap_secs: SETTLE_CAP_SECS };
}

/// What a run produced (the CLI prints it as JSON).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RunReport {
    pub probes: std::collections::BTreeMap<String, [f64; 3]>,
    /// Probe displacements averaged over the last simulated second (over the whole run when
    /// shorter): the state an oscillation that never settles hovers around.
    pub probes_last_second_mean: std::collections::BTreeMap<String, [f64; 3]>,
    pub frames: u64,
    pub sim_seconds: f64,
    /// Median wall-clock time of one frame (stepping only), milliseconds; NaN (`null` in JSON)
    /// for a run of no frames.
    pub ms_per_frame: f64,
    pub settled: bool,
    pub kinetic_energy_j: f64,
    pub elastic_energy_j: f64,
}

/// Runs `instance` and reports. `progress(sim_seconds, fraction)` is called after every frame
/// (`fraction` is None when settling, whose length is not known in advance).
pub fn run(
    instance: &mut Instance,
    mode: RunMode,
    progress: &mut dyn FnMut(f64, Option<f64>),
) -> Result<RunReport, SceneError> {
    run_observed(instance, mode, progress, &mut |_| Ok(()))
}

/// [`run`], calling `on_frame(instance)` after every frame (outside the frame timing), e.g. to
/// write the frame to a file; its error stops the run.
pub fn run_observed(
    instance: &mut Instance,
    mode: RunMode,
    progress: &mut dyn FnMut(f64, Option<f64>),
    on_frame: &mut dyn FnMut(&Instance) -> Result<(), SceneError>,
) -> Result<RunReport, SceneError> {
    let frame_secs = 1.0 / instance.scene.params().frames_per_second;
    let source = instance.scene.source.clone();
    let fail =
        |e: hox_sim::solver::SimError| SceneError::Simulation { source_name: source.clone(), message: e.to_string() };
    let mut settled = false;
    let mut frame_ms: Vec<f64> = Vec::new();
    let window = (instance.scene.params().frames_per_second.round() as usize).max(1);
    let mut history: std::collections::VecDeque<Vec<(String, [f64; 3])>> =
        std::collections::VecDeque::with_capacity(window + 1);
    let mut remember = |instance: &Instance| {
        history.push_back(instance.probe_displacements());
        if history.len() > window {
            history.pop_front();
        }
    };
    let start_frames = instance.sim.frames();
    // one frame, timed and remembered
    let mut step = |instance: &mut Instance| -> Result<(), SceneError> {
        let clock = Instant::now();
        instance.sim.step_frame().map_err(fail)?;
        frame_ms.push(1e3 * clock.elapsed().as_secs_f64());
        remember(instance);
        on_frame(instance)
    };
    match mode {
        RunMode::Seconds(t) => {
            let frames = (t / frame_secs).round().max(0.0) as u64;
            for f in 0..frames {
                step(instance)?;
                progress(instance.sim.time_secs(), Some((f + 1) as f64 / frames as f64));
            }
        }
        RunMode::Settle { cap_secs } => {
            let damping = instance.scene.params().settle_damping_per_sec;
            if damping > 0.0 {
                instance.sim.add_effect(Box::new(Damping { rate_per_sec: damping })).map_err(fail)?;
            }
            // a warm-started run (positions set by the caller) has its drives already applied
            let driven_until =
                if instance.sim.time_secs() > 0.0 { 0.0 } else { driven_until_secs(&instance.scene.file.effects) };
            let (lo, hi) = instance.sim.mesh().bounding_box();
            let tolerance_m = SETTLE_TOLERANCE_REL * (hi - lo).norm();
            let mut quiet = 0;
            let mut before = instance.sim.positions.clone();
            let give_up_at = instance.sim.time_secs() + cap_secs;
            while instance.sim.time_secs() < give_up_at {
                step(instance)?;
                let moved = instance.sim.positions.iter().zip(&before).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                before.copy_from_slice(&instance.sim.positions);
                quiet = if moved < tolerance_m && instance.sim.time_secs() >= driven_until { quiet + 1 } else { 0 };
                progress(instance.sim.time_secs(), None);
                if quiet >= SETTLE_FRAMES {
                    settled = true;
                    break;
                }
            }
        }
    }
    let frames = instance.sim.frames() - start_frames;
    let mut mean: std::collections::BTreeMap<String, [f64; 3]> = std::collections::BTreeMap::new();
    for frame in &history {
        for (name, u) in frame {
            let m = mean.entry(name.clone()).or_insert([0.0; 3]);
            for d in 0..3 {
                m[d] += u[d] / history.len() as f64;
            }
        }
    }
    Ok(RunReport {
        probes: instance.probe_displacements().into_iter().collect(),
        probes_last_second_mean: mean,
        frames,
        sim_seconds: instance.sim.time_secs(),
        ms_per_frame: median(&mut frame_ms),
        settled,
        kinetic_energy_j: instance.sim.kinetic_energy_j(),
        elastic_energy_j: instance.sim.elastic_energy_j(),
    })
}

pub use hox_sim::measure::median;

/// Time after which no listed effect drives motion any more (ramps done, planes stopped).
fn driven_until_secs(effects: &[EffectSpec]) -> f64 {
    effects
        .iter()
        .map(|e| match e {
            EffectSpec::Prescribed { ramp_secs, .. } => *ramp_secs,
            EffectSpec::Contact { velocity_m_s, move_secs, .. } if velocity_m_s.iter().any(|v| *v != 0.0) => {
                move_secs.unwrap_or(f64::INFINITY).min(SETTLE_CAP_SECS)
            }
            _ => 0.0,
        })
        .fold(0.0, f64::max)
}
