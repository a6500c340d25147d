//! The app's live Rerun output (streamed to a viewer or saved to an .rrd file) through the logging
//! module it shares with `hox record`.

use super::HoxApp;
use super::session::Session;
use crate::recording::{Configuration, LogSettings, Recorder};
use hox_sim::Vec3;
use std::path::PathBuf;

/// Live Rerun output through the shared logging module.
pub(super) struct RerunLink {
    rec: rerun::RecordingStream,
    recorder: Option<Recorder>,
    generation: u64,
    target: String,
}

impl RerunLink {
    /// Opens the recording `name`: saved to `file` if `to_file`, otherwise streamed to the viewer
    /// at `url`. The error is the message to show.
    fn start(name: String, to_file: bool, url: &str, file: &str) -> Result<RerunLink, String> {
        let builder = rerun::RecordingStreamBuilder::new("hox").recording_name(name);
        let (rec, target) = if to_file {
            let path = PathBuf::from(file);
            if let Err(e) = crate::output::check_writable(&path) {
                return Err(format!("Rerun: {e:#}"));
            }
            (builder.save(&path), format!("saving to {}", path.display()))
        } else {
            (builder.connect_grpc_opts(url.to_string()), format!("streaming to {url}"))
        };
        match rec {
            Ok(rec) => Ok(RerunLink { rec, recorder: None, generation: u64::MAX, target }),
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
    ) -> Result<(), rerun::RecordingStreamError> {
        if self.generation != generation || self.recorder.is_none() {
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
            let settings = LogSettings::new(&first.config);
            let fields = crate::display::fields(&first.config);
            self.recorder = Some(Recorder::new(&self.rec, &configs, &settings, &fields)?);
            self.generation = generation;
        }
        let instances: Vec<&hox_scenes::Instance> = sessions.iter().map(|s| &s.instance).collect();
        let ms: Vec<f64> = sessions.iter().map(|s| s.ms_per_frame).collect();
        if let Some(r) = &mut self.recorder {
            r.log_frame(&self.rec, &instances, &ms)?;
        }
        Ok(())
    }
}

impl HoxApp {
    /// Starts or stops live Rerun output: `to_file` saves to the .rrd path, otherwise streams to
    /// the viewer URL.
    pub fn set_rerun(&mut self, on: bool, to_file: bool) {
        if !on {
            if let Some(link) = self.rerun.take() {
                self.message = Some(link.stop());
            }
            return;
        }
        let name = format!("hox app {}", self.scene.label());
        match RerunLink::start(name, to_file, &self.rerun_url, &self.rerun_file) {
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

    /// Logs the sessions' current frame to the live link, if any; an error closes the link.
    pub(super) fn log_rerun(&mut self) {
        let offsets = self.offsets();
        let Some(link) = &mut self.rerun else { return };
        if let Err(e) = link.log(&self.sessions, &offsets, self.generation) {
            self.message = Some(format!("Rerun: {e}"));
            self.rerun = None;
        }
    }
}
