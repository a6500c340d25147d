//! The error of everything hox-scenes does with a scene: an unknown name, a file that does not
//! parse or validate, a mesh, simulation or probe that cannot be built. Each names its source
//! (`builtin:bending`, a file's path).

/// What went wrong with a scene, naming its source.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("unknown scene '{name}' (available: {available})")]
    Unknown { name: String, available: String },
    #[error("{source_name}: {message}")]
    Parse { source_name: String, message: String },
    #[error("{source_name}: {key} = {value}: {reason}")]
    Invalid { source_name: String, key: String, value: String, reason: String },
    #[error("cannot read scene file {path}: {message}")]
    Io { path: String, message: String },
    #[error("{source_name}: cannot build the mesh: {message}")]
    Mesh { source_name: String, message: String },
    /// A mesh file's own error (it names the file).
    #[error("{0}")]
    MeshFile(String),
    #[error("{source_name}: {message}")]
    Simulation { source_name: String, message: String },
    #[error("{source_name}: {message}")]
    Probe { source_name: String, message: String },
}
