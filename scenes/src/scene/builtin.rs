//! The built-in scenes: the one list of scenes the CLI, the app, tests and benchmarks read
//! ([`BUILTIN`], each a TOML file in `assets/scenes/` plus one line), found by name
//! ([`by_name`]); and the mesh files they name (the curved parts of `assets/parts/`, made by
//! `scripts/gmsh_parts.py`). Both are embedded in the binary, so that `hox` runs from anywhere;
//! a mesh file is read once per process.

use super::Scene;
use crate::error::SceneError;

/// The built-in scenes: (name, TOML text). Adding a scene: its file plus one line here.
pub const BUILTIN: &[(&str, &str)] = &[
    ("bending", include_str!("../../../assets/scenes/bending.toml")),
    ("tension", include_str!("../../../assets/scenes/tension.toml")),
    ("torsion", include_str!("../../../assets/scenes/torsion.toml")),
    ("drop", include_str!("../../../assets/scenes/drop.toml")),
    ("twist", include_str!("../../../assets/scenes/twist.toml")),
    ("squash", include_str!("../../../assets/scenes/squash.toml")),
    ("tube", include_str!("../../../assets/scenes/tube.toml")),
    ("elbow", include_str!("../../../assets/scenes/elbow.toml")),
    ("hook", include_str!("../../../assets/scenes/hook.toml")),
];

/// The paper's three scenes.
pub const PAPER_SCENES: [&str; 3] = ["bending", "tension", "torsion"];

/// Names of the built-in scenes, comma-separated.
pub fn names() -> String {
    BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// Every built-in scene, parsed and validated.
pub fn registry() -> Result<Vec<Scene>, SceneError> {
    BUILTIN.iter().map(|(n, text)| Scene::from_toml(text, &format!("builtin:{n}"))).collect()
}

/// A built-in scene by name.
pub fn by_name(name: &str) -> Result<Scene, SceneError> {
    let (n, text) = BUILTIN
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| SceneError::Unknown { name: name.to_string(), available: names() })?;
    Scene::from_toml(text, &format!("builtin:{n}"))
}

/// The mesh files the built-in scenes name (the curved parts, `scripts/gmsh_parts.py`), embedded
/// so that `hox` runs from anywhere: (the name a scene gives, relative to `assets/scenes/`; the
/// file's bytes).
pub const BUILTIN_MESHES: &[(&str, &[u8])] = &[
    ("../parts/tube-p1.msh", include_bytes!("../../../assets/parts/tube-p1.msh")),
    ("../parts/tube-p2.msh", include_bytes!("../../../assets/parts/tube-p2.msh")),
    ("../parts/tube-p3.msh", include_bytes!("../../../assets/parts/tube-p3.msh")),
    ("../parts/elbow-p1.msh", include_bytes!("../../../assets/parts/elbow-p1.msh")),
    ("../parts/elbow-p2.msh", include_bytes!("../../../assets/parts/elbow-p2.msh")),
    ("../parts/elbow-p3.msh", include_bytes!("../../../assets/parts/elbow-p3.msh")),
    ("../parts/hook-p1.msh", include_bytes!("../../../assets/parts/hook-p1.msh")),
    ("../parts/hook-p2.msh", include_bytes!("../../../assets/parts/hook-p2.msh")),
    ("../parts/hook-p3.msh", include_bytes!("../../../assets/parts/hook-p3.msh")),
];

/// What a mesh opened from its bytes is named by ([`open_mesh_bytes`]): `opened:NAME`.
pub const OPENED_PREFIX: &str = "opened:";

type OpenedMeshes =
    std::sync::Mutex<std::collections::HashMap<String, std::sync::Arc<hox_sim::io::gmsh::ImportedMesh>>>;

/// The meshes opened from their bytes in this process, by name.
fn opened() -> &'static OpenedMeshes {
    static OPENED: std::sync::OnceLock<OpenedMeshes> = std::sync::OnceLock::new();
    OPENED.get_or_init(Default::default)
}

/// A mesh file given as bytes rather than a path (a file dropped into the app's web page, which
/// has no file system; issue #59): read and checked now (a broken file is the reader's message,
/// naming `file_name`), kept for this process, and named `opened:FILE_NAME`, the name a scene's
/// `mesh_file` then gives to find it as it finds the built-in ones ([`builtin_mesh`]).
pub fn open_mesh_bytes(file_name: &str, bytes: &[u8]) -> Result<String, String> {
    let mesh = hox_sim::io::gmsh::read_msh_bytes(bytes, file_name).map_err(|e| e.to_string())?;
    let name = format!("{OPENED_PREFIX}{file_name}");
    opened().lock().unwrap_or_else(|e| e.into_inner()).insert(name.clone(), std::sync::Arc::new(mesh));
    Ok(name)
}

/// The embedded mesh file `name` ([`BUILTIN_MESHES`]), read once per process (switching a part's
/// element type back and forth in the app reads nothing again), or a mesh opened from its bytes
/// ([`open_mesh_bytes`]); None if neither has that name.
pub fn builtin_mesh(name: &str) -> Option<Result<std::sync::Arc<hox_sim::io::gmsh::ImportedMesh>, String>> {
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, OnceLock};
    if name.starts_with(OPENED_PREFIX) {
        let mesh = opened().lock().ok().and_then(|m| m.get(name).cloned());
        return Some(mesh.ok_or_else(|| format!("{name}: no such mesh was opened in this session")));
    }
    type Cache = Mutex<HashMap<&'static str, Arc<hox_sim::io::gmsh::ImportedMesh>>>;
    static READ: OnceLock<Cache> = OnceLock::new();
    let (key, bytes) = BUILTIN_MESHES.iter().find(|(n, _)| *n == name)?;
    let cache = READ.get_or_init(Default::default);
    if let Some(m) = cache.lock().ok().and_then(|c| c.get(key).cloned()) {
        return Some(Ok(m));
    }
    let read =
        hox_sim::io::gmsh::read_msh_bytes(bytes, &format!("builtin:{key}")).map(Arc::new).map_err(|e| e.to_string());
    if let (Ok(m), Ok(mut c)) = (&read, cache.lock()) {
        c.insert(key, m.clone());
    }
    Some(read)
}
