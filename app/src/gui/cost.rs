//! Guard rails for expensive settings (issue #35: refine 3 gave 81,920 elements and 368
//! substeps, 13.6 s per frame; the window ran at about 1 fps and the next typed value was lost).
//!
//! - **Before**: a change that rebuilds or re-tunes a configuration is estimated first. The
//!   frame's work is `Σ elements × quadrature points × nodes per element` times the solver's
//!   sweeps per frame (the solver's steps — XPBD's substeps, with the stability guard's — times
//!   its registry entry's [`MethodInfo::sweeps_per_step`]: XPBD's iterations, VBD's, or a
//!   Newton-type solver's usual iterations); the new configuration's
//!   time per frame is the current one's measured time scaled by the ratio of the two works. A
//!   change of solver settings is estimated on the current mesh (nothing is built: dragging the
//!   substeps slider stays cheap); a new mesh is built to be counted; a new material is not
//!   estimated (the slow-frame pause below catches a stiffer one's extra substeps).
//!   Above [`SLOW_FRAME_MS`] the app asks first, saying the estimate and the frame rate it
//!   means, and keeps the current configuration until the answer.
//! - **After**: a frame that took more than [`SLOW_FRAME_MS`] pauses the app (a slow frame then
//!   runs only on Step), so the window stays usable and typing is not lost.

use super::config::Config;
use super::session::Session;
#[cfg(doc)]
use hox_sim::solver::MethodInfo;
use hox_sim::solver::{Simulation, SolverSettings, SweepsPerStep};

/// A frame slower than this (under 4 frames per second) is asked about and pauses the app.
pub const SLOW_FRAME_MS: f64 = 250.0;

/// A change held back until the user says: the control, the configuration, what it will cost.
pub struct PendingChange {
    pub control: String,
    pub config: Config,
    pub estimate: String,
}

/// Element–point–node visits of one sweep over `sim`'s elements.
fn sweep_work(sim: &Simulation) -> f64 {
    sim.geometry()
        .iter()
        .zip(&sim.mesh().blocks)
        .map(|(g, b)| (b.len() * g.points_per_element * g.nodes_per_element) as f64)
        .sum()
}

/// Sweeps per frame of `settings`, XPBD's with `substeps` (the stability guard's, if raised).
fn sweeps(settings: &SolverSettings, substeps: u32) -> f64 {
    let info = settings.method.info();
    let steps = if info.implicit { settings.steps_per_frame } else { substeps };
    let per_step = match info.sweeps_per_step {
        SweepsPerStep::Iterations => f64::from(settings.iterations.max(1)),
        SweepsPerStep::VbdIterations => f64::from(settings.vbd.iterations.max(1)),
        SweepsPerStep::About(n) => n,
    };
    f64::from(steps.max(1)) * per_step
}

/// The work of one frame of `sim`, in element–point–node visits (module docs).
pub fn frame_work(sim: &Simulation) -> f64 {
    sweep_work(sim) * sweeps(sim.settings(), sim.substeps_per_frame())
}

/// The estimated time per frame of `candidate`, from `current`'s measured `current_ms`.
pub fn estimated_ms(current: &Simulation, current_ms: f64, candidate: &Simulation) -> f64 {
    current_ms * frame_work(candidate) / frame_work(current).max(1.0)
}

/// The estimated time per frame of `current` run with `settings` instead (the same mesh, so
/// nothing is built: dragging the substeps slider stays cheap); the stability guard keeps XPBD's
/// substeps at least where it raised them.
pub fn estimated_ms_with(current: &Simulation, current_ms: f64, settings: &SolverSettings) -> f64 {
    let raised = current.substeps_per_frame() > current.settings().substeps;
    let substeps = if settings.stability_guard && raised {
        settings.substeps.max(current.substeps_per_frame())
    } else {
        settings.substeps
    };
    current_ms * sweeps(settings, substeps) / sweeps(current.settings(), current.substeps_per_frame()).max(1e-9)
}

/// Whether `new` for `s` would be slow: the estimate in words, or None (cheap enough, not
/// measurable yet, or not buildable: applying it says why).
pub fn too_slow(s: &Session, new: &Config) -> Option<String> {
    use super::config::Invalidates;
    if s.ms_per_frame <= 0.0 {
        return None;
    }
    let what = s.config.invalidated_by(new);
    let scene = match what {
        // a new material may raise the guard's substeps: a slow frame then pauses (below)
        Invalidates::Nothing | Invalidates::Material => return None,
        Invalidates::Settings | Invalidates::Mesh => super::config::resolve(new, &s.base).ok()?,
    };
    // the same mesh: estimated from the settings alone; a new mesh is built to be counted
    let (ms, elements, work) = if what == Invalidates::Settings {
        let settings = scene.settings();
        let ms = estimated_ms_with(&s.instance.sim, s.ms_per_frame, &settings);
        (ms, s.instance.sim.mesh().num_elements(), format!("{} solver", settings.method.name()))
    } else {
        let candidate = hox_scenes::Instance::new(scene).ok()?;
        let ms = estimated_ms(&s.instance.sim, s.ms_per_frame, &candidate.sim);
        (ms, candidate.sim.mesh().num_elements(), candidate.sim.work_summary())
    };
    (ms > SLOW_FRAME_MS).then(|| {
        format!(
            "{elements} elements, {work}: about {} per frame on this machine (now {:.1} ms), {}.",
            if ms >= 1000.0 { format!("{:.1} s", ms / 1e3) } else { format!("{ms:.0} ms") },
            s.ms_per_frame,
            if ms >= 1000.0 {
                "under one frame per second".to_string()
            } else {
                format!("about {:.0} frames per second", 1000.0 / ms)
            }
        )
    })
}

/// After stepping while playing: the message that pauses the app when a frame took more than
/// [`SLOW_FRAME_MS`], or None.
pub fn slow_frame(sessions: &[Session]) -> Option<String> {
    let slowest = sessions.iter().map(|s| s.ms_per_frame).fold(0.0, f64::max);
    (slowest > SLOW_FRAME_MS).then(|| {
        format!(
            "Paused: a frame takes {:.1} s, too slow to play (Step, S, advances one frame; fewer elements or substeps play).",
            slowest / 1e3
        )
    })
}
