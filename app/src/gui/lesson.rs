//! A lesson under way in the model (issue #21): a lesson's steps ([`hox_scenes::lesson`]) set
//! the configurations, camera and view; each step is prepared in the background
//! ([`super::background::Background`]: meshes built, static solutions solved) and installed by
//! the model once ready. What the class sees of it is `lesson_panel.rs`.

use super::background::{Background, Pending};
use super::session::Session;
use hox_scenes::lesson::{Lesson, Measure, Measured, Run, Step};

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
    pub(super) play_until_secs: Option<f64>,
    /// Why the last step could not be set up, if it could not.
    pub problem: Option<String>,
    /// What each configuration's measurement is against, when it needs one of its own (the
    /// solver's error: the static solution of that mesh, solved when the step opens).
    own_references: Vec<Option<hox_scenes::reference::Reference>>,
    /// The step being prepared in the background (meshes built, static solutions solved):
    /// until it is ready the panel says so and shows no numbers (issue #35: the last step's
    /// answer stayed 5–6 s with no sign of work).
    preparing: Option<Pending<Prepared>>,
}

/// A step's configurations, built and (for a static step, or the solver's error) solved.
pub struct Prepared {
    pub sessions: Vec<Session>,
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
    /// `lesson` on its first step, being prepared (by `background`).
    pub fn open(lesson: Lesson, background: Background) -> LessonState {
        let mut state = LessonState {
            lesson,
            step: 0,
            revealed: false,
            play_until_secs: None,
            problem: None,
            own_references: Vec::new(),
            preparing: None,
        };
        state.go_to(0, background);
        state
    }

    /// Starts preparing step `k` (by `background`); a step asked for while another is prepared
    /// replaces it (its result is dropped).
    pub fn go_to(&mut self, k: usize, background: Background) {
        let k = k.min(self.lesson.steps.len() - 1);
        self.step = k;
        self.revealed = false;
        self.problem = None;
        self.play_until_secs = None;
        let step = self.lesson.steps[k].clone();
        self.preparing = Some(background.run(move || prepare(&step)));
    }

    /// The step `delta` steps from the one on screen, within the lesson; None if it is this one.
    pub fn step_by(&self, delta: i64) -> Option<usize> {
        let k = (self.step as i64 + delta).clamp(0, self.lesson.steps.len() as i64 - 1) as usize;
        (k != self.step).then_some(k)
    }

    /// Shows the answer, once the step is prepared (its numbers on screen).
    pub fn reveal(&mut self) {
        self.revealed |= !self.preparing();
    }

    /// Frames of `frame_secs` left at `t` seconds before a step that plays some seconds ends
    /// (None: it does not end so).
    pub fn frames_left(&self, t: f64, frame_secs: f64) -> Option<usize> {
        self.play_until_secs.map(|until| ((until - t) / frame_secs - 1e-6).ceil().max(0.0) as usize)
    }

    /// Whether a step that plays some seconds has played them at `t` (then it plays no more).
    pub fn played_to_its_end(&mut self, t: f64) -> bool {
        let ended = self.play_until_secs.is_some_and(|until| t >= until - 1e-9);
        if ended {
            self.play_until_secs = None;
        }
        ended
    }

    /// The step on screen.
    pub fn current(&self) -> &Step {
        &self.lesson.steps[self.step]
    }

    /// The prepared step's configurations once ready (`wait`: waiting for them), its problem
    /// kept; None while it is being prepared, or when it has no configurations to install.
    pub fn take_prepared(&mut self, wait: bool) -> Option<Vec<Session>> {
        if !wait && !self.preparing.as_ref().is_some_and(Pending::is_ready) {
            return None;
        }
        let prepared = self.preparing.take()?.take().unwrap_or_else(|| Prepared {
            sessions: Vec::new(),
            own_references: Vec::new(),
            problem: Some("preparing the step stopped unexpectedly".into()),
        });
        self.problem = prepared.problem;
        if prepared.sessions.is_empty() {
            return None;
        }
        self.own_references = prepared.own_references;
        self.play_until_secs = match self.current().run {
            Run::Seconds(secs) => Some(secs),
            _ => None,
        };
        Some(prepared.sessions)
    }

    /// Whether the step on screen times its frames (their median is its measurement): its
    /// configurations then step one after the other, as `hox lesson` steps them.
    pub fn times_frames(&self) -> bool {
        self.current().measure == Measure::MsPerFrame
    }

    /// "A: Element p1 · Poisson ratio ν 0.49", a line per configuration of the step on screen:
    /// the parameters the lesson's steps change.
    pub fn parameter_lines(&self) -> Vec<String> {
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
                None if step.run == Run::Static && s.solving_static => {
                    Measured { value: f64::NAN, text: "solving the static equilibrium of the values shown…".into() }
                }
                // issue #57: the old shape kept the old numbers under the new values
                None if step.run == Run::Static && !s.shown_static && s.changed_at_secs.is_some() => Measured {
                    value: f64::NAN,
                    text: "changed: not the static equilibrium of the values shown (Settle for it)".into(),
                },
                None if step.run == Run::Settle && s.settle_outcome.is_none() && s.settler.is_some() => {
                    Measured { value: f64::NAN, text: format!("settling… (t = {:.2} s)", s.instance.sim.time_secs()) }
                }
                None if step.run == Run::Settle && s.settle_outcome.is_none() => {
                    Measured { value: f64::NAN, text: "changed: not settled for the values shown (Settle)".into() }
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

    /// The step's claim judged against its `measured` numbers ([`LessonState::measured`]), once
    /// they are all measured.
    pub fn judge_claim(&self, measured: &[Measured]) -> Option<hox_scenes::claim::Judged> {
        let values: Vec<f64> = measured.iter().map(|m| m.value).collect();
        self.current().claim.as_ref()?.judge(&values)
    }

    /// The step as the browsers' "Lesson" view shows it: title, question, the numbers as the
    /// app's panel shows them, the answer once revealed.
    pub fn step_markdown(&self, sessions: &[Session]) -> String {
        let step = self.current();
        let mut text = format!(
            "# {}\n\n## Step {} of {}: {}\n\n{}\n\n",
            self.lesson.title,
            self.step + 1,
            self.lesson.steps.len(),
            step.title,
            step.question
        );
        if self.preparing() {
            text += &format!("*{PREPARING}*\n");
            return text;
        }
        let measured = self.measured(sessions);
        for (k, m) in measured.iter().enumerate() {
            text += &format!("- **{}**: {}\n", ["A", "B"][k.min(1)], m.text);
        }
        if self.revealed {
            text += &format!("\n**Answer:** {}\n", step.answer);
            if let Some(j) = self.judge_claim(&measured) {
                text += &format!("\n*{}*\n", j.text);
            }
        }
        text
    }
}
