//! One configuration of a scene as the app's controls see it: the scene's parameters
//! ([`hox_scenes::params`], every value resolved), and what a change of it invalidates.

use hox_scenes::Scene;
pub use hox_scenes::params::Invalidates;
use std::path::PathBuf;

/// Where the scene comes from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SceneSource {
    Builtin(String),
    File(PathBuf),
    /// A mesh file opened from its bytes (dropped into the page, issue #59): its name in
    /// [`hox_scenes::open_mesh_bytes`]'s list, the group held.
    Opened {
        mesh: String,
        clamp_group: String,
    },
}

impl SceneSource {
    pub fn load(&self) -> Result<Scene, String> {
        match self {
            SceneSource::Builtin(name) => hox_scenes::by_name(name).map_err(|e| e.to_string()),
            SceneSource::File(path) => Scene::load(path).map_err(|e| e.to_string()),
            SceneSource::Opened { mesh, clamp_group } => {
                let file = mesh_scene(std::path::Path::new(mesh), clamp_group)?;
                Scene::from_file(file, mesh).map_err(|e| e.to_string())
            }
        }
    }
    pub fn label(&self) -> String {
        match self {
            SceneSource::Builtin(name) => name.clone(),
            // a scene written for a mesh file is named by the mesh (issue #57: the scene box
            // showed a temporary path)
            SceneSource::File(path) if path.parent().is_some_and(|p| p.ends_with(MESH_SCENES)) => {
                let name = path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
                format!("{} (mesh file)", name.trim_end_matches(".toml"))
            }
            SceneSource::File(path) => {
                path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
            }
            SceneSource::Opened { mesh, .. } => {
                format!("{} (mesh file)", mesh.trim_start_matches(hox_scenes::OPENED_PREFIX))
            }
        }
    }
}

/// The scene of a mesh file: the mesh, its `clamp_group` clamped, gravity, the paper beam's
/// material (`hox simulate --mesh FILE --clamp GROUP`'s), a probe at the node farthest from the
/// clamp. A missing group is an error naming it.
pub fn mesh_scene(mesh: &std::path::Path, clamp_group: &str) -> Result<hox_scenes::SceneFile, String> {
    let scene =
        hox_scenes::Scene::from_mesh_file(mesh, &[clamp_group.to_string()], &[], true).map_err(|e| e.to_string())?;
    let mut file = scene.file.clone();
    file.description = format!("{} with group '{clamp_group}' clamped, under gravity", mesh.display());
    // a probe at the node farthest from the clamp (issue #57: no probe, so a flat probe plot
    // and no reference, although the part's static solution is its reference elsewhere)
    if file.probes.is_empty()
        && let Some(imported) = scene.mesh.imported()
        && let Ok(held) = imported.node_set(clamp_group)
        && !held.is_empty()
    {
        let rest = &imported.mesh.rest_positions;
        let centre = held.iter().map(|&n| rest[n as usize]).sum::<hox_sim::Vec3>() / held.len() as f64;
        if let Some(tip) = rest.iter().max_by(|a, b| (*a - centre).norm().total_cmp(&(*b - centre).norm())) {
            file.probes.push(hox_scenes::scene::ProbeSpec { name: "tip".into(), point_m: [tip.x, tip.y, tip.z] });
        }
    }
    Ok(file)
}

/// The labels of two configurations of `base`, told apart: when their labels are the same, each
/// says the (first two) parameters in which they differ (issue #57: two "P2 8×2×2 five" beams
/// of 50 and 100 substeps).
pub fn distinct_labels(configs: &[&Config], base: &Scene) -> Vec<String> {
    let mut labels: Vec<String> = configs.iter().map(|c| label(c, base)).collect();
    if let [a, b] = configs
        && labels[0] == labels[1]
    {
        let keys: Vec<&str> = a
            .changed_keys(b)
            .into_iter()
            .filter(|k| hox_scenes::params::by_key(k).is_some_and(|p| p.group != hox_scenes::params::Group::Display))
            .take(2)
            .collect();
        for (label, c) in labels.iter_mut().zip([a, b]) {
            for k in &keys {
                if let Some(p) = hox_scenes::params::by_key(k) {
                    label.push_str(&format!(" · {k} {}", (p.get)(c)));
                }
            }
        }
    }
    labels
}

/// The folder (in the system's temporary one) of the scene files written for mesh files.
pub const MESH_SCENES: &str = "hox-app-scenes";

/// Every live control of one simulation: the parameter table's values. Persisted across runs.
pub type Config = hox_scenes::Params;

/// The values a validated scene resolves to.
pub fn from_scene(scene: &Scene) -> Config {
    scene.params().clone()
}

/// Validates `config` on `base`: the scene it gives, or the reason it is refused. A mesh file's
/// scene takes no box parameters.
pub fn resolve(config: &Config, base: &Scene) -> Result<Scene, String> {
    base.with_overrides(&config.as_overrides(base.mesh_kind())).map_err(|e| plain_words(&e))
}

/// A refusal in the words of the panel (issue #35: "builtin:bending: material.poisson_ratio
/// (--poisson) = 0.5: …" read as internals): the control's label, the value and the reason.
pub fn plain_words(e: &hox_scenes::SceneError) -> String {
    match e {
        hox_scenes::SceneError::Invalid { key, value, reason, .. } => {
            let entry = hox_scenes::params::PARAMS.iter().find(|p| key.starts_with(&p.file_path()));
            match entry {
                Some(p) => format!("{} = {value}: {reason}", p.label),
                None => format!("{key} = {value}: {reason}"),
            }
        }
        other => other.to_string(),
    }
}

/// A short label, e.g. `P2 8×2×2 five`, `P2 tube` (a part meshed per element type), or
/// "mesh file".
pub fn label(config: &Config, base: &Scene) -> String {
    match base.mesh_kind() {
        hox_scenes::params::MeshKind::Box => config.box_label(),
        hox_scenes::params::MeshKind::Files => format!("{} {}", config.element.name().to_uppercase(), base.name()),
        hox_scenes::params::MeshKind::File => "mesh file".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_invalidation() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let c = from_scene(&scene);
        assert_eq!((c.element.name(), c.grid, c.substeps), ("p2", [8, 2, 2], 50));
        let again = from_scene(&resolve(&c, &scene).unwrap());
        assert_eq!(again, c);
        let mut e = c.clone();
        e.youngs_modulus_pa = 1e7;
        assert_eq!(c.invalidated_by(&e), Invalidates::Material);
        e.element = hox_sim::element::ElementType::from_name("q2").unwrap();
        assert_eq!(c.invalidated_by(&e), Invalidates::Mesh);
        let mut s = c.clone();
        s.substeps = 10;
        assert_eq!(c.invalidated_by(&s), Invalidates::Settings);
        assert_eq!(c.invalidated_by(&c.clone()), Invalidates::Nothing);
    }

    #[test]
    fn the_element_default_quadrature_resets_an_explicit_degree() {
        let text =
            include_str!("../../../assets/scenes/bending.toml").replace("[solver]", "[solver]\nquadrature_degree = 4");
        let scene = Scene::from_toml(&text, "bending-q4").unwrap();
        let mut c = from_scene(&scene);
        assert_eq!(c.quadrature_degree, Some(4));
        c.quadrature_degree = None;
        assert_eq!(resolve(&c, &scene).unwrap().settings().quadrature_degree, None);
    }

    #[test]
    fn bad_values_are_refused_with_the_reason() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let mut c = from_scene(&scene);
        c.poisson_ratio = 0.5;
        let reason = resolve(&c, &scene).unwrap_err();
        assert!(reason.to_lowercase().contains("poisson"), "{reason}");
        let mut c = from_scene(&scene);
        c.youngs_modulus_pa = -1.0;
        assert!(resolve(&c, &scene).unwrap_err().to_lowercase().contains("young"));
        let mut c = from_scene(&scene);
        c.grid = [0, 2, 2];
        assert!(resolve(&c, &scene).unwrap_err().contains("Grid"));
    }
}
