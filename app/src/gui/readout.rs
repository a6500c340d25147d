//! The numbers a class looks at (issue #20): the error against the reference of the
//! configuration on screen ([`ReferenceState`]), shown settled or as the mean and amplitude of
//! the motion ([`Readout`]), never as an instantaneous value of a swinging body.
//!
//! - **Reference**: [`hox_scenes::reference`] — committed for a paper scene's own physics;
//!   otherwise computed on three Q2 levels in a background thread (with progress; cached on
//!   disk by what determines it) and replaced whenever the physics change (ν, E, ρ, model).
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
use std::thread::JoinHandle;

/// How the app finds references: the default (Q2 levels up to
/// [`hox_scenes::reference::FINEST_CELLS`] cells, the disk cache); the UI tests use small levels
/// and no disk cache, to stay quick in a debug build and leave the home folder alone.
fn lookup() -> Lookup {
    if cfg!(test) { Lookup { finest_cells: 64, cache_dir: None } } else { Lookup::default() }
}

/// What is known of the reference of a session's physics.
pub enum ReferenceState {
    /// The scene has none (contact, no probes); why.
    Unavailable(String),
    /// Being computed in the background: what it is doing and how far (0–1).
    Computing {
        key: String,
        progress: Arc<Mutex<(String, f64)>>,
        handle: Option<JoinHandle<Result<Reference, String>>>,
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
        let progress = Arc::new(Mutex::new(("reference: starting".to_string(), 0.0)));
        let (scene, shared) = (scene.clone(), progress.clone());
        let handle = std::thread::spawn(move || {
            let mut report = |what: &str, fraction: f64| {
                if let Ok(mut p) = shared.lock() {
                    *p = (what.to_string(), fraction);
                }
            };
            if with_field { lookup.with_field(&scene, &mut report) } else { lookup.for_scene(&scene, &mut report) }
                .map_err(|e| e.to_string())
        });
        ReferenceState::Computing { key, progress, handle: Some(handle) }
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
            // a computation no longer wanted finishes in the background (and fills the cache)
            *self = ReferenceState::for_scene(scene, with_field);
        }
    }

    /// Takes a finished background computation in (non-blocking); whether it did.
    pub fn poll(&mut self) -> bool {
        let ReferenceState::Computing { key, handle, .. } = self else { return false };
        if !handle.as_ref().is_some_and(|h| h.is_finished()) {
            return false;
        }
        let key = key.clone();
        *self = match handle.take().map(|h| h.join()) {
            Some(Ok(Ok(r))) => ReferenceState::Ready { key, reference: Arc::new(r) },
            Some(Ok(Err(message))) => ReferenceState::Failed { key, message },
            _ => ReferenceState::Failed { key, message: "the reference computation stopped unexpectedly".into() },
        };
        true
    }

    /// Waits for a background computation (tests).
    #[cfg(test)]
    pub fn wait(&mut self) {
        if let ReferenceState::Computing { handle, .. } = self
            && let Some(h) = handle.as_ref()
        {
            while !h.is_finished() {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
        }
        let _ = self.poll();
    }

    pub fn reference(&self) -> Option<&Reference> {
        match self {
            ReferenceState::Ready { reference, .. } => Some(reference),
            _ => None,
        }
    }

    /// One line: the reference's label, or what is being done, or why there is none.
    pub fn status(&self) -> String {
        match self {
            ReferenceState::Unavailable(why) => format!("no reference: {why}"),
            ReferenceState::Computing { progress, .. } => {
                let (what, fraction) = progress.lock().map(|p| p.clone()).unwrap_or_default();
                format!("computing the reference for this configuration: {what}, {:.0} %", 100.0 * fraction)
            }
            ReferenceState::Ready { reference, .. } => format!("reference: {}", reference.label()),
            ReferenceState::Failed { message, .. } => format!("no reference: {message}"),
        }
    }
}

/// The probe readout of a session.
#[derive(Clone, Debug, PartialEq)]
pub enum Readout {
    /// No reference (yet): the reference state's status line.
    NoReference(String),
    /// At rest: the error of every probe now, metres and % of the reference's size.
    Settled { error_m: f64, error_pct: f64, in_equilibrium: bool },
    /// Oscillating: the error of the first probe's mean over its last full oscillation.
    Moving { error_m: f64, error_pct: f64, amplitude_m: f64, period_secs: f64, drift_m: Option<f64> },
    /// Moving, but no full oscillation recorded yet.
    Starting,
    /// Not run yet: at t = 0, the start state (issue #35: it read "moving").
    NotStarted,
}

impl Readout {
    /// The error and its uncertainty, metres, where one can be stated: settled (no uncertainty
    /// beyond the solver's own), or moving with the drift between the last two oscillations'
    /// means (or, with only one, the amplitude).
    pub fn error_with_uncertainty_m(&self) -> Option<(f64, f64)> {
        match *self {
            Readout::Settled { error_m, .. } => Some((error_m, 0.0)),
            Readout::Moving { error_m, amplitude_m, drift_m, .. } => Some((error_m, drift_m.unwrap_or(amplitude_m))),
            _ => None,
        }
    }

    /// The error alone, for the status line.
    pub fn error_text(&self) -> String {
        let m = |v: f64| crate::colour::format_value(v, "m");
        match *self {
            Readout::NoReference(_) => "no reference".into(),
            Readout::Settled { error_m, error_pct, .. } => format!("settled error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Moving { error_m, error_pct, .. } => format!("mean error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Starting => "moving".into(),
            Readout::NotStarted => "not started".into(),
        }
    }

    /// A few words for the label above a body in the viewport.
    pub fn short_text(&self) -> String {
        let m = |v: f64| crate::colour::format_value(v, "m");
        match *self {
            Readout::NoReference(_) => "no reference".into(),
            Readout::Settled { error_m, error_pct, .. } => format!("settled: error {} ({error_pct:.2} %)", m(error_m)),
            Readout::Moving { error_m, error_pct, amplitude_m, .. } => {
                format!("mean error {} ({error_pct:.2} %), swinging ± {}", m(error_m), m(amplitude_m))
            }
            Readout::Starting => "moving".into(),
            Readout::NotStarted => "not started".into(),
        }
    }

    /// Short text for the status line and the viewport.
    pub fn text(&self) -> String {
        let m = crate::recording::format_metres;
        match *self {
            Readout::NoReference(ref why) => why.clone(),
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
            Readout::Starting => "moving: no full oscillation yet (Settle for the equilibrium)".into(),
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
