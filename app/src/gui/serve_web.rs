//! The class's browsers in the app (issue #38): `hox app --serve-web` starts serving at once
//! (the address printed on stdout); in presenter mode the address is shown with its QR code in
//! the 3D view's top right corner, for students to scan from the projection.

use super::HoxApp;
use super::lesson::LessonState;
use super::rerun_link::RerunTarget;
use super::session::Session;
use eframe::egui;

impl HoxApp {
    /// `--serve-web`: serves the class's browsers from the start. A refusal (a port in use, an
    /// address not of this machine) is printed and shown, and the app runs on without serving.
    pub(super) fn serve_web_at_start(&mut self) {
        self.set_rerun(Some(RerunTarget::Browsers));
        match self.web_url() {
            Some(url) => {
                println!("{url}");
                eprintln!("serving the class's browsers: open {url}");
            }
            None => eprintln!("warning: not serving browsers: {}", self.message.as_deref().unwrap_or("unknown error")),
        }
    }
}

impl LessonState {
    /// The step as the browsers' "Lesson" view shows it: title, question, the numbers as the
    /// app's panel shows them, the answer once revealed.
    pub fn step_markdown(&self, sessions: &[Session]) -> String {
        let step = &self.lesson.steps[self.step];
        let mut text = format!(
            "# {}\n\n## Step {} of {}: {}\n\n{}\n\n",
            self.lesson.title,
            self.step + 1,
            self.lesson.steps.len(),
            step.title,
            step.question
        );
        if self.preparing() {
            text += &format!("*{}*\n", super::lesson::PREPARING);
            return text;
        }
        for (k, m) in self.measured(sessions).iter().enumerate() {
            text += &format!("- **{}**: {}\n", ["A", "B"][k.min(1)], m.text);
        }
        if self.revealed {
            text += &format!("\n**Answer:** {}\n", step.answer);
        }
        text
    }
}

/// Presenter mode while serving: the address and its QR code in a narrow panel at the right of
/// the 3D view (dark modules on white, with the quiet zone a scanner needs), beside the bodies,
/// never over them (issue #35's rule: no text over a body).
pub fn address_ui(app: &HoxApp, ui: &mut egui::Ui) {
    let Some(url) = app.web_url() else { return };
    let Some((width, modules)) = crate::web::qr_modules(url) else { return };
    let side = ui.available_width().clamp(120.0, 220.0);
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
