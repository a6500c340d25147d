//! The app's command-line options (`hox app`).

use std::path::PathBuf;

/// What the central view shows at start (`--view`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StartView {
    Model,
    ReferenceElement,
}

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
    /// Start in compare mode: alone, P1 refined once against P2 on the paper scenes; given twice
    /// with values, these two configurations, as `hox record --compare` takes them (e.g.
    /// `--compare element=p1,refine=1 --compare element=p2`), on top of the other options.
    #[arg(long, value_name = "OPTION=VALUE,...", num_args = 0..=1, default_missing_value = "")]
    pub compare: Vec<String>,
    #[command(flatten)]
    pub mesh: crate::config::MeshArgs,
    #[command(flatten)]
    pub physics: crate::config::PhysicsArgs,
    #[command(flatten)]
    pub display: crate::config::DisplayArgs,
    /// What the central view shows at start: the model, or the reference element's shape
    /// functions and quadrature points.
    #[arg(long, value_enum)]
    pub view: Option<StartView>,
    /// The camera preset at start (keys 1–4 in the app).
    #[arg(long, value_enum)]
    pub camera: Option<super::presets::ViewPreset>,
    /// Open on a built-in lesson (`hox lessons` lists them).
    #[arg(long, conflicts_with = "lesson_file")]
    pub lesson: Option<String>,
    /// Open the lesson on this step (1 is the first): a class resuming where it stopped.
    #[arg(long, value_name = "N")]
    pub lesson_step: Option<usize>,
    /// Open on a lesson file of your own (TOML, docs/LESSONS.md).
    #[arg(long)]
    pub lesson_file: Option<PathBuf>,
    /// Presenter mode: a larger interface for a projector, the 3D view filling the window (P).
    #[arg(long)]
    pub presenter: bool,
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
    /// Serve what the app shows to the class's browsers (the Rerun web viewer): students open
    /// the address printed (and shown with a QR code in presenter mode) and follow live.
    #[arg(long)]
    pub serve_web: bool,
    /// Frames a second sent to the browsers at most (the app simulates 60), for the network's
    /// sake: the P2 beam takes about 10 Mbit/s per browser at 30, 3.3 at 10. 0: every frame.
    #[arg(long, default_value_t = 30)]
    pub serve_fps: u32,
    #[command(flatten)]
    pub serve: crate::web::ServeArgs,
}

/// The app's options from command-line words (the UI tests start the app as a teacher would).
#[cfg(test)]
pub fn parse_for_test(words: &[&str]) -> AppArgs {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct Line {
        #[command(flatten)]
        app: AppArgs,
    }
    let all = std::iter::once("hox").chain(words.iter().copied());
    Line::try_parse_from(all).unwrap_or_else(|e| panic!("{words:?}: {e}")).app
}
