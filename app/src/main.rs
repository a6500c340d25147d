//! `hox`: the command-line entry point (headless).
//!
//! - `hox elements` lists the element types with their nodes and quadrature;
//! - `hox scenes` lists the scene registry;
//! - `hox mesh` builds a scene's mesh and prints its counts and volume;
//! - `hox simulate` runs a scene for a time or until it settles and prints probe displacements.
//!
//! Errors are printed as one clear message on stderr with a non-zero exit.

mod cli;
mod colour;
mod display;
mod gui;
mod output;
mod recording;

use clap::Parser;

fn main() -> std::process::ExitCode {
    match cli::main(cli::Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
