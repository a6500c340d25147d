//! The interactive app (eframe/egui): explore and teach element behaviour live.
//!
//! Layout: a menu bar; on the left every control of the simulation (scene, element type, tet
//! split, grid, material, solver, playback, view, Rerun); in the middle the 3D viewport
//! ([`viewport`]); at the bottom the plots ([`plots`]) and a status line. Compare mode runs two
//! configurations side by side with per-control links. A change rebuilds only what it
//! invalidates ([`config::Invalidates`]); a value the scene validation refuses leaves the
//! running simulation untouched and shows the reason next to the control.
//!
//! Shortcuts: space play/pause, S single step, E settle, R reset. Settings persist across runs.
//!
//! Where to find things: [`HoxApp`] and its core (scene, compare mode, applying a change,
//! stepping) here; the window's panels and frame bookkeeping in `window.rs`; opening the window
//! in `run.rs`; playing and the clock in `playback.rs`; compare-mode links in `links.rs`; what
//! persists across runs in `persist.rs`; the live Rerun output in `rerun_link.rs`; frame-rate
//! measurement in `measure.rs`; the command-line options in `args.rs`.

mod args;
pub mod config;
pub mod controls;
mod cost;
mod figure;
pub mod gl_view;
pub mod lesson;
mod links;
mod measure;
mod persist;
mod playback;
pub mod plots;
pub mod raster;
pub mod readout;
mod rerun_link;
mod run;
mod serve_web;
pub mod session;
pub mod study_chart;
pub mod teach;
pub mod viewport;
mod window;

pub use args::AppArgs;
pub use links::Links;
pub use persist::{Persisted, SceneSource};
pub use playback::Playback;
pub use run::run;

use config::Config;
use hox_sim::Vec3;
use measure::{FrameTimes, Measure};
use playback::step_sessions;
use rerun_link::RerunLink;
use session::Session;
use viewport::{ViewOptions, Viewport};
use window::Screenshot;

/// The app: the running configurations and everything the window shows of them.
pub struct HoxApp {
    pub scene: SceneSource,
    pub sessions: Vec<Session>,
    pub active: usize,
    pub compare: bool,
    pub links: Links,
    pub view: ViewOptions,
    pub viewport: Viewport,
    pub playback: Playback,
    /// The last refused change: control, reason, when.
    pub refusal: Option<(String, String)>,
    pub message: Option<String>,
    /// A slow change waiting for the user's answer ([`cost`]).
    pub pending_change: Option<cost::PendingChange>,
    pub show_reference_element: bool,
    pub reference_element: teach::ReferenceElementView,
    pub bottom_tab: plots::Tab,
    /// The probe plot's components (None: u_z alone when comparing, else all three).
    pub probe_axes: Option<[bool; 3]>,
    pub rerun_url: String,
    pub rerun_file: String,
    /// Where *Export figure* writes the paper's figure of the view.
    pub figure_folder: String,
    /// Where the class's browsers are served (`--bind`, the ports, the history bound).
    pub serve: crate::web::ServeArgs,
    /// `--serve-fps`: frames a second sent to browsers at most (0: every frame).
    pub serve_fps: u32,
    rerun: Option<RerunLink>,
    generation: u64,
    /// Text being edited in numeric fields, by control.
    pub edits: std::collections::HashMap<String, String>,
    pub open_dialog: Option<controls::OpenDialog>,
    times: FrameTimes,
    screenshot: Option<Screenshot>,
    measure: Option<Measure>,
    /// The window has an OpenGL context (false in the headless UI tests).
    gl_available: bool,
    /// The OpenGL renderer's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"), if known.
    pub renderer: Option<String>,
    /// While playing, paint when the next simulated frame is due instead of at once: set for a
    /// software renderer (no vertical sync paces it) unless `--no-vsync` asks for the most
    /// frames (frame-rate measurements); off in the headless UI tests.
    pub pace_paint: bool,
    /// Frames to step once this frame's UI is built (in the background while the window paints).
    deferred_frames: usize,
    /// Sessions being stepped in the background, and how many frames.
    background: Option<(std::thread::JoinHandle<Vec<Session>>, usize)>,
    /// The lesson under way, if any ([`lesson`]).
    pub lesson: Option<lesson::LessonState>,
    /// Presenter mode: a larger interface, the 3D view filling the window.
    pub presenter: bool,
    /// An interface scale to apply at the next frame.
    zoom_wanted: Option<f32>,
    /// On the first frame that knows the monitor's size: shrink a window larger than the screen
    /// (a geometry saved on a larger screen, or a --size too large) to fit it.
    fit_to_screen: bool,
    /// Frames to wait before fitting (the scale set at the start takes a frame to reach eframe's
    /// report of the monitor and window sizes).
    fit_to_screen_in_frames: u8,
    /// The first start offers the lessons.
    pub offer_lessons: bool,
}

/// Whether a change from `old` to `new` changes how a configuration is drawn (a `[display]`
/// parameter of the table).
fn redraws(old: &Config, new: &Config) -> bool {
    old.changed_keys(new)
        .iter()
        .any(|k| hox_scenes::params::by_key(k).is_some_and(|p| p.group == hox_scenes::params::Group::Display))
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
        let view = saved.as_ref().map(|s| s.view.clone()).unwrap_or_default();
        let mut app = HoxApp {
            scene: scene.clone(),
            sessions: Vec::new(),
            active: 0,
            compare: false,
            links: saved.as_ref().map(|s| s.links.clone()).unwrap_or_default(),
            viewport: Viewport::new(saved.as_ref().filter(|_| same_scene).and_then(|s| s.camera)),
            view,
            playback: Playback::new(args.play, saved.as_ref().map_or(1.0, |s| s.time_scale)),
            refusal: None,
            message: None,
            pending_change: None,
            show_reference_element: saved.as_ref().is_some_and(|s| s.show_reference_element),
            reference_element: teach::ReferenceElementView::default(),
            bottom_tab: plots::Tab::default(),
            probe_axes: None,
            rerun_url: saved
                .as_ref()
                .map_or_else(|| "rerun+http://127.0.0.1:9876/proxy".into(), |s| s.rerun_url.clone()),
            rerun_file: saved.as_ref().map_or_else(|| "hox.rrd".into(), |s| s.rerun_file.clone()),
            figure_folder: "figures".into(),
            serve: args.serve.clone(),
            serve_fps: args.serve_fps,
            rerun: None,
            generation: 0,
            edits: Default::default(),
            open_dialog: None,
            times: FrameTimes::default(),
            screenshot: args.screenshot.clone().map(|p| Screenshot::new(p, args.after_secs)),
            measure: args.measure_secs.map(Measure::new),
            gl_available: false,
            renderer: None,
            pace_paint: false,
            deferred_frames: 0,
            background: None,
            lesson: None,
            presenter: false,
            // an ordinary start is at the ordinary scale, whatever egui's saved memory holds
            // from a presenter-mode session (issue #35: its 1.6 leaked into the next start)
            zoom_wanted: Some(1.0),
            fit_to_screen: true,
            fit_to_screen_in_frames: 3,
            // the very first start (no saved settings) offers the lessons
            offer_lessons: saved.is_none()
                && !args.fresh
                && args.lesson.is_none()
                && args.lesson_file.is_none()
                && args.screenshot.is_none()
                && args.measure_secs.is_none(),
        };
        let configs = saved.filter(|_| same_scene).map(|s| (s.configs, s.compare));
        app.load_scene(scene, configs)?;
        app.start_configurations(args)?;
        if let Some(v) = args.view {
            app.show_reference_element = v == args::StartView::ReferenceElement;
        }
        if let Some(preset) = args.camera {
            app.set_camera(preset);
        }
        if args.lesson_step.is_some() && args.lesson.is_none() && args.lesson_file.is_none() {
            return Err("--lesson-step needs a lesson: --lesson NAME or --lesson-file FILE".into());
        }
        if args.lesson.is_some() || args.lesson_file.is_some() {
            let lesson = crate::config::load_lesson(args.lesson.as_deref(), args.lesson_file.as_deref())
                .map_err(|e| format!("{e:#}"))?;
            let steps = lesson.steps.len();
            app.open_lesson(lesson);
            if let Some(n) = args.lesson_step {
                if !(1..=steps).contains(&n) {
                    return Err(format!("--lesson-step {n}: the lesson has steps 1 to {steps}"));
                }
                app.go_to_step(n - 1);
            }
            app.poll_lesson(true);
        }
        if args.presenter {
            app.set_presenter(true);
        }
        if args.serve_web {
            app.serve_web_at_start();
        }
        if app.measure.is_some() {
            app.playback.playing = true;
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
        if o.iter().next().is_none() && specs.is_empty() {
            if wants_pair && !self.compare {
                self.set_compare(true);
            }
            return Ok(());
        }
        let overrides = match specs.len() {
            0 => vec![o],
            2 => specs
                .iter()
                .map(|s| crate::config::parse_compare(s, &o).map_err(|e| format!("{e:#}")))
                .collect::<Result<Vec<_>, _>>()?,
            n => return Err(format!("--compare with values needs exactly two configurations for the app, got {n}")),
        };
        let base = self.sessions[0].base.clone();
        let mut sessions = Vec::new();
        for (k, o) in overrides.iter().enumerate() {
            let scene = base.with_overrides(o).map_err(|e| match specs.get(k) {
                Some(spec) => format!("--compare '{spec}': {e}"),
                None => e.to_string(),
            })?;
            sessions.push(Session::new(base.clone(), scene.params().clone())?);
        }
        self.sessions = sessions;
        self.compare = self.sessions.len() > 1;
        self.active = 0;
        self.rebuilt();
        if wants_pair && !self.compare {
            self.set_compare(true);
        }
        let offsets = self.offsets();
        self.viewport.reset_camera(&self.sessions, &offsets);
        Ok(())
    }

    /// Switches to `source`, with saved configurations if given (falling back to the scene's).
    pub fn load_scene(&mut self, source: SceneSource, configs: Option<(Vec<Config>, bool)>) -> Result<(), String> {
        let base = source.load()?;
        let defaults = config::from_scene(&base);
        let wanted = configs.clone().map(|c| c.0).filter(|c| !c.is_empty()).unwrap_or_else(|| vec![defaults.clone()]);
        let mut sessions = Vec::new();
        for c in wanted.into_iter().take(2) {
            // a saved configuration the scene no longer accepts falls back to the scene's own
            let s = Session::new(base.clone(), c).or_else(|_| Session::new(base.clone(), defaults.clone()))?;
            sessions.push(s);
        }
        self.scene = source;
        self.compare = sessions.len() > 1 && configs.is_some_and(|c| c.1);
        sessions.truncate(if self.compare { 2 } else { 1 });
        self.sessions = sessions;
        self.active = 0;
        self.refusal = None;
        self.rebuilt();
        self.viewport.reset_camera(&self.sessions, &self.offsets());
        Ok(())
    }

    /// Turns compare mode on (a second configuration: P1 refined once on a P2 scene, else a
    /// copy) or off.
    pub fn set_compare(&mut self, on: bool) {
        if on == self.compare {
            return;
        }
        if on {
            let first = &self.sessions[0];
            let mut c = first.config.clone();
            let is_box = first.base.is_box();
            // P2 is compared with P1 refined once (the same nodes), and P1 with P2
            let other = match c.element.name() {
                "p2" => Some(("p1", 1)),
                "p1" => Some(("p2", 0)),
                _ => None,
            };
            if is_box
                && let Some((name, refine)) = other
                && let Some(element) = hox_sim::element::ElementType::from_name(name)
            {
                c.element = element;
                c.refine = refine;
            }
            // a part meshed per element type: the same part at the other order (P1's facets
            // against P2's curved faces)
            if first.base.mesh_kind() == hox_scenes::params::MeshKind::Files
                && let Some((name, _)) = other
                && let Some(element) = hox_sim::element::ElementType::from_name(name)
            {
                c.element = element;
            }
            let second = Session::new(first.base.clone(), c.clone())
                .or_else(|_| Session::new(first.base.clone(), first.config.clone()));
            match second {
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
        self.viewport.reset_camera(&self.sessions, &self.offsets());
    }

    /// World offsets of the sessions: side by side across the camera preset's line of sight
    /// ([`crate::display`], [`viewport::ViewPreset::layout_axis`]).
    pub fn offsets(&self) -> Vec<Vec3> {
        let Some(first) = self.sessions.first() else { return Vec::new() };
        let axis = self.viewport.preset.layout_axis();
        crate::display::side_by_side_offsets(first.instance.sim.mesh(), self.sessions.len(), axis)
    }

    /// Colours by `field` (every session: colours compare only on one field).
    pub fn set_field(&mut self, field: hox_sim::measure::field::Field) {
        for k in 0..self.sessions.len() {
            let mut c = self.sessions[k].config.clone();
            c.field = vec![field];
            if let Err(e) = self.sessions[k].apply(c) {
                self.refusal = Some(("field".into(), e));
            }
        }
        self.generation += 1;
    }

    /// The field after the one drawn (key F).
    pub fn next_field(&mut self) {
        use hox_sim::measure::field::Field;
        let Some(first) = self.sessions.first() else { return };
        let now = crate::display::fields(&first.config)[0];
        let k = Field::ALL.iter().position(|f| *f == now).unwrap_or(0);
        self.set_field(Field::ALL[(k + 1) % Field::ALL.len()]);
    }

    /// Looks from `preset`: the configurations laid apart across its line of sight, framed.
    pub fn set_camera(&mut self, preset: viewport::ViewPreset) {
        self.viewport.preset = preset;
        let offsets = self.offsets();
        self.viewport.reset_camera(&self.sessions, &offsets);
        // the layout changed: recordings log it again
        self.generation += 1;
    }

    /// Applies `new` to the active session and, in compare mode, the linked fields to the
    /// other; a change estimated too slow to play waits for the user's answer ([`cost`]). A
    /// refusal keeps everything as it was and records the reason.
    pub fn apply(&mut self, control: &str, new: Config) {
        if let Some(estimate) = self.too_slow(&new) {
            self.pending_change = Some(cost::PendingChange { control: control.to_string(), config: new, estimate });
            return;
        }
        self.apply_now(control, new);
    }

    /// [`HoxApp::apply`] without asking.
    pub fn apply_now(&mut self, control: &str, new: Config) {
        let k = self.active;
        let old = self.sessions[k].config.clone();
        match self.sessions[k].apply(new.clone()) {
            Ok(what) => {
                self.refusal = None;
                // a new mesh, or a new way of drawing it: Rerun logs the static data again
                if what == config::Invalidates::Mesh || redraws(&old, &new) {
                    self.rebuilt();
                }
            }
            Err(reason) => {
                self.refusal = Some((control.to_string(), reason));
                return;
            }
        }
        if self.compare {
            let other = 1 - k;
            let mut follow = self.sessions[other].config.clone();
            for f in old.changed_keys(&new) {
                if self.links.linked(f) {
                    follow.copy_from(&new, f);
                }
            }
            match self.sessions[other].apply(follow) {
                Ok(config::Invalidates::Mesh) => self.rebuilt(),
                Ok(_) if redraws(&old, &new) => self.rebuilt(),
                Ok(_) => {}
                Err(reason) => {
                    self.refusal = Some((control.to_string(), format!("the other configuration refused it: {reason}")))
                }
            }
        }
    }

    /// Something was rebuilt: Rerun loggers must log the new static data.
    fn rebuilt(&mut self) {
        self.generation += 1;
    }

    /// The *Settle* action (E): every configuration runs with its settle damping, as fast as
    /// the machine allows, until at rest, then pauses ([`Session::start_settle`]).
    pub fn settle(&mut self) {
        self.join_background();
        for s in &mut self.sessions {
            s.start_settle();
        }
        self.playback.playing = true;
    }

    /// Whether a *Settle* is under way in any configuration.
    pub fn settling(&self) -> bool {
        playback::any_settling(&self.sessions)
    }

    pub fn reset(&mut self) {
        for s in &mut self.sessions {
            s.reset();
        }
        self.playback.frame_budget_secs = 0.0;
        self.rebuilt();
    }

    /// Advances every session by `frames` frames (in parallel in compare mode); a *Settle* that
    /// ends on the way stops there, at rest (issue #35: the frames left ran on undamped).
    pub fn step(&mut self, frames: usize) {
        self.join_background();
        let one_at_a_time = self.lesson_times_frames();
        let settling = self.settling();
        for _ in 0..frames {
            if settling && !self.settling() {
                break;
            }
            step_sessions(&mut self.sessions, one_at_a_time);
            self.log_rerun();
            if let Some(m) = &mut self.measure {
                m.sim_frames += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests;
