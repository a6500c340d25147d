//! The bottom panel: the probe displacement and the energies over simulated time, and the
//! study's accuracy-versus-time chart with the running configuration(s) marked.

use super::HoxApp;
use super::study_chart::{StudyPoint, study_chart_ui};
use eframe::egui;
use egui_plot::{Legend, Line, Plot, PlotPoints};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tab {
    #[default]
    Probe,
    Energy,
    Study,
}

pub fn plots_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.selectable_value(&mut app.bottom_tab, Tab::Probe, "Probe displacement").on_hover_text("The first probe's displacement components over simulated time, metres.");
        ui.selectable_value(&mut app.bottom_tab, Tab::Energy, "Energies").on_hover_text("Kinetic and elastic energy over simulated time, joules.");
        ui.selectable_value(&mut app.bottom_tab, Tab::Study, "Accuracy vs time").on_hover_text("The study's probe error against the reference solution versus milliseconds per frame; the running configurations are marked.");
    });
    let names = ["A", "B"];
    match app.bottom_tab {
        Tab::Probe => {
            let probe = app.sessions[0].instance.probes.first().map_or("probe".to_string(), |p| p.name.clone());
            Plot::new("probe").legend(Legend::default()).x_axis_label("t (s)").y_axis_label(format!("{probe} u (m)")).show(ui, |plot| {
                for (k, s) in app.sessions.iter().enumerate() {
                    let h = &s.history;
                    for (axis, label) in ["u_x", "u_y", "u_z"].iter().enumerate() {
                        let points: PlotPoints = h.time_secs.iter().zip(&h.probe_m).map(|(t, u)| [*t, u[axis]]).collect();
                        let name = if app.compare { format!("{} {} {label}", names[k], s.config.label()) } else { label.to_string() };
                        plot.line(Line::new(name, points));
                    }
                    // the reference displacement, as a dashed level
                    if let Some((_, r)) = s.reference.iter().find(|(n, _)| *n == probe)
                        && k == 0
                    {
                        let t1 = h.time_secs.last().copied().unwrap_or(1.0).max(1e-3);
                        plot.line(Line::new("reference u_z", PlotPoints::from(vec![[0.0, r.z], [t1, r.z]])).style(egui_plot::LineStyle::dashed_loose()));
                    }
                }
            });
        }
        Tab::Energy => {
            Plot::new("energy").legend(Legend::default()).x_axis_label("t (s)").y_axis_label("energy (J)").show(ui, |plot| {
                for (k, s) in app.sessions.iter().enumerate() {
                    let h = &s.history;
                    let prefix = if app.compare { format!("{} ", names[k]) } else { String::new() };
                    plot.line(Line::new(format!("{prefix}kinetic"), h.time_secs.iter().zip(&h.kinetic_j).map(|(t, e)| [*t, *e]).collect::<PlotPoints>()));
                    plot.line(Line::new(format!("{prefix}elastic"), h.time_secs.iter().zip(&h.elastic_j).map(|(t, e)| [*t, *e]).collect::<PlotPoints>()));
                }
            });
        }
        Tab::Study => {
            let current: Vec<StudyPoint> = app
                .sessions
                .iter()
                .filter_map(|s| s.probe_error_m().map(|e| StudyPoint { label: format!("now: {}", s.config.label()), ms_per_frame: s.ms_per_frame, error_m: e }))
                .collect();
            study_chart_ui(ui, app.sessions[0].base.name(), &current);
        }
    }
}
