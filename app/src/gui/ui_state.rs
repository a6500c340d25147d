//! The UI's own state, apart from the model: what is open, the camera, the text being edited,
//! the interface's scale; and [`Ctx`], what a panel sees — the model to read, this state, what the
//! services report, and the commands it returns.

use super::action::Commands;
use super::model::Model;
use super::teach::ReferenceElementView;
use super::viewport::Viewport;
use hox_sim::element::ElementType;

/// The bottom panel's tab.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tab {
    #[default]
    Probe,
    Energy,
    Study,
}

/// The File → Open dialog: a path typed or picked from the project's assets.
#[derive(Clone, Debug, Default)]
pub struct OpenDialog {
    pub mesh: bool,
    pub path: String,
    pub clamp_group: String,
    pub error: Option<String>,
}

/// What the services report, for the panels to show (a snapshot taken each frame).
#[derive(Clone, Debug, Default)]
pub struct Status {
    /// Where the live Rerun output goes ("serving browsers at …"), if anywhere.
    pub rerun_target: Option<String>,
    /// The page the class's browsers open, while serving them.
    pub web_url: Option<String>,
    /// The address browsers are served on (`--bind`).
    pub bind: String,
    /// Wall time between displayed frames, CPU of the app's part and of the 3D view, ms.
    pub ui_frame_ms: f64,
    pub app_ms: f64,
    /// The OpenGL renderer's name, if known.
    pub renderer: Option<String>,
}

/// The UI's state.
pub struct UiState {
    pub viewport: Viewport,
    /// The lesson step's measurements this frame, taken once by the window for the panel, the
    /// caption, the status line and the labels (None: no lesson, or a step being prepared).
    pub lesson_measured: Option<Vec<hox_scenes::lesson::Measured>>,
    pub reference_element: ReferenceElementView,
    /// The controls panel shown or folded as asked (None: folded in a lesson on a narrow window).
    pub controls_shown: Option<bool>,
    pub bottom_tab: Tab,
    /// The probe plot's components (None: u_z alone when comparing, else all three).
    pub probe_axes: Option<[bool; 3]>,
    /// The Rerun section's viewer URL and file, and the Figure section's folder.
    pub rerun_url: String,
    pub rerun_file: String,
    pub figure_folder: String,
    /// Text being edited in numeric fields, by control.
    pub edits: std::collections::HashMap<String, String>,
    pub open_dialog: Option<OpenDialog>,
    /// An interface scale to apply at the next frame.
    pub zoom_wanted: Option<f32>,
    /// On the first frames that know the monitor's size: shrink a window larger than the
    /// screen to fit it, after so many frames (the start's scale takes a frame to reach
    /// eframe's report of the monitor and window sizes).
    pub fit_to_screen: bool,
    /// The window's size was restored, not asked for (`--size`): one too small to use grows.
    pub grow_to_usable: bool,
    pub fit_to_screen_in_frames: u8,
    /// The first start offers the lessons.
    pub offer_lessons: bool,
    /// What of the model this state has followed ([`UiState::follow`]).
    seen: Seen,
}

#[derive(Default)]
struct Seen {
    layout: u64,
    presenter: bool,
    reference_element: Option<ElementType>,
}

impl UiState {
    pub fn new(viewport: Viewport, rerun_url: String, rerun_file: String, offer_lessons: bool) -> UiState {
        UiState {
            viewport,
            lesson_measured: None,
            reference_element: ReferenceElementView::default(),
            controls_shown: None,
            bottom_tab: Tab::default(),
            probe_axes: None,
            rerun_url,
            rerun_file,
            figure_folder: "figures".into(),
            edits: Default::default(),
            open_dialog: None,
            // an ordinary start is at the ordinary scale, whatever egui's saved memory holds
            // from a presenter-mode session (issue #35: its 1.6 leaked into the next start)
            zoom_wanted: Some(1.0),
            fit_to_screen: true,
            grow_to_usable: true,
            fit_to_screen_in_frames: 3,
            offer_lessons,
            seen: Seen::default(),
        }
    }

    /// Follows what the model changed: a new layout of the bodies frames them again from its
    /// preset, presenter mode scales the interface, a lesson step's element is shown in the
    /// reference-element view.
    pub fn follow(&mut self, model: &Model) {
        if model.sessions().is_empty() {
            return;
        }
        if model.layout() != self.seen.layout {
            self.seen.layout = model.layout();
            self.viewport.preset = model.preset();
            self.viewport.reset_camera(model.sessions(), &model.offsets());
        }
        if model.presenter() != self.seen.presenter {
            self.seen.presenter = model.presenter();
            self.zoom_wanted = Some(if model.presenter() { super::lesson::PRESENTER_ZOOM } else { 1.0 });
        }
        if model.reference_element() != self.seen.reference_element {
            self.seen.reference_element = model.reference_element();
            if let Some(e) = model.reference_element() {
                self.reference_element.set_element(e);
            }
        }
    }

    /// Which displacement components the probe plot shows: the user's choice, else all three
    /// for one configuration and u_z alone when comparing (six lines would bury each other).
    pub fn probe_axes(&self, compare: bool) -> [bool; 3] {
        self.probe_axes.unwrap_or(if compare { [false, false, true] } else { [true, true, true] })
    }
}

/// What a panel sees: the model (read only), the UI's state, the services' status, and the
/// commands it returns.
pub struct Ctx<'a> {
    pub model: &'a Model,
    pub state: &'a mut UiState,
    pub status: &'a Status,
    pub out: &'a mut Commands,
}
