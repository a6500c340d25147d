//! The window's frame: the model polled and ticked by egui's clock, the panels laid out around
//! the 3D view (each returning commands, carried out once the frame is built), the repaints
//! asked for, the bookkeeping after a frame (screenshot, measurement), and the `eframe::App` the
//! window runs.

use super::action::{Action, Commands};
use super::app::HoxApp;
use super::readout::ReferenceState;
#[cfg(not(target_arch = "wasm32"))]
use super::serve_web;
use super::ui_state::Ctx;
use super::{controls, dialogs, lesson_panel, menu, plots, status};
use eframe::egui;
use web_time::Instant;

/// The smallest window a restored geometry keeps, points: below it a lesson's panels leave no
/// room for the view (issue #57: a presenter session once left a 784×386 window, the projector's
/// size in presenter mode's points, that the next plain start reopened).
pub(super) const USABLE_INNER_SIZE: egui::Vec2 = egui::vec2(1024.0, 640.0);

/// Below this width (points) a lesson folds the controls away unless asked for.
const NARROW_PT: f32 = 1500.0;

/// The inner size of a window of size `inner` that fits on a monitor of size `monitor` (both in
/// the same points, with room for the window's decorations) and, when `grow` (a restored size,
/// not one asked for), is at least [`USABLE_INNER_SIZE`] where the monitor has room for it; None
/// when it already is.
pub(super) fn fitted_inner_size(inner: egui::Vec2, monitor: egui::Vec2, grow: bool) -> Option<egui::Vec2> {
    // title bar and borders, and a panel the desktop may keep
    let room = egui::vec2(monitor.x - 16.0, monitor.y - 64.0).max(egui::vec2(320.0, 240.0));
    let wanted = if grow { inner.max(USABLE_INNER_SIZE.min(room)) } else { inner };
    let fitted = wanted.min(room);
    (fitted != inner).then_some(fitted)
}

impl HoxApp {
    /// Shrinks the window to the screen once the monitor's size is known ([`fitted_inner_size`]),
    /// a few frames after the start: eframe reports the monitor and the window in the points of
    /// the scale of an earlier frame, which the start's own scale may have just changed.
    fn fit_window_to_screen(&mut self, ctx: &egui::Context) {
        if self.ui.fit_to_screen_in_frames > 0 {
            self.ui.fit_to_screen_in_frames -= 1;
            return;
        }
        let (monitor, inner) = ctx.input(|i| (i.viewport().monitor_size, i.viewport().inner_rect));
        let (Some(monitor), Some(inner)) = (monitor, inner) else { return };
        self.ui.fit_to_screen = false;
        if let Some(size) = fitted_inner_size(inner.size(), monitor, self.ui.grow_to_usable) {
            ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(size));
        }
    }

    /// The whole window (also driven by the headless UI tests).
    pub fn ui_all(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        self.times.frame_started(now);
        self.act(Action::Poll { wait_for_lesson: false });
        // a reference computed in the background arrives; until then its progress is shown
        self.poll_figure();
        if self.figure.is_some()
            || self.model.sessions().iter().any(|s| matches!(s.reference, ReferenceState::Computing { .. }))
        {
            ctx.request_repaint_after(std::time::Duration::from_millis(250));
        }
        if self.model.lesson().is_some_and(|l| l.preparing()) || self.model.building().is_some() {
            // a lesson step being prepared, a mesh being built: look again soon
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
        let status = self.status();
        let mut keys = Commands::default();
        menu::shortcuts(&mut Ctx { model: &self.model, state: &mut self.ui, status: &status, out: &mut keys }, &ctx);
        // a mesh file dropped onto the window (in a page the only way to bring one's own part)
        for (name, bytes) in super::platform::dropped_files(&ctx) {
            match bytes {
                Ok(bytes) => keys.push(super::action::Command::OpenMeshBytes { name, bytes }),
                Err(e) => keys.push(Action::Say(format!("{name} could not be read: {e}"))),
            }
        }
        self.act_all(keys);
        if let Some(z) = self.ui.zoom_wanted.take() {
            ctx.set_zoom_factor(z);
        }
        if self.ui.fit_to_screen {
            self.fit_window_to_screen(&ctx);
        }
        // Simulated time follows egui's clock (the window's: wall time between frames; the
        // headless tests': exactly their step), never the wall clock read here, so a test plays
        // the same frames in a slow debug build and a fast release one. With an OpenGL context and
        // no live Rerun link (which logs every frame in order) the frames are stepped on the
        // stepper while the window paints.
        let real_dt_secs = f64::from(ctx.input(|i| i.unstable_dt));
        let in_background = self.gl_available && !self.rerun.is_open();
        self.act(Action::Tick { real_dt_secs, one_frame_per_tick: self.measure.is_some(), in_background });

        // the lesson step's numbers, measured once for every panel that shows them
        self.ui.lesson_measured =
            self.model.lesson().filter(|l| !l.preparing()).map(|l| l.measured(self.model.sessions()));
        let status = self.status();
        let mut out = Commands::default();
        let gl = self.gl_available;
        let mut cx = Ctx { model: &self.model, state: &mut self.ui, status: &status, out: &mut out };
        // The panels are not filled: the window is cleared to the panel colour (`clear_color`), and
        // a software renderer pays per blended pixel for each fill (docs/APP.md).
        let frame = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        let presenter = cx.model.presenter();
        egui::Panel::top("menu").frame(frame).show(ui, |ui| menu::menu_bar_ui(&mut cx, ui));
        egui::Panel::bottom("status").frame(frame).show(ui, |ui| status::status_line_ui(&cx, ui));
        // presenter mode: the 3D view fills the window, the lesson's caption in a panel below it
        if presenter && cx.model.lesson().is_some() {
            egui::Panel::bottom("caption").frame(frame).show(ui, |ui| lesson_panel::caption_ui(&cx, ui));
        }
        // presenter mode while serving the class's browsers: the address and its QR code beside
        // the view (the desktop's: a page serves no one)
        #[cfg(not(target_arch = "wasm32"))]
        if presenter && cx.status.web_url.is_some() {
            egui::Panel::right("serve_web").frame(frame).resizable(false).default_size(230.0).show(ui, |ui| {
                serve_web::address_ui(&cx, ui);
            });
        }
        if !presenter {
            egui::Panel::bottom("plots")
                .frame(frame)
                .resizable(true)
                .default_size(230.0)
                .show(ui, |ui| plots::plots_ui(&mut cx, ui));
            if cx.model.lesson().is_some() {
                egui::Panel::right("lesson").frame(frame).resizable(true).default_size(380.0).show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| lesson_panel::lesson_panel_ui(&mut cx, ui));
                });
            }
            // issue #57: at 1280×720 a lesson's panel and the controls left the 3D view 300 px
            // wide; in a lesson on a narrow window the controls fold to a strip (the lesson sets
            // the configuration), a click away
            let lesson = cx.model.lesson().is_some();
            let folded = !cx.state.controls_shown.unwrap_or(!(lesson && ctx.content_rect().width() < NARROW_PT));
            if folded {
                egui::Panel::left("controls_folded").frame(frame).resizable(false).exact_size(34.0).show(ui, |ui| {
                    if ui.button("»").on_hover_text("Show the controls (scene, mesh, material, solver)").clicked() {
                        cx.state.controls_shown = Some(true);
                    }
                });
            } else {
                egui::Panel::left("controls").frame(frame).resizable(true).default_size(330.0).show(ui, |ui| {
                    if lesson && ui.button("« Hide controls").on_hover_text("More room for the 3D view").clicked() {
                        cx.state.controls_shown = Some(false);
                    }
                    egui::ScrollArea::vertical().show(ui, |ui| controls::controls_ui(&mut cx, ui));
                });
            }
        }
        lesson_panel::welcome_ui(&mut cx, &ctx);
        dialogs::reference_element_ui(&mut cx, &ctx);
        dialogs::open_dialog_ui(&mut cx, &ctx);
        dialogs::pending_change_ui(&mut cx, &ctx);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            cx.state.viewport.short_labels = presenter && cx.model.lesson().is_some();
            cx.state.viewport.lesson_labels = cx.model.lesson().zip(cx.state.lesson_measured.as_ref()).map(|(l, m)| {
                let title = l.current().measure.title();
                m.iter().map(|m| format!("{title}: {}", m.text)).collect()
            });
            let offsets = cx.model.offsets();
            let drag = cx.state.viewport.ui(ui, cx.model.sessions(), &offsets, cx.model.view(), gl);
            if let Some((session, drag)) = drag {
                cx.out.push(Action::Drag { session, drag });
            }
        });
        self.act_all(out);
        if self.model.sessions().iter().any(|s| s.drag.is_some()) {
            ctx.request_repaint();
        } else if self.model.playing() {
            match self.paint_pace() {
                Some(wait) => ctx.request_repaint_after(wait),
                None => ctx.request_repaint(),
            }
        }
        // paused or settled in this frame (a button, a shortcut, the settle's end): the browsers
        // get the frame the app stopped on, if the frame cap held it back
        let flushed = self.rerun.flush(&self.model);
        if let Some(e) = flushed {
            self.act(Action::Say(e));
        }
        let ms = now.elapsed().as_secs_f64() * 1e3;
        self.times.app_part(ms);
        self.after_frame(&ctx, now);
        // before the sessions go out to be stepped (in a page, at once, in place)
        #[cfg(target_arch = "wasm32")]
        super::platform::page::publish_state(&self.page_state());
        self.act(Action::StepDeferred);
    }

    /// Screenshot and measurement bookkeeping: once `--measure-secs` have passed, prints the
    /// measurement and closes the window (unless a screenshot is still to be taken).
    fn after_frame(&mut self, ctx: &egui::Context, now: Instant) {
        if let Some(m) = &mut self.measure {
            if let Some(done) = m.after_frame(now, self.model.frames_stepped()) {
                let s = &self.model.sessions()[0];
                println!(
                    "{}",
                    serde_json::json!({
                        "configuration": s.label(),
                        "seconds": done.seconds,
                        "display_frames": done.display_frames,
                        "display_fps": done.display_frames as f64 / done.seconds,
                        "median_display_frame_ms": done.median_display_frame_ms,
                        "sim_frames": done.sim_frames,
                        "sim_ms_per_frame": s.ms_per_frame,
                        "render_ms": self.ui.viewport.render_ms,
                        "app_ms": self.times.app_ms,
                        "frame_cpu_ms": self.times.frame_cpu_ms,
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
        if let Some(shot) = &mut self.screenshot {
            ctx.request_repaint();
            if !shot.requested && shot.started.elapsed().as_secs_f64() >= shot.after_secs && self.measure.is_none() {
                shot.requested = true;
                let path = shot.path.clone();
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
            self.times.whole_frame_cpu(cpu as f64 * 1e3);
        }
        self.gl_available = frame.gl().is_some();
        self.ui_all(ui);
    }

    /// The panels' colour, opaque: the panels themselves are drawn unfilled over it.
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_opaque().to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        // the sessions back from the stepper first
        self.act(Action::Poll { wait_for_lesson: false });
        self.persisted().save(storage);
    }
}
