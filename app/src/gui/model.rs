//! The app's model: what runs and what the class is shown, without a window or threads of its
//! own — the scene, the running configurations ([`Session`]s) and compare mode with its links,
//! playback, the drawing options and camera preset, the lesson under way, the last refusal and
//! message. It changes only through [`Model::apply`] (an [`Action`]); panels read it. The work
//! it hands off goes through [`super::background`]'s two interfaces, so the same model runs in
//! the desktop app (threads), in a test and, next, in a web page (in place).
//!
//! A change of a configuration rebuilds only what it invalidates ([`Invalidates`]); a value the
//! scene's validation refuses leaves the running simulation untouched and records the reason
//! for the control. In compare mode the linked parameters of the other configuration follow.

use super::action::Action;
use super::background::{Background, Stepper, any_settling, step_sessions};
use super::config::{Config, Invalidates, SceneSource};
use super::cost;
use super::lesson::LessonState;
use super::links::Links;
use super::playback::{Playback, SETTLE_STEP_BUDGET_MS};
use super::presets::{ViewOptions, ViewPreset};
use super::rebuild::{Build, PendingChange, StaticJobs, builds_at_once, redraws};
use super::session::Session;
use hox_scenes::lesson::Run;
use hox_sim::Vec3;
use hox_sim::element::ElementType;
use hox_sim::measure::field::Field;

/// What a model starts from besides its scene: the settings kept from the last run and the
/// services it hands work to.
pub struct Start {
    pub links: Links,
    pub view: ViewOptions,
    pub playing: bool,
    pub time_scale: f64,
    pub show_reference_element: bool,
    /// Where one-off jobs (a lesson step's preparation) run.
    pub background: Background,
    /// Where frames are stepped while the window paints.
    pub stepper: Box<dyn Stepper>,
}

pub struct Model {
    scene: SceneSource,
    sessions: Vec<Session>,
    active: usize,
    compare: bool,
    links: Links,
    playback: Playback,
    view: ViewOptions,
    preset: ViewPreset,
    /// The last refused change: control, reason.
    refusal: Option<(String, String)>,
    message: Option<String>,
    /// A slow change waiting for the user's answer ([`cost`]).
    pending_change: Option<PendingChange>,
    lesson: Option<LessonState>,
    /// The configurations and compare mode before the lesson opened: what a restart keeps.
    before_lesson: Option<(Vec<Config>, bool)>,
    presenter: bool,
    show_reference_element: bool,
    /// The element type a lesson step shows in the reference-element view.
    reference_element: Option<ElementType>,
    /// Counts rebuilds: a recording logs the static data again when it changes.
    generation: u64,
    /// Counts new layouts of the bodies (scene, compare mode, preset): the camera frames them
    /// again when it changes.
    layout: u64,
    /// Frames stepped since the start, in place or on the stepper.
    frames_stepped: u64,
    /// Frames the ticks deferred to the stepper ([`Action::Tick`]'s `in_background`).
    deferred_frames: usize,
    /// Static equilibria being solved in the background for a lesson's static step after a
    /// change.
    static_jobs: StaticJobs,
    /// A change's new meshes being built in the background.
    building: Option<Build>,
    /// What the user gets: the interval between the window's frames, and its drawing part.
    display: cost::Display,
    /// What a unit of a solver's work costs on this machine, as last measured.
    rates: cost::Rates,
    background: Background,
    stepper: Box<dyn Stepper>,
}

impl Model {
    /// The model on `scene` with `configs` (saved configurations and compare mode; falling back
    /// to the scene's own).
    pub fn new(scene: SceneSource, configs: Option<(Vec<Config>, bool)>, start: Start) -> Result<Model, String> {
        let mut model = Model {
            scene: scene.clone(),
            sessions: Vec::new(),
            active: 0,
            compare: false,
            links: start.links,
            playback: Playback::new(start.playing, start.time_scale),
            view: start.view,
            preset: ViewPreset::default(),
            refusal: None,
            message: None,
            pending_change: None,
            lesson: None,
            before_lesson: None,
            presenter: false,
            show_reference_element: start.show_reference_element,
            reference_element: None,
            generation: 0,
            layout: 0,
            frames_stepped: 0,
            deferred_frames: 0,
            static_jobs: StaticJobs::default(),
            building: None,
            display: cost::Display::default(),
            rates: cost::Rates::default(),
            background: start.background,
            stepper: start.stepper,
        };
        model.load_scene(scene, configs)?;
        Ok(model)
    }

    // --- reading
    pub fn scene(&self) -> &SceneSource {
        &self.scene
    }
    /// The running configurations (A, and B in compare mode).
    pub fn sessions(&self) -> &[Session] {
        &self.sessions
    }
    /// The configuration the controls change.
    pub fn active(&self) -> usize {
        self.active
    }
    pub fn active_session(&self) -> &Session {
        &self.sessions[self.active]
    }
    pub fn compare(&self) -> bool {
        self.compare
    }
    pub fn links(&self) -> &Links {
        &self.links
    }
    pub fn playback(&self) -> &Playback {
        &self.playback
    }
    pub fn playing(&self) -> bool {
        self.playback.playing
    }
    pub fn view(&self) -> &ViewOptions {
        &self.view
    }
    pub fn preset(&self) -> ViewPreset {
        self.preset
    }
    pub fn refusal(&self) -> Option<&(String, String)> {
        self.refusal.as_ref()
    }
    pub fn message(&self) -> Option<&str> {
        self.message.as_deref()
    }
    pub fn pending_change(&self) -> Option<&PendingChange> {
        self.pending_change.as_ref()
    }
    pub fn lesson(&self) -> Option<&LessonState> {
        self.lesson.as_ref()
    }
    pub fn presenter(&self) -> bool {
        self.presenter
    }
    pub fn show_reference_element(&self) -> bool {
        self.show_reference_element
    }
    pub fn reference_element(&self) -> Option<ElementType> {
        self.reference_element
    }
    pub fn generation(&self) -> u64 {
        self.generation
    }
    pub fn layout(&self) -> u64 {
        self.layout
    }
    pub fn frames_stepped(&self) -> u64 {
        self.frames_stepped
    }
    /// Whether the sessions are out on the stepper (until the next [`Action::Poll`]).
    #[cfg(test)]
    pub fn stepping_in_background(&self) -> bool {
        self.stepper.busy()
    }

    /// World offsets of the sessions: side by side across the camera preset's line of sight
    /// ([`crate::display`], [`ViewPreset::layout_axis`]).
    pub fn offsets(&self) -> Vec<Vec3> {
        let Some(first) = self.sessions.first() else { return Vec::new() };
        crate::display::side_by_side_offsets(first.instance.sim.mesh(), self.sessions.len(), self.preset.layout_axis())
    }

    /// Whether a *Settle* is under way in any configuration.
    pub fn settling(&self) -> bool {
        any_settling(&self.sessions)
    }

    /// Whether the step on screen times its frames: its configurations then step one after the
    /// other, as `hox lesson` steps them.
    pub fn lesson_times_frames(&self) -> bool {
        self.lesson.as_ref().is_some_and(LessonState::times_frames)
    }

    /// The open lesson's step as the browsers show it.
    /// The configurations and compare mode a restart keeps: a lesson's are its own (issue #57:
    /// two "P2 8×2×2 five" beams of a lesson's step came back at the next plain start).
    pub fn kept_configurations(&self) -> (Vec<Config>, bool) {
        let now = || (self.sessions.iter().map(|s| s.config.clone()).collect(), self.compare);
        self.before_lesson.clone().filter(|_| self.lesson.is_some()).unwrap_or_else(now)
    }

    pub fn lesson_text(&self) -> Option<String> {
        self.lesson.as_ref().map(|l| l.step_markdown(&self.sessions))
    }

    /// The sessions to change directly: tests only (waiting for a reference, a measured time).
    #[cfg(test)]
    pub fn sessions_mut(&mut self) -> &mut [Session] {
        self.join();
        &mut self.sessions
    }

    // --- changing
    /// Applies `action`; a refusal is returned (and recorded where the panels show it).
    pub fn apply(&mut self, action: Action) -> Result<(), String> {
        self.apply_observed(action, &mut |_| {})
    }

    /// [`Model::apply`], calling `on_frame` after every frame stepped in place (a live
    /// recording logs each).
    pub fn apply_observed(&mut self, action: Action, on_frame: &mut dyn FnMut(&Model)) -> Result<(), String> {
        self.join();
        match action {
            Action::Poll { wait_for_lesson } => self.poll(wait_for_lesson),
            Action::StepDeferred => {
                let frames = std::mem::take(&mut self.deferred_frames);
                if frames > 0 && !self.sessions.is_empty() {
                    let one_at_a_time = self.lesson_times_frames();
                    self.stepper.start(std::mem::take(&mut self.sessions), frames, one_at_a_time);
                }
            }
            Action::Tick { real_dt_secs, one_frame_per_tick, in_background } => {
                self.tick(real_dt_secs, one_frame_per_tick, in_background, on_frame)
            }
            Action::SetPlaying(on) => self.playback.playing = on,
            Action::TogglePlaying => self.playback.playing = !self.playback.playing,
            Action::Step(frames) => self.step(frames, on_frame),
            Action::Settle => self.settle(),
            Action::Reset => self.reset(),
            Action::SetTimeScale(x) => self.playback.time_scale = x,
            Action::LoadScene(source) => return self.load_scene(source, None),
            Action::Configure(overrides) => return self.configure(&overrides),
            Action::SetCompare(on) => self.set_compare(on),
            Action::SetActive(k) => self.active = k.min(self.sessions.len().saturating_sub(1)),
            Action::Change { control, config } => {
                if let Some(estimate) =
                    cost::too_slow(&self.sessions[self.active], &config, &self.rates, self.display.draw_ms)
                {
                    self.pending_change = Some(PendingChange { control, config: *config, estimate, built: None });
                    return Ok(());
                }
                return self.change_or_build(&control, *config, true);
            }
            Action::ChangeNow { control, config } => return self.change_or_build(&control, *config, false),
            Action::AnswerPending(apply) => {
                // either answer ends the question; only "apply" changes anything
                if let Some(p) = self.pending_change.take()
                    && apply
                {
                    self.playback.playing = false;
                    return match p.built {
                        Some(built) => self.install(&p.control, built),
                        None => self.change(&p.control, p.config),
                    };
                }
            }
            Action::Refuse { control, reason } => self.refusal = Some((control, reason)),
            Action::SetLink { key, linked } => {
                self.links.0.insert(key, linked);
            }
            Action::SetField(field) => self.set_field(field),
            Action::NextField => {
                let Some(first) = self.sessions.first() else { return Ok(()) };
                let now = crate::display::fields(&first.config)[0];
                let k = Field::ALL.iter().position(|f| *f == now).unwrap_or(0);
                self.set_field(Field::ALL[(k + 1) % Field::ALL.len()]);
            }
            Action::SetPreset(preset) => self.set_preset(preset),
            Action::SetView(view) => self.view = view,
            Action::ShowReferenceElement(on) => self.show_reference_element = on,
            Action::Drag { session, drag } => {
                if let Some(s) = self.sessions.get_mut(session) {
                    s.drag = drag;
                }
            }
            Action::OpenLesson(lesson) => {
                if self.lesson.is_none() {
                    self.before_lesson = Some(self.kept_configurations());
                }
                self.lesson = Some(LessonState::open(*lesson, self.background));
                self.playback.playing = false;
            }
            Action::GoToStep(k) => self.go_to_step(k),
            Action::LessonStep(delta) => {
                if let Some(k) = self.lesson.as_ref().and_then(|l| l.step_by(delta)) {
                    self.go_to_step(k);
                }
            }
            Action::RevealAnswer => self.lesson.iter_mut().for_each(LessonState::reveal),
            Action::CloseLesson => (self.lesson, self.before_lesson) = (None, None),
            Action::SetPresenter(on) => self.presenter = on,
            Action::Say(message) => self.message = Some(message),
        }
        Ok(())
    }

    /// Replaces the configurations: `overrides` on the scene's own, one session each (the text
    /// that asked for each names it in a refusal). Two turn compare mode on.
    fn configure(&mut self, overrides: &[(Option<String>, hox_scenes::SceneOverrides)]) -> Result<(), String> {
        self.sessions = super::rebuild::configured(&self.sessions[0].base, overrides)?;
        self.compare = self.sessions.len() > 1;
        self.active = 0;
        self.rebuilt();
        self.layout += 1;
        Ok(())
    }

    /// Takes back the sessions out on the stepper, counting their frames.
    fn join(&mut self) {
        if let Some((sessions, frames)) = self.stepper.finish() {
            self.sessions = sessions;
            self.frames_stepped += frames as u64;
        }
    }

    fn rebuilt(&mut self) {
        self.generation += 1;
    }

    /// Takes in what finished in the background (the stepper's sessions are back already).
    fn poll(&mut self, wait_for_lesson: bool) {
        for s in &mut self.sessions {
            s.poll_reference();
        }
        self.poll_lesson(wait_for_lesson);
        self.poll_static_jobs();
        self.poll_build();
    }

    /// What is being built for a change, if anything: a line for the status.
    pub fn building(&self) -> Option<String> {
        Some(self.building.as_ref()?.status(&self.sessions[0].base))
    }

    /// Applies `new` to the active configuration (and the linked fields to the other): at once,
    /// or, when it needs a new mesh, built in the background first ([`Build`]); `ask`: a build
    /// estimated slower than the machine can play asks first ([`cost::too_slow_built`]).
    fn change_or_build(&mut self, control: &str, new: Config, ask: bool) -> Result<(), String> {
        let k = self.active;
        let s = &self.sessions[k];
        if builds_at_once(s, &new) {
            return self.change(control, new);
        }
        let mut configs = vec![(k, new.clone())];
        if self.compare {
            let other = 1 - k;
            let follow =
                super::rebuild::follow(&self.links, &self.sessions[k].config, &new, &self.sessions[other].config);
            if follow != self.sessions[other].config {
                configs.push((other, follow));
            }
        }
        // checked against the table now (a refusal at once, for the control); built later
        match Build::start(control, ask, configs, &self.sessions, k, self.background) {
            Ok(build) => self.building = Some(build),
            Err(reason) => {
                self.refusal = Some((control.to_string(), reason.clone()));
                return Err(reason);
            }
        }
        self.refusal = None;
        self.poll_build();
        Ok(())
    }

    /// Takes a build that finished in: asks first if it would be slow, else installs it.
    fn poll_build(&mut self) {
        if !self.building.as_ref().is_some_and(|b| b.is_ready()) {
            return;
        }
        let Some(b) = self.building.take() else { return };
        let control = b.control.clone();
        let ask = b.ask;
        let built = match b.finish() {
            Ok(built) => built,
            Err(reason) => {
                self.refusal = Some((control, reason));
                return;
            }
        };
        if ask
            && let Some(estimate) = super::rebuild::question(&built, &self.sessions, &self.rates, self.display.draw_ms)
        {
            let config = built[0].1.clone();
            self.pending_change = Some(PendingChange { control, config, estimate, built: Some(built) });
            return;
        }
        let _ = self.install(&control, built);
    }

    /// Installs meshes built for a change.
    fn install(&mut self, control: &str, built: super::rebuild::Built) -> Result<(), String> {
        for (k, config, prepared) in built {
            let Some(s) = self.sessions.get_mut(k) else { continue };
            if let Err(reason) = prepared.install(s, config) {
                self.refusal = Some((control.to_string(), reason.clone()));
                return Err(reason);
            }
            self.rebuilt();
            self.solve_static_again(k);
        }
        self.refusal = None;
        self.clear_slow_pause();
        Ok(())
    }

    /// A change was applied: the message of a slow frame's pause is of another configuration.
    fn clear_slow_pause(&mut self) {
        self.message = self.message.take().filter(|m| !m.starts_with(cost::SLOW_PAUSE));
    }

    /// In a lesson's static step, solves the static equilibrium of session `k`'s configuration
    /// (in the background); until shown, its readout and the lesson's numbers say so.
    fn solve_static_again(&mut self, k: usize) {
        if self.lesson.as_ref().is_none_or(|l| l.preparing() || l.current().run != Run::Static) {
            return;
        }
        self.static_jobs.start(k, &mut self.sessions[k], self.background);
        self.poll_static_jobs();
    }

    /// Shows the static equilibria solved since, where the configuration is still theirs.
    fn poll_static_jobs(&mut self) {
        let (shown, message) = self.static_jobs.poll(&mut self.sessions);
        if shown {
            self.generation += 1;
        }
        if message.is_some() {
            self.message = message;
        }
    }

    fn load_scene(&mut self, source: SceneSource, configs: Option<(Vec<Config>, bool)>) -> Result<(), String> {
        let mut sessions = super::rebuild::loaded(&source.load()?, configs.clone().map(|c| c.0))?;
        self.scene = source;
        self.compare = sessions.len() > 1 && configs.is_some_and(|c| c.1);
        sessions.truncate(if self.compare { 2 } else { 1 });
        self.sessions = sessions;
        self.active = 0;
        self.refusal = None;
        self.rebuilt();
        self.layout += 1;
        Ok(())
    }

    /// Compare mode on (a second configuration: P1 refined once on a P2 scene, else a copy) or
    /// off.
    fn set_compare(&mut self, on: bool) {
        if on == self.compare {
            return;
        }
        if on {
            match super::rebuild::compare_partner(&self.sessions[0]) {
                Ok(s) => {
                    // P1 first, so the pair reads "P1 vs P2" left to right
                    self.sessions.push(s);
                    if self.sessions[1].config.element.name() == "p1" {
                        self.sessions.swap(0, 1);
                    }
                    self.compare = true;
                }
                Err(e) => self.message = Some(e),
            }
        } else {
            self.sessions.truncate(1);
            self.compare = false;
        }
        self.active = 0;
        self.rebuilt();
        self.layout += 1;
    }

    /// Colours by `field` (every session: colours compare only on one field).
    fn set_field(&mut self, field: Field) {
        for k in 0..self.sessions.len() {
            let mut c = self.sessions[k].config.clone();
            c.field = vec![field];
            if let Err(e) = self.sessions[k].apply(c) {
                self.refusal = Some(("field".into(), e));
            }
        }
        self.generation += 1;
    }

    /// Looks from `preset`: the configurations laid apart across its line of sight.
    fn set_preset(&mut self, preset: ViewPreset) {
        self.preset = preset;
        self.layout += 1;
        // the layout changed: recordings log it again
        self.generation += 1;
    }

    /// Applies `new` to the active session and, in compare mode, the linked fields to the other.
    fn change(&mut self, control: &str, new: Config) -> Result<(), String> {
        let k = self.active;
        let old = self.sessions[k].config.clone();
        match self.sessions[k].apply(new.clone()) {
            Ok(what) => {
                self.refusal = None;
                self.clear_slow_pause();
                // a new mesh, or a new way of drawing it: Rerun logs the static data again
                if what == Invalidates::Mesh || redraws(&old, &new) {
                    self.rebuilt();
                }
                if what != Invalidates::Nothing {
                    self.solve_static_again(k);
                }
            }
            Err(reason) => {
                self.refusal = Some((control.to_string(), reason.clone()));
                return Err(reason);
            }
        }
        if self.compare {
            let other = 1 - k;
            let follow = super::rebuild::follow(&self.links, &old, &new, &self.sessions[other].config);
            match self.sessions[other].apply(follow) {
                Ok(Invalidates::Mesh) => {
                    self.rebuilt();
                    self.solve_static_again(other);
                }
                Ok(Invalidates::Nothing) if redraws(&old, &new) => self.rebuilt(),
                Ok(Invalidates::Nothing) => {}
                Ok(_) => {
                    if redraws(&old, &new) {
                        self.rebuilt();
                    }
                    self.solve_static_again(other);
                }
                Err(reason) => {
                    let reason = format!("the other configuration refused it: {reason}");
                    self.refusal = Some((control.to_string(), reason.clone()));
                    return Err(reason);
                }
            }
        }
        Ok(())
    }

    /// *Settle*: every configuration runs with its settle damping, as fast as the machine
    /// allows, until at rest, then pauses ([`Session::start_settle`]).
    fn settle(&mut self) {
        for s in &mut self.sessions {
            s.start_settle();
        }
        self.playback.playing = true;
    }

    fn reset(&mut self) {
        for s in &mut self.sessions {
            s.reset();
        }
        self.playback.frame_budget_secs = 0.0;
        self.rebuilt();
    }

    /// Steps `frames` frames in place (in parallel in compare mode); a *Settle* that ends on
    /// the way stops there, at rest (issue #35: the frames left ran on undamped).
    fn step(&mut self, frames: usize, on_frame: &mut dyn FnMut(&Model)) {
        let one_at_a_time = self.lesson_times_frames();
        let settling = self.settling();
        for _ in 0..frames {
            if settling && !self.settling() {
                break;
            }
            step_sessions(&mut self.sessions, one_at_a_time);
            self.frames_stepped += 1;
            on_frame(self);
        }
    }

    /// Real time passed: steps as much simulated time as passed × the time scale (at most
    /// about 50 ms of stepping per tick, at least 4 frames: `Playback::frames_due`);
    /// while settling as many frames as about 50 ms of stepping allows; then a step that plays
    /// some seconds pauses at its end, and a slow frame pauses.
    fn tick(
        &mut self,
        real_dt_secs: f64,
        one_frame_per_tick: bool,
        in_background: bool,
        on_frame: &mut dyn FnMut(&Model),
    ) {
        // the first tick's interval is not a real one
        let dt = if self.playback.last_clock_frame { real_dt_secs } else { 0.0 };
        let frames = self.frames_due(dt, one_frame_per_tick);
        if frames > 0 {
            if in_background {
                self.deferred_frames += frames;
            } else {
                self.step(frames, on_frame);
            }
        }
        self.lesson_after_advance();
        for s in &self.sessions {
            self.rates.learn(&s.instance.sim, s.ms_per_frame);
        }
        // what the user gets: the interval between the window's frames, and its drawing part
        let sim_ms = self.sessions.iter().map(|s| s.ms_per_frame).fold(0.0, f64::max);
        self.display.observe(self.playback.playing, dt, sim_ms);
        if self.playback.playing && !self.settling() {
            let slow = cost::slow_frame(&self.sessions).or_else(|| self.display.slow(sim_ms));
            if let Some(message) = slow {
                self.playback.playing = false;
                self.display.paused();
                self.message = Some(message);
            }
        }
        self.playback.last_clock_frame = true;
        let paused = !self.playback.playing && !self.settling();
        for s in &mut self.sessions {
            s.paused = paused;
        }
    }

    /// The frames due after `dt` seconds of real time ([`Model::tick`]).
    fn frames_due(&mut self, dt: f64, one_frame_per_tick: bool) -> usize {
        self.playback.was_settling |= self.settling();
        if !self.playback.playing || self.sessions.iter().all(|s| s.failure.is_some()) {
            self.playback.frame_budget_secs = 0.0;
            return 0;
        }
        let frame_secs = 1.0 / self.sessions[0].config.frames_per_second;
        if self.settling() {
            let ms = self.sessions.iter().map(|s| s.ms_per_frame).fold(0.0, f64::max).max(0.05);
            return ((SETTLE_STEP_BUDGET_MS / ms) as usize).clamp(1, 400);
        }
        if self.sessions.iter().any(|s| s.settle_outcome.is_some()) && self.playback.was_settling {
            // the settle just ended: show the state it reached
            self.playback.was_settling = false;
            self.playback.playing = false;
            return 0;
        }
        if one_frame_per_tick {
            return 1;
        }
        let frames = self.playback.frames_due(dt, frame_secs, self.sessions.iter().map(|s| s.ms_per_frame).sum());
        // a lesson step that plays some seconds ends on its last frame exactly, as `hox lesson`
        let t = self.sessions.first().map(|s| s.instance.sim.time_secs());
        frames.min(self.lesson.as_ref().zip(t).and_then(|(l, t)| l.frames_left(t, frame_secs)).unwrap_or(usize::MAX))
    }

    /// A step that plays for some seconds pauses at its end.
    fn lesson_after_advance(&mut self) {
        let t = self.sessions.first().map(|s| s.instance.sim.time_secs());
        if let (Some(state), Some(t)) = (&mut self.lesson, t) {
            self.playback.playing &= !state.played_to_its_end(t);
        }
    }

    /// Starts preparing step `k` of the open lesson; the model pauses until it is installed.
    fn go_to_step(&mut self, k: usize) {
        let Some(state) = &mut self.lesson else { return };
        state.go_to(k, self.background);
        self.playback.playing = false;
    }

    /// Installs the lesson step prepared in the background once it is ready (`wait`: waiting).
    fn poll_lesson(&mut self, wait: bool) {
        let Some(state) = &mut self.lesson else { return };
        let Some(sessions) = state.take_prepared(wait) else { return };
        let step = state.current().clone();
        self.sessions = sessions;
        self.compare = self.sessions.len() > 1;
        self.active = 0;
        self.show_reference_element = step.reference_element;
        if step.reference_element {
            self.reference_element = Some(step.configurations[0].params().element);
        }
        self.rebuilt();
        self.set_preset(step.camera.as_deref().and_then(ViewPreset::from_name).unwrap_or_default());
        self.playback.playing = step.run != Run::Static;
        self.playback.frame_budget_secs = 0.0;
        if step.run == Run::Settle {
            self.settle();
        }
    }
}
