//! Accuracy in motion: the bending beam released from rest, against a reference motion.
//!
//! The reference (`assets/reference/bending-motion.json`, made by
//! `cargo run --release -p hox-scenes --example reference_motion`, recipe in
//! `assets/reference/README.md`) is the tip probe's displacement every 1/60 s over 3 s on Q2
//! 16×4×4, integrated by Newmark's average-acceleration rule (the Newton solver with
//! [`hox_sim::solver::Integrator::Newmark`],
//! energy-conserving) with a step converged against its half.
//!
//! Two numbers summarise a motion `u_z(t)` released from rest (a turning point at t = 0):
//! - the **first period**: the time of the first return to the top, i.e. of the second
//!   turning point after release; each turning point is the vertex of the parabola through the
//!   extreme sample and its two neighbours (accurate to a small fraction of a frame);
//! - the **amplitude around 2 s**: half the height between the two successive turning points
//!   (a top and a bottom) whose mid-time is nearest [`AMPLITUDE_AT_SECS`], which a scheme's
//!   numerical damping shrinks.

use crate::error::SceneError;
use crate::instance::Instance;

/// When the amplitude "after 2 s" is measured, seconds.
pub const AMPLITUDE_AT_SECS: f64 = 2.0;

/// Simulated time a compared motion runs, seconds.
pub const MOTION_SECS: f64 = 2.5;

/// The committed reference motion of the bending beam.
pub const REFERENCE_MOTION_JSON: &str = include_str!("../../../../assets/reference/bending-motion.json");

/// A probe's motion sampled at a fixed interval from release.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub sample_secs: f64,
    /// Vertical displacement of the tip probe at `k · sample_secs`, k = 0, 1, …, m.
    pub tip_z_m: Vec<f64>,
}

/// The summary of a motion ([`Motion::metrics`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MotionMetrics {
    /// Time from release to the first return to the top, seconds (None if the motion has no
    /// two turning points).
    pub period_secs: Option<f64>,
    /// Half the height between the top and bottom turning points around [`AMPLITUDE_AT_SECS`],
    /// metres (None without two turning points).
    pub amplitude_m: Option<f64>,
}

impl Motion {
    /// The turning points after release: `(time, value)` of each interior local extremum,
    /// refined by a parabola through three samples.
    pub fn turning_points(&self) -> Vec<(f64, f64)> {
        let y = &self.tip_z_m;
        let dt = self.sample_secs;
        let mut out = Vec::new();
        for k in 1..y.len().saturating_sub(1) {
            let (a, b, c) = (y[k - 1], y[k], y[k + 1]);
            let is_min = b < a && b <= c;
            let is_max = b > a && b >= c;
            if !(is_min || is_max) {
                continue;
            }
            let curvature = a - 2.0 * b + c;
            let shift = if curvature != 0.0 { 0.5 * (a - c) / curvature } else { 0.0 };
            let shift = shift.clamp(-1.0, 1.0);
            out.push(((k as f64 + shift) * dt, b - 0.25 * (a - c) * shift));
        }
        out
    }

    pub fn metrics(&self) -> MotionMetrics {
        let turning = self.turning_points();
        let period_secs = turning.get(1).map(|p| p.0);
        let amplitude_m = turning
            .windows(2)
            .min_by(|a, b| {
                let mid = |w: &[(f64, f64)]| (0.5 * (w[0].0 + w[1].0) - AMPLITUDE_AT_SECS).abs();
                mid(a).total_cmp(&mid(b))
            })
            .map(|w| 0.5 * (w[0].1 - w[1].1).abs());
        MotionMetrics { period_secs, amplitude_m }
    }
}

/// The committed reference motion (the tip of the bending beam released from rest).
pub fn reference_motion() -> Result<Motion, SceneError> {
    parse_motion(REFERENCE_MOTION_JSON, "assets/reference/bending-motion.json")
}

/// Reads a motion file: `{"sample_secs": …, "tip_z_m": [...], …}`.
pub fn parse_motion(text: &str, source_name: &str) -> Result<Motion, SceneError> {
    let bad = |m: &str| SceneError::Parse { source_name: source_name.to_string(), message: m.to_string() };
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(&e.to_string()))?;
    let sample_secs = v["sample_secs"].as_f64().filter(|s| *s > 0.0).ok_or_else(|| bad("no positive sample_secs"))?;
    let tip_z_m: Vec<f64> = v["tip_z_m"]
        .as_array()
        .ok_or_else(|| bad("no tip_z_m array"))?
        .iter()
        .map(|x| {
            x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| bad("tip_z_m holds a value that is not a finite number"))
        })
        .collect::<Result<_, _>>()?;
    if tip_z_m.len() < 3 {
        return Err(bad("tip_z_m needs at least three samples"));
    }
    Ok(Motion { sample_secs, tip_z_m })
}

/// A motion recorded by [`record_motion`], with what it cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    pub motion: Motion,
    /// Mean wall-clock time of one frame (stepping only), ms.
    pub mean_ms_per_frame: f64,
}

/// Runs `instance` (at rest, as built) for `secs` without any added damping and records the
/// vertical displacement of its probe `probe` once per frame, from t = 0, timing the frames.
pub fn record_motion(instance: &mut Instance, secs: f64, probe: &str) -> Result<Recorded, SceneError> {
    let source = instance.scene.source.clone();
    let index = instance.probes.iter().position(|p| p.name == probe).ok_or_else(|| SceneError::Simulation {
        source_name: source.clone(),
        message: format!("the scene has no probe named {probe}"),
    })?;
    let probe_z = |instance: &Instance| {
        instance.probes[index].displacement(&instance.sim.positions, &instance.sim.mesh().rest_positions).z
    };
    let fps = instance.scene.params().frames_per_second;
    let frames = (secs * fps).round() as usize;
    let mut tip_z_m = Vec::with_capacity(frames + 1);
    tip_z_m.push(probe_z(instance));
    let mut stepping_secs = 0.0;
    for _ in 0..frames {
        let clock = web_time::Instant::now();
        instance
            .sim
            .step_frame()
            .map_err(|e| SceneError::Simulation { source_name: source.clone(), message: e.to_string() })?;
        stepping_secs += clock.elapsed().as_secs_f64();
        tip_z_m.push(probe_z(instance));
    }
    Ok(Recorded {
        motion: Motion { sample_secs: 1.0 / fps, tip_z_m },
        mean_ms_per_frame: 1e3 * stepping_secs / frames.max(1) as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn damped_cosine(period: f64, decay_per_sec: f64, secs: f64, dt: f64) -> Motion {
        let n = (secs / dt).round() as usize;
        let w = 2.0 * std::f64::consts::PI / period;
        let tip_z_m = (0..=n).map(|k| {
            let t = k as f64 * dt;
            -0.3 + 0.3 * (-decay_per_sec * t).exp() * (w * t).cos()
        });
        Motion { sample_secs: dt, tip_z_m: tip_z_m.collect() }
    }

    #[test]
    fn the_period_of_a_sampled_cosine_is_found_within_a_small_fraction_of_a_frame() {
        for period in [0.5, 0.87, 1.3] {
            let m = damped_cosine(period, 0.0, 2.6, 1.0 / 60.0).metrics();
            let found = m.period_secs.unwrap();
            assert!((found - period).abs() < 1e-3 * period, "period {period}: found {found}");
            let a = m.amplitude_m.unwrap();
            assert!((a - 0.3).abs() < 2e-3 * 0.3, "amplitude {a}");
        }
    }

    #[test]
    fn damping_shrinks_the_amplitude_around_two_seconds() {
        let undamped = damped_cosine(0.9, 0.0, 2.5, 1.0 / 60.0).metrics().amplitude_m.unwrap();
        let damped = damped_cosine(0.9, 0.5, 2.5, 1.0 / 60.0).metrics().amplitude_m.unwrap();
        // e^{-0.5 t} around t = 2 s: about 0.37
        assert!(damped < 0.45 * undamped && damped > 0.3 * undamped, "{damped} vs {undamped}");
    }

    #[test]
    fn a_short_or_still_motion_has_no_period_or_amplitude() {
        let still = Motion { sample_secs: 0.1, tip_z_m: vec![0.0; 5] };
        assert_eq!(still.metrics(), MotionMetrics { period_secs: None, amplitude_m: None });
    }

    #[test]
    fn a_broken_motion_file_is_refused_naming_the_problem() {
        let err = parse_motion(r#"{"sample_secs": 0.1, "tip_z_m": [0, "x", 1]}"#, "m.json").unwrap_err().to_string();
        assert!(err.contains("m.json") && err.contains("finite"), "{err}");
        let err = parse_motion(r#"{"tip_z_m": [0, 1, 2]}"#, "m.json").unwrap_err().to_string();
        assert!(err.contains("sample_secs"), "{err}");
    }

    /// The summary figures the reference file states are those of its own trace (a rerun of
    /// the example after a change of definition rewrites both).
    #[test]
    fn the_committed_reference_motion_states_the_metrics_of_its_own_trace() {
        let v: serde_json::Value = serde_json::from_str(REFERENCE_MOTION_JSON).unwrap();
        let m = reference_motion().unwrap().metrics();
        let stated = |key: &str| v[key].as_f64().unwrap_or_else(|| panic!("no {key}"));
        assert!((stated("period_secs") - m.period_secs.unwrap()).abs() < 1e-12, "{m:?}");
        assert!((stated("amplitude_m") - m.amplitude_m.unwrap()).abs() < 1e-12, "{m:?}");
        assert_eq!(stated("amplitude_at_secs"), AMPLITUDE_AT_SECS);
    }

    #[test]
    fn the_committed_reference_motion_reads_and_oscillates() {
        let m = reference_motion().unwrap();
        let metrics = m.metrics();
        assert!(metrics.period_secs.is_some_and(|t| t > 0.3 && t < 2.0), "{metrics:?}");
        assert!(metrics.amplitude_m.is_some_and(|a| a > 0.0));
    }
}
