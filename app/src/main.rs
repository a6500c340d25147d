//! `hox`: the entry point. It parses the command line and runs one command, a headless one
//! (`cli`) or the interactive app (`gui`):
//!
//! - `hox elements` lists the element types: nodes, faces, default quadrature;
//! - `hox scenes` lists the built-in scenes;
//! - `hox solvers` lists the solvers and the implicit solvers' integrators;
//! - `hox mesh` builds a scene's mesh and prints its element and node counts and volume;
//! - `hox static` solves a scene's static equilibrium (Newton, load stepping) and prints the
//!   probe displacements;
//! - `hox study` runs the accuracy-versus-time study over the paper scenes and writes its tables
//!   and chart;
//! - `hox bench` times the XPBD loop on the paper's Table 1 beams and the other element types
//!   (`--solver vbd|newton`: an implicit solver);
//! - `hox simulate` runs a scene for a time or until it settles and prints the probe
//!   displacements;
//! - `hox record` records a scene, or configurations side by side, to a Rerun file (.rrd);
//! - `hox inspect` reads a Rerun recording back and lists its entities, components and frames;
//! - `hox lessons` lists the built-in lessons;
//! - `hox lesson` runs a lesson headlessly step by step, and records it with `--record` or serves
//!   it to browsers with `--serve-web`;
//! - `hox serve` serves a recording (.rrd) to browsers with the Rerun web viewer (`web.rs`);
//! - `hox app` opens the interactive app (the default when no command is given).
//!
//! The app's modules ("rooms") use each other in one order, `colour`, `output` → `config` →
//! `display` → `recording` → `cli`, `gui` → `main` (docs/ARCHITECTURE.md, kept by
//! `tests/tests/rooms.rs`): `cli` and `gui` share what both need through `config` and never
//! use each other, so only this file knows both.
//!
//! Errors are printed as one clear message on stderr with a non-zero exit.
//!
//! In a web page (wasm32, issue #59) there is no command line: `main` starts the app on the
//! page's canvas with the options its link carries (`gui::start_in_page`). The headless commands
//! (`cli`) and the Rerun recordings (`recording`) are the desktop's only.

#[cfg(not(target_arch = "wasm32"))]
mod cli;
mod config;
mod display;
mod gui;
mod output;
#[cfg(not(target_arch = "wasm32"))]
mod recording;
mod web;

#[cfg(not(target_arch = "wasm32"))]
use clap::{Parser, Subcommand};

#[cfg(not(target_arch = "wasm32"))]
#[derive(Parser)]
#[command(name = "hox", version, about = "hox: see, measure and teach high-order finite elements in XPBD")]
struct Hox {
    #[command(subcommand)]
    command: Option<Command>,
}

// Every command: the headless ones, then the app. (A plain comment: clap's derive reads doc
// comments as help text, and the help stays as it was.)
#[cfg(not(target_arch = "wasm32"))]
#[derive(Subcommand)]
enum Command {
    #[command(flatten)]
    Headless(Box<cli::Command>),
    /// Open the interactive app (the default when no command is given).
    App(Box<gui::AppArgs>),
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    let result = match Hox::parse().command {
        Some(Command::Headless(command)) => cli::run(*command),
        Some(Command::App(args)) => gui::run(*args),
        None => gui::run(gui::AppArgs::default()),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// The page's entry point: the generated JavaScript calls it once the module is loaded. In a Web
/// Worker (the page's reference computations, `app/web/worker.js`) there is no window and
/// nothing to start: the worker calls the module's functions itself.
#[cfg(target_arch = "wasm32")]
fn main() {
    if web_sys::window().is_some() {
        gui::start_in_page();
    }
}
