//! The sections below the parameter rows of the control panel: playback, the view's options and
//! camera presets, the live Rerun output, and the paper's figure of the view. Each reads the model
//! and returns commands ([`Ctx`]).

use super::action::{Action, Command, RerunTarget};
use super::presets::ViewPreset;
use super::ui_state::Ctx;
use eframe::egui;

/// A row label with a tooltip.
pub fn label(ui: &mut egui::Ui, text: &str, tip: &str) -> egui::Response {
    ui.label(text).on_hover_text(tip)
}

/// *Settle* (E): run to rest with the settle damping, as `hox simulate --settle` does.
pub fn settle_button_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    let settling = cx.model.settling();
    let text = if settling { "Settling…" } else { "Settle" };
    let tip = "Run every configuration with the scene's settle damping, as fast as the machine allows, until it is at rest (E); then the readout shows the settled error against the reference, as `hox simulate --settle` does.";
    if ui.add_enabled(!settling, egui::Button::new(text)).on_hover_text(tip).clicked() {
        cx.out.push(Action::Settle);
    }
}

/// Play or pause, one step, reset, settle: the menu bar's and the playback section's buttons.
pub fn play_buttons_ui(cx: &mut Ctx, ui: &mut egui::Ui, long_tips: bool) {
    let play = if cx.model.playing() { "Pause" } else { "Play" };
    let tips = if long_tips {
        [
            "Run or pause the simulation (space).",
            "Advance exactly one frame (S).",
            "Back to the rest shape at t = 0 (R).",
        ]
    } else {
        ["Run or pause (space).", "One frame (S).", "Rest shape, t = 0 (R)."]
    };
    if ui.button(play).on_hover_text(tips[0]).clicked() {
        cx.out.push(Action::TogglePlaying);
    }
    if ui.button("Step").on_hover_text(tips[1]).clicked() {
        cx.out.push(Action::SetPlaying(false));
        cx.out.push(Action::Step(1));
    }
    if ui.button("Reset").on_hover_text(tips[2]).clicked() {
        cx.out.push(Action::Reset);
    }
    settle_button_ui(cx, ui);
}

pub fn playback_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.heading("Playback");
    ui.horizontal(|ui| play_buttons_ui(cx, ui, false));
    ui.horizontal(|ui| {
        let l = label(ui, "Time scale", "Simulated seconds per real second (1 = real time; the simulation slows down by itself when a frame costs more than real time).");
        let mut scale = cx.model.playback().time_scale;
        let r = ui.add(egui::Slider::new(&mut scale, 0.05..=4.0).logarithmic(true).suffix("×")).labelled_by(l.id);
        if r.changed() {
            cx.out.push(Action::SetTimeScale(scale));
        }
    });
}

pub fn view_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.heading("View");
    let mut v = cx.model.view().clone();
    ui.horizontal_wrapped(|ui| {
        ui.checkbox(&mut v.edges, "edges")
            .on_hover_text("Element edges on the surface (curved for high-order elements).");
        ui.checkbox(&mut v.nodes, "nodes")
            .on_hover_text("Corner nodes white, high-order (edge, face, interior) nodes cyan.");
        ui.checkbox(&mut v.boundary_conditions, "clamped / driven")
            .on_hover_text("Clamped nodes blue, nodes with prescribed motion magenta.");
        ui.checkbox(&mut v.ghost, "rest shape").on_hover_text("The undeformed shape's edges as a faint ghost.");
        ui.checkbox(&mut v.probes, "probes").on_hover_text("The probe points the study measures (red).");
    });
    if &v != cx.model.view() {
        cx.out.push(Action::SetView(v));
    }
    camera_ui(cx, ui);
}

/// The camera presets (keys 1–4): compared configurations are laid apart across the line of
/// sight, so neither hides the other.
pub fn camera_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.label("Camera");
        for (k, preset) in ViewPreset::ALL.into_iter().enumerate() {
            let help = match preset {
                ViewPreset::Iso => "Three-quarter view from the front, above",
                ViewPreset::Front => "Looking at the x–z plane: the bending of a beam",
                ViewPreset::Side => "Looking along the beam at the y–z plane: twist and sideways bend",
                ViewPreset::Top => "Looking down at the x–y plane: a sideways bend (the tet split's bias)",
            };
            let selected = cx.model.preset() == preset;
            if ui.selectable_label(selected, preset.name()).on_hover_text(format!("{help} (key {}).", k + 1)).clicked()
            {
                cx.out.push(Action::SetPreset(preset));
            }
        }
    });
}

pub fn rerun_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.heading("Rerun");
    let on = cx.status.rerun_target.is_some();
    ui.horizontal(|ui| {
        let l = label(ui, "Viewer", "A running Rerun viewer 0.36.3 to stream to (start one with scripts/rerun.sh).");
        ui.add_enabled(!on, egui::TextEdit::singleline(&mut cx.state.rerun_url).desired_width(200.0)).labelled_by(l.id);
    });
    ui.horizontal(|ui| {
        let l = label(ui, "File", "An .rrd file to save the recording to.");
        ui.add_enabled(!on, egui::TextEdit::singleline(&mut cx.state.rerun_file).desired_width(200.0))
            .labelled_by(l.id);
    });
    ui.horizontal_wrapped(|ui| {
        if on {
            if ui.button("Stop Rerun").clicked() {
                cx.out.push(Command::Rerun(None));
            }
        } else {
            if ui
                .button("Stream to viewer")
                .on_hover_text("Log every simulated frame to the viewer at the URL above.")
                .clicked()
            {
                cx.out.push(Command::Rerun(Some(RerunTarget::Viewer)));
            }
            if ui.button("Save to file").on_hover_text("Log every simulated frame to the .rrd file above.").clicked() {
                cx.out.push(Command::Rerun(Some(RerunTarget::File)));
            }
            let bind = &cx.status.bind;
            if ui
                .button("Serve to browsers")
                .on_hover_text(format!(
                    "Serve the Rerun web viewer on {bind} (--bind names another address, e.g. 0.0.0.0 for the \
                     classroom network): students open the address shown below and follow live, nothing to install."
                ))
                .clicked()
            {
                cx.out.push(Command::Rerun(Some(RerunTarget::Browsers)));
            }
        }
    });
    if let Some(t) = &cx.status.rerun_target {
        ui.label(format!("Rerun: {t}"));
    }
    if let Some(url) = &cx.status.web_url
        && ui.button("Copy the address").clicked()
    {
        ui.ctx().copy_text(url.clone());
    }
}

/// The paper's figure of the configurations on screen, exported as SVG and PNG (issue #39).
pub fn figure_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.heading("Figure");
    ui.horizontal(|ui| {
        let l = label(ui, "Folder", "Where the figure's SVG and PNG are written.");
        ui.add(egui::TextEdit::singleline(&mut cx.state.figure_folder).desired_width(200.0)).labelled_by(l.id);
    });
    let name = cx.model.active_session().base.name().to_string();
    let paper = hox_scenes::paper::FigureKind::of_scene(&name).is_some();
    let help = if paper {
        "Draw the configurations on screen (A and B in compare mode) as they are now in the style of the paper's \
         figure for this scene (hox paper): sampled inside the elements, against the reference in red."
    } else {
        "The paper's figures are of its three scenes: tension, torsion and bending."
    };
    if ui
        .add_enabled(paper, egui::Button::new("Export figure"))
        .on_hover_text(help)
        .on_disabled_hover_text(help)
        .clicked()
    {
        cx.out.push(Command::ExportFigure);
    }
}
