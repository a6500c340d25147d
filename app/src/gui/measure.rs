//! Frame-rate measurement: the running frame times the status line shows, and the
//! `--measure-secs` run that prints them with the frame counts as JSON and closes the window.

use super::HoxApp;
use eframe::egui;
use std::time::Instant;

/// Running averages of the displayed frames' times, milliseconds (the status line shows them).
#[derive(Default)]
pub(super) struct FrameTimes {
    /// Wall time between displayed frames, milliseconds.
    pub(super) ui_frame_ms: f64,
    /// Wall time of our own part of a frame (stepping, controls, viewport, plots), milliseconds.
    pub(super) app_ms: f64,
    /// CPU time of a whole frame (ours, egui's layout and painting; not waiting for vsync), ms.
    pub(super) frame_cpu_ms: f64,
    last_ui_frame: Option<Instant>,
}

impl FrameTimes {
    /// A displayed frame starts at `now`.
    pub(super) fn frame_started(&mut self, now: Instant) {
        let dt = self.last_ui_frame.map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.last_ui_frame = Some(now);
        if dt > 0.0 {
            self.ui_frame_ms = if self.ui_frame_ms == 0.0 { dt * 1e3 } else { 0.9 * self.ui_frame_ms + 0.1 * dt * 1e3 };
        }
    }

    /// Our own part of a frame took `ms`.
    pub(super) fn app_part(&mut self, ms: f64) {
        smooth(&mut self.app_ms, ms);
    }

    /// A whole frame took `ms` of CPU time.
    pub(super) fn whole_frame_cpu(&mut self, ms: f64) {
        smooth(&mut self.frame_cpu_ms, ms);
    }
}

/// Folds `ms` into the running average `average` (0: none yet).
fn smooth(average: &mut f64, ms: f64) {
    *average = if *average == 0.0 { ms } else { 0.9 * *average + 0.1 * ms };
}

/// Frame-rate measurement for `--measure-secs`.
pub(super) struct Measure {
    until_secs: f64,
    started: Option<Instant>,
    frames: u64,
    pub(super) sim_frames: u64,
    frame_ms: Vec<f64>,
    last: Option<Instant>,
}

impl Measure {
    /// A measurement of `until_secs` seconds, starting at the first frame.
    pub(super) fn new(until_secs: f64) -> Measure {
        Measure { until_secs, started: None, frames: 0, sim_frames: 0, frame_ms: Vec::new(), last: None }
    }
}

impl HoxApp {
    /// Measurement bookkeeping after a frame: once `--measure-secs` have passed, prints the
    /// measurement and closes the window (unless a screenshot is still to be taken).
    pub(super) fn measure_after_frame(&mut self, ctx: &egui::Context, now: Instant) {
        if let Some(m) = &mut self.measure {
            let started = *m.started.get_or_insert(now);
            if let Some(last) = m.last {
                m.frame_ms.push(now.duration_since(last).as_secs_f64() * 1e3);
            }
            m.last = Some(now);
            m.frames += 1;
            let secs = now.duration_since(started).as_secs_f64();
            if secs >= m.until_secs {
                let mut ms = m.frame_ms.clone();
                let median = hox_scenes::median(&mut ms);
                let s = &self.sessions[0];
                println!(
                    "{}",
                    serde_json::json!({
                        "configuration": s.label(),
                        "seconds": secs,
                        "display_frames": m.frames,
                        "display_fps": m.frames as f64 / secs,
                        "median_display_frame_ms": median,
                        "sim_frames": m.sim_frames,
                        "sim_ms_per_frame": s.ms_per_frame,
                        "render_ms": self.viewport.render_ms,
                        "app_ms": self.times.app_ms,
                        "frame_cpu_ms": self.times.frame_cpu_ms,
                        "window_points": ctx.input(|i| i.viewport().inner_rect.map(|r| [r.width(), r.height()])),
                        "pixels_per_point": ctx.pixels_per_point(),
                        "renderer": self.renderer,
                        "feathering": ctx.tessellation_options(|o| o.feathering),
                    })
                );
                if self.screenshot.is_none() {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
                self.measure = None;
            }
            ctx.request_repaint();
        }
    }
}
