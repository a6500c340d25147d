//! hox-scenes: scenes as data and what is done with them. Its rooms, lowest first (each uses
//! only those before it; `tests/tests/rooms.rs` keeps the order and docs/ARCHITECTURE.md states
//! it):
//! - [`error`] — [`SceneError`]; [`present`] — the colour map and colour ranges, SVG drawing
//!   (the lab's figures and the app's views);
//! - [`params`] — the parameter table, every parameter defined once;
//! - [`scene`] — a scene file read, validated and built, and the built-in scenes ([`BUILTIN`],
//!   [`by_name`]: a TOML file in `assets/scenes/` plus one line);
//! - [`instance`] — a scene built into a running simulation ([`Instance`]) or solved statically;
//! - [`run`] — running for a time or until settled;
//! - [`lab`] — what is done with a loaded scene, which scene loading never uses: [`reference`],
//!   [`study`], [`paper`], [`bench`] (`hox bench`), [`lesson`] (re-exported here by name).
//!
//! This file is the crate's front: `mod` lines and re-exports only.

pub mod error;
pub mod instance;
pub mod lab;
pub mod params;
pub mod present;
pub mod run;
pub mod scene;

pub use error::SceneError;
pub use instance::{Instance, solve_static, static_problem};
pub use lab::{bench, claim, lesson, paper, reference, study};
pub use params::{Params, SceneOverrides};
pub use run::{
    RestWatch, RunMode, RunReport, SETTLE_CAP_SECS, SETTLE_DAMPING_NAME, SETTLE_EQUILIBRIUM_FRAMES, SETTLE_FRAMES,
    SETTLE_KINETIC_REL, SETTLE_RESIDUAL_REL, SettleState, Settler, driven_until_secs, in_equilibrium, median, run,
    run_observed,
};
pub use scene::builtin::{BUILTIN, PAPER_SCENES, by_name, names, registry};
pub use scene::{
    BUILTIN_MESHES, Drive, NodeSelector, OPENED_PREFIX, Scene, SceneFile, SceneMesh, builtin_mesh, open_mesh_bytes,
};

#[cfg(test)]
mod tests;
