//! The window's contents, frame by frame: the panels around the 3D view, the status line, the
//! bookkeeping after a frame (screenshot, measurement), and the `eframe::App` the window runs.

use super::{HoxApp, controls, plots};
use eframe::egui;
use std::path::PathBuf;
use std::time::Instant;

/// A screenshot to save some seconds after the start (`--screenshot`); the window closes then.
pub(super) struct Screenshot {
    path: PathBuf,
    after_secs: f64,
    /// When the app started.
    started: Instant,
    requested: bool,
}

impl Screenshot {
    pub(super) fn new(path: PathBuf, after_secs: f64) -> Screenshot {
        Screenshot { path, after_secs, started: Instant::now(), requested: false }
    }
}

/// The inner size of a window of size `inner` that fits on a monitor of size `monitor` (both in
/// the same points, with room for the window's decorations), or None when it already fits.
pub(super) fn fitted_inner_size(inner: egui::Vec2, monitor: egui::Vec2) -> Option<egui::Vec2> {
    // title bar and borders, and a panel the desktop may keep
    let room = egui::vec2(monitor.x - 16.0, monitor.y - 64.0).max(egui::vec2(320.0, 240.0));
    (inner.x > room.x || inner.y > room.y).then(|| inner.min(room))
}

impl HoxApp {
    /// Shrinks the window to the screen once the monitor's size is known ([`fitted_inner_size`]),
    /// a few frames after the start: eframe reports the monitor and the window in the points of
    /// the scale of an earlier frame, which the start's own scale may have just changed.
    fn fit_window_to_screen(&mut self, ctx: &egui::Context) {
        if self.fit_to_screen_in_frames > 0 {
            self.fit_to_screen_in_frames -= 1;
            return;
        }
        let (monitor, inner) = ctx.input(|i| (i.viewport().monitor_size, i.viewport().inner_rect));
        let (Some(monitor), Some(inner)) = (monitor, inner) else { return };
        self.fit_to_screen = false;
        if let Some(size) = fitted_inner_size(inner.size(), monitor) {
            ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(size));
        }
    }

    fn status_line_ui(&self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            for (k, s) in self.sessions.iter().enumerate() {
                let sim = &s.instance.sim;
                let solver = sim.work_summary();
                // one short line per configuration; the details on hover
                let mut text = format!(
                    "{}{}: {} nodes, {} el, {:.1} ms/frame, {}",
                    if self.compare { ["A ", "B "][k] } else { "" },
                    s.label(),
                    sim.mesh().num_nodes(),
                    sim.mesh().num_elements(),
                    s.ms_per_frame,
                    s.readout().error_text()
                );
                if s.settler.is_some() {
                    text += " (settling…)";
                }
                let raised = sim.substeps_per_frame() > s.config.substeps;
                if raised {
                    text += &format!(", {} substeps (guard)", sim.substeps_per_frame());
                }
                // the reference's state on hover: the line stays one line (the labels carry it)
                let details = format!(
                    "{} nodes, {} elements, {solver}, residual {:.1e}, t = {:.2} s\n{}\n{}",
                    sim.mesh().num_nodes(),
                    sim.mesh().num_elements(),
                    s.residual,
                    sim.time_secs(),
                    s.readout().text(),
                    s.reference.status()
                );
                let label = ui.label(egui::RichText::new(text).monospace()).on_hover_text(details);
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
            // paused, the window repaints only on input: a frame rate then means nothing (issue
            // #35: "0–1 fps" whenever paused)
            let rate = if self.playback.playing || self.settling() {
                format!("{:.0} fps", 1000.0 / self.times.ui_frame_ms.max(1e-3))
            } else {
                "paused".to_string()
            };
            ui.label(egui::RichText::new(rate).monospace())
                .on_hover_text(format!("Displayed frames per second; view {:.1} ms and app {:.1} ms of CPU per frame (the 3D view's preparation and the app's whole frame). Renderer: {}.", self.viewport.render_ms, self.times.app_ms, self.renderer.as_deref().unwrap_or("none (no OpenGL: CPU rasteriser)")));
            if let Some(e) = self.viewport.gl_error() {
                ui.colored_label(egui::Color32::from_rgb(255, 170, 60), format!("OpenGL view unavailable, drawn on the CPU: {e}"));
            }
        });
    }

    /// The whole window (also driven by the headless UI tests).
    pub fn ui_all(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        self.times.frame_started(now);
        self.join_background();
        // a reference computed in the background arrives; until then its progress is shown
        let mut computing = false;
        for s in &mut self.sessions {
            s.poll_reference();
            computing |= matches!(s.reference, super::readout::ReferenceState::Computing { .. });
        }
        if computing {
            ctx.request_repaint_after(std::time::Duration::from_millis(250));
        }
        if self.lesson.as_ref().is_some_and(|l| l.preparing()) {
            // a lesson step being prepared: look again soon
            self.poll_lesson(false);
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
        self.shortcuts(&ctx);
        self.lesson_shortcuts(&ctx);
        if let Some(z) = self.zoom_wanted.take() {
            ctx.set_zoom_factor(z);
        }
        if self.fit_to_screen {
            self.fit_window_to_screen(&ctx);
        }
        // Simulated time follows egui's clock (the window's: wall time between frames; the
        // headless tests': exactly their step), never the wall clock read here, so a test plays
        // the same frames in a slow debug build and a fast release one.
        let clock_dt = f64::from(ctx.input(|i| i.unstable_dt));
        self.advance(if self.playback.last_clock_frame { clock_dt } else { 0.0 });
        self.lesson_after_advance();
        self.pause_if_slow();
        self.playback.last_clock_frame = true;
        let paused = !self.playback.playing && !self.settling();
        for s in &mut self.sessions {
            s.paused = paused;
        }

        // The panels are not filled: the window is cleared to the panel colour (`clear_color`), and
        // a software renderer pays per blended pixel for each fill (docs/APP.md).
        let frame = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        egui::Panel::top("menu").frame(frame).show(ui, |ui| controls::menu_bar_ui(self, ui));
        egui::Panel::bottom("status").frame(frame).show(ui, |ui| self.status_line_ui(ui));
        // presenter mode: the 3D view fills the window, the lesson's caption in a panel below it
        if self.presenter && self.lesson.is_some() {
            egui::Panel::bottom("caption").frame(frame).show(ui, |ui| super::lesson::caption_ui(self, ui));
        }
        // presenter mode while serving the class's browsers: the address and its QR code beside
        // the view
        if self.presenter && self.web_url().is_some() {
            egui::Panel::right("serve_web").frame(frame).resizable(false).default_size(230.0).show(ui, |ui| {
                super::serve_web::address_ui(self, ui);
            });
        }
        if !self.presenter {
            egui::Panel::bottom("plots")
                .frame(frame)
                .resizable(true)
                .default_size(230.0)
                .show(ui, |ui| plots::plots_ui(self, ui));
            if self.lesson.is_some() {
                egui::Panel::right("lesson").frame(frame).resizable(true).default_size(380.0).show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| super::lesson::lesson_panel_ui(self, ui));
                });
            }
            egui::Panel::left("controls").frame(frame).resizable(true).default_size(330.0).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| controls::controls_ui(self, ui));
            });
        }
        super::lesson::welcome_ui(self, &ctx);
        if self.show_reference_element {
            let mut open = true;
            egui::Window::new("Reference element")
                .open(&mut open)
                .default_size([420.0, 460.0])
                .show(&ctx, |ui| self.reference_element.ui(ui));
            self.show_reference_element = open;
        }
        controls::open_dialog_ui(self, &ctx);
        super::cost::pending_change_ui(self, &ctx);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            self.viewport.short_labels = self.presenter && self.lesson.is_some();
            let offsets = self.offsets();
            self.viewport.ui(ui, &mut self.sessions, &offsets, &self.view, self.gl_available);
        });
        if self.sessions.iter().any(|s| s.drag.is_some()) {
            ctx.request_repaint();
        } else if self.playback.playing {
            match self.paint_pace() {
                Some(wait) => ctx.request_repaint_after(wait),
                None => ctx.request_repaint(),
            }
        }
        // paused or settled in this frame (a button, a shortcut, the settle's end): the browsers
        // get the frame the app stopped on, if the frame cap held it back
        self.flush_rerun();
        let ms = now.elapsed().as_secs_f64() * 1e3;
        self.times.app_part(ms);
        self.after_frame(&ctx, now);
        self.start_background_step();
    }

    /// Screenshot and measurement bookkeeping.
    fn after_frame(&mut self, ctx: &egui::Context, now: Instant) {
        self.measure_after_frame(ctx, now);
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
        self.join_background();
        self.persisted().save(storage);
    }
}
