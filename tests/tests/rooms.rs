//! The rooms of every crate in one stated order (docs/ARCHITECTURE.md states the same): a room
//! uses only the rooms of the layers before its own; within hox-sim's `solver/`, hox-scenes'
//! `lab/` and `present/` and the app's `gui/` the same holds for its files.
//! The checker is `hox_tests::rooms`; each test names the file, the line and the path of every
//! use against the order.

use hox_tests::rooms::{
    FRONT, Order, Use, front_names, is_test_file, module_path, order_text, read_crate, uses, violations, workspace_dir,
};

/// hox-sim's rooms, lowest first; `lib` (the crate's front) last.
const SIM: &[&[&str]] = &[
    &["math"],
    &["element"],
    &["material"],
    &["mesh"],
    &["fem"],
    &["measure"],
    &["io"],
    &["xpbd"],
    &["effect"],
    &["solver"],
    &["lib"],
];

/// The files of hox-sim's `solver/`, lowest first (`mod.rs`, the room's front, declares them);
/// [`SOLVERS`] stands for the layer of the solvers themselves, which are the files `registry.rs`
/// names ([`solver_files`]): a new solver needs no line here.
const SOLVER_FILES_STATED: &[&[&str]] = &[
    &["method", "integrator"],
    &["error"],
    &["settings"],
    &["nan_guard"],
    &["step"],
    &["residual", "sparse", "stability"],
    &["potential"],
    &["newton_core"],
    &[SOLVERS],
    &["statics"],
    &["registry", "node_loops"],
    &["simulation"],
];

/// The solvers' layer of [`SOLVER_FILES_STATED`], as docs/ARCHITECTURE.md words it.
const SOLVERS: &str = "the solvers";

/// [`SOLVER_FILES_STATED`] with the solvers' layer filled in from `registry.rs`: every file it
/// uses (`use super::NAME::…`) that no other layer lists, in the order it names them.
fn solver_files() -> &'static [&'static [&'static str]] {
    static FILES: std::sync::OnceLock<Vec<&'static [&'static str]>> = std::sync::OnceLock::new();
    FILES.get_or_init(|| {
        let path = workspace_dir().join("sim/src/solver/registry.rs");
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let stated: Vec<&str> = SOLVER_FILES_STATED.iter().flat_map(|l| l.iter().copied()).collect();
        let mut solvers: Vec<&'static str> = Vec::new();
        for line in text.lines() {
            if let Some(rest) = line.trim().strip_prefix("use super::") {
                let name = rest.split("::").next().unwrap_or("").trim_end_matches(';');
                if !stated.contains(&name) && !solvers.contains(&name) {
                    solvers.push(Box::leak(name.to_string().into_boxed_str()));
                }
            }
        }
        assert!(solvers.len() >= 3, "registry.rs names only {solvers:?} as solvers");
        let solvers: &'static [&'static str] = Box::leak(solvers.into_boxed_slice());
        SOLVER_FILES_STATED.iter().map(|l| if *l == [SOLVERS] { solvers } else { *l }).collect()
    })
}

/// hox-scenes' rooms, lowest first; `lib` (the front: `mod` lines and re-exports) last. Scene
/// loading (`params` to `run`) never uses the lab.
const SCENES: &[&[&str]] =
    &[&["error", "present"], &["params"], &["scene"], &["instance"], &["run"], &["lab"], &["lib"]];

/// The files of hox-scenes' `lab/`, lowest first (`mod.rs`, a pure front, declares them).
const LAB_FILES: &[&[&str]] = &[&["claim", "reference"], &["study"], &["paper", "bench", "lesson"]];

/// The files of hox-scenes' `present/`, lowest first.
const PRESENT_FILES: &[&[&str]] = &[&["colour"], &["svg"]];

/// The app's rooms (`hox`), lowest first: `cli` and `gui` share what both need through `config`.
const APP: &[&[&str]] = &[&["output", "web"], &["config"], &["display"], &["recording"], &["cli", "gui"], &["main"]];

/// The files of the app's `gui/`, lowest first (`mod.rs`, a pure front, declares them): the
/// model's parts, the model, its services, the UI's state, the panels, the app, the window.
const GUI_FILES: &[&[&str]] = &[
    &["platform"],
    &["config", "links", "presets", "readout", "raster", "study_chart", "measure", "playback"],
    &["session", "args", "gl_view", "teach"],
    &["session_view", "background", "cost"],
    &["lesson", "viewport", "rebuild"],
    &["action"],
    &["model"],
    &["figure", "rerun_link"],
    &["ui_state"],
    &["persist", "sections", "serve_web", "status", "dialogs", "lesson_panel", "plots"],
    &["controls", "menu"],
    &["app"],
    &["window"],
    &["launch"],
];

/// hox-sim's one room with an order of its own files.
fn sim_files_of() -> &'static [(&'static str, &'static [&'static [&'static str]])] {
    static OF: std::sync::OnceLock<[(&str, &[&[&str]]); 1]> = std::sync::OnceLock::new();
    OF.get_or_init(|| [("solver", solver_files())])
}

fn orders() -> [Order<'static>; 3] {
    [
        Order { crate_dir: "sim", layers: SIM, files_of: sim_files_of() },
        Order { crate_dir: "scenes", layers: SCENES, files_of: &[("lab", LAB_FILES), ("present", PRESENT_FILES)] },
        Order { crate_dir: "app", layers: APP, files_of: &[("gui", GUI_FILES)] },
    ]
}

/// The app's order with `gui/`'s files ordered too.
fn app_with_gui() -> Order<'static> {
    Order { crate_dir: "app", layers: APP, files_of: &[("gui", GUI_FILES)] }
}

fn assert_clean(order: &Order<'_>) {
    let files = read_crate(order.crate_dir);
    assert!(files.len() > 10, "{}: only {} source files found", order.crate_dir, files.len());
    let found = violations(order, &files);
    assert!(
        found.is_empty(),
        "{} use(s) against the room order of {} ({}; docs/ARCHITECTURE.md):\n{}",
        found.len(),
        order.crate_dir,
        order_text(order.layers),
        found.join("\n")
    );
}

#[test]
fn sim_rooms_and_solver_files_use_only_those_before_them() {
    assert_clean(&orders()[0]);
}

#[test]
fn scenes_rooms_and_lab_and_present_files_use_only_those_before_them() {
    assert_clean(&orders()[1]);
}

#[test]
fn app_rooms_use_only_those_before_them() {
    assert_clean(&orders()[2]);
}

/// The rooms of `order` on disk and those it lists, and the same for each room with an order of
/// its own files: (what, on disk, listed), sorted.
fn on_disk_and_listed(order: &Order<'_>) -> Vec<(String, Vec<String>, Vec<String>)> {
    let files = read_crate(order.crate_dir);
    let code: Vec<Vec<String>> =
        files.iter().filter(|(rel, _)| !is_test_file(rel)).map(|(rel, _)| module_path(rel)).collect();
    let sorted = |mut v: Vec<String>| {
        v.sort();
        v.dedup();
        v
    };
    let listed = |layers: &[&[&str]]| sorted(layers.iter().flat_map(|l| l.iter().map(|r| r.to_string())).collect());
    let rooms = code.iter().map(|m| m.first().cloned().unwrap_or_else(|| "lib".into()));
    let main = files.iter().any(|(rel, _)| rel == "main.rs");
    let rooms = rooms.map(|r| if r == "lib" && main { "main".into() } else { r });
    let mut out =
        vec![(format!("{}: the rooms under src/", order.crate_dir), sorted(rooms.collect()), listed(order.layers))];
    for &(room, layers) in order.files_of {
        let files_here = code.iter().filter(|m| m.first().is_some_and(|r| r == room));
        let mut on_disk: Vec<String> = files_here.filter_map(|m| m.get(1).cloned()).collect();
        // the front is `mod` in the order when it holds code the files use
        if listed(layers).iter().any(|f| f == FRONT) {
            on_disk.push(FRONT.into());
        }
        out.push((format!("{}: the files of src/{room}/", order.crate_dir), sorted(on_disk), listed(layers)));
    }
    out
}

/// A room or an ordered room's file on disk that no layer lists fails (and a listed one must exist).
#[test]
fn every_room_on_disk_is_in_the_order() {
    for order in orders() {
        for (what, on_disk, listed) in on_disk_and_listed(&order) {
            assert_eq!(on_disk, listed, "{what} and their stated order differ");
        }
    }
}

/// The app's `gui/` with its files' order: no file uses one of a later layer or of its own,
/// nor the front (`mod.rs` holds no code: `HoxApp` is `app.rs`'s), so no two-way ties.
#[test]
fn gui_files_use_only_those_before_them() {
    let order = app_with_gui();
    for (what, on_disk, listed) in on_disk_and_listed(&order).into_iter().skip(1) {
        assert_eq!(on_disk, listed, "{what} and their stated order differ");
    }
    assert_clean(&order);
}

#[test]
fn the_docs_state_the_same_orders() {
    let path = workspace_dir().join("docs/ARCHITECTURE.md");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    for layers in [SIM, SOLVER_FILES_STATED, SCENES, LAB_FILES, PRESENT_FILES, APP, GUI_FILES] {
        let order = order_text(layers).replace(&format!("`{SOLVERS}`"), SOLVERS);
        assert!(text.contains(&order), "docs/ARCHITECTURE.md does not state the order {order}");
    }
}

#[test]
fn the_scanner_finds_uses_in_code_only_and_resolves_them() {
    let src = r##"//! A doc that names crate::gui::run.
use crate::config::MeshArgs;
use crate::{
    display::f32s,
    gui::{AppArgs, run},
    self,
};
/// crate::cli in a doc comment, /* and */ in a block: /* crate::cli */
fn f<'a>(x: &'a str) -> char {
    let _ = "crate::cli::run in a string";
    let _ = r#"crate::cli"#;
    crate::recording::format_metres(1.0);
    super::super::newton::Potential::new();
    '"'
}
#[cfg(test)]
mod tests {
    use crate::cli::Hidden;
    fn g() { let _ = "}"; }
}
"##;
    let module: Vec<String> = ["solver", "vbd", "coarse"].map(String::from).into();
    let found: Vec<(usize, String)> =
        uses(src, &module, false).into_iter().map(|Use { line, path }| (line, path.join("::"))).collect();
    let want = [
        (2, "config::MeshArgs"),
        (3, "display::f32s"),
        (3, "gui"),
        (12, "recording::format_metres"),
        (13, "solver::newton::Potential::new"),
    ];
    assert_eq!(found, want.map(|(l, p)| (l, p.to_string())).to_vec());
}

#[test]
fn a_use_against_the_order_is_named_with_its_file_and_line() {
    let sim = &orders()[0];
    let files = vec![
        ("material/stvk.rs".to_string(), "//! StVK.\n\nuse crate::xpbd::kernels::F64x4;\n".to_string()),
        ("solver/vbd/coarse.rs".to_string(), "use super::super::newton::Potential;\n".to_string()),
        ("solver/settings.rs".to_string(), "use super::SimError;\n".to_string()),
        ("extra.rs".to_string(), String::new()),
    ];
    let found = violations(sim, &files);
    assert_eq!(found.len(), 4, "{found:#?}");
    assert!(found[0].starts_with("sim/src/material/stvk.rs:3: the room `material` uses `xpbd`"), "{}", found[0]);
    assert!(found[0].ends_with("use crate::xpbd::kernels::F64x4;"), "{}", found[0]);
    assert!(found[1].starts_with("sim/src/solver/vbd/coarse.rs:1: `solver/vbd` uses `newton`"), "{}", found[1]);
    assert!(found[2].contains("reaches `solver` through its front"), "{}", found[2]);
    assert!(found[3].contains("`extra` is in no layer"), "{}", found[3]);
    let app = &orders()[2];
    let cycle = vec![("gui/args.rs".to_string(), "pub mesh: crate::cli::MeshArgs,\n".to_string())];
    let found = violations(app, &cycle);
    assert!(found.len() == 1 && found[0].contains("uses `cli`") && found[0].contains("same layer"), "{found:#?}");
}

fn planted(files: &[(&str, &str)]) -> Vec<(String, String)> {
    files.iter().map(|(rel, text)| (rel.to_string(), text.to_string())).collect()
}

#[test]
fn a_front_s_names_unfold_groups_paths_and_aliases() {
    let lib = "//! `pub use nothing::Here;` in a doc.\npub mod lab;\npub use lab::{bench, study::{self, Row as StudyRow}};\n\
               pub(crate) use crate::run::{\n    Settler,\n    run,\n};\npub use error::*;\nuse private::Hidden;\n";
    let found: Vec<(String, String)> =
        front_names(lib).into_iter().map(|(name, path)| (name, path.join("::"))).collect();
    let want = [
        ("bench", "lab::bench"),
        ("study", "lab::study"),
        ("StudyRow", "lab::study::Row"),
        ("Settler", "run::Settler"),
        ("run", "run::run"),
        ("Hidden", "private::Hidden"),
    ];
    assert_eq!(found, want.map(|(n, p)| (n.to_string(), p.to_string())).to_vec());
}

/// A planted back-arrow through the crate root: `crate::Instance` is `crate::instance::Instance`,
/// a later room than `scene`, and `crate::study::…` is in `lab/`, after everything scene loading
/// is; an item the root defines itself, and a re-exported one from an earlier room, are fine.
#[test]
fn a_crate_item_is_a_use_of_the_room_that_defines_it() {
    let scenes = &orders()[1];
    let files = planted(&[
        (
            "lib.rs",
            "pub mod error;\npub mod instance;\npub mod lab;\npub use error::SceneError;\npub use instance::Instance;\n\
             pub use lab::{study, paper};\npub struct Shared;\n",
        ),
        (
            "scene/mod.rs",
            "//! Scenes.\nuse crate::{SceneError, Shared};\n\npub fn f() -> crate::Instance { todo!() }\n",
        ),
        ("params/mod.rs", "fn g() {\n    let _ = crate::study::run_study(true);\n}\n"),
        ("run.rs", "use crate::{Instance, SceneError};\n"),
        ("lab/paper/mod.rs", "use crate::study::StudyConfig;\nuse crate::lab::bench::Case;\n"),
    ]);
    let found = violations(scenes, &files);
    assert_eq!(found.len(), 3, "{found:#?}");
    assert!(
        found[0].starts_with(
            "scenes/src/scene/mod.rs:4: the room `scene` uses `instance` (Instance = instance::Instance), which comes later"
        ),
        "{}",
        found[0]
    );
    assert!(
        found[1].starts_with(
            "scenes/src/params/mod.rs:2: the room `params` uses `lab` (study::run_study = lab::study::run_study)"
        ),
        "{}",
        found[1]
    );
    // within `lab/`, the root's re-export names the file: `paper` uses `study` (fine) and `bench`
    // (the same layer)
    assert!(found[2].starts_with("scenes/src/lab/paper/mod.rs:2: `lab/paper` uses `bench`"), "{}", found[2]);
    assert!(found[2].contains("same layer of the files' order"), "{}", found[2]);
}

/// A planted back-arrow in `gui/`'s files: a file using a later file, a file using the front's
/// code when the front is placed last, a file reaching a file through the front's re-export; and,
/// with the front placed first, the front's own bare use of a later file.
#[test]
fn a_gui_file_using_a_later_file_or_the_front_is_named() {
    let gui_mod = "mod config;\nmod session;\nmod window;\npub use window::Panel;\npub struct HoxApp;\n\
                   fn f() {\n    window::draw();\n}\n";
    let files = planted(&[
        ("gui/mod.rs", gui_mod),
        ("gui/config.rs", "use super::viewport::View;\n"),
        ("gui/session.rs", "use super::HoxApp;\n"),
        ("gui/viewport.rs", "use super::Panel;\n"),
        ("gui/window.rs", "use super::session::Session;\nuse super::config::Config;\n"),
    ]);
    // the app's own order, whose front holds no code: a use of the front's item is named too
    let found = violations(&app_with_gui(), &files);
    assert!(
        found.iter().any(|f| f.starts_with("app/src/gui/session.rs:1: `gui::HoxApp` reaches `gui` through its front")),
        "{found:#?}"
    );
    // the front placed last
    const HIGH_FRONT: &[&[&str]] = &[&["config", "session"], &["viewport"], &["window"], &[FRONT]];
    let order = Order { crate_dir: "app", layers: APP, files_of: &[("gui", HIGH_FRONT)] };
    let found = violations(&order, &files);
    assert_eq!(found.len(), 3, "{found:#?}");
    assert!(found[0].starts_with("app/src/gui/config.rs:1: `gui/config` uses `viewport`"), "{}", found[0]);
    assert!(found[0].contains("comes later in the files' order"), "{}", found[0]);
    assert!(found[1].starts_with("app/src/gui/session.rs:1: `gui/session` uses `mod` (the front"), "{}", found[1]);
    assert!(
        found[2].contains("`gui::Panel` reaches `gui` through its front (`gui/mod.rs` brings in `window::Panel`)"),
        "{}",
        found[2]
    );
    // the front placed first: the files may use it, and its own use of `window` runs back up
    const LOW_FRONT: &[&[&str]] = &[&[FRONT], &["config", "session"], &["viewport"], &["window"]];
    let order = Order { crate_dir: "app", layers: APP, files_of: &[("gui", LOW_FRONT)] };
    let found = violations(&order, &files);
    assert_eq!(found.len(), 3, "{found:#?}");
    assert!(found[0].starts_with("app/src/gui/mod.rs:7: `gui/mod` uses `window` (gui::window::draw)"), "{}", found[0]);
    assert!(found[1].starts_with("app/src/gui/config.rs:1: `gui/config` uses `viewport`"), "{}", found[1]);
    assert!(found[2].contains("through its front (`gui/mod.rs` brings in `window::Panel`)"), "{}", found[2]);
}
