//! What can be done to the app: [`Action`]s change the model ([`super::model::Model::apply`], the
//! one way it changes); [`Command`]s are what panels and keys return — an action, or a request to
//! a service (the Rerun link, a file to write, the open dialog's file to read). As Rerun's viewer
//! sends `SystemCommand`s from panels that see a narrow context.

use super::config::{Config, SceneSource};
use super::presets::{ViewOptions, ViewPreset};
use super::session::Drag;
use hox_scenes::lesson::Lesson;
use hox_sim::measure::field::Field;

/// A change of the model. (A few are not sent by the window's panels: the model's tests and, next,
/// other front ends send them.)
#[derive(Clone, Debug)]
#[cfg_attr(not(test), allow(dead_code))]
pub enum Action {
    /// Takes in what finished in the background: stepped frames, references, a lesson step
    /// (waiting for the lesson step when `wait_for_lesson`).
    Poll {
        wait_for_lesson: bool,
    },
    /// `real_dt_secs` of real time passed: the frames due are stepped (one per tick when
    /// `one_frame_per_tick`, measuring the frame rate), on the stepper when `in_background`.
    Tick {
        real_dt_secs: f64,
        one_frame_per_tick: bool,
        in_background: bool,
    },
    /// Hands the frames the ticks deferred to the stepper (stepped while the window paints);
    /// the next action takes the sessions back.
    StepDeferred,
    SetPlaying(bool),
    TogglePlaying,
    /// Steps so many frames now (a settle that ends on the way stops there).
    Step(usize),
    Settle,
    Reset,
    SetTimeScale(f64),
    LoadScene(SceneSource),
    /// Replaces the configurations: these overrides on the scene's own, one configuration each
    /// (with the text that asked for it, named in a refusal); two turn compare mode on.
    Configure(Vec<(Option<String>, hox_scenes::SceneOverrides)>),
    SetCompare(bool),
    /// The configuration the controls change (0: A, 1: B).
    SetActive(usize),
    /// A control's new configuration for the active session; a change estimated too slow to play
    /// waits for the user's answer.
    Change {
        control: String,
        config: Box<Config>,
    },
    /// The same, without asking.
    ChangeNow {
        control: String,
        config: Box<Config>,
    },
    /// The answer to a held-back slow change: apply it (paused) or keep the current one.
    AnswerPending(bool),
    /// A control's value refused before it reached the model (it did not parse).
    Refuse {
        control: String,
        reason: String,
    },
    SetLink {
        key: String,
        linked: bool,
    },
    SetField(Field),
    NextField,
    SetPreset(ViewPreset),
    SetView(ViewOptions),
    ShowReferenceElement(bool),
    /// The mouse drag of session `session` (None: released).
    Drag {
        session: usize,
        drag: Option<Drag>,
    },
    OpenLesson(Box<Lesson>),
    GoToStep(usize),
    /// The next (+1) or previous (−1) step.
    LessonStep(i64),
    RevealAnswer,
    CloseLesson,
    SetPresenter(bool),
    /// A message for the status of the menu bar (a service's outcome).
    Say(String),
}

impl Action {
    /// A control's change of the active configuration.
    pub fn change(control: &str, config: Config) -> Action {
        Action::Change { control: control.to_string(), config: Box::new(config) }
    }
}

/// Where the live Rerun output goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RerunTarget {
    /// A running Rerun viewer at the URL of the Rerun section.
    Viewer,
    /// The .rrd file of the Rerun section.
    File,
    /// The class's browsers: the web viewer served on the addresses of `--bind` and the ports.
    Browsers,
}

/// What a panel or a key asks for.
#[derive(Clone, Debug)]
pub enum Command {
    Model(Action),
    /// Starts live Rerun output to a target (stopping any), or stops it.
    Rerun(Option<RerunTarget>),
    /// Writes the paper's figure of the configurations on screen to the folder of the Figure
    /// section.
    ExportFigure,
    /// Opens the scene file of the open dialog (`mesh`: a mesh file with a clamp group).
    OpenFile {
        mesh: bool,
        path: std::path::PathBuf,
        clamp_group: String,
    },
    /// Opens a mesh file given as bytes (dropped onto the window or the page), its group
    /// `clamp` held, gravity on.
    OpenMeshBytes {
        name: String,
        bytes: std::sync::Arc<[u8]>,
    },
}

impl From<Action> for Command {
    fn from(a: Action) -> Command {
        Command::Model(a)
    }
}

/// The commands of one frame, in the order given.
#[derive(Default)]
pub struct Commands(pub Vec<Command>);

impl Commands {
    pub fn push(&mut self, c: impl Into<Command>) {
        self.0.push(c.into());
    }
}
