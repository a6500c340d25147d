//! The app's windows over the view: the File → Open dialog (a scene file, or a mesh file with a
//! clamp group), the question about a change too slow to play ([`super::cost`]), and the
//! reference element's view.

use super::action::{Action, Command};
use super::ui_state::Ctx;
use eframe::egui;

/// The File → Open dialog.
pub fn open_dialog_ui(cx: &mut Ctx, ctx: &egui::Context) {
    let Some(mut dialog) = cx.state.open_dialog.take() else { return };
    let mut open = true;
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
            // the app reads the file and closes the dialog, or puts the reason in it
            let path = std::path::PathBuf::from(dialog.path.trim());
            cx.out.push(Command::OpenFile { mesh: dialog.mesh, path, clamp_group: dialog.clamp_group.trim().into() });
        }
    });
    if open {
        cx.state.open_dialog = Some(dialog);
    }
}

/// The question about a held-back change: apply it (paused) or keep the current one.
pub fn pending_change_ui(cx: &mut Ctx, ctx: &egui::Context) {
    let model = cx.model;
    let Some(pending) = model.pending_change() else { return };
    egui::Window::new("This change is slow")
        .collapsible(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::vec2(0.0, 0.0))
        .show(ctx, |ui| {
            ui.label(format!("{}: {}", pending.control, pending.estimate));
            ui.label("The window would stay usable (paused, Step advances a frame), but it would not play.");
            ui.horizontal(|ui| {
                if ui.button("Apply, paused").clicked() {
                    cx.out.push(Action::AnswerPending(true));
                }
                if ui.button("Keep the current configuration").clicked() {
                    cx.out.push(Action::AnswerPending(false));
                }
            });
        });
}

/// The reference element's window (View → Reference element), while shown.
pub fn reference_element_ui(cx: &mut Ctx, ctx: &egui::Context) {
    if !cx.model.show_reference_element() {
        return;
    }
    let mut open = true;
    egui::Window::new("Reference element")
        .open(&mut open)
        .default_size([420.0, 460.0])
        .show(ctx, |ui| cx.state.reference_element.ui(ui));
    if !open {
        cx.out.push(Action::ShowReferenceElement(false));
    }
}

/// A scene file for a mesh file: the mesh, its `clamp_group` clamped, gravity, the paper
/// beam's material; written next to the user's settings so it can be reopened.
pub fn mesh_scene_file(mesh: &std::path::Path, clamp_group: &str) -> Result<std::path::PathBuf, String> {
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
