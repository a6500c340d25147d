//! The menu bar (File, Lessons, View, the playback buttons, the time and the last message) and
//! the keyboard shortcuts: space play/pause, S single step, E settle, R reset, 1–4 the camera
//! presets, F the next field; in a lesson → / N next step, ← / B previous, A the answer; P
//! presenter mode. Each returns commands ([`Ctx`]).

use super::action::Action;
use super::presets::ViewPreset;
use super::sections::play_buttons_ui;
use super::ui_state::Ctx;
#[cfg(not(target_arch = "wasm32"))]
use super::ui_state::OpenDialog;
use eframe::egui;

pub fn menu_bar_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    egui::MenuBar::new().ui(ui, |ui| {
        #[cfg(not(target_arch = "wasm32"))]
        file_menu_ui(cx, ui);
        #[cfg(target_arch = "wasm32")]
        page_menu_ui(cx, ui);
        lessons_menu_ui(cx, ui);
        ui.menu_button("View", |ui| {
            let mut shown = cx.model.show_reference_element();
            if ui
                .checkbox(&mut shown, "Reference element")
                .on_hover_text("Shape functions of a reference element as colour fields, with its quadrature points.")
                .changed()
            {
                cx.out.push(Action::ShowReferenceElement(shown));
            }
            if ui
                .button("Reset camera")
                .on_hover_text("Frame the bodies again (double-click in the view does the same).")
                .clicked()
            {
                cx.state.viewport.reset_camera(cx.model.sessions(), &cx.model.offsets());
                ui.close();
            }
            ui.separator();
            for (k, preset) in ViewPreset::ALL.into_iter().enumerate() {
                let mut name = format!("{} view", preset.name());
                name[..1].make_ascii_uppercase();
                if ui
                    .selectable_label(cx.model.preset() == preset, name)
                    .on_hover_text(format!("Key {}.", k + 1))
                    .clicked()
                {
                    cx.out.push(Action::SetPreset(preset));
                    ui.close();
                }
            }
        });
        ui.separator();
        play_buttons_ui(cx, ui, true);
        ui.label(format!("t = {:.2} s", cx.model.sessions()[0].instance.sim.time_secs()));
        if let Some(m) = cx.model.message() {
            ui.separator();
            // cut to the bar's width with "…", whole on hover (issue #57: the serving address ran
            // off the window's edge)
            ui.add(egui::Label::new(m).truncate()).on_hover_text(m);
        }
    });
}

/// The desktop's File menu: a scene file or a mesh file opened by its path.
#[cfg(not(target_arch = "wasm32"))]
fn file_menu_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.menu_button("File", |ui| {
        if ui
            .button("Open scene file…")
            .on_hover_text("Load a scene from a TOML file (see assets/scenes/).")
            .clicked()
        {
            cx.state.open_dialog =
                Some(OpenDialog { mesh: false, path: "assets/scenes/".into(), ..Default::default() });
            ui.close();
        }
        if ui
            .button("Open mesh file…")
            .on_hover_text("Simulate a Gmsh .msh mesh: clamp one of its physical groups, gravity on.")
            .clicked()
        {
            cx.state.open_dialog = Some(OpenDialog {
                mesh: true,
                path: "assets/meshes/".into(),
                clamp_group: "clamp".into(),
                ..Default::default()
            });
            ui.close();
        }
        ui.separator();
        if ui
            .button("Copy page link")
            .on_hover_text("The link query that opens this configuration (or lesson step) in hox's web page: `hox serve-app --link` takes it, and so does the page's address.")
            .clicked()
        {
            let query = link_query_of(cx);
            ui.ctx().copy_text(query.clone());
            cx.out.push(Action::Say(format!("Copied: {query} (hox serve-app --link takes it)")));
            ui.close();
        }
    });
}

/// The link query that opens what is on screen ([`super::args::link_query`]).
fn link_query_of(cx: &Ctx) -> String {
    let configs: Vec<_> = cx.model.sessions().iter().map(|s| (&s.config, s.base.params())).collect();
    let lesson = cx.model.lesson().map(|l| (l.lesson.name.as_str(), l.step + 1));
    super::args::link_query(cx.model.scene(), &configs, lesson)
}

/// The page's menu (no files to open by path): copy the link that opens what is on screen, and
/// how to bring a mesh of one's own (dropped onto the page).
#[cfg(target_arch = "wasm32")]
fn page_menu_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.menu_button("Page", |ui| {
        if ui
            .button("Copy link")
            .on_hover_text("A link that opens this configuration (or this lesson step): hand it to the class.")
            .clicked()
        {
            let link = format!("{}{}", super::platform::page::page_address().unwrap_or_default(), link_query_of(cx));
            ui.ctx().copy_text(link.clone());
            cx.out.push(Action::Say(format!("Link copied: {link}")));
            ui.close();
        }
        ui.separator();
        ui.label("Your own mesh: drop a Gmsh .msh file onto the page\n(its group 'clamp' is held, gravity on).");
    });
}

/// The Lessons menu: every built-in lesson, and presenter mode.
fn lessons_menu_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    ui.menu_button("Lessons", |ui| {
        match hox_scenes::lesson::registry() {
            Ok(all) => {
                for l in all {
                    if ui.button(&l.title).on_hover_text(&l.goal).clicked() {
                        cx.out.push(Action::OpenLesson(Box::new(l)));
                        ui.close();
                    }
                }
            }
            Err(e) => {
                ui.label(e.to_string());
            }
        }
        ui.separator();
        let mut on = cx.model.presenter();
        if ui.checkbox(&mut on, "Presenter mode (P)").clicked() {
            cx.out.push(Action::SetPresenter(on));
        }
    });
}

/// The keyboard shortcuts (when no text field has the keyboard).
pub fn shortcuts(cx: &mut Ctx, ctx: &egui::Context) {
    if ctx.egui_wants_keyboard_input() {
        return;
    }
    let pressed = |k: egui::Key| ctx.input(|i| i.key_pressed(k));
    // camera presets 1–4, and F for the next field
    let keys = [egui::Key::Num1, egui::Key::Num2, egui::Key::Num3, egui::Key::Num4];
    if let Some(k) = keys.iter().position(|k| pressed(*k)) {
        cx.out.push(Action::SetPreset(ViewPreset::ALL[k]));
    }
    if pressed(egui::Key::F) {
        cx.out.push(Action::NextField);
    }
    if pressed(egui::Key::E) {
        cx.out.push(Action::Settle);
    }
    if pressed(egui::Key::Space) {
        cx.out.push(Action::TogglePlaying);
    }
    if pressed(egui::Key::S) {
        cx.out.push(Action::SetPlaying(false));
        cx.out.push(Action::Step(1));
    }
    if pressed(egui::Key::R) {
        cx.out.push(Action::Reset);
    }
    if pressed(egui::Key::P) {
        cx.out.push(Action::SetPresenter(!cx.model.presenter()));
    }
    if cx.model.lesson().is_none() {
        return;
    }
    if pressed(egui::Key::ArrowRight) || pressed(egui::Key::N) {
        cx.out.push(Action::LessonStep(1));
    }
    if pressed(egui::Key::ArrowLeft) || pressed(egui::Key::B) {
        cx.out.push(Action::LessonStep(-1));
    }
    if pressed(egui::Key::A) {
        cx.out.push(Action::RevealAnswer);
    }
}
