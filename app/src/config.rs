//! The configuration both front ends take from the command line: the scene parameter flags
//! (mesh, physics, display: [`params`]) and the overrides they give, a `--compare` value on top
//! of them, and a lesson by name or file. The headless commands (`cli`) and the app (`gui`) read
//! it; it reads neither (the room order in docs/ARCHITECTURE.md, kept by `tests/tests/rooms.rs`).

use anyhow::{Context, Result};
use hox_scenes::SceneOverrides;
use hox_scenes::lesson::Lesson;
use std::path::Path;

mod params;
pub use params::{DisplayArgs, MeshArgs, PhysicsArgs, overrides};

/// What a page's link may carry besides the parameter table's keys (`element`, `poisson`, …, as
/// `--compare` takes them): the scene, a lesson and its step, compare mode, the camera, the
/// start view, playing and presenter mode; `nu` is the table's `poisson` (`gui::args::from_link`
/// reads a link, `hox serve-app --link` checks one).
#[cfg_attr(target_arch = "wasm32", allow(dead_code))] // `hox serve-app --link`'s, a desktop command
pub const LINK_KEYS: &[&str] = &["scene", "lesson", "step", "compare", "camera", "view", "play", "presenter", "nu"];

/// Applies one `--compare` value (`key=value,...`, the keys of the parameter table) on top of
/// `base`; an unknown key or a bad value is an error naming it.
pub fn parse_compare(spec: &str, base: &SceneOverrides) -> Result<SceneOverrides> {
    let mut o = base.clone();
    for pair in spec.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) =
            pair.split_once('=').with_context(|| format!("--compare '{spec}': '{pair}' is not option=value"))?;
        o.set_text(key.trim(), value).map_err(|e| anyhow::anyhow!("--compare '{spec}': {e}"))?;
    }
    Ok(o)
}

/// The lesson a lesson file (`file`, which wins) or a built-in lesson's `name` gives.
pub fn load_lesson(name: Option<&str>, file: Option<&Path>) -> Result<Lesson> {
    Ok(match (name, file) {
        (_, Some(path)) => hox_scenes::lesson::from_file(path)?,
        (Some(n), None) => hox_scenes::lesson::by_name(n)?,
        (None, None) => anyhow::bail!("name a lesson (hox lessons lists them) or give --lesson-file"),
    })
}
