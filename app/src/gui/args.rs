//! The app's command-line options (`hox app`).

use std::path::PathBuf;

/// Command-line options of the app.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct AppArgs {
    /// Start on this built-in scene (default: the last one used, or bending).
    #[arg(long)]
    pub scene: Option<String>,
    /// Start on this scene file.
    #[arg(long, conflicts_with = "scene")]
    pub scene_file: Option<PathBuf>,
    /// Ignore the saved settings.
    #[arg(long)]
    pub fresh: bool,
    /// Start playing at once.
    #[arg(long)]
    pub play: bool,
    /// Start in compare mode (P1 refined once against P2 on the paper scenes).
    #[arg(long)]
    pub compare: bool,
    /// Save a PNG of the window after --after-secs and quit (for docs and tests).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Measure the frame rate for this many seconds of playing, print it and quit.
    #[arg(long)]
    pub measure_secs: Option<f64>,
    /// Delay before --screenshot, seconds.
    #[arg(long, default_value_t = 3.0)]
    pub after_secs: f64,
    /// Window size in points, WIDTHxHEIGHT (default: the size of the last run, else 1400x900).
    #[arg(long)]
    pub size: Option<String>,
    /// Do not wait for the display's vertical sync (frame-rate measurements).
    #[arg(long)]
    pub no_vsync: bool,
}
