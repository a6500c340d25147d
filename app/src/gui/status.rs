//! The status line: one short line per configuration (its label, size, time per frame and
//! readout; the details on hover), the stability guard's substeps, a failure, and the frame rate.

use super::ui_state::Ctx;
use eframe::egui;

pub fn status_line_ui(cx: &Ctx, ui: &mut egui::Ui) {
    let model = cx.model;
    let names = super::session::labels(model.sessions());
    // in a lesson, the step's measurement, as its panel and the labels show it (issue #57:
    // "paused mid-swing" on steps that are not about motion)
    let lesson = model.lesson().zip(cx.state.lesson_measured.as_ref()).map(|(l, m)| (l.current().measure.title(), m));
    ui.horizontal_wrapped(|ui| {
        for (k, s) in model.sessions().iter().enumerate() {
            let sim = &s.instance.sim;
            let solver = sim.work_summary();
            // one short line per configuration; the details on hover
            // a frame time only once frames were stepped (issue #57: "0.0 ms/frame" on static steps)
            let ms = if s.frame_ms.is_empty() { "no frame yet".to_string() } else { format!("{:.1} ms/frame", s.ms_per_frame) };
            let mut text = format!(
                "{}{}: {} nodes, {} el, {ms}, {}",
                if model.compare() { ["A ", "B "][k] } else { "" },
                names[k],
                sim.mesh().num_nodes(),
                sim.mesh().num_elements(),
                match &lesson {
                    Some((title, measured)) => measured.get(k).map_or_else(String::new, |m| format!("{title} {}", m.text)),
                    None => s.readout().error_text(),
                }
            );
            if s.settler.is_some() {
                text += " (settling…)";
            }
            // the guard's substeps matter to frames stepped, not to a solved static equilibrium
            let raised = sim.substeps_per_frame() > s.config.substeps && !s.shown_static;
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
                ui.colored_label(ui.visuals().error_fg_color, f);
            }
            ui.separator();
        }
        if let Some(building) = model.building() {
            ui.label(egui::RichText::new(building).monospace().color(ui.visuals().warn_fg_color));
            ui.separator();
        }
        // paused, the window repaints only on input: a frame rate then means nothing (issue
        // #35: "0–1 fps" whenever paused)
        let rate = if model.playing() || model.settling() {
            format!("{:.0} fps", 1000.0 / cx.status.ui_frame_ms.max(1e-3))
        } else {
            "paused".to_string()
        };
        ui.label(egui::RichText::new(rate).monospace())
            .on_hover_text(format!("Displayed frames per second; view {:.1} ms and app {:.1} ms of CPU per frame (the 3D view's preparation and the app's whole frame). Renderer: {}.", cx.state.viewport.render_ms, cx.status.app_ms, cx.status.renderer.as_deref().unwrap_or("none (no OpenGL: CPU rasteriser)")));
        if let Some(e) = cx.state.viewport.gl_error() {
            ui.colored_label(ui.visuals().warn_fg_color, format!("OpenGL view unavailable, drawn on the CPU: {e}"));
        }
    });
}
