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
//!   substeps slider stays cheap); a new mesh is built to be counted; a new material by the
//!   substeps the stability guard will take with it (its rest ω², computed apart on a large
//!   mesh, [`too_slow_material`]).
//!   Above [`SLOW_FRAME_MS`] the app asks first, saying the estimate and the frame rate it
//!   means, and keeps the current configuration until the answer.
//! - **After**: a frame that took more than [`SLOW_FRAME_MS`] pauses the app (a slow frame then
//!   runs only on Step), so the window stays usable and typing is not lost.
//!
//! Issue #57 (P1 refine 3, then 64 cells along x while paused: 655,360 elements accepted without
//! a question, Play froze the window for minutes): a new mesh is built in the background (the
//! window stays responsive however large it is) and estimated once built, paused or playing —
//! from the current configuration's measured frame when there is one, else from the time per
//! unit of work this machine last measured for the solver ([`Rates`]), else a conservative
//! default. The estimate counts what the user gets: the simulation and the drawing, the
//! drawing's time per frame scaled by the surface (elements^⅔). A display slower than
//! [`SLOW_FRAME_MS`] per frame while playing pauses too ([`slow_display`]).

use super::config::Config;
use super::session::Session;
#[cfg(doc)]
use hox_sim::solver::MethodInfo;
use hox_sim::solver::{Simulation, SolverSettings, SweepsPerStep};

/// A frame slower than this (under 4 frames per second) is asked about and pauses the app.
pub const SLOW_FRAME_MS: f64 = 250.0;

/// The most element–node pairs a mesh is built on, or its stability guard computed again on,
/// in place (well under a second); larger ones are prepared in the background (`rebuild.rs`).
pub const IN_PLACE_NODE_VISITS: f64 = 60_000.0;

/// `sim`'s element–node pairs.
pub fn element_node_pairs(sim: &Simulation) -> f64 {
    sim.mesh().blocks.iter().map(|b| (b.len() * b.nodes_per_element()) as f64).sum()
}

/// What one unit of work ([`frame_work`]) costs on this machine, ms, before any frame has been
/// measured: explicit (XPBD) and implicit solvers. On the safe side: issue #57's 655,360 P1
/// elements at 629 substeps took 22 s per frame, 1.3e-5 ms per unit.
const DEFAULT_MS_PER_WORK: [f64; 2] = [2e-5, 1e-4];

/// What a unit of work costs on this machine, ms, by solver: the last measured, else the
/// default ([`DEFAULT_MS_PER_WORK`]).
#[derive(Clone, Debug, Default)]
pub struct Rates {
    learned: Vec<(&'static str, f64)>,
}

impl Rates {
    /// Takes a measured frame time of `sim` (ms) in.
    pub fn learn(&mut self, sim: &Simulation, ms_per_frame: f64) {
        if !(ms_per_frame > 0.0 && ms_per_frame.is_finite()) {
            return;
        }
        let rate = ms_per_frame / frame_work(sim).max(1.0);
        let name = sim.settings().method.name();
        match self.learned.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = rate,
            None => self.learned.push((name, rate)),
        }
    }

    /// ms per unit of work of `method`.
    fn ms_per_work(&self, method: hox_sim::solver::Method) -> f64 {
        let learned = self.learned.iter().find(|(n, _)| *n == method.name()).map(|e| e.1);
        learned.unwrap_or(DEFAULT_MS_PER_WORK[usize::from(method.info().implicit)])
    }
}

/// The estimated time per frame, simulation and drawing, of `candidate` replacing `current`'s
/// simulation; `draw_ms`: what drawing a frame costs now.
pub fn estimated_total_ms(current: &Session, candidate: &Simulation, rates: &Rates, draw_ms: f64) -> f64 {
    let same_solver = current.instance.sim.settings().method == candidate.settings().method;
    let sim_ms = if current.ms_per_frame > 0.0 && same_solver {
        estimated_ms(&current.instance.sim, current.ms_per_frame, candidate)
    } else {
        rates.ms_per_work(candidate.settings().method) * frame_work(candidate)
    };
    let surface = |n: usize| (n.max(1) as f64).powf(2.0 / 3.0);
    let draw = draw_ms * surface(candidate.mesh().num_elements()) / surface(current.instance.sim.mesh().num_elements());
    sim_ms + draw
}

/// The question for a built change estimated at `ms` per frame (above [`SLOW_FRAME_MS`]), or
/// None.
pub fn too_slow_built(current: &Session, candidate: &Simulation, rates: &Rates, draw_ms: f64) -> Option<String> {
    let ms = estimated_total_ms(current, candidate, rates, draw_ms);
    (ms > SLOW_FRAME_MS).then(|| {
        let now = if current.ms_per_frame > 0.0 {
            format!("now {:.1} ms", current.ms_per_frame + draw_ms)
        } else {
            "not measured yet".to_string()
        };
        describe(candidate.mesh().num_elements(), &candidate.work_summary(), ms, &now)
    })
}

/// "N elements, WORK: about T per frame on this machine (NOW), about F frames per second."
fn describe(elements: usize, work: &str, ms: f64, now: &str) -> String {
    format!(
        "{elements} elements, {work}: about {} per frame on this machine ({now}), {}.",
        if ms >= 1000.0 { format!("{:.1} s", ms / 1e3) } else { format!("{ms:.0} ms") },
        if ms >= 1000.0 {
            "under one frame per second".to_string()
        } else {
            format!("about {:.0} frames per second", 1000.0 / ms)
        }
    )
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

/// Whether a change of solver settings `new` for `s` (the same mesh: estimated without
/// building anything, so dragging the substeps slider stays cheap) would be slow: the question,
/// or None. A new mesh is estimated once built ([`too_slow_built`]); a new material by its
/// stability guard's substeps ([`too_slow_material`]).
pub fn too_slow(s: &Session, new: &Config, rates: &Rates, draw_ms: f64) -> Option<String> {
    use super::config::Invalidates;
    match s.config.invalidated_by(new) {
        Invalidates::Settings => {}
        Invalidates::Material => return too_slow_material(s, new, None, rates, draw_ms),
        Invalidates::Mesh | Invalidates::Nothing => return None,
    }
    let settings = super::config::resolve(new, &s.base).ok()?.settings();
    let current = &s.instance.sim;
    let sim_ms = if s.ms_per_frame > 0.0 && settings.method == current.settings().method {
        estimated_ms_with(current, s.ms_per_frame, &settings)
    } else {
        let raised = current.substeps_per_frame().max(settings.substeps);
        rates.ms_per_work(settings.method)
            * sweep_work(current)
            * sweeps(&settings, if settings.stability_guard { raised } else { settings.substeps })
    };
    let ms = sim_ms + draw_ms;
    (ms > SLOW_FRAME_MS).then(|| {
        describe(current.mesh().num_elements(), &format!("{} solver", settings.method.name()), ms, &now(s, draw_ms))
    })
}

/// Whether a new material `new` for `s` would be slow: the frame of the substeps the stability
/// guard will take with it (a stiffer material, ν near 0.5, takes many more), from its rest ω²
/// per E/ρ: `omega2` when computed apart (a large mesh, in the background), else the current one
/// for a new E or ρ (which only scale it), else computed here on a mesh small enough
/// ([`IN_PLACE_NODE_VISITS`]); a large mesh's is estimated once prepared (None here).
pub fn too_slow_material(
    s: &Session,
    new: &Config,
    omega2: Option<f64>,
    rates: &Rates,
    draw_ms: f64,
) -> Option<String> {
    let scene = super::config::resolve(new, &s.base).ok()?;
    let (settings, material) = (scene.settings(), scene.material());
    let current = &s.instance.sim;
    let same_stiffness = (s.config.material, s.config.poisson_ratio) == (new.material, new.poisson_ratio);
    let omega2 = match omega2 {
        Some(w) => w,
        None if same_stiffness => current.rest_omega2_per_e_over_rho()?,
        None if element_node_pairs(current) <= IN_PLACE_NODE_VISITS => {
            current.rest_omega2_job(&material)().ok()?.per_e_over_rho.0
        }
        None => return None,
    };
    let (substeps, _) = hox_sim::solver::stability::substeps_for(&settings, &material, omega2);
    let new_sweeps = sweeps(&settings, substeps);
    let sim_ms = if s.ms_per_frame > 0.0 {
        s.ms_per_frame * new_sweeps / sweeps(current.settings(), current.substeps_per_frame()).max(1e-9)
    } else {
        rates.ms_per_work(settings.method) * sweep_work(current) * new_sweeps
    };
    let ms = sim_ms + draw_ms;
    let work = format!("{substeps} substeps per frame (the stability guard's, for this material)");
    (ms > SLOW_FRAME_MS).then(|| describe(current.mesh().num_elements(), &work, ms, &now(s, draw_ms)))
}

/// "now 12.3 ms" (the frame as measured, drawing included), or "not measured yet".
fn now(s: &Session, draw_ms: f64) -> String {
    if s.ms_per_frame > 0.0 { format!("now {:.1} ms", s.ms_per_frame + draw_ms) } else { "not measured yet".into() }
}

/// The start of the message a slow frame pauses the app with (cleared by the next change).
pub const SLOW_PAUSE: &str = "Paused: a frame takes";

/// After stepping while playing: the message that pauses the app when a frame took more than
/// [`SLOW_FRAME_MS`], or None.
pub fn slow_frame(sessions: &[Session]) -> Option<String> {
    let slowest = sessions.iter().map(|s| s.ms_per_frame).fold(0.0, f64::max);
    (slowest > SLOW_FRAME_MS).then(|| {
        format!(
            "{SLOW_PAUSE} {:.1} s, too slow to play (Step, S, advances one frame; fewer elements or substeps play).",
            slowest / 1e3
        )
    })
}

/// What the user gets while playing: the interval between the window's frames, smoothed, and
/// the part of it that is not the simulation's (the drawing); a frame slow to draw is as
/// unplayable as one slow to compute (issue #57: refine 3 at 95–160 ms of computing ran at 2 fps
/// on screen, unasked).
#[derive(Clone, Debug, Default)]
pub struct Display {
    display_ms: f64,
    /// The drawing's part of a frame, ms.
    pub draw_ms: f64,
    /// The last tick was played (its interval is one between two frames played: the first
    /// after a pause is the pause's length).
    playing: bool,
    /// Intervals in a row slower than [`SLOW_FRAME_MS`], the fastest of them, ms, and their
    /// total, seconds.
    slow_count: u32,
    slow_ms: f64,
    slow_secs: f64,
}

/// A display slow for at least this long (and three intervals) pauses: a machine busy for a
/// moment — a browser starting beside the app on its two cores, which paused a served app in
/// CI — is not a configuration too slow to play.
const SLOW_DISPLAY_SECS: f64 = 3.0;

impl Display {
    /// A tick of `dt_secs` (`playing` or not), the simulation taking `sim_ms` per frame.
    pub fn observe(&mut self, playing: bool, dt_secs: f64, sim_ms: f64) {
        if playing && self.playing && dt_secs > 0.0 {
            let ms = dt_secs * 1e3;
            self.display_ms = if self.display_ms == 0.0 { ms } else { 0.7 * self.display_ms + 0.3 * ms };
            self.draw_ms = (self.display_ms - sim_ms).max(0.0);
            self.slow_count = if ms > SLOW_FRAME_MS { self.slow_count + 1 } else { 0 };
            self.slow_ms = if self.slow_count == 1 { ms } else { self.slow_ms.min(ms) };
            self.slow_secs = if self.slow_count == 0 { 0.0 } else { self.slow_secs + dt_secs };
        }
        self.playing = playing;
    }

    /// The message that pauses the app after intervals in a row slower than [`SLOW_FRAME_MS`]
    /// for [`SLOW_DISPLAY_SECS`], three at least (not a hiccup of the machine), or None.
    pub fn slow(&self, sim_ms: f64) -> Option<String> {
        (self.slow_count >= 3 && self.slow_secs >= SLOW_DISPLAY_SECS)
            .then(|| slow_display(self.slow_ms, sim_ms))
            .flatten()
    }

    /// The app paused: the intervals start again.
    pub fn paused(&mut self) {
        self.display_ms = 0.0;
        self.slow_count = 0;
        self.slow_secs = 0.0;
    }
}

/// The message that pauses the app when the window shows a frame every `display_ms` (more than
/// [`SLOW_FRAME_MS`]), `sim_ms` of it simulating; None when faster.
fn slow_display(display_ms: f64, sim_ms: f64) -> Option<String> {
    (display_ms > SLOW_FRAME_MS).then(|| {
        format!(
            "{SLOW_PAUSE} {:.1} s on screen ({:.0} ms simulating, the rest drawing), too slow to play (Step, S, advances one frame; fewer elements, face segments or substeps play).",
            display_ms / 1e3,
            sim_ms
        )
    })
}
