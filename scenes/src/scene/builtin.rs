//! The mesh files of the built-in scenes (the curved parts of `assets/parts/`, made by
//! `scripts/gmsh_parts.py`), embedded in the binary like the scenes' TOML, so that `hox` runs
//! from anywhere, and read once per process.

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

/// The embedded mesh file `name` ([`BUILTIN_MESHES`]), read once per process (switching a part's
/// element type back and forth in the app reads nothing again); None if no built-in scene names it.
pub fn builtin_mesh(name: &str) -> Option<Result<std::sync::Arc<hox_sim::io::gmsh::ImportedMesh>, String>> {
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, OnceLock};
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
