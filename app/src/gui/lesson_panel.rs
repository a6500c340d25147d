//! The lesson as the class sees it (issue #21): a panel with the step's text, its question, the
//! live measurement of each configuration beside it and, on demand, the answer; in presenter mode
//! (P, or `--presenter`: the interface scaled up for a projector, the side panel and plots hidden)
//! the step's caption and numbers below the 3D view; the first start's offer of the lessons.

use super::action::Action;
use super::lesson::PREPARING;
use super::ui_state::Ctx;
use eframe::egui;

/// The lesson panel: title, step, text, question, the live measurement of A and B, the answer
/// on demand, and the step buttons.
pub fn lesson_panel_ui(cx: &mut Ctx, ui: &mut egui::Ui) {
    let model = cx.model;
    let Some(state) = model.lesson() else { return };
    let step = &state.lesson.steps[state.step];
    let measured = cx.state.lesson_measured.clone().unwrap_or_default();
    let n = state.lesson.steps.len();
    ui.heading(&state.lesson.title);
    // the step buttons first: they never scroll out of view below a long answer (issue #57)
    let at = state.step;
    ui.horizontal_wrapped(|ui| {
        if ui.add_enabled(at > 0, egui::Button::new("< Previous (left arrow)")).clicked() {
            cx.out.push(Action::LessonStep(-1));
        }
        if ui.add_enabled(at + 1 < n, egui::Button::new("Next (right arrow) >")).clicked() {
            cx.out.push(Action::LessonStep(1));
        }
        if ui.button("Close lesson").clicked() {
            cx.out.push(Action::CloseLesson);
        }
    });
    ui.label(egui::RichText::new(&state.lesson.goal).italics());
    ui.separator();
    ui.label(egui::RichText::new(format!("Step {} of {n}: {}", state.step + 1, step.title)).strong().size(18.0));
    for line in state.parameter_lines() {
        ui.label(egui::RichText::new(line).monospace());
    }
    ui.label(&step.text);
    ui.add_space(6.0);
    ui.label(egui::RichText::new(format!("Question: {}", step.question)).strong());
    ui.add_space(6.0);
    ui.label(egui::RichText::new(step.measure.title()).underline());
    if state.preparing() {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(PREPARING);
        });
    } else {
        let names = super::session::labels(model.sessions());
        for (k, (m, name)) in measured.iter().zip(&names).enumerate() {
            ui.label(egui::RichText::new(format!("{} {name}: {}", ["A", "B"][k.min(1)], m.text)).monospace());
        }
    }
    if let Some(p) = &state.problem {
        ui.colored_label(Palette::of(ui.visuals()).warning, p);
    }
    ui.add_space(6.0);
    // no answer while the step is prepared: the numbers it speaks of are not there yet
    let (revealed, preparing) = (state.revealed, state.preparing());
    let answer = step.answer.clone();
    if preparing {
        ui.label(egui::RichText::new("(the answer once the step is ready)").weak());
    } else if revealed {
        ui.label(egui::RichText::new(format!("Answer: {answer}")).color(Palette::of(ui.visuals()).numbers));
        claim_ui(cx, ui);
    } else if ui.button("Reveal the answer (A)").clicked() {
        cx.out.push(Action::RevealAnswer);
    }
}

/// The lesson's colours on the theme's panels: light on the dark theme, dark on the light one
/// (found in the page, issue #59: a browser that prefers light showed the presenter caption's
/// white title and question on light grey).
pub struct Palette {
    pub title: egui::Color32,
    pub text: egui::Color32,
    /// The measured numbers (amber).
    pub numbers: egui::Color32,
    /// The answer (blue).
    pub answer: egui::Color32,
    /// A claim that holds (green).
    pub holds: egui::Color32,
    /// A claim that does not, a problem (orange).
    pub warning: egui::Color32,
}

impl Palette {
    pub fn of(visuals: &egui::Visuals) -> Palette {
        use egui::Color32 as C;
        if visuals.dark_mode {
            Palette {
                title: C::WHITE,
                text: C::from_gray(220),
                numbers: C::from_rgb(250, 220, 120),
                answer: C::from_rgb(180, 230, 255),
                holds: C::from_rgb(170, 220, 170),
                warning: C::from_rgb(250, 170, 80),
            }
        } else {
            Palette {
                title: C::BLACK,
                text: C::from_gray(40),
                numbers: C::from_rgb(130, 80, 0),
                answer: C::from_rgb(20, 70, 150),
                holds: C::from_rgb(20, 110, 40),
                warning: C::from_rgb(170, 60, 0),
            }
        }
    }
}

/// In presenter mode: the step's caption and numbers in a panel below the 3D view (issue #35:
/// laid over the view, the answer covered both bodies' labels at 1280×720).
pub fn caption_ui(cx: &Ctx, ui: &mut egui::Ui) {
    let Some(state) = cx.model.lesson() else { return };
    let step = &state.lesson.steps[state.step];
    let measured = cx.state.lesson_measured.as_deref().unwrap_or_default();
    let colours = Palette::of(ui.visuals());
    ui.label(egui::RichText::new(format!("{} — {}", state.lesson.title, step.title)).strong().color(colours.title));
    for line in state.parameter_lines() {
        ui.label(egui::RichText::new(line).monospace().color(colours.text));
    }
    // the step's explanation too (issue #57: presenter mode dropped it)
    ui.label(egui::RichText::new(&step.text).color(colours.text));
    ui.label(egui::RichText::new(&step.question).color(colours.title));
    if state.preparing() {
        ui.label(egui::RichText::new(PREPARING).color(colours.numbers));
        return;
    }
    for (k, m) in measured.iter().enumerate() {
        ui.label(
            egui::RichText::new(format!("{} {}: {}", ["A", "B"][k.min(1)], step.measure.title(), m.text))
                .monospace()
                .color(colours.numbers),
        );
    }
    if state.revealed {
        ui.label(egui::RichText::new(&step.answer).color(colours.answer));
        claim_ui(cx, ui);
    }
}

/// Under the answer: its claim judged against the numbers on screen (issue #57: an answer of
/// "1.15 to 2.6 times less" stood under 1.07× measured), in amber when this machine's value is
/// outside it.
fn claim_ui(cx: &Ctx, ui: &mut egui::Ui) {
    let measured = cx.state.lesson_measured.as_deref().unwrap_or_default();
    let Some(j) = cx.model.lesson().and_then(|l| l.judge_claim(measured)) else { return };
    let colours = Palette::of(ui.visuals());
    let colour = if j.holds { colours.holds } else { colours.warning };
    ui.label(egui::RichText::new(j.text).color(colour));
}

/// The first start's offer: the lessons, or the free app.
pub fn welcome_ui(cx: &mut Ctx, ctx: &egui::Context) {
    if !cx.state.offer_lessons {
        return;
    }
    let mut open = true;
    // centred in the window, below the menu bar it used to cover (issue #35)
    egui::Window::new("Welcome to hox")
        .collapsible(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::vec2(0.0, 0.0))
        .open(&mut open)
        .show(ctx, |ui| {
            ui.label("Start with a guided lesson, or explore freely (the Lessons menu has them all).");
            if let Ok(all) = hox_scenes::lesson::registry() {
                for l in all {
                    if ui.button(&l.title).on_hover_text(&l.goal).clicked() {
                        cx.out.push(Action::OpenLesson(Box::new(l)));
                        cx.state.offer_lessons = false;
                    }
                }
            }
            if ui.button("Explore freely").clicked() {
                cx.state.offer_lessons = false;
            }
        });
    if !open {
        cx.state.offer_lessons = false;
    }
}
