//! Playing the simulation: play/pause and the time scale, and the clock that turns displayed
//! time into simulated frames (the model's [`super::action::Action::Tick`]; the clock itself is
//! the window's, passed in, never read here).

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
pub const SETTLE_STEP_BUDGET_MS: f64 = 50.0;
/// Wall time of stepping per displayed frame while playing, ms (at least 4 frames are stepped).
pub const PLAY_STEP_BUDGET_MS: f64 = 50.0;

impl Playback {
    pub fn new(playing: bool, time_scale: f64) -> Playback {
        Playback { playing, time_scale, frame_budget_secs: 0.0, last_clock_frame: false, was_settling: false }
    }

    /// Real time until the next frame of `frame_secs` is due, at the time scale.
    pub fn until_next_frame(&self, frame_secs: f64) -> std::time::Duration {
        let secs = (frame_secs - self.frame_budget_secs).max(0.0) / self.time_scale.max(1e-6);
        std::time::Duration::from_secs_f64(secs.min(frame_secs / self.time_scale.max(1e-6)).min(0.25))
    }

    /// The frames of `frame_secs` due after `real_dt_secs` of real time, each costing `step_ms`
    /// of stepping: as many as [`PLAY_STEP_BUDGET_MS`] of stepping allows, at least 4 (so a
    /// slow configuration slows down instead of freezing the window, and a cheap one keeps real
    /// time when the window draws slowly, as a page without a GPU does); the remainder, less
    /// than a frame, is kept for the next call.
    pub(super) fn frames_due(&mut self, real_dt_secs: f64, frame_secs: f64, step_ms: f64) -> usize {
        self.frame_budget_secs += real_dt_secs.min(0.25) * self.time_scale;
        let most = ((PLAY_STEP_BUDGET_MS / step_ms.max(1e-3)) as usize).max(4);
        let frames = ((self.frame_budget_secs / frame_secs).floor() as usize).min(most);
        self.frame_budget_secs = (self.frame_budget_secs - frames as f64 * frame_secs).min(frame_secs);
        frames
    }
}
