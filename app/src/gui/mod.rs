//! The interactive app (eframe/egui): explore and teach element behaviour live.
//!
//! Three layers, as Rerun's viewer and Avian keep them apart:
//! - **the model** ([`model::Model`]): the scene, the running configurations ([`session`]: the
//!   run; how each is drawn is its view, [`session_view`]), compare mode and its links, playback,
//!   the lesson under way — headless, changed only through `Model::apply` with an
//!   [`action::Action`]; the work it hands off goes through [`background`]'s two interfaces
//!   (threads in the window, in place in a test or a web page);
//! - **the UI's state** ([`ui_state::UiState`]): the camera and 3D view, what is open, text being
//!   edited, the interface's scale;
//! - **panels** (the menu bar and shortcuts, the control panel and its sections, the plots, the
//!   lesson's panel and caption, the dialogs, the status line, the 3D view): they read the model
//!   and the UI's state ([`ui_state::Ctx`]) and return [`action::Command`]s.
//!
//! What differs between the desktop and a web page (clock, threads, storage, files, Rerun, the
//! start) is [`platform`]'s.
//!
//! [`HoxApp`] (`app.rs`) holds the three and the services (the live Rerun link, the frame clock
//! and measurements) and carries out the commands; `window.rs` is a frame of the window.
//!
//! Layout: a menu bar; on the left every control of the simulation; in the middle the 3D
//! viewport; at the bottom the plots and a status line. Shortcuts: space play/pause, S single
//! step, E settle, R reset, 1–4 camera presets, F next field. Settings persist across runs.

pub mod action;
mod app;
mod args;
pub mod background;
pub mod config;
pub mod controls;
mod cost;
mod dialogs;
mod figure;
pub mod gl_view;
mod launch;
pub mod lesson;
mod lesson_panel;
mod links;
mod measure;
mod menu;
pub mod model;
mod persist;
pub mod platform;
mod playback;
pub mod plots;
pub mod presets;
pub mod raster;
pub mod readout;
mod rebuild;
// the desktop's only (platform.rs says what the page has instead)
#[cfg(not(target_arch = "wasm32"))]
mod rerun_link;
mod sections;
#[cfg(not(target_arch = "wasm32"))]
mod serve_web;
pub mod session;
pub mod session_view;
mod status;
pub mod study_chart;
pub mod teach;
mod ui_state;
pub mod viewport;
mod window;

#[cfg(not(target_arch = "wasm32"))]
pub use args::AppArgs;
#[cfg(not(target_arch = "wasm32"))]
pub use launch::run;
#[cfg(target_arch = "wasm32")]
pub use launch::start_in_page;

#[cfg(test)]
mod model_tests;
#[cfg(test)]
mod tests;
