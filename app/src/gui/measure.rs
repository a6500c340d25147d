//! The app's clock and measurements: the running frame times the status line shows, the
//! `--measure-secs` run that prints them with the frame counts as JSON and closes the window, and
//! the `--screenshot` taken some seconds after the start.

use web_time::Instant;

/// Running averages of the displayed frames' times, milliseconds (the status line shows them).
#[derive(Default)]
pub struct FrameTimes {
    /// Wall time between displayed frames, milliseconds.
    pub ui_frame_ms: f64,
    /// Wall time of our own part of a frame (stepping, controls, viewport, plots), milliseconds.
    pub app_ms: f64,
    /// CPU time of a whole frame (ours, egui's layout and painting; not waiting for vsync), ms.
    pub frame_cpu_ms: f64,
    last_ui_frame: Option<Instant>,
}

impl FrameTimes {
    /// A displayed frame starts at `now`.
    pub fn frame_started(&mut self, now: Instant) {
        let dt = self.last_ui_frame.map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.last_ui_frame = Some(now);
        if dt > 0.0 {
            self.ui_frame_ms = if self.ui_frame_ms == 0.0 { dt * 1e3 } else { 0.9 * self.ui_frame_ms + 0.1 * dt * 1e3 };
        }
    }

    /// Our own part of a frame took `ms`.
    pub fn app_part(&mut self, ms: f64) {
        smooth(&mut self.app_ms, ms);
    }

    /// A whole frame took `ms` of CPU time.
    pub fn whole_frame_cpu(&mut self, ms: f64) {
        smooth(&mut self.frame_cpu_ms, ms);
    }
}

/// Folds `ms` into the running average `average` (0: none yet).
fn smooth(average: &mut f64, ms: f64) {
    *average = if *average == 0.0 { ms } else { 0.9 * *average + 0.1 * ms };
}

/// Frame-rate measurement for `--measure-secs`.
pub struct Measure {
    until_secs: f64,
    started: Option<Instant>,
    frames: u64,
    /// The model's frames stepped when the measurement started.
    sim_frames_at_start: Option<u64>,
    frame_ms: Vec<f64>,
    last: Option<Instant>,
}

/// A finished measurement.
pub struct Measured {
    pub seconds: f64,
    pub display_frames: u64,
    pub median_display_frame_ms: f64,
    pub sim_frames: u64,
}

impl Measure {
    /// A measurement of `until_secs` seconds, starting at the first frame.
    pub fn new(until_secs: f64) -> Measure {
        Measure { until_secs, started: None, frames: 0, sim_frames_at_start: None, frame_ms: Vec::new(), last: None }
    }

    /// A displayed frame ended at `now` with `frames_stepped` simulated frames stepped since the
    /// start (the model's count); the measurement once its seconds have passed.
    pub fn after_frame(&mut self, now: Instant, frames_stepped: u64) -> Option<Measured> {
        let started = *self.started.get_or_insert(now);
        let at_start = *self.sim_frames_at_start.get_or_insert(frames_stepped);
        if let Some(last) = self.last {
            self.frame_ms.push(now.duration_since(last).as_secs_f64() * 1e3);
        }
        self.last = Some(now);
        self.frames += 1;
        let seconds = now.duration_since(started).as_secs_f64();
        (seconds >= self.until_secs).then(|| Measured {
            seconds,
            display_frames: self.frames,
            median_display_frame_ms: hox_scenes::median(&mut self.frame_ms.clone()),
            sim_frames: frames_stepped - at_start,
        })
    }
}

/// A screenshot to save some seconds after the start (`--screenshot`); the window closes then.
pub struct Screenshot {
    pub path: std::path::PathBuf,
    pub after_secs: f64,
    /// When the app started.
    pub started: Instant,
    pub requested: bool,
}

impl Screenshot {
    pub fn new(path: std::path::PathBuf, after_secs: f64) -> Screenshot {
        Screenshot { path, after_secs, started: Instant::now(), requested: false }
    }
}
