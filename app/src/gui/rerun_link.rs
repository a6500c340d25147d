//! The app's live Rerun output (streamed to a viewer, saved to an .rrd file, or served to the
//! class's browsers with the Rerun web viewer: `web.rs`) through the logging module it shares
//! with `hox record`. While a lesson is open its step text (question, numbers, answer once
//! revealed) is logged to `lesson/step` and shown above the legend.
//!
//! Served to browsers, the stream carries at most `--serve-fps` frames a second ([`FrameCap`];
//! 30 by default against the 60 the app simulates): every browser is sent every frame, so the
//! classroom network carries the frame rate times the class (the P2 beam: about 10 Mbit/s per
//! browser at 30 frames; docs/WEB.md). A frame held back while playing is
//! replaced by a later one; the one the app stops on (pause, the end of a settle) is always
//! sent, as are rebuilds (a lesson's new step is one) at once. While the app is paused a change
//! of the lesson's text (the answer revealed) is sent as it happens.
//!
//! The stream runs on across rebuilds: new configurations start after the frames logged, the
//! old ones are cleared there, and what they logged that the new ones do not (their static
//! rest shapes, chart lines, colour bars) is retired at every time (`recording/retire.rs`), so a
//! page following the stream shows only what the app shows. An .rrd file saved from the app
//! therefore keeps, of a configuration gone, only what is logged under a name still in use.

use super::action::RerunTarget;
use super::model::Model;
use super::session::Session;
use crate::recording::{Configuration, LogSettings, Recorder};
use hox_sim::Vec3;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Live Rerun output through the shared logging module.
struct RerunLink {
    rec: rerun::RecordingStream,
    recorder: Option<Recorder>,
    generation: u64,
    target: String,
    /// The web viewer's server when serving browsers (its page's URL is `web.url`).
    web: Option<crate::web::WebServer>,
    /// The lesson text logged last (logged again only when it changes).
    lesson_text: Option<String>,
    /// The bound on the frames sent per second (browsers only).
    cap: Option<FrameCap>,
    /// The simulation frame of the first configuration logged last, and how many were.
    last_logged_frame: Option<u64>,
    frames_logged: u64,
    /// Added to the configurations' own frame and time (`frame`, `sim_time`): the stream's clock
    /// never goes back when new configurations start from t = 0 (a lesson's next step, a new
    /// mesh, a reset), so that a browser following its latest time shows only what runs now.
    time_offset: (i64, f64),
    /// The stream's latest frame and time logged (with the offset).
    logged_until: Option<(i64, f64)>,
    /// Streamed to a viewer or browsers (not saved to a file).
    live: bool,
    /// Configuration entity names retired in this stream: their static empties shadow whatever
    /// is logged there later at every time, so a configuration coming back under such a name
    /// (a lesson's step repeating an earlier step's beam) is streamed under a fresh one.
    retired_names: std::collections::HashSet<String>,
}

/// At most so many frames a second: a frame is admitted when the one admitted before it is
/// at least nine tenths of the interval old (so that 60 simulated frames a second capped at 30
/// send every other one despite the paints' jitter); the others are held back, and the link
/// remembers that the newest frame is still unsent ([`FrameCap::pending`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct FrameCap {
    interval: Duration,
    last: Option<Instant>,
    /// A frame was held back and none admitted since.
    pub pending: bool,
}

impl FrameCap {
    /// `fps` frames a second at most; `None` (every frame) for 0.
    pub fn new(fps: u32) -> Option<FrameCap> {
        (fps > 0).then(|| FrameCap { interval: Duration::from_secs(1) / fps, last: None, pending: false })
    }

    /// Whether the frame at `now` is sent; a frame held back is remembered as pending.
    pub fn admit(&mut self, now: Instant) -> bool {
        let due = self.last.is_none_or(|last| now.saturating_duration_since(last) >= self.interval.mul_f64(0.9));
        if due {
            self.sent(now);
        } else {
            self.pending = true;
        }
        due
    }

    /// A frame was sent at `now` whatever the cap (a rebuild, a lesson step, the last frame).
    pub fn sent(&mut self, now: Instant) {
        self.last = Some(now);
        self.pending = false;
    }
}

impl RerunLink {
    /// Opens the recording `name` for `target`. The error is the message to show.
    fn start(
        name: String,
        target: RerunTarget,
        url: &str,
        file: &str,
        serve: &crate::web::ServeArgs,
        serve_fps: u32,
    ) -> Result<RerunLink, String> {
        let builder = rerun::RecordingStreamBuilder::new("hox").recording_name(name.clone());
        let mut web = None;
        let cap = if target == RerunTarget::Browsers { FrameCap::new(serve_fps) } else { None };
        let live = target != RerunTarget::File;
        let (rec, target) = match target {
            RerunTarget::File => {
                let path = PathBuf::from(file);
                if let Err(e) = crate::output::check_writable(&path) {
                    return Err(format!("Rerun: {e:#}"));
                }
                (builder.save(&path).map_err(|e| e.to_string()), format!("saving to {}", path.display()))
            }
            RerunTarget::Viewer => {
                (builder.connect_grpc_opts(url.to_string()).map_err(|e| e.to_string()), format!("streaming to {url}"))
            }
            RerunTarget::Browsers => {
                let (rec, server) = crate::web::serve_recording(&name, serve).map_err(|e| format!("{e:#}"))?;
                let target = format!("serving browsers at {}", server.url);
                web = Some(server);
                (Ok(rec), target)
            }
        };
        match rec {
            Ok(rec) => Ok(RerunLink {
                rec,
                recorder: None,
                generation: u64::MAX,
                target,
                web,
                lesson_text: None,
                cap,
                last_logged_frame: None,
                frames_logged: 0,
                time_offset: (0, 0.0),
                logged_until: None,
                live,
                retired_names: Default::default(),
            }),
            Err(e) => Err(format!("Rerun: {e}")),
        }
    }

    /// Flushes what is still buffered and closes the link; the message to show.
    fn stop(self) -> String {
        let _ = self.rec.flush_blocking();
        format!("Rerun: stopped ({})", self.target)
    }

    /// Whether a frame held back by the cap is still unsent.
    fn pending(&self) -> bool {
        self.cap.is_some_and(|c| c.pending)
    }

    /// Logs the current frame of `sessions` (drawn at `offsets`), preceded by their static data
    /// when `generation` is not the one logged last (something was rebuilt). Held back by the
    /// cap unless `force`d or something was rebuilt (a lesson's new step is).
    fn log(
        &mut self,
        sessions: &[Session],
        offsets: &[Vec3],
        generation: u64,
        lesson_text: Option<String>,
        force: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        let lesson_changed = lesson_text.is_some() != self.lesson_text.is_some();
        let rebuilt = self.generation != generation || self.recorder.is_none() || lesson_changed;
        if let Some(cap) = &mut self.cap {
            let now = Instant::now();
            if force || rebuilt {
                cap.sent(now);
            } else if !cap.admit(now) {
                return Ok(());
            }
        }
        let mut retired = None;
        if rebuilt {
            let configs: Vec<Configuration<'_>> = sessions
                .iter()
                .zip(offsets)
                .enumerate()
                .map(|(k, (s, o))| Configuration {
                    name: fresh_name(&self.retired_names, &format!("{}_{}", ["a", "b"][k.min(1)], s.label())),
                    instance: &s.instance,
                    offset_m: *o,
                    reference: s.reference.reference(),
                })
                .collect();
            let Some(first) = sessions.first() else { return Ok(()) };
            // issue #57: after → to the next lesson step, the page drew the last step's beams
            // over the new ones. The new configurations start after what was logged (their clock
            // from 0 would fall inside the old ones' time), and the old ones end there.
            let own = (first.instance.sim.frames() as i64, first.instance.sim.time_secs());
            if let Some(until) = self.logged_until
                && own.0 + self.time_offset.0 < until.0
            {
                let frame_secs = 1.0 / first.config.frames_per_second;
                self.time_offset = (until.0 + 1 - own.0, until.1 + frame_secs - own.1);
            }
            if let Some(old) = &self.recorder {
                self.rec.set_time_sequence("frame", own.0 + self.time_offset.0);
                self.rec.set_duration_secs("sim_time", own.1 + self.time_offset.1);
                old.clear(&self.rec)?;
            }
            let mut settings = LogSettings::new(&first.config);
            settings.time_offset = self.time_offset;
            settings.lesson_text = lesson_text.is_some();
            // a viewer or a browser opened late starts at the present, not at t = 0
            settings.follow_latest = self.live;
            let fields = crate::display::fields(&first.config);
            retired = self.recorder.replace(Recorder::new(&self.rec, &configs, &settings, &fields)?);
            self.generation = generation;
        }
        let instances: Vec<&hox_scenes::Instance> = sessions.iter().map(|s| &s.instance).collect();
        let ms: Vec<f64> = sessions.iter().map(|s| s.ms_per_frame).collect();
        if let Some(r) = &mut self.recorder {
            r.log_frame(&self.rec, &instances, &ms)?;
            // what the last configurations logged (static data, chart lines) and the new ones
            // do not, hidden at every time: the clear above hides only the rest, after it
            if let Some(old) = &retired {
                old.retire(&self.rec, r)?;
                let kept = r.names();
                let gone = old.names().into_iter().filter(|n| !kept.contains(n)).map(str::to_string);
                self.retired_names.extend(gone.collect::<Vec<_>>());
            }
        }
        self.last_logged_frame = sessions.first().map(|s| s.instance.sim.frames());
        if let Some(first) = sessions.first() {
            let now = (
                first.instance.sim.frames() as i64 + self.time_offset.0,
                first.instance.sim.time_secs() + self.time_offset.1,
            );
            self.logged_until = Some(self.logged_until.map_or(now, |u| (u.0.max(now.0), u.1.max(now.1))));
        }
        self.frames_logged += 1;
        if lesson_text != self.lesson_text {
            if let Some(text) = &lesson_text {
                self.rec.log("lesson/step", &rerun::TextDocument::from_markdown(text.as_str()))?;
            }
            self.lesson_text = lesson_text;
        }
        Ok(())
    }
}

/// The entity name of configuration `label` in a stream that retired `retired`: the label's
/// own, or with the first suffix `_2`, `_3`, … not retired (regression: the locking lesson's
/// cure step repeats step 2's B and step 3's A, and drew no chart line of its own;
/// `gui::tests::a_browser_following_a_lesson_shows_only_the_current_step_s_bodies`).
fn fresh_name(retired: &std::collections::HashSet<String>, label: &str) -> String {
    let base = crate::recording::entity_name(label);
    (1..)
        .map(|k| if k == 1 { base.clone() } else { format!("{base}_{k}") })
        .find(|n| !retired.contains(n))
        .unwrap_or(base)
}

/// The live Rerun output as a service of the app: at most one link open, fed the model's frames.
pub struct Rerun {
    link: Option<RerunLink>,
    /// Where the class's browsers are served (`--bind`, the ports, the history bound).
    serve: crate::web::ServeArgs,
    /// `--serve-fps`: frames a second sent to browsers at most (0: every frame).
    serve_fps: u32,
}

impl Rerun {
    pub fn new(serve: crate::web::ServeArgs, serve_fps: u32) -> Rerun {
        Rerun { link: None, serve, serve_fps }
    }

    /// Starts live output of `model` to `target` (stopping any), or stops it (`None`), the viewer's
    /// URL and the file as given; the message to show.
    pub fn set(&mut self, target: Option<RerunTarget>, model: &Model, url: &str, file: &str) -> Option<String> {
        let stopped = self.link.take().map(RerunLink::stop);
        let Some(target) = target else { return stopped };
        let name = format!("hox app {}", model.scene().label());
        match RerunLink::start(name, target, url, file, &self.serve, self.serve_fps) {
            Ok(link) => {
                let started = format!("Rerun: {}", link.target);
                self.link = Some(link);
                Some(self.log(model).unwrap_or(started))
            }
            Err(e) => Some(e),
        }
    }

    pub fn is_open(&self) -> bool {
        self.link.is_some()
    }

    pub fn target(&self) -> Option<&str> {
        self.link.as_ref().map(|l| l.target.as_str())
    }

    /// The page the class's browsers open, while serving them.
    pub fn web_url(&self) -> Option<&str> {
        self.link.as_ref().and_then(|l| l.web.as_ref()).map(|w| w.url.as_str())
    }

    /// The address browsers are served on.
    pub fn bind(&self) -> String {
        self.serve.bind.to_string()
    }

    /// Logs the model's current frame to the link, if any (browsers: unless the frame cap holds
    /// it back); an error closes the link and is returned.
    pub fn log(&mut self, model: &Model) -> Option<String> {
        self.link.as_ref()?;
        self.log_now(model, false, model.lesson_text())
    }

    /// While the model is not playing (paused, a settle ended), sends the frame the cap held back
    /// last, and the lesson's text when it changed (the answer revealed): called after each
    /// frame's steps, so browsers always end on what the app shows.
    pub fn flush(&mut self, model: &Model) -> Option<String> {
        if model.playing() {
            return None;
        }
        let link = self.link.as_ref()?;
        let text = model.lesson_text();
        if link.pending() || text != link.lesson_text { self.log_now(model, true, text) } else { None }
    }

    fn log_now(&mut self, model: &Model, force: bool, lesson_text: Option<String>) -> Option<String> {
        let link = self.link.as_mut()?;
        let offsets = model.offsets();
        match link.log(model.sessions(), &offsets, model.generation(), lesson_text, force) {
            Ok(()) => None,
            Err(e) => {
                self.link = None;
                Some(format!("Rerun: {e}"))
            }
        }
    }

    /// The entity names (`world/<name>`) the open link streams the configurations on screen
    /// under, in order (the UI tests read them).
    #[cfg(test)]
    pub fn streamed_names(&self) -> Vec<String> {
        let recorder = self.link.as_ref().and_then(|l| l.recorder.as_ref());
        recorder.map(|r| r.names().into_iter().map(str::to_string).collect()).unwrap_or_default()
    }

    /// What the open link sent (the UI tests read it).
    #[cfg(test)]
    pub fn sent(&self) -> Option<Sent> {
        self.link.as_ref().map(|l| Sent {
            frames_logged: l.frames_logged,
            last_logged_frame: l.last_logged_frame,
            pending: l.pending(),
            lesson_text: l.lesson_text.clone(),
        })
    }
}

/// What a link sent: how many frames, the first configuration's frame logged last, whether a
/// frame is held back, the lesson text logged last.
#[cfg(test)]
pub struct Sent {
    pub frames_logged: u64,
    pub last_logged_frame: Option<u64>,
    pub pending: bool,
    pub lesson_text: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_cap_sends_every_other_frame_of_sixty_at_thirty_despite_jitter_and_remembers_the_one_held_back() {
        let start = Instant::now();
        let mut cap = FrameCap::new(30).unwrap();
        // 60 frames a second, each paint up to 3 ms early or late
        let jitter = [0.0, 3.0, -3.0, 2.0, -2.0, 1.0, -1.0, 3.0, -3.0, 0.0];
        let sent: Vec<bool> = (0..60)
            .map(|k| {
                let ms = k as f64 * 1000.0 / 60.0 + jitter[k % jitter.len()];
                cap.admit(start + Duration::from_secs_f64(ms.max(0.0) / 1000.0))
            })
            .collect();
        assert_eq!(sent.iter().filter(|&&s| s).count(), 30, "{sent:?}");
        assert!(sent.iter().step_by(2).all(|&s| s), "every other frame: {sent:?}");
        assert!(cap.pending, "the 60th frame was held back");
        cap.sent(start + Duration::from_secs(1));
        assert!(!cap.pending);
        assert!(FrameCap::new(0).is_none(), "0: every frame");
    }

    #[test]
    fn a_frame_sent_out_of_turn_restarts_the_interval() {
        let start = Instant::now();
        let mut cap = FrameCap::new(10).unwrap();
        assert!(cap.admit(start));
        cap.sent(start + Duration::from_millis(50)); // a rebuild
        assert!(!cap.admit(start + Duration::from_millis(120)), "70 ms after the rebuild's frame");
        assert!(cap.admit(start + Duration::from_millis(150)));
    }
}
