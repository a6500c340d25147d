//! Lessons in the app (issue #21): a lesson's steps ([`hox_scenes::lesson`]) set the
//! configurations, camera and view; a panel shows the step's text, its question, the live
//! measurement of each configuration beside it and, on demand, the answer. Keys: → / N next
//! step, ← / B previous, A reveal the answer (plus the app's own: space, E settle, R reset).
//! **Presenter mode** (P, or `--presenter`): the interface scaled up for a projector at the
//! back of a room, the side panel and plots hidden so the 3D view fills the window, the step's
//! caption and numbers over it.

use super::HoxApp;
use super::session::Session;
use eframe::egui;
use hox_scenes::lesson::{Lesson, Measure, Measured, Run};

/// What the panel and the caption say while a step is prepared.
pub(super) const PREPARING: &str = "Preparing this step: building its meshes and solving what it needs…";

/// Interface scale of presenter mode.
pub const PRESENTER_ZOOM: f32 = 1.6;

/// A lesson under way.
pub struct LessonState {
    pub lesson: Lesson,
    pub step: usize,
    pub revealed: bool,
    /// Simulated seconds the step plays for ([`Run::Seconds`]), then the app pauses.
    play_until_secs: Option<f64>,
    /// Why the last step could not be set up, if it could not.
    pub problem: Option<String>,
    /// What each configuration's measurement is against, when it needs one of its own (the
    /// solver's error: the static solution of that mesh, solved when the step opens).
    own_references: Vec<Option<hox_scenes::reference::Reference>>,
    /// The step being prepared in the background (meshes built, static solutions solved):
    /// until it is ready the panel says so and shows no numbers (issue #35: the last step's
    /// answer stayed 5–6 s with no sign of work).
    preparing: Option<std::thread::JoinHandle<Prepared>>,
}

/// A step's configurations, built and (for a static step, or the solver's error) solved.
struct Prepared {
    sessions: Vec<Session>,
    own_references: Vec<Option<hox_scenes::reference::Reference>>,
    problem: Option<String>,
}

/// Builds step `step`'s configurations as the lesson runs them (`hox lesson`'s
/// [`hox_scenes::lesson::StepRunner::start`]): a static step shows the static equilibrium, the
/// solver's error is measured against each mesh's own static solution.
fn prepare(step: &hox_scenes::lesson::Step) -> Prepared {
    let mut sessions = Vec::new();
    for scene in &step.configurations {
        let session = hox_scenes::by_name(scene.name())
            .map_err(|e| e.to_string())
            .and_then(|base| Session::new(base, scene.params().clone()));
        match session {
            Ok(s) => sessions.push(s),
            Err(problem) => {
                return Prepared { sessions: Vec::new(), own_references: Vec::new(), problem: Some(problem) };
            }
        }
    }
    let own_references = step
        .configurations
        .iter()
        .map(|scene| match step.measure {
            Measure::SolverError => {
                hox_scenes::lesson::reference_for(step.measure, scene, &mut |_, _| {}).ok().flatten()
            }
            _ => None,
        })
        .collect();
    let mut problem = None;
    for s in &mut sessions {
        s.watch_min_det_f = step.measure == Measure::MinDetF;
        if step.run == Run::Static
            && let Err(e) = s.show_static_equilibrium()
        {
            problem = Some(e);
        }
        s.watch();
    }
    Prepared { sessions, own_references, problem }
}

impl LessonState {
    /// "A: Element p1 · Poisson ratio ν 0.49", a line per configuration of the step on screen:
    /// the parameters the lesson's steps change.
    fn parameter_lines(&self) -> Vec<String> {
        let lines = self.lesson.step_parameters(self.step);
        lines.iter().enumerate().map(|(k, line)| format!("{}: {line}", ["A", "B"][k.min(1)])).collect()
    }

    /// Whether the step on screen is still being prepared.
    pub fn preparing(&self) -> bool {
        self.preparing.is_some()
    }

    /// The measurement of every session now, for the step on screen: while a step plays or
    /// settles, a settle-measured number is not yet the answer's and reads "settling…".
    pub fn measured(&self, sessions: &[Session]) -> Vec<Measured> {
        let step = &self.lesson.steps[self.step];
        sessions
            .iter()
            .enumerate()
            .map(|(k, s)| match &s.failure {
                Some(f) => Measured { value: f64::INFINITY, text: format!("failed: {f}") },
                None if step.run == Run::Settle && s.settle_outcome.is_none() => {
                    Measured { value: f64::NAN, text: format!("settling… (t = {:.2} s)", s.instance.sim.time_secs()) }
                }
                None => {
                    let reference = self.own_references.get(k).and_then(Option::as_ref).or(s.reference.reference());
                    // the median of the step's frames, only where it is the measure (drawn every frame)
                    let ms = match step.measure {
                        Measure::MsPerFrame if !s.frame_ms.is_empty() => hox_scenes::median(&mut s.frame_ms.clone()),
                        _ => f64::NAN,
                    };
                    hox_scenes::lesson::measure(step.measure, &s.instance, reference, ms, s.min_det_f)
                }
            })
            .collect()
    }
}

impl HoxApp {
    /// Opens `lesson` on its first step (prepared in the background: [`HoxApp::poll_lesson`]).
    pub fn open_lesson(&mut self, lesson: Lesson) {
        self.lesson = Some(LessonState {
            lesson,
            step: 0,
            revealed: false,
            play_until_secs: None,
            problem: None,
            own_references: Vec::new(),
            preparing: None,
        });
        self.go_to_step(0);
    }

    /// Starts preparing step `k` of the open lesson in the background; the app pauses and the
    /// panel says "preparing" until [`HoxApp::poll_lesson`] installs it.
    pub fn go_to_step(&mut self, k: usize) {
        let Some(state) = &mut self.lesson else { return };
        let k = k.min(state.lesson.steps.len() - 1);
        state.step = k;
        state.revealed = false;
        state.problem = None;
        state.play_until_secs = None;
        let step = state.lesson.steps[k].clone();
        // a step asked for while another is prepared replaces it (its thread's result is dropped)
        state.preparing = Some(std::thread::spawn(move || prepare(&step)));
        self.playback.playing = false;
    }

    /// Installs the step prepared in the background once it is ready (non-blocking; `wait`:
    /// blocking, for the first step of `--lesson` and the tests); whether it did.
    pub fn poll_lesson(&mut self, wait: bool) -> bool {
        let Some(state) = &mut self.lesson else { return false };
        if !wait && !state.preparing.as_ref().is_some_and(|h| h.is_finished()) {
            return false;
        }
        let Some(handle) = state.preparing.take() else { return false };
        let prepared = match handle.join() {
            Ok(p) => p,
            Err(_) => Prepared {
                sessions: Vec::new(),
                own_references: Vec::new(),
                problem: Some("preparing the step stopped unexpectedly".into()),
            },
        };
        state.problem = prepared.problem;
        if prepared.sessions.is_empty() {
            return true;
        }
        state.own_references = prepared.own_references;
        let step = state.lesson.steps[state.step].clone();
        state.play_until_secs = match step.run {
            Run::Seconds(secs) => Some(secs),
            _ => None,
        };
        self.join_background();
        self.sessions = prepared.sessions;
        self.compare = self.sessions.len() > 1;
        self.active = 0;
        self.show_reference_element = step.reference_element;
        if step.reference_element {
            self.reference_element.set_element(step.configurations[0].params().element);
        }
        self.rebuilt();
        let preset = step
            .camera
            .as_deref()
            .and_then(|c| super::viewport::ViewPreset::ALL.into_iter().find(|p| p.name() == c))
            .unwrap_or_default();
        self.set_camera(preset);
        self.playback.playing = step.run != Run::Static;
        self.playback.frame_budget_secs = 0.0;
        if step.run == Run::Settle {
            self.settle();
        }
        true
    }

    /// Whether the step on screen times its frames (their median is its measurement): its
    /// configurations then step one after the other, as `hox lesson` steps them.
    pub(super) fn lesson_times_frames(&self) -> bool {
        self.lesson.as_ref().is_some_and(|l| l.lesson.steps[l.step].measure == Measure::MsPerFrame)
    }

    /// Frames left before a step that plays some seconds ends; None when none is playing.
    pub(super) fn lesson_frames_left(&self, frame_secs: f64) -> Option<usize> {
        let until = self.lesson.as_ref()?.play_until_secs?;
        let t = self.sessions.first()?.instance.sim.time_secs();
        Some(((until - t) / frame_secs - 1e-6).ceil().max(0.0) as usize)
    }

    /// The next (`+1`) or previous (`-1`) step.
    pub fn lesson_step(&mut self, delta: i64) {
        let Some(state) = &self.lesson else { return };
        let last = state.lesson.steps.len() as i64 - 1;
        let k = (state.step as i64 + delta).clamp(0, last) as usize;
        if k != state.step {
            self.go_to_step(k);
        }
    }

    /// Reveals the step's answer.
    pub fn reveal_answer(&mut self) {
        if let Some(state) = &mut self.lesson
            && !state.preparing()
        {
            state.revealed = true;
        }
    }

    /// A step that plays for some seconds pauses at its end.
    pub(super) fn lesson_after_advance(&mut self) {
        let Some(until) = self.lesson.as_ref().and_then(|s| s.play_until_secs) else { return };
        if self.sessions.first().is_some_and(|s| s.instance.sim.time_secs() >= until - 1e-9) {
            self.playback.playing = false;
            if let Some(state) = &mut self.lesson {
                state.play_until_secs = None;
            }
        }
    }

    /// The lesson's keys: → / N next, ← / B previous, A answer, P presenter mode.
    pub(super) fn lesson_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (next, previous, answer, presenter) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::ArrowRight) || i.key_pressed(egui::Key::N),
                i.key_pressed(egui::Key::ArrowLeft) || i.key_pressed(egui::Key::B),
                i.key_pressed(egui::Key::A),
                i.key_pressed(egui::Key::P),
            )
        });
        if presenter {
            self.set_presenter(!self.presenter);
        }
        if self.lesson.is_none() {
            return;
        }
        if next {
            self.lesson_step(1);
        }
        if previous {
            self.lesson_step(-1);
        }
        if answer {
            self.reveal_answer();
        }
    }

    /// Presenter mode on or off: a larger interface, the 3D view filling the window.
    pub fn set_presenter(&mut self, on: bool) {
        self.presenter = on;
        self.zoom_wanted = Some(if on { PRESENTER_ZOOM } else { 1.0 });
    }
}

/// The lesson panel: title, step, text, question, the live measurement of A and B, the answer
/// on demand, and the step buttons.
pub fn lesson_panel_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    let Some(state) = &app.lesson else { return };
    let step = &state.lesson.steps[state.step];
    let measured = state.measured(&app.sessions);
    let n = state.lesson.steps.len();
    ui.heading(&state.lesson.title);
    ui.label(egui::RichText::new(&state.lesson.goal).italics());
    ui.separator();
    ui.label(egui::RichText::new(format!("Step {} of {n}: {}", state.step + 1, step.title)).strong().size(18.0));
    for line in state.parameter_lines() {
        ui.label(egui::RichText::new(line).monospace());
    }
    ui.label(&step.text);
    ui.add_space(6.0);
    ui.label(egui::RichText::new(format!("Question: {}", step.question)).strong());
    ui.add_space(6.0);
    ui.label(egui::RichText::new(step.measure.title()).underline());
    if state.preparing() {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(PREPARING);
        });
    } else {
        for (k, (m, s)) in measured.iter().zip(&app.sessions).enumerate() {
            ui.label(egui::RichText::new(format!("{} {}: {}", ["A", "B"][k.min(1)], s.label(), m.text)).monospace());
        }
    }
    if let Some(p) = &state.problem {
        ui.colored_label(egui::Color32::from_rgb(255, 120, 90), p);
    }
    ui.add_space(6.0);
    // no answer while the step is prepared: the numbers it speaks of are not there yet
    let (revealed, preparing) = (state.revealed, state.preparing());
    let (at, answer) = (state.step, step.answer.clone());
    if preparing {
        ui.label(egui::RichText::new("(the answer once the step is ready)").weak());
    } else if revealed {
        ui.label(egui::RichText::new(format!("Answer: {answer}")).color(egui::Color32::from_rgb(250, 220, 120)));
    } else if ui.button("Reveal the answer (A)").clicked() {
        app.reveal_answer();
    }
    ui.add_space(6.0);
    ui.horizontal(|ui| {
        if ui.add_enabled(at > 0, egui::Button::new("< Previous (left arrow)")).clicked() {
            app.lesson_step(-1);
        }
        if ui.add_enabled(at + 1 < n, egui::Button::new("Next (right arrow) >")).clicked() {
            app.lesson_step(1);
        }
        if ui.button("Close lesson").clicked() {
            app.lesson = None;
        }
    });
}

/// In presenter mode: the step's caption and numbers in a panel below the 3D view (issue #35:
/// laid over the view, the answer covered both bodies' labels at 1280×720).
pub fn caption_ui(app: &HoxApp, ui: &mut egui::Ui) {
    let Some(state) = &app.lesson else { return };
    let step = &state.lesson.steps[state.step];
    let measured = state.measured(&app.sessions);
    ui.label(
        egui::RichText::new(format!("{} — {}", state.lesson.title, step.title)).strong().color(egui::Color32::WHITE),
    );
    for line in state.parameter_lines() {
        ui.label(egui::RichText::new(line).monospace().color(egui::Color32::from_rgb(200, 200, 200)));
    }
    ui.label(egui::RichText::new(&step.question).color(egui::Color32::WHITE));
    if state.preparing() {
        ui.label(egui::RichText::new(PREPARING).color(egui::Color32::from_rgb(250, 220, 120)));
        return;
    }
    for (k, m) in measured.iter().enumerate() {
        ui.label(
            egui::RichText::new(format!("{}: {}", ["A", "B"][k.min(1)], m.text))
                .monospace()
                .color(egui::Color32::from_rgb(250, 220, 120)),
        );
    }
    if state.revealed {
        ui.label(egui::RichText::new(&step.answer).color(egui::Color32::from_rgb(180, 230, 255)));
    }
}

/// The Lessons menu: every built-in lesson.
pub fn lessons_menu_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.menu_button("Lessons", |ui| {
        match hox_scenes::lesson::registry() {
            Ok(all) => {
                for l in all {
                    if ui.button(&l.title).on_hover_text(&l.goal).clicked() {
                        app.open_lesson(l);
                        ui.close();
                    }
                }
            }
            Err(e) => {
                ui.label(e.to_string());
            }
        }
        ui.separator();
        let mut on = app.presenter;
        if ui.checkbox(&mut on, "Presenter mode (P)").clicked() {
            app.set_presenter(on);
        }
    });
}

/// The first start's offer: the lessons, or the free app.
pub fn welcome_ui(app: &mut HoxApp, ctx: &egui::Context) {
    if !app.offer_lessons {
        return;
    }
    let mut open = true;
    // centred in the window, below the menu bar it used to cover (issue #35)
    egui::Window::new("Welcome to hox")
        .collapsible(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::vec2(0.0, 0.0))
        .open(&mut open)
        .show(ctx, |ui| {
            ui.label("Start with a guided lesson, or explore freely (the Lessons menu has them all).");
            if let Ok(all) = hox_scenes::lesson::registry() {
                for l in all {
                    if ui.button(&l.title).on_hover_text(&l.goal).clicked() {
                        app.open_lesson(l);
                        app.offer_lessons = false;
                    }
                }
            }
            if ui.button("Explore freely").clicked() {
                app.offer_lessons = false;
            }
        });
    if !open {
        app.offer_lessons = false;
    }
}
