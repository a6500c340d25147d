//! What the app keeps across runs (scene, configurations, links, view, camera, time scale, Rerun
//! targets), and eframe's storage of it.

use super::config::{Config, SceneSource};
use super::links::Links;
use super::model::Model;
use super::presets::ViewOptions;
use super::raster;
use super::ui_state::UiState;

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

impl Persisted {
    /// What of `model` and the UI's `state` persists, as they are now.
    pub fn of(model: &Model, state: &UiState) -> Persisted {
        let (configs, compare) = model.kept_configurations();
        Persisted {
            // a mesh opened from its bytes lives as long as the page: the next start opens the
            // default scene instead
            scene: match model.scene() {
                SceneSource::Opened { .. } => SceneSource::Builtin("bending".into()),
                s => s.clone(),
            },
            configs,
            compare,
            links: model.links().clone(),
            view: model.view().clone(),
            camera: Some(state.viewport.camera),
            time_scale: model.playback().time_scale,
            show_reference_element: model.show_reference_element(),
            rerun_url: state.rerun_url.clone(),
            rerun_file: state.rerun_file.clone(),
            presenter_at_exit: model.presenter(),
        }
    }
}
