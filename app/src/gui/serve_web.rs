//! The class's browsers in presenter mode (issue #38): `hox app --serve-web` starts serving at
//! once (the app prints the address on stdout; the serving itself is `rerun_link.rs`); in
//! presenter mode this panel shows the address with its QR code at the right of the 3D view, for
//! students to scan from the projection.

use super::ui_state::Ctx;
use eframe::egui;

/// Presenter mode while serving: the address and its QR code in a narrow panel at the right of
/// the 3D view (dark modules on white, with the quiet zone a scanner needs), beside the bodies,
/// never over them (issue #35's rule: no text over a body).
pub fn address_ui(cx: &Ctx, ui: &mut egui::Ui) {
    let Some(url) = cx.status.web_url.as_deref() else { return };
    let Some((width, modules)) = crate::web::qr_modules(url) else { return };
    // the code and the address under it both fit: beside a lesson's caption the panel is low
    // (issue #57: at 1280×720 the code was cut off and the address below it lost)
    let address_room = 4.0 * ui.text_style_height(&egui::TextStyle::Small) + 8.0;
    let title_room = ui.text_style_height(&egui::TextStyle::Body) + 8.0;
    let side = ui.available_width().min(ui.available_height() - address_room - title_room).clamp(90.0, 220.0);
    let module = (side / (width as f32 + 8.0)).floor().max(2.0);
    let quiet = 4.0 * module;
    let side = width as f32 * module + 2.0 * quiet;
    ui.label(egui::RichText::new("Follow in your browser:").strong());
    let (rect, _) = ui.allocate_exact_size(egui::vec2(side, side), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, egui::Color32::WHITE);
    for (k, _) in modules.iter().enumerate().filter(|(_, dark)| **dark) {
        let (row, col) = ((k / width) as f32, (k % width) as f32);
        let min = rect.min + egui::vec2(quiet + col * module, quiet + row * module);
        painter.rect_filled(egui::Rect::from_min_size(min, egui::vec2(module, module)), 0.0, egui::Color32::BLACK);
    }
    ui.add(egui::Label::new(egui::RichText::new(url).monospace().small()).wrap());
}
