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
    /// Open what a page's link opens (its query, e.g. "lesson=locking&step=2" or the whole
    /// address): what a student's browser running `hox serve-app`'s page shows, on top of the
    /// other options.
    #[arg(long, value_name = "QUERY")]
    pub link: Option<String>,
}

impl AppArgs {
    /// These options with `--link`'s on top (`--link`'s own problems refused by name).
    #[cfg(not(target_arch = "wasm32"))] // the page reads its own address instead
    pub fn with_link(mut self) -> Result<AppArgs, String> {
        let Some(link) = self.link.take() else { return Ok(self) };
        let query = link.split_once('?').map_or(link.as_str(), |(_, q)| q);
        let (from, problems) = from_link(query);
        if !problems.is_empty() {
            return Err(format!("--link: {}", problems.join("; ")));
        }
        self.scene = from.scene.or(self.scene);
        self.lesson = from.lesson.or(self.lesson);
        self.lesson_step = from.lesson_step.or(self.lesson_step);
        self.camera = from.camera.or(self.camera);
        self.view = from.view.or(self.view);
        self.play |= from.play;
        self.presenter |= from.presenter;
        if !from.compare.is_empty() {
            self.compare = from.compare;
        }
        self.physics.overrides = self.physics.overrides.merged(&from.physics.overrides);
        Ok(self)
    }
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

/// The app's options from a page's link (issue #59): the query `?lesson=locking&step=2` or
/// `?element=p2&nu=0.49&play`, parsed as `hox app --lesson locking --lesson-step 2` and
/// `hox app --element p2 --nu 0.49 --play` would be. A parameter that cannot be understood (an
/// unknown key, a value out of range, a scene or lesson that does not exist) is left out and
/// named in the returned messages; the others still apply, so a garbage link opens the app as
/// the rest of it says, with a message. A link with parameters opens what it says, not the
/// page's saved settings, and without the welcome (`--fresh`); a bare link keeps them.
pub fn from_link(query: &str) -> (AppArgs, Vec<String>) {
    let mut args =
        AppArgs { fresh: query.trim_start_matches('?').split('&').any(|p| !p.is_empty()), ..Default::default() };
    let mut problems = Vec::new();
    let mut compare = Vec::new();
    for pair in query.trim_start_matches('?').split('&').filter(|p| !p.is_empty()) {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        let (key, value) = (percent_decoded(key), percent_decoded(value));
        if let Err(e) = apply_link_pair(&mut args, &mut compare, &key, &value) {
            problems.push(format!("link parameter '{key}={value}': {e}"));
        }
    }
    // a step the lesson has (the step alone is kept for a lesson the link names)
    if let (Some(n), Some(name)) = (args.lesson_step, &args.lesson)
        && let Ok(lesson) = crate::config::load_lesson(Some(name), None)
        && n > lesson.steps.len()
    {
        problems.push(format!("link parameter 'step={n}': the lesson {name} has steps 1 to {}", lesson.steps.len()));
        args.lesson_step = None;
    }
    if !compare.is_empty() {
        let base = crate::config::overrides(&args.mesh, Some(&args.physics)).merged(&args.display.overrides);
        match compare.iter().try_for_each(|c| crate::config::parse_compare(c, &base).map(drop)) {
            Ok(()) if compare.len() <= 2 => args.compare = compare,
            Ok(()) => problems.push("link parameter 'compare': at most two configurations".into()),
            Err(e) => problems.push(format!("link parameter 'compare': {e:#}")),
        }
    }
    (args, problems)
}

fn apply_link_pair(args: &mut AppArgs, compare: &mut Vec<String>, key: &str, value: &str) -> Result<(), String> {
    let switch = || match value {
        "" | "1" | "true" | "on" | "yes" => Ok(true),
        "0" | "false" | "off" | "no" => Ok(false),
        _ => Err("expected on or off".to_string()),
    };
    match key {
        "scene" => {
            hox_scenes::by_name(value).map_err(|e| e.to_string())?;
            args.scene = Some(value.to_string());
        }
        "lesson" => {
            crate::config::load_lesson(Some(value), None).map_err(|e| format!("{e:#}"))?;
            args.lesson = Some(value.to_string());
        }
        "step" => {
            let n = value.parse::<usize>().ok().filter(|&n| n >= 1).ok_or("a step is a whole number from 1")?;
            args.lesson_step = Some(n);
        }
        "compare" => compare.push(value.to_string()),
        "camera" => args.camera = Some(clap::ValueEnum::from_str(value, true)?),
        "view" => args.view = Some(clap::ValueEnum::from_str(value, true)?),
        "play" => args.play = switch()?,
        "presenter" => args.presenter = switch()?,
        // ν by its letter's name, as the links and a teacher write it
        "nu" => args.physics.overrides.set_text("poisson", value)?,
        _ => args.physics.overrides.set_text(key, value)?,
    }
    Ok(())
}

/// `text` with `+` as a space and `%XX` escapes decoded (a link's query); a broken escape is
/// kept as it is.
fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        match bytes[k] {
            b'+' => out.push(b' '),
            b'%' => match (bytes.get(k + 1).and_then(|&b| hex(b)), bytes.get(k + 2).and_then(|&b| hex(b))) {
                (Some(h), Some(l)) => {
                    out.push((h * 16 + l) as u8);
                    k += 2;
                }
                _ => out.push(b'%'),
            },
            b => out.push(b),
        }
        k += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The query of a link that opens what is on screen (the page's *Copy link*, the desktop's
/// *Copy page link* for `hox serve-app --link`): the scene (a
/// built-in one; a file has no address), the lesson and its step (1 is the first) when one is
/// open, else every shown parameter in which the configuration differs from its scene (in
/// compare mode, one `compare=` per configuration). [`from_link`] reads it back.
pub fn link_query(
    scene: &super::config::SceneSource,
    configs: &[(&hox_scenes::Params, &hox_scenes::Params)],
    lesson: Option<(&str, usize)>,
) -> String {
    let mut pairs: Vec<(String, String)> = Vec::new();
    if let super::config::SceneSource::Builtin(name) = scene {
        pairs.push(("scene".into(), name.clone()));
    }
    let changed = |(config, base): &(&hox_scenes::Params, &hox_scenes::Params)| -> Vec<(String, String)> {
        config
            .changed_keys(base)
            .into_iter()
            .filter_map(hox_scenes::params::by_key)
            .filter(|p| p.surfaces.cli)
            .map(|p| (p.key.to_string(), (p.get)(config).to_string()))
            .collect()
    };
    match (lesson, configs) {
        (Some((name, step)), _) => {
            pairs.push(("lesson".into(), name.into()));
            pairs.push(("step".into(), step.to_string()));
        }
        (None, [one]) => pairs.extend(changed(one)),
        (None, many) => {
            for c in many {
                let spec: Vec<String> = changed(c).into_iter().map(|(k, v)| format!("{k}={v}")).collect();
                pairs.push(("compare".into(), spec.join(",")));
            }
        }
    }
    let text: Vec<String> =
        pairs.iter().map(|(k, v)| format!("{}={}", percent_encoded(k), percent_encoded(v))).collect();
    format!("?{}", text.join("&"))
}

/// `text` with every byte but the unreserved ones (letters, digits, `-._~`) and `,` escaped.
fn percent_encoded(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b',' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

#[cfg(test)]
mod link_tests {
    use super::*;

    fn text(o: &hox_scenes::SceneOverrides, key: &str) -> Option<String> {
        o.iter().find(|(p, _)| p.key == key).map(|(_, v)| v.to_string().to_lowercase())
    }

    #[test]
    fn a_lesson_step_and_a_configuration_arrive_through_the_link() {
        let (args, problems) = from_link("?lesson=locking&step=2");
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!((args.lesson.as_deref(), args.lesson_step), (Some("locking"), Some(2)));
        let (args, problems) = from_link("?element=p2&nu=0.49&play&camera=front");
        assert!(problems.is_empty(), "{problems:?}");
        let o = &args.physics.overrides;
        assert_eq!(text(o, "element").as_deref(), Some("p2"));
        assert_eq!(text(o, "poisson").as_deref(), Some("0.49"));
        assert!(args.play);
        assert_eq!(args.camera, Some(super::super::presets::ViewPreset::Front));
    }

    #[test]
    fn a_garbage_link_parameter_is_a_message_naming_it_and_the_rest_still_applies() {
        let (args, problems) = from_link("?nu=abc&element=p2&bogus=1&scene=nope&step=0&lesson=no-such&poisson=0.5");
        assert_eq!(problems.len(), 6, "{problems:?}");
        for key in ["'nu=abc'", "'bogus=1'", "'scene=nope'", "'step=0'", "'lesson=no-such'", "'poisson=0.5'"] {
            assert!(problems.iter().any(|p| p.contains(key)), "{key} in {problems:?}");
        }
        assert_eq!(text(&args.physics.overrides, "element").as_deref(), Some("p2"));
        assert!(args.scene.is_none() && args.lesson.is_none() && args.lesson_step.is_none());
        // a step beyond the lesson's last: the lesson opens at its start, with the message
        let (args, problems) = from_link("?lesson=locking&step=99");
        assert_eq!((args.lesson.as_deref(), args.lesson_step), (Some("locking"), None));
        assert!(problems.len() == 1 && problems[0].contains("step=99"), "{problems:?}");
    }

    #[test]
    fn the_copied_link_opens_the_same_configuration() {
        let scene = hox_scenes::by_name("torsion").unwrap();
        let mut config = scene.params().clone();
        let mut o = hox_scenes::SceneOverrides::default();
        o.set_text("poisson", "0.45").unwrap();
        o.set_text("element", "q1").unwrap();
        config = config.overridden(&o);
        let source = super::super::config::SceneSource::Builtin("torsion".into());
        let query = link_query(&source, &[(&config, scene.params())], None);
        assert!(query.starts_with("?scene=torsion&"), "{query}");
        let (args, problems) = from_link(&query);
        assert!(problems.is_empty(), "{query}: {problems:?}");
        assert_eq!(args.scene.as_deref(), Some("torsion"));
        assert_eq!(scene.params().overridden(&args.physics.overrides), config, "{query}");
        // compare mode: one `compare=` per configuration, read back as `--compare` twice
        let query = link_query(&source, &[(&config, scene.params()), (scene.params(), scene.params())], None);
        let (args, problems) = from_link(&query);
        assert!(problems.is_empty(), "{query}: {problems:?}");
        assert_eq!(args.compare.len(), 2, "{query}");
        // a lesson: its name and step
        let query = link_query(&source, &[(&config, scene.params())], Some(("locking", 3)));
        assert_eq!(from_link(&query).0.lesson_step, Some(3), "{query}");
        assert_eq!(percent_decoded("a%20b+c%3D%zz"), "a b c=%zz");
    }
}
