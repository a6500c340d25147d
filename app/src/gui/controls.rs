//! The control panel, the menu bar and the open-file dialog. Every control edits a copy of the
//! active configuration and hands it to [`HoxApp::apply`], which validates it through the
//! scene (so the app refuses exactly what a scene file or the CLI would) and rebuilds only
//! what the change invalidates.

use super::config::Config;
use super::rerun_link::RerunTarget;
use super::{HoxApp, SceneSource};
use eframe::egui;
use hox_scenes::params::{self, Group, Kind, Param, Value};

/// The File → Open dialog: a path typed or picked from the project's assets.
#[derive(Clone, Debug, Default)]
pub struct OpenDialog {
    pub mesh: bool,
    pub path: String,
    pub clamp_group: String,
    pub error: Option<String>,
}

pub fn menu_bar_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            if ui
                .button("Open scene file…")
                .on_hover_text("Load a scene from a TOML file (see assets/scenes/).")
                .clicked()
            {
                app.open_dialog = Some(OpenDialog { mesh: false, path: "assets/scenes/".into(), ..Default::default() });
                ui.close();
            }
            if ui
                .button("Open mesh file…")
                .on_hover_text("Simulate a Gmsh .msh mesh: clamp one of its physical groups, gravity on.")
                .clicked()
            {
                app.open_dialog = Some(OpenDialog {
                    mesh: true,
                    path: "assets/meshes/".into(),
                    clamp_group: "clamp".into(),
                    ..Default::default()
                });
                ui.close();
            }
        });
        super::lesson::lessons_menu_ui(app, ui);
        ui.menu_button("View", |ui| {
            ui.checkbox(&mut app.show_reference_element, "Reference element")
                .on_hover_text("Shape functions of a reference element as colour fields, with its quadrature points.");
            if ui
                .button("Reset camera")
                .on_hover_text("Frame the bodies again (double-click in the view does the same).")
                .clicked()
            {
                let offsets = app.offsets();
                app.viewport.reset_camera(&app.sessions, &offsets);
                ui.close();
            }
            ui.separator();
            for (k, preset) in super::viewport::ViewPreset::ALL.into_iter().enumerate() {
                let mut name = format!("{} view", preset.name());
                name[..1].make_ascii_uppercase();
                if ui
                    .selectable_label(app.viewport.preset == preset, name)
                    .on_hover_text(format!("Key {}.", k + 1))
                    .clicked()
                {
                    app.set_camera(preset);
                    ui.close();
                }
            }
        });
        ui.separator();
        let play = if app.playback.playing { "Pause" } else { "Play" };
        if ui.button(play).on_hover_text("Run or pause the simulation (space).").clicked() {
            app.playback.playing = !app.playback.playing;
        }
        if ui.button("Step").on_hover_text("Advance exactly one frame (S).").clicked() {
            app.playback.playing = false;
            app.step(1);
        }
        if ui.button("Reset").on_hover_text("Back to the rest shape at t = 0 (R).").clicked() {
            app.reset();
        }
        settle_button_ui(app, ui);
        ui.label(format!("t = {:.2} s", app.sessions[0].instance.sim.time_secs()));
        if let Some(m) = &app.message {
            ui.separator();
            ui.label(m.as_str());
        }
    });
}

/// A row label with a tooltip.
fn label(ui: &mut egui::Ui, text: &str, tip: &str) -> egui::Response {
    ui.label(text).on_hover_text(tip)
}

/// The reason a control's last change was refused, under it.
fn refusal_ui(app: &HoxApp, ui: &mut egui::Ui, control: &str) {
    if let Some((c, reason)) = &app.refusal
        && c == control
    {
        ui.colored_label(egui::Color32::from_rgb(255, 110, 90), format!("refused: {reason}"));
    }
}

/// A link toggle for `field` in compare mode.
fn link_ui(app: &mut HoxApp, ui: &mut egui::Ui, field: &str) {
    if !app.compare {
        return;
    }
    let linked = app.links.linked(field);
    let text = if linked { "linked" } else { "free" };
    if ui
        .selectable_label(linked, text)
        .on_hover_text("Linked: the other configuration follows this control. Click to unlink.")
        .clicked()
    {
        app.links.0.insert(field.to_string(), !linked);
    }
}

/// A numeric text field for parameter `p` that applies on Enter or focus loss; unparsable or
/// refused values keep the previous value and show the reason.
fn number_ui(app: &mut HoxApp, ui: &mut egui::Ui, p: &'static Param, enabled: bool) {
    let field = p.key;
    let text = p.label_with_unit();
    let value = (p.get)(&app.sessions[app.active].config).to_string();
    ui.horizontal(|ui| {
        let l = label(ui, &text, p.help);
        let key = format!("{}:{field}", app.active);
        let buffer = app.edits.entry(key.clone()).or_insert_with(|| value.clone());
        // greyed like every other row when the configuration does not use it (a solver's own
        // parameter under another solver: issue #35's "Chebyshev ρ" under XPBD)
        let response = ui
            .add_enabled(enabled, egui::TextEdit::singleline(buffer).desired_width(90.0))
            .labelled_by(l.id)
            .on_hover_text(p.help);
        let commit = response.lost_focus() || (response.has_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)));
        if commit {
            let typed = buffer.trim().to_string();
            match p.kind.parse(&typed) {
                Ok(v) if v.to_string() != value => {
                    let mut c = app.sessions[app.active].config.clone();
                    (p.set)(&mut c, v);
                    app.apply(field, c);
                }
                Ok(_) => {}
                Err(e) => app.refusal = Some((field.to_string(), e)),
            }
            // show what is in force now
            let now = (p.get)(&app.sessions[app.active].config).to_string();
            app.edits.insert(key, now);
        } else if !response.has_focus() {
            *buffer = value;
        }
        link_ui(app, ui, field);
    });
    refusal_ui(app, ui, field);
}

pub fn controls_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.heading("Scene");
    let current = app.scene.label();
    let mut chosen = None;
    let l = ui.label("Scene file or built-in scene");
    egui::ComboBox::from_id_salt("scene")
        .selected_text(&current)
        .show_ui(ui, |ui| {
            for name in hox_scenes::BUILTIN.iter().map(|(n, _)| *n) {
                if ui.selectable_label(current == name, name).clicked() {
                    chosen = Some(SceneSource::Builtin(name.to_string()));
                }
            }
        })
        .response
        .labelled_by(l.id)
        .on_hover_text("The scene: its mesh, material, effects (gravity, clamps, motion…) and probes.");
    if let Some(source) = chosen
        && let Err(e) = app.load_scene(source, None)
    {
        app.message = Some(e);
    }
    ui.label(egui::RichText::new(&app.sessions[0].base.file.description).small());
    let mut compare = app.compare;
    if ui
        .checkbox(&mut compare, "Compare two configurations")
        .on_hover_text(
            "Run a second configuration of the scene side by side; 🔗 links choose which controls it shares.",
        )
        .changed()
    {
        app.set_compare(compare);
    }
    if app.compare {
        ui.horizontal(|ui| {
            ui.label("Editing:");
            for k in 0..2 {
                let text = format!("{} {}", ["A", "B"][k], app.sessions[k].label());
                if ui
                    .selectable_label(app.active == k, text)
                    .on_hover_text("The configuration the controls below change.")
                    .clicked()
                {
                    app.active = k;
                }
            }
        });
    }
    ui.separator();
    for group in Group::ALL {
        params_ui(app, ui, group);
        ui.separator();
    }
    playback_ui(app, ui);
    ui.separator();
    view_ui(app, ui);
    ui.separator();
    rerun_ui(app, ui);
    ui.separator();
    figure_ui(app, ui);
}

/// One control row: its label (with tooltip), a widget editing a copy of the value, the link
/// toggle, and under it the reason of a refused change. A changed value goes through
/// [`HoxApp::apply`].
fn row_ui<T: Clone + PartialEq>(
    app: &mut HoxApp,
    ui: &mut egui::Ui,
    field: &str,
    text: &str,
    tip: &str,
    get: impl Fn(&Config) -> T,
    set: impl Fn(&mut Config, T),
    widget: impl FnOnce(&mut egui::Ui, &mut T) -> egui::Response,
) {
    let current = app.sessions[app.active].config.clone();
    ui.horizontal(|ui| {
        let l = label(ui, text, tip);
        let mut value = get(&current);
        widget(ui, &mut value).labelled_by(l.id).on_hover_text(tip);
        if value != get(&current) {
            let mut n = current.clone();
            set(&mut n, value);
            app.apply(field, n);
        }
        link_ui(app, ui, field);
    });
    refusal_ui(app, ui, field);
}

/// A combo box over `options` (value, text).
fn combo<T: Clone + PartialEq>(
    ui: &mut egui::Ui,
    id: (&str, usize),
    value: &mut T,
    shown: String,
    options: Vec<(T, String)>,
) -> egui::Response {
    egui::ComboBox::from_id_salt(id)
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (v, text) in options {
                ui.selectable_value(value, v, text);
            }
        })
        .response
}

/// The controls of one group of the parameter table (mesh, material, solver): a row per
/// parameter the app shows, its widget chosen by the parameter's kind.
fn params_ui(app: &mut HoxApp, ui: &mut egui::Ui, group: Group) {
    ui.heading(group.heading());
    let kind = app.sessions[app.active].base.mesh_kind();
    match (group, kind) {
        (Group::Mesh, params::MeshKind::File) => {
            ui.label("from a mesh file (element type and grid are the file's)");
            return;
        }
        (Group::Mesh, params::MeshKind::Files) => {
            ui.label("a part meshed once, written at each order: the element type picks its file");
        }
        _ => {}
    }
    for p in params::in_group(group).filter(|p| p.surfaces.app && p.used_with(kind)) {
        param_ui(app, ui, p);
    }
}

/// The menu of a choice parameter: `(value, text)` for each option of its table entry
/// ([`Kind::Choice`]), in the table's order — for the element type and the material model,
/// the registries' ([`hox_sim::element::ElementType::all`], [`hox_sim::material::MaterialModel::ALL`]).
/// Empty for a parameter that is not a choice.
pub fn choice_menu(p: &Param) -> Vec<(String, String)> {
    match p.kind {
        Kind::Choice(options) | Kind::Choices(options) => {
            options().into_iter().map(|(n, d)| (n.to_string(), d)).collect()
        }
        _ => Vec::new(),
    }
}

/// What a closed choice menu shows for the value `name`: the option's name in capitals when
/// its text starts with them ("P2 — quadratic tetrahedron" shows "P2"), else its text; a value
/// that is not an option, in capitals.
fn choice_shown(entries: &[(String, String)], name: &str) -> String {
    entries.iter().find(|(n, _)| n == name).map_or(name.to_uppercase(), |(n, d)| {
        if d.starts_with(&n.to_uppercase()) { n.to_uppercase() } else { d.clone() }
    })
}

/// One parameter's row.
fn param_ui(app: &mut HoxApp, ui: &mut egui::Ui, p: &'static Param) {
    let k = app.active;
    let config = app.sessions[k].config.clone();
    let enabled = p.applies_to(&config);
    // a part meshed per element type offers the types it has files for
    let files: Vec<String> = app.sessions[k].base.file.mesh_files.keys().cloned().collect();
    let text = p.label_with_unit();
    let get = |c: &Config| (p.get)(c);
    let set = |c: &mut Config, v: Value| {
        (p.set)(c, v);
    };
    match p.kind {
        Kind::Number { soft: None, .. } => number_ui(app, ui, p, enabled),
        // a list (the fields) is shown and chosen by its first entry: the app draws that one
        Kind::Choice(_) | Kind::Choices(_) => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Text(name) = v else { return ui.label("?") };
            if let Some((first, _)) = name.split_once(',') {
                *name = first.to_string();
            }
            let mut entries = choice_menu(p);
            if p.picks_file && !files.is_empty() {
                entries.retain(|(n, _)| files.contains(n));
            }
            let shown = choice_shown(&entries, name);
            ui.add_enabled_ui(enabled, |ui| combo(ui, (p.key, k), name, shown, entries)).inner
        }),
        Kind::Whole { min, soft_max, .. } => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Whole(n) = v else { return ui.label("?") };
            let log = soft_max >= 20 * min.max(1);
            ui.add_enabled(enabled, egui::Slider::new(n, min..=soft_max).logarithmic(log))
        }),
        Kind::Number { soft: Some((lo, hi)), .. } => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Number(x) = v else { return ui.label("?") };
            let suffix = if p.key == "fps" { " fps".to_string() } else { String::new() };
            ui.add_enabled(enabled, egui::Slider::new(x, lo..=hi).logarithmic(true).suffix(suffix))
        }),
        Kind::Flag => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Flag(b) = v else { return ui.label("?") };
            ui.add_enabled(enabled, egui::Checkbox::new(b, "on"))
        }),
        Kind::Grid { min, max } => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Grid(g) = v else { return ui.label("?") };
            let mut response: Option<egui::Response> = None;
            for (cells, axis) in g.iter_mut().zip(["x", "y", "z"]) {
                let l = ui.label(axis);
                let r = ui.add_enabled(enabled, egui::DragValue::new(cells).range(min..=max)).labelled_by(l.id);
                response = Some(match response {
                    Some(prev) => prev | r,
                    None => r,
                });
            }
            response.expect("three cells")
        }),
        Kind::Degree { max } => row_ui(app, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Degree(d) = v else { return ui.label("?") };
            let name = |d: Option<usize>| d.map_or("element default".to_string(), |d| format!("degree {d}"));
            let shown = name(*d);
            let mut options = vec![(None, name(None))];
            options.extend((1..=max).map(|d| (Some(d), name(Some(d)))));
            ui.add_enabled_ui(enabled, |ui| combo(ui, (p.key, k), d, shown, options)).inner
        }),
        Kind::Point => {}
    }
    if p.key == "solver" {
        solver_motion_ui(ui, config.method, config.integrator);
    }
}

/// Under the solver: what it and, for the implicit ones, their integrator do to the motion
/// (issue #35: the implicit solvers' beam lost half its swing each period with nothing on screen
/// saying why); in amber where the motion is damped (implicit Euler).
pub(super) fn solver_motion_ui(
    ui: &mut egui::Ui,
    method: hox_sim::solver::Method,
    integrator: hox_sim::solver::Integrator,
) {
    let info = method.info();
    let damps = info.implicit && integrator == hox_sim::solver::Integrator::Euler;
    let colour = if damps { egui::Color32::from_rgb(250, 200, 120) } else { ui.visuals().weak_text_color() };
    ui.label(egui::RichText::new(info.motion).small().color(colour));
    if info.implicit {
        let i = integrator.info();
        ui.label(egui::RichText::new(format!("{}: {}", i.long_name, i.motion)).small().color(colour));
    }
}

/// *Settle* (E): run to rest with the settle damping, as `hox simulate --settle` does.
fn settle_button_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    let settling = app.settling();
    let text = if settling { "Settling…" } else { "Settle" };
    let tip = "Run every configuration with the scene's settle damping, as fast as the machine allows, until it is at rest (E); then the readout shows the settled error against the reference, as `hox simulate --settle` does.";
    if ui.add_enabled(!settling, egui::Button::new(text)).on_hover_text(tip).clicked() {
        app.settle();
    }
}

fn playback_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.heading("Playback");
    ui.horizontal(|ui| {
        if ui
            .button(if app.playback.playing { "Pause" } else { "Play" })
            .on_hover_text("Run or pause (space).")
            .clicked()
        {
            app.playback.playing = !app.playback.playing;
        }
        if ui.button("Step").on_hover_text("One frame (S).").clicked() {
            app.playback.playing = false;
            app.step(1);
        }
        if ui.button("Reset").on_hover_text("Rest shape, t = 0 (R).").clicked() {
            app.reset();
        }
        settle_button_ui(app, ui);
    });
    ui.horizontal(|ui| {
        let l = label(ui, "Time scale", "Simulated seconds per real second (1 = real time; the simulation slows down by itself when a frame costs more than real time).");
        ui.add(egui::Slider::new(&mut app.playback.time_scale, 0.05..=4.0).logarithmic(true).suffix("×")).labelled_by(l.id);
    });
}

fn view_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.heading("View");
    let v = &mut app.view;
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
    camera_ui(app, ui);
}

/// The camera presets (keys 1–4): compared configurations are laid apart across the line of
/// sight, so neither hides the other.
pub fn camera_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.label("Camera");
        for (k, preset) in super::viewport::ViewPreset::ALL.into_iter().enumerate() {
            let help = match preset {
                super::viewport::ViewPreset::Iso => "Three-quarter view from the front, above",
                super::viewport::ViewPreset::Front => "Looking at the x–z plane: the bending of a beam",
                super::viewport::ViewPreset::Side => "Looking along the beam at the y–z plane: twist and sideways bend",
                super::viewport::ViewPreset::Top => {
                    "Looking down at the x–y plane: a sideways bend (the tet split's bias)"
                }
            };
            let selected = app.viewport.preset == preset;
            if ui.selectable_label(selected, preset.name()).on_hover_text(format!("{help} (key {}).", k + 1)).clicked()
            {
                app.set_camera(preset);
            }
        }
    });
}

fn rerun_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.heading("Rerun");
    let on = app.rerun_target().is_some();
    ui.horizontal(|ui| {
        let l = label(ui, "Viewer", "A running Rerun viewer 0.36.3 to stream to (start one with scripts/rerun.sh).");
        ui.add_enabled(!on, egui::TextEdit::singleline(&mut app.rerun_url).desired_width(200.0)).labelled_by(l.id);
    });
    ui.horizontal(|ui| {
        let l = label(ui, "File", "An .rrd file to save the recording to.");
        ui.add_enabled(!on, egui::TextEdit::singleline(&mut app.rerun_file).desired_width(200.0)).labelled_by(l.id);
    });
    ui.horizontal_wrapped(|ui| {
        if on {
            if ui.button("Stop Rerun").clicked() {
                app.set_rerun(None);
            }
        } else {
            if ui
                .button("Stream to viewer")
                .on_hover_text("Log every simulated frame to the viewer at the URL above.")
                .clicked()
            {
                app.set_rerun(Some(RerunTarget::Viewer));
            }
            if ui.button("Save to file").on_hover_text("Log every simulated frame to the .rrd file above.").clicked() {
                app.set_rerun(Some(RerunTarget::File));
            }
            let bind = app.serve.bind;
            if ui
                .button("Serve to browsers")
                .on_hover_text(format!(
                    "Serve the Rerun web viewer on {bind} (--bind names another address, e.g. 0.0.0.0 for the \
                     classroom network): students open the address shown below and follow live, nothing to install."
                ))
                .clicked()
            {
                app.set_rerun(Some(RerunTarget::Browsers));
            }
        }
    });
    if let Some(t) = app.rerun_target() {
        ui.label(format!("Rerun: {t}"));
    }
    if let Some(url) = app.web_url() {
        let url = url.to_string();
        if ui.button("Copy the address").clicked() {
            ui.ctx().copy_text(url);
        }
    }
}

/// The paper's figure of the configurations on screen, exported as SVG and PNG (issue #39).
fn figure_ui(app: &mut HoxApp, ui: &mut egui::Ui) {
    ui.heading("Figure");
    ui.horizontal(|ui| {
        let l = label(ui, "Folder", "Where the figure's SVG and PNG are written.");
        ui.add(egui::TextEdit::singleline(&mut app.figure_folder).desired_width(200.0)).labelled_by(l.id);
    });
    let name = app.sessions[app.active].base.name().to_string();
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
        let folder = std::path::PathBuf::from(&app.figure_folder);
        app.message = Some(match super::figure::export_figure(app, &folder) {
            Ok(files) => {
                format!("wrote {}", files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(" and "))
            }
            Err(e) => e,
        });
    }
}

/// The File → Open dialog.
pub fn open_dialog_ui(app: &mut HoxApp, ctx: &egui::Context) {
    let Some(mut dialog) = app.open_dialog.take() else { return };
    let mut open = true;
    let mut done = false;
    let title = if dialog.mesh { "Open mesh file" } else { "Open scene file" };
    egui::Window::new(title).open(&mut open).collapsible(false).show(ctx, |ui| {
        ui.horizontal(|ui| {
            let l = ui.label("Path");
            ui.add(egui::TextEdit::singleline(&mut dialog.path).desired_width(320.0)).labelled_by(l.id);
        });
        if dialog.mesh {
            ui.horizontal(|ui| {
                let l = ui.label("Clamp group").on_hover_text("The physical group (named node set) held fixed.");
                ui.add(egui::TextEdit::singleline(&mut dialog.clamp_group).desired_width(120.0)).labelled_by(l.id);
            });
        }
        // quick picks from the project's assets
        let folder = if dialog.mesh { "assets/meshes" } else { "assets/scenes" };
        let ext = if dialog.mesh { "msh" } else { "toml" };
        if let Ok(entries) = std::fs::read_dir(folder) {
            let mut files: Vec<_> = entries
                .filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == ext))
                .collect();
            files.sort();
            egui::ScrollArea::vertical().max_height(160.0).show(ui, |ui| {
                for f in files {
                    if ui.selectable_label(false, f.display().to_string()).clicked() {
                        dialog.path = f.display().to_string();
                    }
                }
            });
        }
        if let Some(e) = &dialog.error {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 90), e);
        }
        if ui.button("Open").clicked() {
            let path = std::path::PathBuf::from(dialog.path.trim());
            let result = if dialog.mesh {
                mesh_scene_file(&path, dialog.clamp_group.trim())
                    .and_then(|p| app.load_scene(SceneSource::File(p), None))
            } else {
                app.load_scene(SceneSource::File(path), None)
            };
            match result {
                Ok(()) => done = true,
                Err(e) => dialog.error = Some(e),
            }
        }
    });
    if open && !done {
        app.open_dialog = Some(dialog);
    }
}

/// A scene file for a mesh file: the mesh, its `clamp_group` clamped, gravity, the paper
/// beam's material; written next to the user's settings so it can be reopened.
pub(super) fn mesh_scene_file(mesh: &std::path::Path, clamp_group: &str) -> Result<std::path::PathBuf, String> {
    let mesh = std::fs::canonicalize(mesh).map_err(|e| format!("{}: {e}", mesh.display()))?;
    let name = mesh.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().to_string());
    // the scene `hox simulate --mesh FILE --clamp GROUP` runs: the paper's material (read from
    // the bending scene), gravity, the group clamped
    let mut file = hox_scenes::SceneFile::for_mesh_file(&mesh, true);
    file.description = format!("{} with group '{clamp_group}' clamped, under gravity", mesh.display());
    file.effects.push(hox_scenes::scene::EffectSpec::Clamp { nodes: hox_scenes::NodeSelector::group(clamp_group) });
    let text = file.to_toml();
    let dir = std::env::temp_dir().join("hox-app-scenes");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    // validate now, so a missing group is reported in the dialog
    hox_scenes::Scene::load(&path).map_err(|e| e.to_string())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hox_sim::element::ElementType;
    use hox_sim::material::MaterialModel;

    fn menu(key: &str) -> Vec<(String, String)> {
        let p = params::by_key(key).unwrap_or_else(|| panic!("no parameter {key}"));
        assert!(p.surfaces.app, "{key} has a control in the app");
        choice_menu(p)
    }

    #[test]
    fn the_element_and_material_menus_list_exactly_the_registered_types_and_models() {
        let values = |key| menu(key).into_iter().map(|(v, _)| v).collect::<Vec<_>>();
        let elements: Vec<String> = ElementType::all().map(|e| e.name().to_string()).collect();
        let models: Vec<String> = MaterialModel::ALL.iter().map(|m| m.name().to_string()).collect();
        assert_eq!(values("element"), elements);
        assert_eq!(values("material"), models);
    }

    #[test]
    fn a_closed_menu_shows_the_short_name_or_the_description() {
        let elements = menu("element");
        for e in ElementType::all() {
            assert_eq!(choice_shown(&elements, e.name()), e.name().to_uppercase(), "{e}");
        }
        let models = menu("material");
        for m in MaterialModel::ALL {
            assert_eq!(choice_shown(&models, m.name()), m.long_name(), "{m}");
        }
        assert_eq!(choice_shown(&elements, "p9"), "P9");
        assert!(menu("youngs").is_empty());
    }
}
