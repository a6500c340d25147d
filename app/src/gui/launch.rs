//! Opening the app: in a native window (`hox app`'s checks of its options, eframe's window and
//! renderer settings) or on a web page's canvas (the link's options), and the app built on the
//! saved settings in both.

use super::app::HoxApp;
use super::args::AppArgs;
use super::persist::Persisted;
#[cfg(not(target_arch = "wasm32"))]
use eframe::egui;
#[cfg(not(target_arch = "wasm32"))]
use hox_scenes::Scene;

/// Whether an OpenGL renderer name is a software rasteriser (Mesa's llvmpipe or softpipe,
/// SwiftShader, Microsoft's GDI renderer).
pub fn is_software_renderer(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    ["llvmpipe", "softpipe", "swiftshader", "software rasterizer", "gdi generic"].iter().any(|k| n.contains(k))
}

/// Window size in points when neither --size nor a saved geometry gives one.
#[cfg(not(target_arch = "wasm32"))]
const DEFAULT_WINDOW_SIZE: &str = "1400x900";

/// The window's size in points: `--size`, else the default.
#[cfg(not(target_arch = "wasm32"))]
fn window_size(args: &AppArgs) -> anyhow::Result<(f32, f32)> {
    let size = args.size.as_deref().unwrap_or(DEFAULT_WINDOW_SIZE);
    size.split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<f32>().ok()?, h.trim().parse::<f32>().ok()?)))
        .filter(|(w, h)| *w >= 320.0 && *h >= 240.0)
        .ok_or_else(|| anyhow::anyhow!("--size must be WIDTHxHEIGHT in points, at least 320x240, got '{size}'"))
}

/// Opens the window (blocking until it is closed).
#[cfg(not(target_arch = "wasm32"))]
pub fn run(args: AppArgs) -> anyhow::Result<()> {
    let args = args.with_link().map_err(anyhow::Error::msg)?;
    let (w, h) = window_size(&args)?;
    if let Some(p) = &args.screenshot {
        crate::output::check_writable(p)?;
    }
    // fail before opening a window on a bad scene
    if let Some(name) = &args.scene {
        hox_scenes::by_name(name)?;
    }
    if let Some(path) = &args.scene_file {
        Scene::load(path)?;
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([w, h])
            .with_title("hox — high-order elements in XPBD"),
        glow_options: eframe::egui_glow::GlowConfiguration { vsync: !args.no_vsync, ..Default::default() },
        // an explicit --size (or --fresh) wins over the window geometry eframe saved last time
        persist_window: args.size.is_none() && !args.fresh,
        // egui's dithering costs a noise function per pixel in the software renderer and buys
        // nothing for a flat-shaded 3D view and 8-bit widgets
        dithering: false,
        // the 3D view is drawn with depth testing (gui/gl_view.rs)
        depth_buffer: 24,
        ..Default::default()
    };
    let mut error = None;
    let result = eframe::run_native(
        "hox",
        options,
        Box::new(|cc| {
            // egui's saved memory may hold presenter mode's scale: an ordinary start is at scale
            // 1 before any size is asked for in points (issue #35: `--size 1600x900` after a
            // presenter session opened a 2560×1440 window)
            let zoom = if args.presenter { super::lesson::PRESENTER_ZOOM } else { 1.0 };
            cc.egui_ctx.set_zoom_factor(zoom);
            // eframe restores the last window geometry before this point; an explicit --size or
            // --fresh asks for the given (or default) size instead
            if args.size.is_some() || args.fresh {
                cc.egui_ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(egui::vec2(w, h)));
            }
            if args.fresh {
                // egui's own saved state too (panel sizes, open windows)
                cc.egui_ctx.memory_mut(|m| *m = egui::Memory::default());
            }
            match create(cc, &args, Vec::new()) {
                Ok(app) => Ok(Box::new(app) as Box<dyn eframe::App>),
                Err(e) => {
                    error = Some(e.clone());
                    Err(e.into())
                }
            }
        }),
    );
    if let Some(e) = error {
        anyhow::bail!(e);
    }
    result.map_err(|e| anyhow::anyhow!("the window could not be opened: {e} (no display? run the headless commands, e.g. `hox simulate`, or run the app in a virtual display: scripts/app-headless.sh)"))
}

/// The app in eframe's creation context, the desktop's window or the page's canvas: the
/// renderer's name and what it implies, the saved settings, the start options; `problems`
/// (a page link's parameters that could not be understood) are shown as the app's message.
fn create(cc: &eframe::CreationContext<'_>, args: &AppArgs, mut problems: Vec<String>) -> Result<HoxApp, String> {
    let renderer = cc.gl.as_ref().map(|gl| {
        use eframe::glow::HasContext;
        // SAFETY: a plain query on the context eframe has just made current
        unsafe { gl.get_parameter_string(eframe::glow::RENDERER) }
    });
    // Anti-aliasing feathers double the triangles egui hands to the driver; a software
    // renderer pays for each one on the CPU (docs/APP.md), so shapes go without there.
    let software = renderer.as_deref().is_some_and(is_software_renderer);
    cc.egui_ctx.tessellation_options_mut(|o| o.feathering = !software);
    let saved = cc.storage.and_then(Persisted::load);
    // the window geometry eframe restored is in presenter mode's points when the last run
    // ended in it: the start opens at the given (or default) size instead, fitted to the
    // screen on its first frames (issue #35)
    #[cfg(not(target_arch = "wasm32"))]
    if saved.as_ref().is_some_and(|s| s.presenter_at_exit) && args.size.is_none() {
        let (w, h) = window_size(args).unwrap_or((320.0, 240.0));
        cc.egui_ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(egui::vec2(w, h)));
    }
    let mut app = match HoxApp::new(args, saved) {
        Ok(app) => app,
        // a page opens whatever its link says: on the default scene, with the reason, when the
        // app cannot start as asked (a lesson step beyond the last, saved settings of a scene
        // that no longer loads)
        Err(e) if cfg!(target_arch = "wasm32") => {
            problems.push(e);
            HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None)?
        }
        Err(e) => return Err(e),
    };
    app.renderer = renderer;
    // a software renderer has no vertical sync to wait for (Xvfb, a remote desktop, a machine
    // without a graphics driver): while playing, the window paints when a simulated frame is
    // due, not as fast as the CPU allows
    app.pace_paint = software && !args.no_vsync;
    if !problems.is_empty() {
        app.say_at_start(problems.join("; "));
    }
    Ok(app)
}

/// Starts the app on the page's canvas (`<canvas id="hox">`) with the options of the page's
/// link (`args::from_link`): what the link gets wrong is a message in the app, and an app that
/// cannot start says why in the page instead of the canvas.
#[cfg(target_arch = "wasm32")]
pub fn start_in_page() {
    use wasm_bindgen::JsCast;
    let window = web_sys::window().expect("a page has a window");
    let query = window.location().search().unwrap_or_default();
    let (args, problems) = super::args::from_link(&query);
    let document = window.document().expect("a page has a document");
    let canvas = document
        .get_element_by_id("hox")
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .expect("the page has a <canvas id=\"hox\">");
    let web_options = eframe::WebOptions { dithering: false, ..Default::default() };
    wasm_bindgen_futures::spawn_local(async move {
        let started = eframe::WebRunner::new()
            .start(
                canvas,
                web_options,
                Box::new(move |cc| {
                    let zoom = if args.presenter { super::lesson::PRESENTER_ZOOM } else { 1.0 };
                    cc.egui_ctx.set_zoom_factor(zoom);
                    Ok(Box::new(create(cc, &args, problems)?) as Box<dyn eframe::App>)
                }),
            )
            .await;
        let text = started.err().map(|e| format!("hox could not start in this page: {e:?}"));
        if let Some(text) = &text {
            web_sys::console::error_1(&text.into());
        }
        if let Some(status) = document.get_element_by_id("status") {
            status.set_text_content(text.as_deref());
        }
    });
}

/// What [`lesson_answers`] gives for a step whose reference is still being computed after a minute.
#[cfg(target_arch = "wasm32")]
pub const REFERENCE_PENDING: &str = "reference still computing";

/// Every step of the built-in lesson `name` as the app in this page shows it, each played to its
/// end in place and measured once the references its numbers need have come from their Web
/// Workers: JSON, `[[A's numbers, B's numbers], …]` per step. The page's check against the
/// desktop's `hox lesson NAME --json` calls it (app/tests/page.rs, issue #59).
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen::prelude::wasm_bindgen]
pub async fn lesson_answers(name: String) -> Result<String, String> {
    use hox_scenes::lesson::Measure;
    let lesson = hox_scenes::lesson::by_name(&name).map_err(|e| e.to_string())?;
    let mut app = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None)?;
    app.act(super::action::Action::OpenLesson(Box::new(lesson.clone())));
    let mut shown = Vec::new();
    for k in 0..lesson.steps.len() {
        app.play_lesson_step(k);
        // an error's reference comes from a worker, whose reports come between the page's
        // turns: give it those turns, a minute at most (the site carries every lesson's
        // references; one it lacks takes minutes on one thread of a page). The other measures
        // need no reference (the readouts' references may still be coming).
        let needs_reference = matches!(lesson.steps[k].measure, Measure::SettledError | Measure::SolverError);
        for _ in 0..3_000 {
            if !needs_reference || !app.references_computing() {
                break;
            }
            super::platform::page::sleep_ms(20).await;
            app.act(super::action::Action::Poll { wait_for_lesson: false });
        }
        shown.push(if needs_reference && app.references_computing() {
            vec![REFERENCE_PENDING.to_string()]
        } else {
            app.lesson_step_answers()
        });
    }
    serde_json::to_string(&shown).map_err(|e| e.to_string())
}
