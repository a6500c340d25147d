//! The interactive app (eframe/egui): explore and teach element behaviour live.
//!
//! Layout: a menu bar; on the left every control of the simulation (scene, element type, tet
//! split, grid, material, solver, playback, view, Rerun); in the middle the 3D viewport
//! ([`viewport`]); at the bottom the plots ([`plots`]) and a status line. Compare mode runs two
//! configurations side by side with per-control links. A change rebuilds only what it
//! invalidates ([`config::Invalidates`]); a value the scene validation refuses leaves the
//! running simulation untouched and shows the reason next to the control.
//!
//! Shortcuts: space play/pause, S single step, R reset. Settings persist across runs.

pub mod config;
pub mod controls;
pub mod gl_view;
pub mod plots;
pub mod raster;
pub mod session;
pub mod study_chart;
pub mod teach;
pub mod viewport;

use crate::recording::{LogSettings, SimLogger};
use config::Config;
use eframe::egui;
use hox_scenes::Scene;
use hox_sim::Vec3;
use session::Session;
use std::path::PathBuf;
use std::time::Instant;
use viewport::{ViewOptions, Viewport};

/// Which controls of the second configuration follow the first (compare mode).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Links(pub std::collections::BTreeMap<String, bool>);

/// The parameters a link can tie: those the app shows, in control order (the parameter table).
pub fn linkable() -> impl Iterator<Item = &'static str> {
    hox_scenes::params::PARAMS.iter().filter(|p| p.surfaces.app).map(|p| p.key)
}

impl Default for Links {
    fn default() -> Self {
        // the classroom comparison: different element (and refinement), everything else shared
        Links(linkable().map(|f| (f.to_string(), !matches!(f, "element" | "refine"))).collect())
    }
}

impl Links {
    pub fn linked(&self, field: &str) -> bool {
        self.0.get(field).copied().unwrap_or(true)
    }
}

/// Where the scene comes from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SceneSource {
    Builtin(String),
    File(PathBuf),
}

impl SceneSource {
    pub fn load(&self) -> Result<Scene, String> {
        match self {
            SceneSource::Builtin(name) => hox_scenes::by_name(name).map_err(|e| e.to_string()),
            SceneSource::File(path) => Scene::load(path).map_err(|e| e.to_string()),
        }
    }
    pub fn label(&self) -> String {
        match self {
            SceneSource::Builtin(name) => name.clone(),
            SceneSource::File(path) => path.display().to_string(),
        }
    }
}

/// What persists across runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Persisted {
    pub scene: SceneSource,
    pub configs: Vec<Config>,
    pub compare: bool,
    pub links: Links,
    pub view: ViewOptions,
    pub camera: Option<raster::Camera>,
    pub time_scale: f64,
    pub show_reference_element: bool,
    pub rerun_url: String,
    pub rerun_file: String,
}

/// Command-line options of the app.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct AppArgs {
    /// Start on this built-in scene (default: the last one used, or bending).
    #[arg(long)]
    pub scene: Option<String>,
    /// Start on this scene file.
    #[arg(long, conflicts_with = "scene")]
    pub scene_file: Option<PathBuf>,
    /// Ignore the saved settings.
    #[arg(long)]
    pub fresh: bool,
    /// Start playing at once.
    #[arg(long)]
    pub play: bool,
    /// Start in compare mode (P1 refined once against P2 on the paper scenes).
    #[arg(long)]
    pub compare: bool,
    /// Save a PNG of the window after --after-secs and quit (for docs and tests).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Measure the frame rate for this many seconds of playing, print it and quit.
    #[arg(long)]
    pub measure_secs: Option<f64>,
    /// Delay before --screenshot, seconds.
    #[arg(long, default_value_t = 3.0)]
    pub after_secs: f64,
    /// Window size in points, WIDTHxHEIGHT (default: the size of the last run, else 1400x900).
    #[arg(long)]
    pub size: Option<String>,
    /// Do not wait for the display's vertical sync (frame-rate measurements).
    #[arg(long)]
    pub no_vsync: bool,
}

/// Live Rerun output through the shared logging module.
struct RerunLink {
    rec: rerun::RecordingStream,
    loggers: Vec<SimLogger>,
    generation: u64,
    target: String,
}

/// Frame-rate measurement for `--measure-secs`.
struct Measure {
    until_secs: f64,
    started: Option<Instant>,
    frames: u64,
    sim_frames: u64,
    frame_ms: Vec<f64>,
    last: Option<Instant>,
}

pub struct HoxApp {
    pub scene: SceneSource,
    pub sessions: Vec<Session>,
    pub active: usize,
    pub compare: bool,
    pub links: Links,
    pub view: ViewOptions,
    pub viewport: Viewport,
    pub playing: bool,
    pub time_scale: f64,
    frame_budget_secs: f64,
    /// The last refused change: control, reason, when.
    pub refusal: Option<(String, String)>,
    pub message: Option<String>,
    pub show_reference_element: bool,
    pub reference_element: teach::ReferenceElementView,
    pub bottom_tab: plots::Tab,
    pub rerun_url: String,
    pub rerun_file: String,
    rerun: Option<RerunLink>,
    generation: u64,
    /// Text being edited in numeric fields, by control.
    pub edits: std::collections::HashMap<String, String>,
    pub open_dialog: Option<controls::OpenDialog>,
    ui_frame_ms: f64,
    /// Wall time of our own part of a frame (stepping, controls, viewport, plots), milliseconds.
    app_ms: f64,
    /// CPU time of a whole frame (ours, egui's layout and painting; not waiting for vsync), ms.
    frame_cpu_ms: f64,
    last_ui_frame: Option<Instant>,
    /// A frame has been shown (the first frame's clock step is not a real interval).
    last_clock_frame: bool,
    screenshot: Option<(PathBuf, f64)>,
    screenshot_requested: bool,
    measure: Option<Measure>,
    /// The window has an OpenGL context (false in the headless UI tests).
    gl_available: bool,
    /// The OpenGL renderer's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"), if known.
    pub renderer: Option<String>,
    /// Frames to step once this frame's UI is built (in the background while the window paints).
    deferred_frames: usize,
    /// Sessions being stepped in the background, and how many frames.
    background: Option<(std::thread::JoinHandle<Vec<Session>>, usize)>,
    started: Instant,
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
            playing: args.play,
            time_scale: saved.as_ref().map_or(1.0, |s| s.time_scale),
            frame_budget_secs: 0.0,
            refusal: None,
            message: None,
            show_reference_element: saved.as_ref().is_some_and(|s| s.show_reference_element),
            reference_element: teach::ReferenceElementView::default(),
            bottom_tab: plots::Tab::default(),
            rerun_url: saved
                .as_ref()
                .map_or_else(|| "rerun+http://127.0.0.1:9876/proxy".into(), |s| s.rerun_url.clone()),
            rerun_file: saved.as_ref().map_or_else(|| "hox.rrd".into(), |s| s.rerun_file.clone()),
            rerun: None,
            generation: 0,
            edits: Default::default(),
            open_dialog: None,
            ui_frame_ms: 0.0,
            app_ms: 0.0,
            frame_cpu_ms: 0.0,
            last_ui_frame: None,
            last_clock_frame: false,
            screenshot: args.screenshot.clone().map(|p| (p, args.after_secs)),
            screenshot_requested: false,
            measure: args.measure_secs.map(|s| Measure {
                until_secs: s,
                started: None,
                frames: 0,
                sim_frames: 0,
                frame_ms: Vec::new(),
                last: None,
            }),
            gl_available: false,
            renderer: None,
            deferred_frames: 0,
            background: None,
            started: Instant::now(),
        };
        let configs = saved.filter(|_| same_scene).map(|s| (s.configs, s.compare));
        app.load_scene(scene, configs)?;
        if args.compare && !app.compare {
            app.set_compare(true);
        }
        if app.measure.is_some() {
            app.playing = true;
        }
        Ok(app)
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
            if is_box && c.element == "p2" {
                c.element = "p1".into();
                c.refine = 1;
            } else if is_box && c.element == "p1" {
                c.element = "p2".into();
                c.refine = 0;
            }
            let second = Session::new(first.base.clone(), c.clone())
                .or_else(|_| Session::new(first.base.clone(), first.config.clone()));
            match second {
                Ok(s) => {
                    // P1 first, so the pair reads "P1 vs P2" left to right
                    self.sessions.push(s);
                    if self.sessions[1].config.element == "p1" {
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

    /// World offsets of the sessions (side by side along y, [`crate::display`]).
    pub fn offsets(&self) -> Vec<Vec3> {
        let Some(first) = self.sessions.first() else { return Vec::new() };
        crate::display::side_by_side_offsets(first.instance.sim.mesh(), self.sessions.len())
    }

    /// Applies `new` to the active session and, in compare mode, the linked fields to the
    /// other. A refusal keeps everything as it was and records the reason.
    pub fn apply(&mut self, control: &str, new: Config) {
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

    pub fn reset(&mut self) {
        for s in &mut self.sessions {
            s.reset();
        }
        self.frame_budget_secs = 0.0;
        self.rebuilt();
    }

    /// Advances every session by `frames` frames (in parallel in compare mode).
    pub fn step(&mut self, frames: usize) {
        self.join_background();
        for _ in 0..frames {
            step_sessions(&mut self.sessions);
            self.log_rerun();
            if let Some(m) = &mut self.measure {
                m.sim_frames += 1;
            }
        }
    }

    /// Steps the frames `advance` deferred on a background thread, so that the simulation runs
    /// while the window paints (the paint is the longer part of a frame with a software renderer;
    /// docs/APP.md). The next frame starts by taking the sessions back.
    fn start_background_step(&mut self) {
        let frames = std::mem::take(&mut self.deferred_frames);
        if frames == 0 || self.background.is_some() || self.sessions.is_empty() {
            return;
        }
        let mut sessions = std::mem::take(&mut self.sessions);
        let handle = std::thread::spawn(move || {
            for _ in 0..frames {
                step_sessions(&mut sessions);
            }
            sessions
        });
        self.background = Some((handle, frames));
    }

    /// Takes back the sessions stepped in the background (no-op if none are).
    pub fn join_background(&mut self) {
        let Some((handle, frames)) = self.background.take() else { return };
        match handle.join() {
            Ok(sessions) => self.sessions = sessions,
            Err(panic) => std::panic::resume_unwind(panic),
        }
        if let Some(m) = &mut self.measure {
            m.sim_frames += frames as u64;
        }
    }

    /// Steps now, or after the UI is built when the window can overlap stepping with painting
    /// (not with a live Rerun link, which logs every frame in order).
    fn step_or_defer(&mut self, frames: usize) {
        if self.gl_available && self.rerun.is_none() {
            self.deferred_frames += frames;
        } else {
            self.step(frames);
        }
    }

    /// Starts or stops live Rerun output: `to_file` saves to the .rrd path, otherwise streams to
    /// the viewer URL.
    pub fn set_rerun(&mut self, on: bool, to_file: bool) {
        if !on {
            if let Some(link) = self.rerun.take() {
                let _ = link.rec.flush_blocking();
                self.message = Some(format!("Rerun: stopped ({})", link.target));
            }
            return;
        }
        let builder =
            rerun::RecordingStreamBuilder::new("hox").recording_name(format!("hox app {}", self.scene.label()));
        let (rec, target) = if to_file {
            let path = PathBuf::from(&self.rerun_file);
            if let Err(e) = crate::output::check_writable(&path) {
                self.message = Some(format!("Rerun: {e:#}"));
                return;
            }
            (builder.save(&path), format!("saving to {}", path.display()))
        } else {
            (builder.connect_grpc_opts(self.rerun_url.clone()), format!("streaming to {}", self.rerun_url))
        };
        match rec {
            Ok(rec) => {
                self.rerun = Some(RerunLink { rec, loggers: Vec::new(), generation: u64::MAX, target: target.clone() });
                self.message = Some(format!("Rerun: {target}"));
                self.log_rerun();
            }
            Err(e) => self.message = Some(format!("Rerun: {e}")),
        }
    }

    pub fn rerun_target(&self) -> Option<&str> {
        self.rerun.as_ref().map(|l| l.target.as_str())
    }

    fn log_rerun(&mut self) {
        let offsets = self.offsets();
        let Some(link) = &mut self.rerun else { return };
        if link.generation != self.generation {
            let colours = Viewport::colour_range(&self.sessions);
            link.loggers.clear();
            for (k, (s, o)) in self.sessions.iter().zip(&offsets).enumerate() {
                let name = format!("{}_{}", ["a", "b"][k.min(1)], s.label());
                let settings = LogSettings::new(&s.config, colours);
                match SimLogger::new(&link.rec, &name, &s.instance, *o, &settings) {
                    Ok(l) => link.loggers.push(l),
                    Err(e) => {
                        self.message = Some(format!("Rerun: {e}"));
                        self.rerun = None;
                        return;
                    }
                }
            }
            link.generation = self.generation;
        }
        for (s, l) in self.sessions.iter().zip(&mut link.loggers) {
            if let Err(e) = l.log_frame(&link.rec, &s.instance, s.ms_per_frame) {
                self.message = Some(format!("Rerun: {e}"));
                self.rerun = None;
                return;
            }
        }
    }

    pub fn persisted(&self) -> Persisted {
        Persisted {
            scene: self.scene.clone(),
            configs: self.sessions.iter().map(|s| s.config.clone()).collect(),
            compare: self.compare,
            links: self.links.clone(),
            view: self.view.clone(),
            camera: Some(self.viewport.camera),
            time_scale: self.time_scale,
            show_reference_element: self.show_reference_element,
            rerun_url: self.rerun_url.clone(),
            rerun_file: self.rerun_file.clone(),
        }
    }

    /// Keyboard shortcuts (when no text field has the keyboard).
    fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (space, s, r) =
            ctx.input(|i| (i.key_pressed(egui::Key::Space), i.key_pressed(egui::Key::S), i.key_pressed(egui::Key::R)));
        if space {
            self.playing = !self.playing;
        }
        if s {
            self.playing = false;
            self.step(1);
        }
        if r {
            self.reset();
        }
    }

    /// Steps as much simulated time as passed in real time × time scale (at most 4 frames per
    /// displayed frame, so a slow configuration slows down instead of freezing the window).
    fn advance(&mut self, real_dt_secs: f64) {
        if !self.playing || self.sessions.iter().all(|s| s.failure.is_some()) {
            self.frame_budget_secs = 0.0;
            return;
        }
        let frame_secs = 1.0 / self.sessions[0].config.frames_per_second;
        if self.measure.is_some() {
            // measuring: one simulation frame per displayed frame
            self.step_or_defer(1);
            return;
        }
        self.frame_budget_secs += real_dt_secs.min(0.25) * self.time_scale;
        let frames = ((self.frame_budget_secs / frame_secs).floor() as usize).min(4);
        self.frame_budget_secs = (self.frame_budget_secs - frames as f64 * frame_secs).min(frame_secs);
        self.step_or_defer(frames);
    }

    fn status_line_ui(&self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            for (k, s) in self.sessions.iter().enumerate() {
                let sim = &s.instance.sim;
                let mut text = format!(
                    "{}{}: {} nodes, {} elements, {} constraints, {:.2} ms/frame, residual {:.1e}, t = {:.2} s",
                    if self.compare { ["A ", "B "][k] } else { "" },
                    s.label(),
                    sim.mesh().num_nodes(),
                    sim.mesh().num_elements(),
                    sim.num_constraints(),
                    s.ms_per_frame,
                    s.residual,
                    sim.time_secs()
                );
                if let Some(e) = s.probe_error_m() {
                    text += &format!(", probe error {} m", crate::recording::format_metres(e));
                }
                let raised = sim.substeps_per_frame() > s.config.substeps;
                if raised {
                    text += &format!(", {} substeps (guard)", sim.substeps_per_frame());
                }
                let label = ui.label(egui::RichText::new(text).monospace());
                if raised {
                    label.on_hover_text(format!(
                        "The stability guard takes {} substeps per frame instead of {}: the stiffest element's fastest mode needs h·ω_max ≤ {} (docs/STABILITY.md). Switch it off under Solver to see the instability.",
                        sim.substeps_per_frame(),
                        s.config.substeps,
                        hox_sim::solver::stability::GUARD_H_OMEGA
                    ));
                }
                if let Some(f) = &s.failure {
                    ui.colored_label(egui::Color32::from_rgb(255, 90, 80), f);
                }
                ui.separator();
            }
            ui.label(egui::RichText::new(format!("display {:.0} fps, view {:.1} ms, app {:.1} ms", 1000.0 / self.ui_frame_ms.max(1e-3), self.viewport.render_ms, self.app_ms)).monospace())
                .on_hover_text(format!("Displayed frames per second; CPU milliseconds of the 3D view's preparation and of the app's whole frame. Renderer: {}.", self.renderer.as_deref().unwrap_or("none (no OpenGL: CPU rasteriser)")));
            if let Some(e) = self.viewport.gl_error() {
                ui.colored_label(egui::Color32::from_rgb(255, 170, 60), format!("OpenGL view unavailable, drawn on the CPU: {e}"));
            }
        });
    }

    /// The whole window (also driven by the headless UI tests).
    pub fn ui_all(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        let dt = self.last_ui_frame.map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.last_ui_frame = Some(now);
        if dt > 0.0 {
            self.ui_frame_ms = if self.ui_frame_ms == 0.0 { dt * 1e3 } else { 0.9 * self.ui_frame_ms + 0.1 * dt * 1e3 };
        }
        self.join_background();
        self.shortcuts(&ctx);
        // Simulated time follows egui's clock (the window's: wall time between frames; the
        // headless tests': exactly their step), never the wall clock read here, so a test plays
        // the same frames in a slow debug build and a fast release one.
        let clock_dt = f64::from(ctx.input(|i| i.unstable_dt));
        self.advance(if self.last_clock_frame { clock_dt } else { 0.0 });
        self.last_clock_frame = true;

        // The panels are not filled: the window is cleared to the panel colour (`clear_color`), and
        // a software renderer pays per blended pixel for each fill (docs/APP.md).
        let frame = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        egui::Panel::top("menu").frame(frame).show(ui, |ui| controls::menu_bar_ui(self, ui));
        egui::Panel::bottom("status").frame(frame).show(ui, |ui| self.status_line_ui(ui));
        egui::Panel::bottom("plots")
            .frame(frame)
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| plots::plots_ui(self, ui));
        egui::Panel::left("controls").frame(frame).resizable(true).default_size(330.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| controls::controls_ui(self, ui));
        });
        if self.show_reference_element {
            let mut open = true;
            egui::Window::new("Reference element")
                .open(&mut open)
                .default_size([420.0, 460.0])
                .show(&ctx, |ui| self.reference_element.ui(ui));
            self.show_reference_element = open;
        }
        controls::open_dialog_ui(self, &ctx);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let offsets = self.offsets();
            self.viewport.ui(ui, &mut self.sessions, &offsets, &self.view, self.gl_available);
        });
        if self.playing || self.sessions.iter().any(|s| s.drag.is_some()) {
            ctx.request_repaint();
        }
        let ms = now.elapsed().as_secs_f64() * 1e3;
        self.app_ms = if self.app_ms == 0.0 { ms } else { 0.9 * self.app_ms + 0.1 * ms };
        self.after_frame(&ctx, now);
        self.start_background_step();
    }

    /// Screenshot and measurement bookkeeping.
    fn after_frame(&mut self, ctx: &egui::Context, now: Instant) {
        if let Some(m) = &mut self.measure {
            let started = *m.started.get_or_insert(now);
            if let Some(last) = m.last {
                m.frame_ms.push(now.duration_since(last).as_secs_f64() * 1e3);
            }
            m.last = Some(now);
            m.frames += 1;
            let secs = now.duration_since(started).as_secs_f64();
            if secs >= m.until_secs {
                let mut ms = m.frame_ms.clone();
                let median = hox_scenes::median(&mut ms);
                let s = &self.sessions[0];
                println!(
                    "{}",
                    serde_json::json!({
                        "configuration": s.label(),
                        "seconds": secs,
                        "display_frames": m.frames,
                        "display_fps": m.frames as f64 / secs,
                        "median_display_frame_ms": median,
                        "sim_frames": m.sim_frames,
                        "sim_ms_per_frame": s.ms_per_frame,
                        "render_ms": self.viewport.render_ms,
                        "app_ms": self.app_ms,
                        "frame_cpu_ms": self.frame_cpu_ms,
                        "window_points": ctx.input(|i| i.viewport().inner_rect.map(|r| [r.width(), r.height()])),
                        "pixels_per_point": ctx.pixels_per_point(),
                        "renderer": self.renderer,
                        "feathering": ctx.tessellation_options(|o| o.feathering),
                    })
                );
                if self.screenshot.is_none() {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
                self.measure = None;
            }
            ctx.request_repaint();
        }
        if let Some((path, after)) = self.screenshot.clone() {
            ctx.request_repaint();
            if !self.screenshot_requested && self.started.elapsed().as_secs_f64() >= after && self.measure.is_none() {
                self.screenshot_requested = true;
                let ctx2 = ctx.clone();
                ctx.request_screenshot(move |image| {
                    match save_png(&path, &image) {
                        Ok(()) => eprintln!("wrote {}", path.display()),
                        Err(e) => eprintln!("error: cannot write {}: {e}", path.display()),
                    }
                    ctx2.send_viewport_cmd(egui::ViewportCommand::Close);
                    ctx2.request_repaint();
                });
            }
        }
    }
}

/// Writes an egui image as PNG.
pub fn save_png(path: &std::path::Path, image: &egui::ColorImage) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), image.size[0] as u32, image.size[1] as u32);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    writer.write_image_data(&bytes).map_err(|e| e.to_string())
}

impl eframe::App for HoxApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        if let Some(cpu) = frame.info().cpu_usage {
            let ms = cpu as f64 * 1e3;
            self.frame_cpu_ms = if self.frame_cpu_ms == 0.0 { ms } else { 0.9 * self.frame_cpu_ms + 0.1 * ms };
        }
        self.gl_available = frame.gl().is_some();
        self.ui_all(ui);
    }

    /// The panels' colour, opaque: the panels themselves are drawn unfilled over it.
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_opaque().to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.join_background();
        eframe::set_value(storage, eframe::APP_KEY, &self.persisted());
    }
}

/// One frame of every session (in parallel in compare mode).
fn step_sessions(sessions: &mut [Session]) {
    use rayon::prelude::*;
    if sessions.len() > 1 {
        sessions.par_iter_mut().for_each(|s| s.step(1));
    } else if let Some(s) = sessions.first_mut() {
        s.step(1);
    }
}

/// Whether an OpenGL renderer name is a software rasteriser (Mesa's llvmpipe or softpipe,
/// SwiftShader, Microsoft's GDI renderer).
pub fn is_software_renderer(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    ["llvmpipe", "softpipe", "swiftshader", "software rasterizer", "gdi generic"].iter().any(|k| n.contains(k))
}

/// Window size in points when neither --size nor a saved geometry gives one.
const DEFAULT_WINDOW_SIZE: &str = "1400x900";

/// Opens the window (blocking until it is closed).
pub fn run(args: AppArgs) -> anyhow::Result<()> {
    let size = args.size.as_deref().unwrap_or(DEFAULT_WINDOW_SIZE);
    let (w, h) = size
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<f32>().ok()?, h.trim().parse::<f32>().ok()?)))
        .filter(|(w, h)| *w >= 320.0 && *h >= 240.0)
        .ok_or_else(|| anyhow::anyhow!("--size must be WIDTHxHEIGHT in points, at least 320x240, got '{size}'"))?;
    if let Some(p) = &args.screenshot {
        crate::output::check_writable(p)?;
    }
    // fail before opening a window on a bad scene
    if let Some(name) = &args.scene {
        hox_scenes::by_name(name)?;
    }
    if let Some(path) = &args.scene_file {
        Scene::load(path)?;
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([w, h])
            .with_title("hox — high-order elements in XPBD"),
        glow_options: eframe::egui_glow::GlowConfiguration { vsync: !args.no_vsync, ..Default::default() },
        // an explicit --size (or --fresh) wins over the window geometry eframe saved last time
        persist_window: args.size.is_none() && !args.fresh,
        // egui's dithering costs a noise function per pixel in the software renderer and buys
        // nothing for a flat-shaded 3D view and 8-bit widgets
        dithering: false,
        // the 3D view is drawn with depth testing (gui/gl_view.rs)
        depth_buffer: 24,
        ..Default::default()
    };
    let mut error = None;
    let result = eframe::run_native(
        "hox",
        options,
        Box::new(|cc| {
            // eframe restores the last window geometry before this point; an explicit --size or
            // --fresh asks for the given (or default) size instead
            if args.size.is_some() || args.fresh {
                cc.egui_ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(egui::vec2(w, h)));
            }
            if args.fresh {
                // egui's own saved state too (panel sizes, open windows)
                cc.egui_ctx.memory_mut(|m| *m = egui::Memory::default());
            }
            let renderer = cc.gl.as_ref().map(|gl| {
                use eframe::glow::HasContext;
                // SAFETY: a plain query on the context eframe has just made current
                unsafe { gl.get_parameter_string(eframe::glow::RENDERER) }
            });
            // Anti-aliasing feathers double the triangles egui hands to the driver; a software
            // renderer pays for each one on the CPU (docs/APP.md), so shapes go without there.
            let software = renderer.as_deref().is_some_and(is_software_renderer);
            cc.egui_ctx.tessellation_options_mut(|o| o.feathering = !software);
            let saved = cc.storage.and_then(|s| eframe::get_value::<Persisted>(s, eframe::APP_KEY));
            match HoxApp::new(&args, saved) {
                Ok(mut app) => {
                    app.renderer = renderer;
                    Ok(Box::new(app) as Box<dyn eframe::App>)
                }
                Err(e) => {
                    error = Some(e.clone());
                    Err(e.into())
                }
            }
        }),
    );
    if let Some(e) = error {
        anyhow::bail!(e);
    }
    result.map_err(|e| anyhow::anyhow!("the window could not be opened: {e} (no display? run the headless commands, e.g. `hox simulate`, or run the app in a virtual display: scripts/app-headless.sh)"))
}

#[cfg(test)]
mod tests;
