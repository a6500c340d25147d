//! What the app keeps across runs (scene, configurations, links, view, camera, time scale, Rerun
//! targets), where the scene comes from, and eframe's storage of it.

use super::HoxApp;
use super::config::Config;
use super::links::Links;
use super::raster;
use super::viewport::ViewOptions;
use hox_scenes::Scene;
use std::path::PathBuf;

/// Where the scene comes from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SceneSource {
    Builtin(String),
    File(PathBuf),
}

impl SceneSource {
    pub fn load(&self) -> Result<Scene, String> {
        match self {
            SceneSource::Builtin(name) => hox_scenes::by_name(name).map_err(|e| e.to_string()),
            SceneSource::File(path) => Scene::load(path).map_err(|e| e.to_string()),
        }
    }
    pub fn label(&self) -> String {
        match self {
            SceneSource::Builtin(name) => name.clone(),
            SceneSource::File(path) => path.display().to_string(),
        }
    }
}

/// What persists across runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Persisted {
    pub scene: SceneSource,
    pub configs: Vec<Config>,
    pub compare: bool,
    pub links: Links,
    pub view: ViewOptions,
    pub camera: Option<raster::Camera>,
    pub time_scale: f64,
    pub show_reference_element: bool,
    pub rerun_url: String,
    pub rerun_file: String,
    /// The app was in presenter mode when it closed: the window geometry eframe saved is the
    /// projector's, in presenter mode's points, and an ordinary start does not reuse it.
    #[serde(default)]
    pub presenter_at_exit: bool,
}

impl Persisted {
    /// The settings eframe saved in `storage` on the last run, if any.
    pub fn load(storage: &dyn eframe::Storage) -> Option<Persisted> {
        eframe::get_value::<Persisted>(storage, eframe::APP_KEY)
    }

    /// Saves the settings in eframe's `storage`.
    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, self);
    }
}

impl HoxApp {
    /// What of the app persists, as it is now.
    pub fn persisted(&self) -> Persisted {
        Persisted {
            scene: self.scene.clone(),
            configs: self.sessions.iter().map(|s| s.config.clone()).collect(),
            compare: self.compare,
            links: self.links.clone(),
            view: self.view.clone(),
            camera: Some(self.viewport.camera),
            time_scale: self.playback.time_scale,
            show_reference_element: self.show_reference_element,
            rerun_url: self.rerun_url.clone(),
            rerun_file: self.rerun_file.clone(),
            presenter_at_exit: self.presenter,
        }
    }
}
