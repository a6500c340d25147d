//! The control panel: the scene, compare mode and one generic row per parameter of the table
//! ([`hox_scenes::params`]), its widget chosen by the parameter's kind. Every row edits a copy of
//! the active configuration and returns it as an [`Action::Change`]: the model validates it
//! through the scene (so the app refuses exactly what a scene file or the CLI would) and
//! rebuilds only what the change invalidates. The playback, view, Rerun and figure sections
//! below the rows are `sections.rs`.

use super::action::Action;
use super::config::{Config, SceneSource};
use super::sections::label;
use super::ui_state::Ctx;
use eframe::egui;
use hox_scenes::params::{self, Group, Kind, Param, Value};

pub fn controls_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.heading("Scene");
    let current = cx.model.scene().label();
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
    if let Some(source) = chosen {
        cx.out.push(Action::LoadScene(source));
    }
    // at the body's size (issue #57: at about 8 px a class could not read it)
    ui.label(egui::RichText::new(&cx.model.sessions()[0].base.file.description).weak());
    let mut compare = cx.model.compare();
    if ui
        .checkbox(&mut compare, "Compare two configurations")
        .on_hover_text(
            "Run a second configuration of the scene side by side; 🔗 links choose which controls it shares.",
        )
        .changed()
    {
        cx.out.push(Action::SetCompare(compare));
    }
    if cx.model.compare() {
        let names = super::session::labels(cx.model.sessions());
        ui.horizontal(|ui| {
            ui.label("Editing:");
            for k in 0..2 {
                let text = format!("{} {}", ["A", "B"][k], names[k]);
                if ui
                    .selectable_label(cx.model.active() == k, text)
                    .on_hover_text("The configuration the controls below change.")
                    .clicked()
                {
                    cx.out.push(Action::SetActive(k));
                }
            }
        });
    }
    ui.separator();
    for group in Group::ALL {
        params_ui(cx, ui, group);
        ui.separator();
    }
    super::sections::playback_ui(cx, ui);
    ui.separator();
    super::sections::view_ui(cx, ui);
    ui.separator();
    super::sections::rerun_ui(cx, ui);
    ui.separator();
    super::sections::figure_ui(cx, ui);
}

/// The reason a control's last change was refused, under it.
fn refusal_ui(cx: &Ctx, ui: &mut egui::Ui, control: &str) {
    if let Some((c, reason)) = cx.model.refusal()
        && c == control
    {
        ui.colored_label(ui.visuals().error_fg_color, format!("refused: {reason}"));
    }
}

/// A link toggle for `field` in compare mode.
fn link_ui(cx: &mut Ctx, ui: &mut egui::Ui, field: &str) {
    if !cx.model.compare() {
        return;
    }
    let linked = cx.model.links().linked(field);
    let text = if linked { "linked" } else { "free" };
    if ui
        .selectable_label(linked, text)
        .on_hover_text("Linked: the other configuration follows this control. Click to unlink.")
        .clicked()
    {
        cx.out.push(Action::SetLink { key: field.to_string(), linked: !linked });
    }
}

/// A numeric text field for parameter `p` that applies on Enter or focus loss; unparsable or
/// refused values keep the previous value and show the reason.
fn number_ui(cx: &mut Ctx, ui: &mut egui::Ui, p: &'static Param, enabled: bool) {
    let field = p.key;
    let text = p.label_with_unit();
    let model = cx.model;
    let config = &model.active_session().config;
    let value = (p.get)(config).to_string();
    ui.horizontal(|ui| {
        let l = label(ui, &text, p.help);
        let key = format!("{}:{field}", cx.model.active());
        let buffer = cx.state.edits.entry(key.clone()).or_insert_with(|| value.clone());
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
                    let mut c = config.clone();
                    (p.set)(&mut c, v);
                    cx.out.push(Action::change(field, c));
                }
                Ok(_) => {}
                Err(e) => cx.out.push(Action::Refuse { control: field.to_string(), reason: e }),
            }
            // the next frame shows what is in force then
            cx.state.edits.remove(&key);
        } else if !response.has_focus() {
            *buffer = value;
        }
        link_ui(cx, ui, field);
    });
    refusal_ui(cx, ui, field);
}

/// One control row: its label (with tooltip), a widget editing a copy of the value, the link
/// toggle, and under it the reason of a refused change. A changed value goes through
/// [`Action::Change`]. A number typed into a slider or a cell applies on Enter or focus loss,
/// not digit by digit (issue #57: typing "64" first rebuilt the beam at 6 cells).
#[allow(clippy::too_many_arguments)]
fn row_ui<T: Clone + PartialEq>(
    cx: &mut Ctx,
    ui: &mut egui::Ui,
    field: &str,
    text: &str,
    tip: &str,
    get: impl Fn(&Config) -> T,
    set: impl Fn(&mut Config, T),
    widget: impl FnOnce(&mut egui::Ui, &mut T) -> egui::Response,
) {
    let model = cx.model;
    let current = &model.active_session().config;
    ui.horizontal(|ui| {
        let l = label(ui, text, tip);
        let mut value = get(current);
        widget(ui, &mut value).labelled_by(l.id).on_hover_text(tip);
        if value != get(current) {
            let mut n = current.clone();
            set(&mut n, value);
            cx.out.push(Action::change(field, n));
        }
        link_ui(cx, ui, field);
    });
    refusal_ui(cx, ui, field);
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
fn params_ui(cx: &mut Ctx, ui: &mut egui::Ui, group: Group) {
    ui.heading(group.heading());
    let kind = cx.model.active_session().base.mesh_kind();
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
        param_ui(cx, ui, p);
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
fn param_ui(cx: &mut Ctx, ui: &mut egui::Ui, p: &'static Param) {
    let model = cx.model;
    let k = model.active();
    let session = model.active_session();
    let config = session.config.clone();
    let enabled = p.applies_to(&config);
    // a part meshed per element type offers the types it has files for
    let files: Vec<String> = session.base.file.mesh_files.keys().cloned().collect();
    let text = p.label_with_unit();
    let get = |c: &Config| (p.get)(c);
    let set = |c: &mut Config, v: Value| {
        (p.set)(c, v);
    };
    match p.kind {
        Kind::Number { soft: None, .. } => number_ui(cx, ui, p, enabled),
        // a list (the fields) is shown and chosen by its first entry: the app draws that one
        Kind::Choice(_) | Kind::Choices(_) => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
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
        Kind::Whole { min, soft_max, .. } => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Whole(n) = v else { return ui.label("?") };
            let log = soft_max >= 20 * min.max(1);
            ui.add_enabled(enabled, egui::Slider::new(n, min..=soft_max).logarithmic(log).update_while_editing(false))
        }),
        Kind::Number { soft: Some((lo, hi)), .. } => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Number(x) = v else { return ui.label("?") };
            let suffix = if p.key == "fps" { " fps".to_string() } else { String::new() };
            ui.add_enabled(
                enabled,
                egui::Slider::new(x, lo..=hi).logarithmic(true).suffix(suffix).update_while_editing(false),
            )
        }),
        Kind::Flag => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Flag(b) = v else { return ui.label("?") };
            ui.add_enabled(enabled, egui::Checkbox::new(b, "on"))
        }),
        Kind::Grid { min, max } => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
            let Value::Grid(g) = v else { return ui.label("?") };
            let mut response: Option<egui::Response> = None;
            for (cells, axis) in g.iter_mut().zip(["x", "y", "z"]) {
                let l = ui.label(axis);
                let r = ui
                    .add_enabled(enabled, egui::DragValue::new(cells).range(min..=max).update_while_editing(false))
                    .labelled_by(l.id);
                response = Some(match response {
                    Some(prev) => prev | r,
                    None => r,
                });
            }
            response.expect("three cells")
        }),
        Kind::Degree { max } => row_ui(cx, ui, p.key, &text, p.help, get, set, |ui, v| {
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
        // issue #61: the solver that is not the one for this part says so, and names the one
        if let Some(advice) = hox_scenes::run::solver_advice(&session.instance) {
            ui.label(egui::RichText::new(advice).color(ui.visuals().warn_fg_color));
        }
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
    let damps = info.implicit && integrator.info().damps_motion;
    let colour = if damps { ui.visuals().warn_fg_color } else { ui.visuals().weak_text_color() };
    ui.label(egui::RichText::new(info.motion).color(colour));
    if info.implicit {
        let i = integrator.info();
        ui.label(egui::RichText::new(format!("{}: {}", i.long_name, i.motion)).color(colour));
    }
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
