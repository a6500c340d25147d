//! The app's live Rerun output (streamed to a viewer, saved to an .rrd file, or served to the
//! class's browsers with the Rerun web viewer: `web.rs`) through the logging module it shares
//! with `hox record`. While a lesson is open its step text (question, numbers, answer once
//! revealed) is logged to `lesson/step` and shown above the legend.

use super::HoxApp;
use super::session::Session;
use crate::recording::{Configuration, LogSettings, Recorder};
use hox_sim::Vec3;
use std::path::PathBuf;

/// Where the live output goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RerunTarget {
    /// A running Rerun viewer at the URL of the Rerun section.
    Viewer,
    /// The .rrd file of the Rerun section.
    File,
    /// The class's browsers: the web viewer served on the addresses of `--bind` and the ports.
    Browsers,
}

/// Live Rerun output through the shared logging module.
pub(super) struct RerunLink {
    rec: rerun::RecordingStream,
    recorder: Option<Recorder>,
    generation: u64,
    target: String,
    /// The web viewer's server when serving browsers (its page's URL is `web.url`).
    web: Option<crate::web::WebServer>,
    /// The lesson text logged last (logged again only when it changes).
    lesson_text: Option<String>,
}

impl RerunLink {
    /// Opens the recording `name` for `target`. The error is the message to show.
    fn start(
        name: String,
        target: RerunTarget,
        url: &str,
        file: &str,
        serve: &crate::web::ServeArgs,
    ) -> Result<RerunLink, String> {
        let builder = rerun::RecordingStreamBuilder::new("hox").recording_name(name.clone());
        let mut web = None;
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
            Ok(rec) => Ok(RerunLink { rec, recorder: None, generation: u64::MAX, target, web, lesson_text: None }),
            Err(e) => Err(format!("Rerun: {e}")),
        }
    }

    /// Flushes what is still buffered and closes the link; the message to show.
    fn stop(self) -> String {
        let _ = self.rec.flush_blocking();
        format!("Rerun: stopped ({})", self.target)
    }

    /// Logs the current frame of `sessions` (drawn at `offsets`), preceded by their static data
    /// when `generation` is not the one logged last (something was rebuilt).
    fn log(
        &mut self,
        sessions: &[Session],
        offsets: &[Vec3],
        generation: u64,
        lesson_text: Option<String>,
    ) -> Result<(), rerun::RecordingStreamError> {
        let lesson_changed = lesson_text.is_some() != self.lesson_text.is_some();
        if self.generation != generation || self.recorder.is_none() || lesson_changed {
            let configs: Vec<Configuration<'_>> = sessions
                .iter()
                .zip(offsets)
                .enumerate()
                .map(|(k, (s, o))| Configuration {
                    name: format!("{}_{}", ["a", "b"][k.min(1)], s.label()),
                    instance: &s.instance,
                    offset_m: *o,
                    reference: s.reference.reference(),
                })
                .collect();
            let Some(first) = sessions.first() else { return Ok(()) };
            let mut settings = LogSettings::new(&first.config);
            settings.lesson_text = lesson_text.is_some();
            let fields = crate::display::fields(&first.config);
            self.recorder = Some(Recorder::new(&self.rec, &configs, &settings, &fields)?);
            self.generation = generation;
        }
        let instances: Vec<&hox_scenes::Instance> = sessions.iter().map(|s| &s.instance).collect();
        let ms: Vec<f64> = sessions.iter().map(|s| s.ms_per_frame).collect();
        if let Some(r) = &mut self.recorder {
            r.log_frame(&self.rec, &instances, &ms)?;
        }
        if lesson_text != self.lesson_text {
            if let Some(text) = &lesson_text {
                self.rec.log("lesson/step", &rerun::TextDocument::from_markdown(text.as_str()))?;
            }
            self.lesson_text = lesson_text;
        }
        Ok(())
    }
}

impl HoxApp {
    /// Starts live Rerun output to `target` (stopping any), or stops it (`None`).
    pub fn set_rerun(&mut self, target: Option<RerunTarget>) {
        if let Some(link) = self.rerun.take() {
            self.message = Some(link.stop());
        }
        let Some(target) = target else { return };
        let name = format!("hox app {}", self.scene.label());
        match RerunLink::start(name, target, &self.rerun_url, &self.rerun_file, &self.serve) {
            Ok(link) => {
                self.message = Some(format!("Rerun: {}", link.target));
                self.rerun = Some(link);
                self.log_rerun();
            }
            Err(message) => self.message = Some(message),
        }
    }

    pub fn rerun_target(&self) -> Option<&str> {
        self.rerun.as_ref().map(|l| l.target.as_str())
    }

    /// The page the class's browsers open, while serving them.
    pub fn web_url(&self) -> Option<&str> {
        self.rerun.as_ref().and_then(|l| l.web.as_ref()).map(|w| w.url.as_str())
    }

    /// Logs the sessions' current frame to the live link, if any; an error closes the link.
    pub(super) fn log_rerun(&mut self) {
        let offsets = self.offsets();
        let lesson_text = self.lesson.as_ref().map(|l| l.step_markdown(&self.sessions));
        let Some(link) = &mut self.rerun else { return };
        if let Err(e) = link.log(&self.sessions, &offsets, self.generation, lesson_text) {
            self.message = Some(format!("Rerun: {e}"));
            self.rerun = None;
        }
    }
}
