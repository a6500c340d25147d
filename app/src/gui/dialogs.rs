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
        // the folder of the path typed, browsed: folders open, files of the kind asked for pick
        let ext = if dialog.mesh { "msh" } else { "toml" };
        let (folder, entries) = browse(&dialog.path, ext);
        ui.label(egui::RichText::new(format!("in {}", folder.display())).small());
        egui::ScrollArea::vertical().max_height(180.0).show(ui, |ui| {
            if let Some(parent) = folder.parent()
                && ui.selectable_label(false, "⬆ ..").clicked()
            {
                dialog.path = format!("{}/", parent.display());
            }
            for (name, is_dir) in entries {
                let shown = if is_dir { format!("🗀 {name}/") } else { name.clone() };
                if ui.selectable_label(false, shown).clicked() {
                    let picked = folder.join(&name);
                    dialog.path = if is_dir { format!("{}/", picked.display()) } else { picked.display().to_string() };
                }
            }
        });
        if let Some(e) = &dialog.error {
            ui.colored_label(ui.visuals().error_fg_color, e);
        }
        if ui.button("Open").clicked() {
            // the app reads the file and closes the dialog, or puts the reason in it
            match resolve(dialog.path.trim()) {
                Ok(path) => cx.out.push(Command::OpenFile {
                    mesh: dialog.mesh,
                    path,
                    clamp_group: dialog.clamp_group.trim().into(),
                }),
                Err(e) => dialog.error = Some(e),
            }
        }
    });
    if open {
        cx.state.open_dialog = Some(dialog);
    }
}

/// The folder `typed` names (itself if it is one or ends in '/', else its parent; relative to
/// the folder hox runs in) and its entries: folders, and files ending in `.ext`, sorted.
pub fn browse(typed: &str, ext: &str) -> (std::path::PathBuf, Vec<(String, bool)>) {
    let cwd = std::env::current_dir().unwrap_or_default();
    let path = cwd.join(typed.trim());
    let folder = if typed.trim().is_empty() || typed.ends_with('/') || path.is_dir() {
        path
    } else {
        path.parent().map_or(cwd, std::path::Path::to_path_buf)
    };
    let mut entries: Vec<(String, bool)> = std::fs::read_dir(&folder)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter_map(|e| {
                    let is_dir = e.file_type().ok()?.is_dir();
                    let name = e.file_name().to_string_lossy().into_owned();
                    (!name.starts_with('.') && (is_dir || name.ends_with(&format!(".{ext}")))).then_some((name, is_dir))
                })
                .collect()
        })
        .unwrap_or_default();
    entries.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    (folder, entries)
}

/// The file `typed` names, relative to the folder hox runs in; an error naming where it looked
/// (issue #57: a relative path failed with a bare "os error 2").
pub fn resolve(typed: &str) -> Result<std::path::PathBuf, String> {
    let cwd = std::env::current_dir().map_err(|e| format!("the folder hox runs in is unreadable: {e}"))?;
    let path = cwd.join(typed);
    if typed.is_empty() {
        return Err("type or pick a file".into());
    }
    if path.is_dir() {
        return Err(format!("{} is a folder: pick a file in it", path.display()));
    }
    if !path.is_file() {
        return Err(format!(
            "no file at {} (a relative path is read from the folder hox runs in, {})",
            path.display(),
            cwd.display()
        ));
    }
    Ok(path)
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
/// beam's material, a probe at the node farthest from the clamp; written where it can be
/// reopened.
pub fn mesh_scene_file(mesh: &std::path::Path, clamp_group: &str) -> Result<std::path::PathBuf, String> {
    let mesh = std::fs::canonicalize(mesh).map_err(|e| format!("{}: {e}", mesh.display()))?;
    let name = mesh.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().to_string());
    let file = super::config::mesh_scene(&mesh, clamp_group)?;
    let text = file.to_toml();
    let dir = std::env::temp_dir().join(super::config::MESH_SCENES);
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join(format!("{name}.msh.toml"));
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    // validate now, so a missing group is reported in the dialog
    hox_scenes::Scene::load(&path).map_err(|e| e.to_string())?;
    Ok(path)
}
