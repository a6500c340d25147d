//! Playing the simulation: play/pause and the time scale, the clock that turns displayed time
//! into simulated frames, the keyboard shortcuts, and stepping on a background thread while the
//! window paints.

use super::HoxApp;
use super::session::Session;
use eframe::egui;

/// Playing or paused, how fast, and the clock's remainder.
pub struct Playback {
    pub playing: bool,
    /// Simulated seconds per real second.
    pub time_scale: f64,
    /// Simulated time owed but not yet stepped, seconds.
    pub(super) frame_budget_secs: f64,
    /// A frame has been shown (the first frame's clock step is not a real interval).
    pub(super) last_clock_frame: bool,
    /// A *Settle* was under way at the last frame (it pauses when it ends).
    pub(super) was_settling: bool,
}

/// Wall time of stepping per displayed frame while settling, ms.
const SETTLE_STEP_BUDGET_MS: f64 = 50.0;

impl Playback {
    pub(super) fn new(playing: bool, time_scale: f64) -> Playback {
        Playback { playing, time_scale, frame_budget_secs: 0.0, last_clock_frame: false, was_settling: false }
    }

    /// Real time until the next frame of `frame_secs` is due, at the time scale.
    pub(super) fn until_next_frame(&self, frame_secs: f64) -> std::time::Duration {
        let secs = (frame_secs - self.frame_budget_secs).max(0.0) / self.time_scale.max(1e-6);
        std::time::Duration::from_secs_f64(secs.min(frame_secs / self.time_scale.max(1e-6)).min(0.25))
    }

    /// The frames of `frame_secs` due after `real_dt_secs` of real time (at most 4); the
    /// remainder, less than a frame, is kept for the next call.
    fn frames_due(&mut self, real_dt_secs: f64, frame_secs: f64) -> usize {
        self.frame_budget_secs += real_dt_secs.min(0.25) * self.time_scale;
        let frames = ((self.frame_budget_secs / frame_secs).floor() as usize).min(4);
        self.frame_budget_secs = (self.frame_budget_secs - frames as f64 * frame_secs).min(frame_secs);
        frames
    }
}

impl HoxApp {
    /// Steps the frames `advance` deferred on a background thread, so that the simulation runs
    /// while the window paints (the paint is the longer part of a frame with a software renderer;
    /// docs/APP.md). The next frame starts by taking the sessions back.
    pub(super) fn start_background_step(&mut self) {
        let frames = std::mem::take(&mut self.deferred_frames);
        if frames == 0 || self.background.is_some() || self.sessions.is_empty() {
            return;
        }
        let mut sessions = std::mem::take(&mut self.sessions);
        let one_at_a_time = self.lesson_times_frames();
        let handle = std::thread::spawn(move || {
            let was_settling = any_settling(&sessions);
            for _ in 0..frames {
                // a settle that ends stops there, at rest (as [`HoxApp::step`])
                if was_settling && !any_settling(&sessions) {
                    break;
                }
                step_sessions(&mut sessions, one_at_a_time);
            }
            sessions
        });
        self.background = Some((handle, frames));
    }

    /// Takes back the sessions stepped in the background (no-op if none are).
    pub fn join_background(&mut self) {
        let Some((handle, frames)) = self.background.take() else { return };
        match handle.join() {
            Ok(sessions) => self.sessions = sessions,
            Err(panic) => std::panic::resume_unwind(panic),
        }
        if let Some(m) = &mut self.measure {
            m.sim_frames += frames as u64;
        }
    }

    /// Steps now, or after the UI is built when the window can overlap stepping with painting
    /// (not with a live Rerun link, which logs every frame in order).
    fn step_or_defer(&mut self, frames: usize) {
        if self.gl_available && self.rerun.is_none() {
            self.deferred_frames += frames;
        } else {
            self.step(frames);
        }
    }

    /// Keyboard shortcuts (when no text field has the keyboard).
    pub(super) fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (space, s, r, e) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::Space),
                i.key_pressed(egui::Key::S),
                i.key_pressed(egui::Key::R),
                i.key_pressed(egui::Key::E),
            )
        });
        // camera presets 1–4, and F for the next field
        let keys = [egui::Key::Num1, egui::Key::Num2, egui::Key::Num3, egui::Key::Num4];
        let preset = keys.iter().position(|k| ctx.input(|i| i.key_pressed(*k)));
        if let Some(k) = preset {
            self.set_camera(super::viewport::ViewPreset::ALL[k]);
        }
        if ctx.input(|i| i.key_pressed(egui::Key::F)) {
            self.next_field();
        }
        if e {
            self.settle();
        }
        if space {
            self.playback.playing = !self.playback.playing;
        }
        if s {
            self.playback.playing = false;
            self.step(1);
        }
        if r {
            self.reset();
        }
    }

    /// Steps as much simulated time as passed in real time × time scale (at most 4 frames per
    /// displayed frame, so a slow configuration slows down instead of freezing the window).
    /// How long to wait before painting the next frame while playing ([`HoxApp::pace_paint`]):
    /// until the next simulated frame is due; None (paint at once) when pacing is off, while
    /// settling (as many frames as the CPU allows) or measuring the frame rate.
    pub(super) fn paint_pace(&self) -> Option<std::time::Duration> {
        if !self.pace_paint || self.settling() || self.measure.is_some() || self.sessions.is_empty() {
            return None;
        }
        Some(self.playback.until_next_frame(1.0 / self.sessions[0].config.frames_per_second))
    }

    pub(super) fn advance(&mut self, real_dt_secs: f64) {
        self.playback.was_settling |= self.settling();
        if !self.playback.playing || self.sessions.iter().all(|s| s.failure.is_some()) {
            self.playback.frame_budget_secs = 0.0;
            return;
        }
        let frame_secs = 1.0 / self.sessions[0].config.frames_per_second;
        if self.settling() {
            // settling: as many frames as about 50 ms of stepping allows, whatever the time scale
            let ms = self.sessions.iter().map(|s| s.ms_per_frame).fold(0.0, f64::max).max(0.05);
            self.step_or_defer(((SETTLE_STEP_BUDGET_MS / ms) as usize).clamp(1, 400));
            return;
        }
        if self.sessions.iter().any(|s| s.settle_outcome.is_some()) && self.playback.was_settling {
            // the settle just ended: show the state it reached
            self.playback.was_settling = false;
            self.playback.playing = false;
            return;
        }
        if self.measure.is_some() {
            // measuring: one simulation frame per displayed frame
            self.step_or_defer(1);
            return;
        }
        let mut frames = self.playback.frames_due(real_dt_secs, frame_secs);
        // a lesson step that plays some seconds ends on its last frame exactly, as `hox lesson`
        if let Some(left) = self.lesson_frames_left(frame_secs) {
            frames = frames.min(left);
        }
        self.step_or_defer(frames);
    }
}

/// Whether a *Settle* is under way in any of `sessions`.
pub(super) fn any_settling(sessions: &[Session]) -> bool {
    sessions.iter().any(|s| s.settler.is_some())
}

/// One frame of every session: in parallel in compare mode, unless `one_at_a_time` (a lesson
/// timing frames: each configuration then has the cores to itself, as in `hox lesson`). While a
/// *Settle* is under way, a configuration that has settled waits at rest for the other (issue
/// #35: it ran on undamped and read other numbers than `hox lesson`).
pub(super) fn step_sessions(sessions: &mut [Session], one_at_a_time: bool) {
    use rayon::prelude::*;
    let settling = any_settling(sessions);
    let step = |s: &mut Session| {
        if !settling || s.settler.is_some() {
            s.step(1);
        }
    };
    if one_at_a_time || sessions.len() == 1 {
        sessions.iter_mut().for_each(step);
    } else {
        sessions.par_iter_mut().for_each(step);
    }
}
