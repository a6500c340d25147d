//! The numbers a class looks at (issue #20): the error against the reference of the
//! configuration on screen ([`ReferenceState`]), shown settled or as the mean and amplitude of
//! the motion ([`Readout`]), never as an instantaneous value of a swinging body.
//!
//! - **Reference**: [`hox_scenes::reference`] — committed for a paper scene's own physics;
//!   otherwise computed on six Q2 levels in a background thread (with progress; cached on
//!   disk by what determines it) and replaced whenever the physics change (ν, E, ρ, model).
//!   While it computes, each provisional estimate is used as it arrives, its error bar and
//!   "refining (level k of 6)" on the labels (issue #35: "no reference" for minutes).
//! - **Settled**: the body is at rest ([`hox_scenes::RestWatch`]: every node still for 30
//!   frames, or residual and kinetic energy at the settle limits): the error of the probes now.
//! - **Moving**: the mean of the first probe over its last full oscillation (from a turning
//!   point to the next of the same kind), its error against the reference, the half
//!   peak-to-peak amplitude over that period, and the drift of that mean from the oscillation
//!   before (its uncertainty).

use hox_scenes::Scene;
use hox_scenes::reference::Lookup;
use hox_scenes::reference::Reference;
use std::sync::{Arc, Mutex};

/// How the app finds references: the default (Q2 levels up to
/// [`hox_scenes::reference::FINEST_CELLS`] cells, the disk cache); the UI tests use small levels
/// and no disk cache, to stay quick in a debug build and leave the home folder alone.
pub(super) fn lookup() -> Lookup {
    if cfg!(test) { Lookup { finest_cells: 64, cache_dir: None } } else { Lookup::default() }
}

/// What is known of the reference of a session's physics.
pub enum ReferenceState {
    /// The scene has none (contact, no probes); why.
    Unavailable(String),
    /// Being computed in the background ([`Job`]), with the latest provisional estimate taken
    /// in by [`ReferenceState::poll`].
    Computing {
        key: String,
        job: Arc<Job>,
        latest: Option<Arc<Reference>>,
    },
    Ready {
        key: String,
        reference: Arc<Reference>,
    },
    Failed {
        key: String,
        message: String,
    },
}

/// A reference computation in the background, shared by every session that wants the same
/// reference (the two configurations compared share their physics: issue #35, one computation
/// instead of two at half speed each).
#[derive(Default)]
pub struct Job {
    /// What is being done and how far, 0–1.
    pub(super) progress: Mutex<(String, f64)>,
    /// The latest provisional estimate.
    pub(super) estimate: Mutex<Option<Arc<Reference>>>,
    /// The outcome, once finished.
    pub(super) result: Mutex<Option<Result<Arc<Reference>, String>>>,
    /// In a page: the Web Worker computing it (terminated with the job).
    #[cfg(target_arch = "wasm32")]
    worker: Mutex<Option<super::platform::page::WorkerJob>>,
}

impl Job {
    fn finished(&self) -> bool {
        self.result.lock().is_ok_and(|r| r.is_some())
    }
}

/// Why a computation stopped: no session wanted it any more.
#[cfg(not(target_arch = "wasm32"))]
struct Cancelled;

/// The computations under way, by key.
fn jobs() -> &'static Mutex<std::collections::HashMap<String, std::sync::Weak<Job>>> {
    static JOBS: std::sync::OnceLock<Mutex<std::collections::HashMap<String, std::sync::Weak<Job>>>> =
        std::sync::OnceLock::new();
    JOBS.get_or_init(Default::default)
}

/// The computation of `key` under way, or a new one started in the background.
fn job(lookup: Lookup, key: &str, scene: &Scene, with_field: bool) -> Arc<Job> {
    let mut jobs = jobs().lock().unwrap_or_else(|e| e.into_inner());
    jobs.retain(|_, j| j.strong_count() > 0);
    if let Some(j) = jobs.get(key).and_then(std::sync::Weak::upgrade).filter(|j| !j.finished()) {
        return j;
    }
    let job = Arc::new(Job { progress: Mutex::new(("computing reference".into(), 0.0)), ..Default::default() });
    jobs.insert(key.to_string(), Arc::downgrade(&job));
    #[cfg(target_arch = "wasm32")]
    in_worker(&job, &lookup, scene, with_field);
    #[cfg(not(target_arch = "wasm32"))]
    in_thread(&job, lookup, scene, with_field);
    job
}

/// On the desktop: the computation on a thread of its own.
#[cfg(not(target_arch = "wasm32"))]
fn in_thread(job: &Arc<Job>, lookup: Lookup, scene: &Scene, with_field: bool) {
    // the thread holds the job weakly: once no session wants it, the next progress report
    // stops the computation (issue #35: a class typing ν after ν had each computation slow
    // the next); `resume_unwind` stops it without the panic hook's message
    let (scene, weak) = (scene.clone(), Arc::downgrade(job));
    std::thread::spawn(move || {
        let wanted = || weak.upgrade().unwrap_or_else(|| std::panic::resume_unwind(Box::new(Cancelled)));
        let run = || {
            let mut report = |what: &str, fraction: f64| {
                if let Ok(mut p) = wanted().progress.lock() {
                    *p = (what.to_string(), fraction);
                }
            };
            let mut on_estimate = |r: &Reference| {
                if let Ok(mut e) = wanted().estimate.lock() {
                    *e = Some(Arc::new(r.clone()));
                }
            };
            lookup.get(&scene, with_field, &mut report, &mut on_estimate).map(Arc::new).map_err(|e| e.to_string())
        };
        let result = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
            Ok(result) => result,
            Err(payload) if payload.is::<Cancelled>() => return,
            Err(_) => Err("the reference computation stopped unexpectedly".into()),
        };
        if let Some(job) = weak.upgrade()
            && let Ok(mut r) = job.result.lock()
        {
            *r = Some(result);
        }
    });
}

/// In a page: the computation on a Web Worker of its own (`platform::page`), its reports taken
/// in as they come between frames; the job holds the worker, which stops with it.
#[cfg(target_arch = "wasm32")]
fn in_worker(job: &Arc<Job>, lookup: &Lookup, scene: &Scene, with_field: bool) {
    use super::platform::page::{WorkerEvent, reference_in_worker};
    let request = serde_json::json!({
        "scene": scene.file.to_toml(),
        "source": scene.source,
        "with_field": with_field,
        "finest_cells": lookup.finest_cells,
    });
    let weak = Arc::downgrade(job);
    let started = reference_in_worker(&request, move |event| {
        let Some(job) = weak.upgrade() else { return };
        let parse = |text: &str| serde_json::from_str::<Reference>(text).map(Arc::new).map_err(|e| e.to_string());
        match event {
            WorkerEvent::Progress(what, fraction) => {
                if let Ok(mut p) = job.progress.lock() {
                    *p = (what, fraction);
                }
            }
            WorkerEvent::Estimate(text) => {
                if let (Ok(r), Ok(mut e)) = (parse(&text), job.estimate.lock()) {
                    *e = Some(r);
                }
            }
            WorkerEvent::Done(result) => {
                if let Ok(mut r) = job.result.lock() {
                    *r = Some(result.and_then(|text| parse(&text)));
                }
            }
        }
    });
    match started {
        Ok(worker) => *job.worker.lock().unwrap_or_else(|e| e.into_inner()) = Some(worker),
        Err(e) => *job.result.lock().unwrap_or_else(|e| e.into_inner()) = Some(Err(e)),
    }
}

/// The key of what is wanted: the reference, or (`with_field`, for the error field) the
/// reference with its displacement field.
fn wanted_key(lookup: &Lookup, scene: &Scene, with_field: bool) -> String {
    if with_field { lookup.field_key(scene) } else { lookup.key(scene) }
}

impl ReferenceState {
    /// The reference of `scene` (`with_field`: with its displacement field, for the error
    /// field): known at once, or computing in the background.
    pub fn for_scene(scene: &Scene, with_field: bool) -> ReferenceState {
        if let Some(why) = hox_scenes::reference::unavailable(scene) {
            return ReferenceState::Unavailable(why);
        }
        let lookup = lookup();
        let key = wanted_key(&lookup, scene, with_field);
        match lookup.known(scene) {
            Ok(Some(r)) if !with_field || r.field.is_some() || !scene.is_box() => {
                return ReferenceState::Ready { key, reference: Arc::new(r) };
            }
            Ok(_) => {}
            Err(e) => return ReferenceState::Failed { key, message: e.to_string() },
        }
        let job = job(lookup, &key, scene, with_field);
        ReferenceState::Computing { key, job, latest: None }
    }

    fn key(&self) -> Option<&str> {
        match self {
            ReferenceState::Unavailable(_) => None,
            ReferenceState::Computing { key, .. }
            | ReferenceState::Ready { key, .. }
            | ReferenceState::Failed { key, .. } => Some(key),
        }
    }

    /// Follows `scene`'s physics (and, for a mesh file, its quadrature) and whether its field
    /// is wanted: a new reference when they changed, the same one otherwise (a reference with
    /// its field serves where none is wanted too).
    pub fn follow(&mut self, scene: &Scene, with_field: bool) {
        let lookup = lookup();
        let unavailable = hox_scenes::reference::unavailable(scene);
        let key = self.key().map(str::to_string);
        let fits = key.as_deref() == Some(wanted_key(&lookup, scene, with_field).as_str())
            || (!with_field && key.as_deref() == Some(lookup.field_key(scene).as_str()));
        if !fits || unavailable.is_some() {
            // a computation no longer wanted by any session stops at its next progress report
            *self = ReferenceState::for_scene(scene, with_field);
        }
    }

    /// Takes a finished background computation, or a new provisional estimate, in
    /// (non-blocking); whether it did.
    pub fn poll(&mut self) -> bool {
        let ReferenceState::Computing { key, job, latest } = self else { return false };
        let result = job.result.lock().ok().and_then(|r| r.clone());
        let Some(result) = result else {
            let new = job.estimate.lock().ok().and_then(|e| e.clone());
            return match new {
                Some(r) if !latest.as_ref().is_some_and(|l| Arc::ptr_eq(l, &r)) => {
                    *latest = Some(r);
                    true
                }
                _ => false,
            };
        };
        let key = key.clone();
        *self = match result {
            Ok(reference) => ReferenceState::Ready { key, reference },
            Err(message) => ReferenceState::Failed { key, message },
        };
        true
    }

    /// Waits for a background computation (tests).
    #[cfg(test)]
    pub fn wait(&mut self) {
        if let ReferenceState::Computing { job, .. } = self {
            while !job.finished() {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
        }
        let _ = self.poll();
    }

    /// The reference, or while one is computed its latest provisional estimate.
    pub fn reference(&self) -> Option<&Reference> {
        match self {
            ReferenceState::Ready { reference, .. } | ReferenceState::Computing { latest: Some(reference), .. } => {
                Some(reference)
            }
            _ => None,
        }
    }

    /// What the computation is doing ("computing reference, level 3 of 6 (static Q2 16×4×4)")
    /// and how far it is overall, 0–1.
    fn progress(&self) -> Option<(String, f64)> {
        match self {
            ReferenceState::Computing { job, .. } => job.progress.lock().ok().map(|p| p.clone()),
            _ => None,
        }
    }

    /// A few words for a body's label: "no reference", "computing reference, level 2 of 6",
    /// or with a provisional estimate "reference 0.2887 m ± 3.97 % (refining, 4 of 6)" (the
    /// first probe's displacement); None for a finished reference (the readout says the rest).
    pub fn short_status(&self) -> Option<String> {
        let level = |what: &str| what.split(" (").next().unwrap_or(what).replace("computing reference, ", "");
        match self {
            ReferenceState::Ready { .. } => None,
            ReferenceState::Computing { latest: Some(r), .. } => {
                let size = match r.probes.iter().next() {
                    Some((_, u)) => format!("{:.4} m", hox_sim::Vec3::from(*u).norm()),
                    None => String::new(),
                };
                // issue #57: "± 0.00 % (refining, 6 of 6)" said nothing
                let pct = match r.estimated_error_pct() {
                    Some(p) if p < 0.01 => "< 0.01 %".to_string(),
                    Some(p) => format!("{p:.2} %"),
                    None => "?".into(),
                };
                let at = level(&self.progress().unwrap_or_default().0).replace("level ", "");
                let last = at.split_once(" of ").is_some_and(|(a, b)| a.trim() == b.trim());
                Some(format!("reference {size} ± {pct} ({}, {at})", if last { "last level" } else { "refining" }))
            }
            ReferenceState::Computing { .. } => {
                Some(self.progress().map_or_else(|| "computing reference".into(), |(what, _)| level(&what)))
                    .map(|l| if l.starts_with("level") { format!("computing reference, {l}") } else { l })
            }
            ReferenceState::Unavailable(_) | ReferenceState::Failed { .. } => Some("no reference".into()),
        }
    }

    /// One line: the reference's label, or what is being done, or why there is none.
    pub fn status(&self) -> String {
        match self {
            ReferenceState::Unavailable(why) => format!("no reference: {why}"),
            ReferenceState::Computing { latest, .. } => {
                let (what, fraction) = self.progress().unwrap_or_default();
                let doing = format!("{what}, {:.0} %", 100.0 * fraction);
                match latest {
                    Some(r) => format!("reference: {}; {doing}", r.label()),
                    None => doing,
                }
            }
            ReferenceState::Ready { reference, .. } => format!("reference: {}", reference.label()),
            ReferenceState::Failed { message, .. } => format!("no reference: {message}"),
        }
    }
}

/// The probe readout of a session.
#[derive(Clone, Debug, PartialEq)]
pub enum Readout {
    /// No reference (yet): a few words ([`ReferenceState::short_status`]) and the reference
    /// state's status line.
    NoReference { short: String, why: String },
    /// At rest: the error of every probe now, metres and % of the reference's size.
    Settled { error_m: f64, error_pct: f64, in_equilibrium: bool },
    /// Oscillating: the error of the first probe's mean over its last full oscillation.
    Moving { error_m: f64, error_pct: f64, amplitude_m: f64, period_secs: f64, drift_m: Option<f64> },
    /// Moving, but no full oscillation recorded yet; `paused` mid-swing (issue #35: a paused
    /// beam read "moving").
    Starting { paused: bool },
    /// The physics changed (ν, E, the solver…) since the body was last at rest or solved, and no
    /// full oscillation since: what is on screen is not the state of the parameters shown
    /// (issue #57: it kept reading "static equilibrium" and "settled").
    Changed { paused: bool },
    /// The static equilibrium, solved and shown (a lesson's static step): its error.
    Static { error_m: f64, error_pct: f64 },
    /// Not run yet: at t = 0, the start state (issue #35: it read "moving").
    NotStarted,
}

impl Readout {
    /// No reference for this readout, for `why` ("the scene has no probes").
    pub fn missing(why: &str) -> Readout {
        Readout::NoReference { short: "no reference".into(), why: format!("no reference: {why}") }
    }

    /// The error and its uncertainty, metres, where one can be stated: settled (no uncertainty
    /// beyond the solver's own), or moving with the drift between the last two oscillations'
    /// means (or, with only one, the amplitude).
    pub fn error_with_uncertainty_m(&self) -> Option<(f64, f64)> {
        match *self {
            Readout::Settled { error_m, .. } | Readout::Static { error_m, .. } => Some((error_m, 0.0)),
            Readout::Moving { error_m, amplitude_m, drift_m, .. } => Some((error_m, drift_m.unwrap_or(amplitude_m))),
            _ => None,
        }
    }

    /// The error alone, for the status line.
    pub fn error_text(&self) -> String {
        let m = |v: f64| hox_scenes::present::colour::format_value(v, "m");
        match *self {
            Readout::NoReference { ref short, .. } => short.clone(),
            Readout::Settled { error_m, error_pct, .. } => format!("settled error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Static { error_m, error_pct } => format!("static, error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Moving { error_m, error_pct, .. } => format!("mean error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Starting { paused: false } => "moving".into(),
            Readout::Starting { paused: true } => "paused mid-swing".into(),
            Readout::Changed { .. } => "changed, not at rest".into(),
            Readout::NotStarted => "not started".into(),
        }
    }

    /// A few words for the label above a body in the viewport.
    pub fn short_text(&self) -> String {
        let m = |v: f64| hox_scenes::present::colour::format_value(v, "m");
        match *self {
            Readout::NoReference { ref short, .. } => short.clone(),
            Readout::Settled { error_m, error_pct, .. } => format!("settled: error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Static { error_m, error_pct } => {
                format!("static equilibrium: error {} ({error_pct:.2} %)", m(error_m))
            }
            Readout::Moving { error_m, error_pct, amplitude_m, .. } => {
                format!("mean error {} ({error_pct:.2} %), swinging ± {}", m(error_m), m(amplitude_m))
            }
            Readout::Starting { paused: false } => "moving".into(),
            Readout::Starting { paused: true } => "paused mid-swing".into(),
            Readout::Changed { .. } => "changed: not yet at rest for these values".into(),
            Readout::NotStarted => "not started".into(),
        }
    }

    /// Short text for the status line and the viewport.
    pub fn text(&self) -> String {
        let m = crate::display::format_metres;
        match *self {
            Readout::NoReference { ref why, .. } => why.clone(),
            Readout::Settled { error_m, error_pct, in_equilibrium } => format!(
                "settled error {} m ({error_pct:.2} %){}",
                m(error_m),
                if in_equilibrium { "" } else { ", at rest off equilibrium" }
            ),
            Readout::Moving { error_m, error_pct, amplitude_m, period_secs, drift_m } => format!(
                "moving: mean error {} m ({error_pct:.2} %){} over the last {period_secs:.2} s swing, amplitude {} m",
                m(error_m),
                drift_m.map(|d| format!(" ± {}", m(d))).unwrap_or_default(),
                m(amplitude_m)
            ),
            Readout::Static { error_m, error_pct } => {
                format!("static equilibrium (solved, shown at rest): error {} m ({error_pct:.2} %)", m(error_m))
            }
            Readout::Starting { paused: false } => {
                "moving: no full oscillation yet (Settle for the equilibrium)".into()
            }
            Readout::Starting { paused: true } => {
                "paused mid-swing: no full oscillation yet (Play, or Settle for the equilibrium)".into()
            }
            Readout::Changed { paused: false } => {
                "changed: moving to the new values' state, no full oscillation yet (Settle for the equilibrium)".into()
            }
            Readout::Changed { paused: true } => {
                "changed: the shape shown is the old values' (Play, or Settle for the new equilibrium)".into()
            }
            Readout::NotStarted => "not started: t = 0 (Play, Step or Settle)".into(),
        }
    }
}

/// The turning points of `values` (index of each confirmed local extremum), with hysteresis:
/// an extremum counts once the signal has come back from it by `delta`.
pub fn turning_points(values: &[f64], delta: f64) -> Vec<usize> {
    let mut out = Vec::new();
    let Some(&first) = values.first() else { return out };
    // direction: +1 rising, −1 falling, 0 not yet known
    let (mut direction, mut extreme, mut at) = (0i8, first, 0usize);
    let (mut lo, mut hi) = ((first, 0usize), (first, 0usize));
    for (k, &v) in values.iter().enumerate() {
        match direction {
            0 => {
                if v < lo.0 {
                    lo = (v, k);
                }
                if v > hi.0 {
                    hi = (v, k);
                }
                if v - lo.0 > delta {
                    (direction, extreme, at) = (1, v, k);
                } else if hi.0 - v > delta {
                    (direction, extreme, at) = (-1, v, k);
                }
            }
            1 if v > extreme => (extreme, at) = (v, k),
            1 if extreme - v > delta => {
                out.push(at);
                (direction, extreme, at) = (-1, v, k);
            }
            -1 if v < extreme => (extreme, at) = (v, k),
            -1 if v - extreme > delta => {
                out.push(at);
                (direction, extreme, at) = (1, v, k);
            }
            _ => {}
        }
    }
    out
}

/// The first probe's last full oscillation in a history: `(mean of each component over it,
/// half peak-to-peak of the component that moves most, period, mean over the oscillation
/// before if recorded)`.
pub fn last_oscillation(time_secs: &[f64], probe_m: &[[f64; 3]]) -> Option<([f64; 3], f64, f64, Option<[f64; 3]>)> {
    if probe_m.len() < 5 {
        return None;
    }
    // the component that moves most over the recorded window
    let range = |d: usize| {
        let (lo, hi) =
            probe_m.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), u| (lo.min(u[d]), hi.max(u[d])));
        hi - lo
    };
    let d = (0..3).max_by(|a, b| range(*a).total_cmp(&range(*b)))?;
    let values: Vec<f64> = probe_m.iter().map(|u| u[d]).collect();
    let turning = turning_points(&values, 1e-3 * range(d).max(1e-12));
    let mean = |a: usize, b: usize| {
        let mut m = [0.0; 3];
        for u in &probe_m[a..b] {
            for c in 0..3 {
                m[c] += u[c] / (b - a) as f64;
            }
        }
        m
    };
    let n = turning.len();
    if n < 3 {
        return None;
    }
    let (a, c) = (turning[n - 3], turning[n - 1]);
    if c <= a {
        return None;
    }
    let (lo, hi) =
        values[a..=c].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    let before = (n >= 5).then(|| mean(turning[n - 5], turning[n - 3]));
    Some((mean(a, c), 0.5 * (hi - lo), time_secs[c] - time_secs[a], before))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn damped(period: f64, decay: f64, secs: f64) -> (Vec<f64>, Vec<[f64; 3]>) {
        let dt = 1.0 / 60.0;
        let n = (secs / dt) as usize;
        let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
        let w = 2.0 * std::f64::consts::PI / period;
        let u = t.iter().map(|&t| [0.0, 0.0, -0.3 + 0.3 * (-decay * t).exp() * (w * t).cos()]).collect();
        (t, u)
    }

    #[test]
    fn the_mean_over_the_last_oscillation_finds_the_centre_of_a_swing() {
        let (t, u) = damped(0.9, 0.0, 4.0);
        let (mean, amplitude, period, before) = last_oscillation(&t, &u).unwrap();
        // the centre of an undamped swing, to what a whole number of frames per period allows
        assert!((mean[2] + 0.3).abs() < 3e-3, "{mean:?}");
        assert!((amplitude - 0.3).abs() < 1e-3, "{amplitude}");
        assert!((period - 0.9).abs() < 2.0 / 60.0, "{period}");
        assert!(before.is_some());
    }

    #[test]
    fn no_oscillation_is_claimed_before_a_full_swing() {
        let (t, u) = damped(0.9, 0.0, 0.6);
        assert!(last_oscillation(&t, &u).is_none());
        // nor from noise around a still value
        let still: Vec<[f64; 3]> = (0..200).map(|k| [0.0, 0.0, -0.3 + 1e-15 * (k % 2) as f64]).collect();
        let times: Vec<f64> = (0..200).map(|k| k as f64 / 60.0).collect();
        assert!(last_oscillation(&times, &still).is_none_or(|(_, a, _, _)| a < 1e-12));
    }

    #[test]
    fn turning_points_ignore_wiggles_below_the_hysteresis() {
        let v = [0.0, 1.0, 0.99, 1.0, 2.0, 1.0, 0.0, -1.0, 0.0];
        assert_eq!(turning_points(&v, 0.5), vec![4, 7]);
    }
}
