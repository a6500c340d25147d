//! [`HoxApp`]: the model ([`Model`]), the UI's state ([`UiState`]) and the services — the live
//! Rerun link, the frame clock and measurements, the window's renderer — and the one place a
//! [`Command`] is carried out: an action goes to the model (every frame stepped in place is logged
//! to the Rerun link), a service's request to its service, whose outcome the model is told. The
//! window's frame itself is `window.rs`.

use super::action::{Action, Command, Commands};
use super::args::{self, AppArgs};
use super::background::{Background, platform_stepper};
use super::config::SceneSource;
use super::measure::{FrameTimes, Measure, Screenshot};
use super::model::{Model, Start};
use super::persist::Persisted;
#[cfg(target_arch = "wasm32")]
use super::platform::page::Rerun;
#[cfg(not(target_arch = "wasm32"))]
use super::rerun_link::Rerun;
use super::ui_state::{Status, UiState};
use super::viewport::Viewport;

/// The group of a dropped mesh file that is held (the Open dialog's default).
pub const MESH_CLAMP_GROUP: &str = "clamp";

/// The app: the model, the UI's state and the services.
pub struct HoxApp {
    pub(super) model: Model,
    pub(super) ui: UiState,
    pub(super) rerun: Rerun,
    pub(super) times: FrameTimes,
    pub(super) measure: Option<Measure>,
    pub(super) screenshot: Option<Screenshot>,
    /// The window has an OpenGL context (false in the headless UI tests).
    pub(super) gl_available: bool,
    /// The OpenGL renderer's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"), if known.
    pub(super) renderer: Option<String>,
    /// While playing, paint when the next simulated frame is due instead of at once: set for a
    /// software renderer (no vertical sync paces it) unless `--no-vsync` asks for the most
    /// frames (frame-rate measurements); off in the headless UI tests.
    pub(super) pace_paint: bool,
    /// A figure export waiting for its reference's field (`figure.rs`).
    pub(super) figure: Option<super::figure::PendingFigure>,
}

impl HoxApp {
    /// The app on `scene` (or the saved settings), from `args`.
    pub fn new(args: &AppArgs, saved: Option<Persisted>) -> Result<HoxApp, String> {
        let saved = if args.fresh { None } else { saved };
        let scene = match (&args.scene, &args.scene_file) {
            (Some(name), _) => SceneSource::Builtin(name.clone()),
            (_, Some(path)) => SceneSource::File(path.clone()),
            _ => saved.as_ref().map(|s| s.scene.clone()).unwrap_or(SceneSource::Builtin("bending".into())),
        };
        let same_scene = saved.as_ref().is_some_and(|s| s.scene == scene);
        let start = Start {
            links: saved.as_ref().map(|s| s.links.clone()).unwrap_or_default(),
            view: saved.as_ref().map(|s| s.view.clone()).unwrap_or_default(),
            playing: args.play,
            time_scale: saved.as_ref().map_or(1.0, |s| s.time_scale),
            show_reference_element: saved.as_ref().is_some_and(|s| s.show_reference_element),
            background: Background::of_platform(),
            stepper: platform_stepper(),
        };
        // the very first start (no saved settings) offers the lessons
        let offer_lessons = saved.is_none()
            && !args.fresh
            && args.lesson.is_none()
            && args.lesson_file.is_none()
            && args.screenshot.is_none()
            && args.measure_secs.is_none();
        let ui = UiState::new(
            Viewport::new(saved.as_ref().filter(|_| same_scene).and_then(|s| s.camera)),
            saved.as_ref().map_or_else(|| "rerun+http://127.0.0.1:9876/proxy".into(), |s| s.rerun_url.clone()),
            saved.as_ref().map_or_else(|| "hox.rrd".into(), |s| s.rerun_file.clone()),
            offer_lessons,
        );
        let configs = saved.filter(|_| same_scene).map(|s| (s.configs, s.compare));
        let model = Model::new(scene, configs, start)?;
        let mut ui = ui;
        ui.grow_to_usable = args.size.is_none();
        let mut app = HoxApp {
            model,
            ui,
            rerun: Rerun::new(args.serve.clone(), args.serve_fps),
            times: FrameTimes::default(),
            measure: args.measure_secs.map(Measure::new),
            screenshot: args.screenshot.clone().map(|p| Screenshot::new(p, args.after_secs)),
            gl_available: false,
            renderer: None,
            pace_paint: false,
            figure: None,
        };
        app.start_configurations(args)?;
        if let Some(v) = args.view {
            app.act(Action::ShowReferenceElement(v == args::StartView::ReferenceElement));
        }
        if let Some(preset) = args.camera {
            app.act(Action::SetPreset(preset));
        }
        if args.lesson_step.is_some() && args.lesson.is_none() && args.lesson_file.is_none() {
            return Err("--lesson-step needs a lesson: --lesson NAME or --lesson-file FILE".into());
        }
        if args.lesson.is_some() || args.lesson_file.is_some() {
            let lesson = crate::config::load_lesson(args.lesson.as_deref(), args.lesson_file.as_deref())
                .map_err(|e| format!("{e:#}"))?;
            let steps = lesson.steps.len();
            app.act(Action::OpenLesson(Box::new(lesson)));
            if let Some(n) = args.lesson_step {
                if !(1..=steps).contains(&n) {
                    return Err(format!("--lesson-step {n}: the lesson has steps 1 to {steps}"));
                }
                app.act(Action::GoToStep(n - 1));
            }
            app.act(Action::Poll { wait_for_lesson: true });
        }
        if args.presenter {
            app.act(Action::SetPresenter(true));
        }
        if args.serve_web {
            app.serve_web_at_start();
        }
        if app.measure.is_some() {
            app.act(Action::SetPlaying(true));
        }
        Ok(app)
    }

    /// The configurations the command line asks for: its overrides on the scene's own
    /// configuration, and `--compare` (alone: the default pair; with values: exactly two
    /// configurations). Nothing given keeps the saved ones. Errors name the option.
    fn start_configurations(&mut self, args: &AppArgs) -> Result<(), String> {
        let o = crate::config::overrides(&args.mesh, Some(&args.physics)).merged(&args.display.overrides);
        let specs: Vec<&String> = args.compare.iter().filter(|s| !s.trim().is_empty()).collect();
        let wants_pair = !args.compare.is_empty();
        if o.iter().next().is_some() || !specs.is_empty() {
            let overrides = match specs.len() {
                0 => vec![(None, o)],
                2 => specs
                    .iter()
                    .map(|s| {
                        crate::config::parse_compare(s, &o)
                            .map(|o| (Some(s.to_string()), o))
                            .map_err(|e| format!("{e:#}"))
                    })
                    .collect::<Result<Vec<_>, _>>()?,
                n => {
                    return Err(format!("--compare with values needs exactly two configurations for the app, got {n}"));
                }
            };
            self.model.apply(Action::Configure(overrides))?;
        }
        if wants_pair && !self.model.compare() {
            self.act(Action::SetCompare(true));
        }
        self.ui.follow(&self.model);
        Ok(())
    }

    /// `--serve-web`: serves the class's browsers from the start. A refusal (a port in use, an
    /// address not of this machine) is printed and shown, and the app runs on without serving.
    fn serve_web_at_start(&mut self) {
        self.act(Command::Rerun(Some(super::action::RerunTarget::Browsers)));
        match self.rerun.web_url() {
            Some(url) => {
                println!("{url}");
                eprintln!("serving the class's browsers: open {url}");
            }
            None => {
                eprintln!("warning: not serving browsers: {}", self.model.message().unwrap_or("unknown error"))
            }
        }
    }

    /// The model (read only: it changes through [`HoxApp::act`]).
    #[cfg(test)]
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The model to change directly: tests only.
    #[cfg(test)]
    pub fn model_mut(&mut self) -> &mut Model {
        &mut self.model
    }

    /// The UI's state.
    #[cfg(test)]
    pub fn ui_state(&self) -> &UiState {
        &self.ui
    }

    /// Carries out `command`: an action changes the model (each frame stepped in place is
    /// logged to the Rerun link), a service's request goes to its service and the model is told
    /// the outcome; the UI's state then follows the model.
    pub fn act(&mut self, command: impl Into<Command>) {
        match command.into() {
            Command::Model(action) => {
                let loading = matches!(action, Action::LoadScene(_));
                let rerun = &mut self.rerun;
                let mut link_error = None;
                let result = self.model.apply_observed(action, &mut |m: &Model| {
                    if let Some(e) = rerun.log(m) {
                        link_error = Some(e);
                    }
                });
                if let (true, Err(e)) = (loading, result) {
                    self.say(Some(e));
                }
                self.say(link_error);
            }
            Command::Rerun(target) => {
                let message = self.rerun.set(target, &self.model, &self.ui.rerun_url, &self.ui.rerun_file);
                self.say(message);
            }
            Command::ExportFigure => {
                let folder = std::path::PathBuf::from(&self.ui.figure_folder);
                match super::figure::start_export(&self.model, &folder) {
                    Ok(super::figure::Export::Pending(pending)) => {
                        self.say(Some(pending.status()));
                        self.figure = Some(pending);
                    }
                    Ok(super::figure::Export::Written(files)) => self.say(Some(written(&files))),
                    Err(e) => self.say(Some(e)),
                }
            }
            Command::OpenFile { mesh, path, clamp_group } => {
                let source = if mesh {
                    super::dialogs::mesh_scene_file(&path, &clamp_group).map(SceneSource::File)
                } else {
                    Ok(SceneSource::File(path))
                };
                // the material and compare mode carry over to the part (issue #57: both were dropped)
                let (material, compare) = (self.model.active_session().config.clone(), self.model.compare());
                match source.and_then(|s| self.model.apply(Action::LoadScene(s))) {
                    Ok(()) => {
                        self.ui.open_dialog = None;
                        self.carry_over(&material, compare);
                    }
                    Err(e) => {
                        if let Some(d) = &mut self.ui.open_dialog {
                            d.error = Some(e);
                        }
                    }
                }
            }
            Command::OpenMeshBytes { name, bytes } => {
                let (material, compare) = (self.model.active_session().config.clone(), self.model.compare());
                let opened = hox_scenes::open_mesh_bytes(&name, &bytes)
                    .map(|mesh| SceneSource::Opened { mesh, clamp_group: MESH_CLAMP_GROUP.into() })
                    .and_then(|s| self.model.apply(Action::LoadScene(s)));
                match opened {
                    Ok(()) => self.carry_over(&material, compare),
                    // the app keeps what it had, and says why the file was not taken
                    Err(e) => self.say(Some(format!("{name} not opened: {e}"))),
                }
            }
        }
        self.ui.follow(&self.model);
    }

    /// After a part is opened: the material of the configuration before (`old`), where the
    /// part's scene accepts it, and compare mode.
    fn carry_over(&mut self, old: &super::config::Config, compare: bool) {
        let mut c = self.model.active_session().config.clone();
        for p in hox_scenes::params::in_group(hox_scenes::params::Group::Material) {
            (p.set)(&mut c, (p.get)(old));
        }
        if self.model.apply(Action::ChangeNow { control: "material".into(), config: Box::new(c) }).is_err() {
            self.say(Some("the part keeps its own material: the one before does not apply to it".into()));
        }
        if compare {
            self.act(Action::SetCompare(true));
        }
    }

    /// Carries out a frame's commands, in order.
    pub(super) fn act_all(&mut self, commands: Commands) {
        for c in commands.0 {
            self.act(c);
        }
    }

    /// Tells the model a service's message.
    /// A figure export waiting for its reference's field: written once the field has come.
    pub(super) fn poll_figure(&mut self) {
        let Some(pending) = &mut self.figure else { return };
        if let Some(done) = pending.poll(&self.model) {
            self.figure = None;
            self.say(Some(done.map_or_else(|e| e, |files| written(&files))));
        }
    }

    /// Plays the lesson step on screen to its end in place (no window, as the window would: a
    /// slow frame's pause is played on, as a teacher presses Play, until the step's seconds are
    /// up).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // the page's (and the tests')
    pub(super) fn play_step_to_its_end(&mut self) {
        for _ in 0..200_000 {
            if !self.model.playing() {
                let unfinished = self.model.lesson().is_some_and(|l| l.play_until_secs.is_some());
                if unfinished && self.model.message().is_some_and(|m| m.starts_with(super::cost::SLOW_PAUSE)) {
                    self.act(Action::SetPlaying(true));
                    continue;
                }
                return;
            }
            self.act(Action::Tick { real_dt_secs: 1.0 / 60.0, one_frame_per_tick: false, in_background: false });
        }
    }

    /// Every step of `lesson` as the app shows it, each prepared and played to its end in place:
    /// the texts of each step's numbers, A's and B's (`after_step` looks at the app after each).
    /// The desktop's test against `hox lesson` (issue #35) reads it; the page's check (issue #59)
    /// runs the same steps, awaiting its Web Workers' references between them (`launch.rs`).
    #[cfg(test)]
    pub fn lesson_answers(
        &mut self,
        lesson: &hox_scenes::lesson::Lesson,
        after_step: &mut dyn FnMut(&HoxApp, usize),
    ) -> Vec<Vec<String>> {
        self.act(Action::OpenLesson(Box::new(lesson.clone())));
        let mut shown = Vec::new();
        for k in 0..lesson.steps.len() {
            self.play_lesson_step(k);
            after_step(self, k);
            shown.push(self.lesson_step_answers());
        }
        shown
    }

    /// Opens step `k` of the lesson open, prepares it and plays it to its end in place.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // the page's (and the tests')
    pub(super) fn play_lesson_step(&mut self, k: usize) {
        self.act(Action::GoToStep(k));
        self.act(Action::Poll { wait_for_lesson: true });
        self.play_step_to_its_end();
    }

    /// The numbers of the lesson step on screen as its panel shows them (A's, B's).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // the page's (and the tests')
    pub(super) fn lesson_step_answers(&self) -> Vec<String> {
        self.model
            .lesson()
            .map_or_else(Vec::new, |l| l.measured(self.model.sessions()).into_iter().map(|m| m.text).collect())
    }

    /// Whether a configuration's reference is still being computed (in the background).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // the page's
    pub(super) fn references_computing(&self) -> bool {
        self.model.sessions().iter().any(|s| matches!(s.reference, super::readout::ReferenceState::Computing { .. }))
    }

    /// What the app shows, as JSON: the scene, each configuration (its label, element, ν, the
    /// simulated time and frames, the time per frame), the frames stepped and the sessions'
    /// generation (a rebuild adds one), playing or not, the message, the lesson
    /// step with its text as the panel shows it (question, numbers, answer once revealed). The
    /// page publishes it as `window.hox_state` for its tests and scripts (issue #59).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // the page's (and the tests')
    pub fn page_state(&self) -> serde_json::Value {
        let m = &self.model;
        let configurations: Vec<serde_json::Value> = m
            .sessions()
            .iter()
            .map(|s| {
                let value = |key: &str| s.config.value(key).map(|v| v.to_string());
                let reference = match &s.reference {
                    super::readout::ReferenceState::Unavailable(why) => format!("unavailable: {why}"),
                    super::readout::ReferenceState::Computing { job, .. } => {
                        let (what, fraction) = job.progress.lock().map(|p| p.clone()).unwrap_or_default();
                        format!("computing: {what} {:.0} %", 100.0 * fraction)
                    }
                    super::readout::ReferenceState::Ready { .. } => "ready".into(),
                    super::readout::ReferenceState::Failed { message, .. } => format!("failed: {message}"),
                };
                serde_json::json!({
                    "reference": reference,
                    "label": s.label(),
                    "element": value("element"),
                    "poisson": value("poisson"),
                    "time_secs": s.instance.sim.time_secs(),
                    "ms_per_frame": s.ms_per_frame,
                })
            })
            .collect();
        let lesson = m.lesson().map(|l| {
            serde_json::json!({
                "name": l.lesson.name,
                "step": l.step + 1,
                "steps": l.lesson.steps.len(),
                "question": l.current().question,
                "revealed": l.revealed,
                "preparing": l.preparing(),
                "text": m.lesson_text(),
            })
        });
        serde_json::json!({
            "scene": m.scene().label(),
            "configurations": configurations,
            "frames_stepped": m.frames_stepped(),
            "generation": m.generation(),
            "playing": m.playing(),
            "message": m.message(),
            "lesson": lesson,
        })
    }

    /// A message to show from the start (a page link's parameters that could not be used).
    pub(super) fn say_at_start(&mut self, message: String) {
        self.act(Command::Model(Action::Say(message)));
    }

    fn say(&mut self, message: Option<String>) {
        if let Some(m) = message {
            let _ = self.model.apply(Action::Say(m));
        }
    }

    /// What the services report, for the panels.
    pub(super) fn status(&self) -> Status {
        Status {
            rerun_target: self.rerun.target().map(String::from),
            web_url: self.rerun.web_url().map(String::from),
            bind: self.rerun.bind(),
            ui_frame_ms: self.times.ui_frame_ms,
            app_ms: self.times.app_ms,
            renderer: self.renderer.clone(),
        }
    }

    /// What of the app persists, as it is now.
    pub fn persisted(&self) -> Persisted {
        Persisted::of(&self.model, &self.ui)
    }

    /// How long to wait before painting the next frame while playing ([`HoxApp::pace_paint`]):
    /// until the next simulated frame is due; None (paint at once) when pacing is off, while
    /// settling (as many frames as the CPU allows) or measuring the frame rate.
    pub(super) fn paint_pace(&self) -> Option<std::time::Duration> {
        let sessions = self.model.sessions();
        if !self.pace_paint || self.model.settling() || self.measure.is_some() || sessions.is_empty() {
            return None;
        }
        Some(self.model.playback().until_next_frame(1.0 / sessions[0].config.frames_per_second))
    }

    /// Steps `frames` frames now (logged to the Rerun link), as the Step button does.
    #[cfg(test)]
    pub fn step(&mut self, frames: usize) {
        self.act(Action::Step(frames));
    }
}

/// "wrote a.svg and a.png".
fn written(files: &[std::path::PathBuf]) -> String {
    format!("wrote {}", files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(" and "))
}
