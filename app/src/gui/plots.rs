//! The bottom panel: the probe displacement and the energies over simulated time, and the
//! study's accuracy-versus-time chart with the running configuration(s) marked.

use super::readout::Readout;
use super::study_chart::{StudyPoint, study_chart_ui};
use super::ui_state::{Ctx, Tab};
use eframe::egui;
use egui_plot::{Line, Plot, PlotPoints};

/// Most points per plotted line: a long run keeps 20,000 samples, which would cost the
/// renderer more than the rest of the window; min/max pairs per bucket keep the envelope.
const MAX_PLOT_POINTS: usize = 1200;

// The time plots' lines are drawn as lines, never as egui_plot's per-pixel bands
// (`Line::allow_band(false)`): once a minute of swinging put several samples in some pixel
// columns, the band drawing covered only those columns and the probe plot turned to dashes
// (issue #57).

/// The samples `(t[i], y(i))`, reduced to at most about `max_points` by keeping each bucket's
/// minimum and maximum in time order (oscillations keep their full amplitude).
pub fn decimate(t: &[f64], y: impl Fn(usize) -> f64, max_points: usize) -> Vec<egui_plot::PlotPoint> {
    let n = t.len();
    if n <= max_points {
        return (0..n).map(|i| egui_plot::PlotPoint::new(t[i], y(i))).collect();
    }
    let bucket = n.div_ceil((max_points / 2).max(1));
    let mut out = Vec::with_capacity(2 * n.div_ceil(bucket));
    for start in (0..n).step_by(bucket) {
        let end = (start + bucket).min(n);
        let (mut lo, mut hi) = (start, start);
        for i in start..end {
            if y(i) < y(lo) {
                lo = i;
            }
            if y(i) > y(hi) {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(egui_plot::PlotPoint::new(t[a], y(a)));
        if b != a {
            out.push(egui_plot::PlotPoint::new(t[b], y(b)));
        }
    }
    out
}

/// The legend of the reference motion's dashed curve.
pub const REFERENCE_MOTION_LABEL: &str = "reference motion u_z (Newmark, Q2 16×4×4)";

/// Line colours: one configuration's components in three hues (u_x red, u_y green, u_z blue);
/// when comparing, per configuration (A, B) a hue and per component a shade (u_x lightest, u_z
/// full); the references grey and pink.
fn line_colour(compare: bool, config: usize, shade: usize) -> egui::Color32 {
    if !compare {
        let c = [[230, 100, 90], [110, 200, 110], [80, 150, 240]][shade.min(2)];
        return egui::Color32::from_rgb(c[0], c[1], c[2]);
    }
    const HUES: [[[u8; 3]; 3]; 2] =
        [[[160, 200, 240], [110, 160, 220], [60, 130, 230]], [[250, 200, 150], [245, 160, 90], [240, 120, 30]]];
    let c = HUES[config.min(1)][shade.min(2)];
    egui::Color32::from_rgb(c[0], c[1], c[2])
}
const REFERENCE_COLOUR: egui::Color32 = egui::Color32::from_rgb(235, 90, 200);
const MOTION_COLOUR: egui::Color32 = egui::Color32::from_rgb(170, 170, 170);

/// The plot's legend as a row of coloured entries above it, so it never covers the data.
fn legend_row_ui(ui: &mut egui::Ui, entries: &[(String, egui::Color32, bool)]) {
    ui.horizontal_wrapped(|ui| {
        for (name, colour, dashed) in entries {
            let (rect, _) = ui.allocate_exact_size(egui::vec2(22.0, 10.0), egui::Sense::hover());
            let y = rect.center().y;
            let stroke = egui::Stroke::new(2.5, *colour);
            if *dashed {
                for k in 0..3 {
                    let x = rect.min.x + 8.0 * k as f32;
                    ui.painter().line_segment([egui::pos2(x, y), egui::pos2(x + 5.0, y)], stroke);
                }
            } else {
                ui.painter().line_segment([egui::pos2(rect.min.x, y), egui::pos2(rect.max.x, y)], stroke);
            }
            ui.label(egui::RichText::new(name).small());
            ui.add_space(8.0);
        }
    });
}

pub fn plots_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    let model = cx.model;
    ui.horizontal(|ui| {
        ui.selectable_value(&mut cx.state.bottom_tab, Tab::Probe, "Probe displacement").on_hover_text("The first probe's displacement components over simulated time, metres.");
        ui.selectable_value(&mut cx.state.bottom_tab, Tab::Energy, "Energies").on_hover_text("Kinetic and elastic energy over simulated time, joules.");
        ui.selectable_value(&mut cx.state.bottom_tab, Tab::Study, "Accuracy vs time").on_hover_text("The study's probe error against the reference solution versus milliseconds per frame; the running configurations are marked.");
        if cx.state.bottom_tab == Tab::Probe {
            ui.separator();
            let mut axes = cx.state.probe_axes(model.compare());
            for (k, name) in ["u_x", "u_y", "u_z"].iter().enumerate() {
                ui.checkbox(&mut axes[k], *name);
            }
            if axes != cx.state.probe_axes(model.compare()) {
                cx.state.probe_axes = Some(axes);
            }
        }
    });
    let names = ["A", "B"];
    let labels = super::session::labels(model.sessions());
    match cx.state.bottom_tab {
        Tab::Probe => {
            let probe = model.sessions()[0].instance.probes.first().map_or("probe".to_string(), |p| p.name.clone());
            let axes = cx.state.probe_axes(model.compare());
            let mut entries = Vec::new();
            for k in 0..model.sessions().len() {
                for (axis, label) in ["u_x", "u_y", "u_z"].iter().enumerate().filter(|(a, _)| axes[*a]) {
                    let name =
                        if model.compare() { format!("{} {} {label}", names[k], labels[k]) } else { label.to_string() };
                    entries.push((name, line_colour(model.compare(), k, axis), false));
                }
            }
            let first = &model.sessions()[0];
            let reference = first.reference.reference().and_then(|r| r.probes.get(&probe)).copied();
            if reference.is_some() && axes[2] {
                entries.push(("reference u_z (static)".to_string(), REFERENCE_COLOUR, true));
            }
            let motion = first.reference_motion().filter(|_| probe == "tip" && axes[2]);
            if motion.is_some() {
                entries.push((REFERENCE_MOTION_LABEL.to_string(), MOTION_COLOUR, true));
            }
            legend_row_ui(ui, &entries);
            Plot::new("probe")
                .show_background(false)
                .x_axis_label("t (s)")
                .y_axis_label(format!("{probe} u (m)"))
                .show(ui, |plot| {
                    for (k, s) in model.sessions().iter().enumerate() {
                        let h = &s.history;
                        for (axis, label) in ["u_x", "u_y", "u_z"].iter().enumerate().filter(|(a, _)| axes[*a]) {
                            let points =
                                PlotPoints::Owned(decimate(&h.time_secs, |i| h.probe_m[i][axis], MAX_PLOT_POINTS));
                            let name = if model.compare() {
                                format!("{} {} {label}", names[k], labels[k])
                            } else {
                                label.to_string()
                            };
                            plot.line(
                                Line::new(name, points).color(line_colour(model.compare(), k, axis)).allow_band(false),
                            );
                        }
                    }
                    let h = &first.history;
                    // the reference displacement, as a dashed level
                    if let Some(r) = reference.filter(|_| axes[2]) {
                        let t1 = h.time_secs.last().copied().unwrap_or(1.0).max(1e-3);
                        plot.line(
                            Line::new("reference u_z (static)", PlotPoints::from(vec![[0.0, r[2]], [t1, r[2]]]))
                                .color(REFERENCE_COLOUR)
                                .style(egui_plot::LineStyle::dashed_loose()),
                        );
                    }
                    // the reference motion (the beam released from rest), dashed, as far as the
                    // run has come
                    if let Some(m) = motion {
                        let t1 = h.time_secs.last().copied().unwrap_or(0.0);
                        let points: Vec<[f64; 2]> = m
                            .tip_z_m
                            .iter()
                            .enumerate()
                            .map(|(i, z)| [i as f64 * m.sample_secs, *z])
                            .take_while(|p| p[0] <= t1 + 1e-9)
                            .collect();
                        if points.len() > 1 {
                            plot.line(
                                Line::new(REFERENCE_MOTION_LABEL, PlotPoints::from(points))
                                    .color(MOTION_COLOUR)
                                    .style(egui_plot::LineStyle::dashed_dense()),
                            );
                        }
                    }
                });
        }
        Tab::Energy => {
            let mut entries = Vec::new();
            for k in 0..model.sessions().len() {
                let prefix = if model.compare() { format!("{} ", names[k]) } else { String::new() };
                entries.push((format!("{prefix}kinetic"), line_colour(model.compare(), k, 0), false));
                entries.push((format!("{prefix}elastic"), line_colour(model.compare(), k, 2), false));
            }
            legend_row_ui(ui, &entries);
            Plot::new("energy").show_background(false).x_axis_label("t (s)").y_axis_label("energy (J)").show(
                ui,
                |plot| {
                    for (k, s) in model.sessions().iter().enumerate() {
                        let h = &s.history;
                        let prefix = if model.compare() { format!("{} ", names[k]) } else { String::new() };
                        plot.line(
                            Line::new(
                                format!("{prefix}kinetic"),
                                PlotPoints::Owned(decimate(&h.time_secs, |i| h.kinetic_j[i], MAX_PLOT_POINTS)),
                            )
                            .color(line_colour(model.compare(), k, 0))
                            .allow_band(false),
                        );
                        plot.line(
                            Line::new(
                                format!("{prefix}elastic"),
                                PlotPoints::Owned(decimate(&h.time_secs, |i| h.elastic_j[i], MAX_PLOT_POINTS)),
                            )
                            .color(line_colour(model.compare(), k, 2))
                            .allow_band(false),
                        );
                    }
                },
            );
        }
        Tab::Study => {
            let current: Vec<StudyPoint> = model
                .sessions()
                .iter()
                .filter_map(|s| {
                    // a settled state or the mean of the motion, never an instantaneous value
                    let readout = s.readout();
                    readout.error_with_uncertainty_m().map(|(error_m, uncertainty_m)| StudyPoint {
                        label: format!(
                            "now: {} ({})",
                            s.label(),
                            if matches!(readout, Readout::Settled { .. }) { "settled" } else { "mean of the motion" }
                        ),
                        ms_per_frame: s.ms_per_frame,
                        error_m,
                        uncertainty_m,
                    })
                })
                .collect();
            study_chart_ui(ui, model.sessions()[0].base.name(), &current);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::decimate;

    #[test]
    fn decimation_keeps_short_series_and_the_envelope_of_long_ones() {
        let t: Vec<f64> = (0..100).map(|i| i as f64).collect();
        assert_eq!(decimate(&t, |i| t[i] * 2.0, 1200).len(), 100);
        // 20,000 samples of a fast oscillation: at most 1,200 points, extremes kept, time ordered
        let t: Vec<f64> = (0..20_000).map(|i| i as f64 * 1e-3).collect();
        let y = |i: usize| (t[i] * 40.0).sin() * (1.0 + t[i]);
        let d = decimate(&t, y, 1200);
        assert!(d.len() <= 1200 && d.len() > 500, "{}", d.len());
        assert!(d.windows(2).all(|w| w[0].x < w[1].x));
        let max = (0..t.len()).map(y).fold(f64::MIN, f64::max);
        let min = (0..t.len()).map(y).fold(f64::MAX, f64::min);
        assert_eq!(d.iter().map(|p| p.y).fold(f64::MIN, f64::max), max);
        assert_eq!(d.iter().map(|p| p.y).fold(f64::MAX, f64::min), min);
    }
}
