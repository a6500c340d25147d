//! The rooms of every crate in one stated order (docs/ARCHITECTURE.md states the same): a room
//! uses only the rooms of the layers before its own; within hox-sim's `solver/` the same holds
//! for its files. The checker is `hox_tests::rooms`; each test names the file, the line and the
//! path of every use against the order.

use hox_tests::rooms::{Order, Use, module_path, order_text, read_crate, uses, violations, workspace_dir};

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

/// hox-scenes' rooms, lowest first; `lib` (the registry of scenes, `Instance`, the front) last.
const SCENES: &[&[&str]] =
    &[&["params"], &["scene"], &["run"], &["reference"], &["study"], &["paper"], &["bench"], &["lesson"], &["lib"]];

/// The app's rooms (`hox`), lowest first: `cli` and `gui` share what both need through `config`.
const APP: &[&[&str]] =
    &[&["colour", "output", "web"], &["config"], &["display"], &["recording"], &["cli", "gui"], &["main"]];

fn orders() -> [Order<'static>; 3] {
    [
        Order { crate_dir: "sim", layers: SIM, files_of: Some(("solver", solver_files())) },
        Order { crate_dir: "scenes", layers: SCENES, files_of: None },
        Order { crate_dir: "app", layers: APP, files_of: None },
    ]
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
fn scenes_rooms_use_only_those_before_them() {
    assert_clean(&orders()[1]);
}

#[test]
fn app_rooms_use_only_those_before_them() {
    assert_clean(&orders()[2]);
}

/// A room or solver file on disk that no layer lists fails (and a listed one must exist).
#[test]
fn every_room_on_disk_is_in_the_order() {
    for order in orders() {
        let mut on_disk: Vec<String> = read_crate(order.crate_dir)
            .iter()
            .filter(|(rel, _)| !hox_tests::rooms::is_test_file(rel))
            .map(|(rel, _)| module_path(rel).first().cloned().unwrap_or_else(|| rel.trim_end_matches(".rs").into()))
            .collect();
        on_disk.sort();
        on_disk.dedup();
        let mut listed: Vec<String> = order.layers.iter().flat_map(|l| l.iter().map(|r| r.to_string())).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "{}: the rooms under src/ and the stated order differ", order.crate_dir);
    }
    let mut solver: Vec<String> = read_crate("sim")
        .iter()
        .filter(|(rel, _)| rel.starts_with("solver/") && !hox_tests::rooms::is_test_file(rel))
        .filter_map(|(rel, _)| module_path(rel).get(1).cloned())
        .collect();
    solver.sort();
    solver.dedup();
    let mut listed: Vec<String> = solver_files().iter().flat_map(|l| l.iter().map(|r| r.to_string())).collect();
    listed.sort();
    assert_eq!(solver, listed, "the files of sim/src/solver/ and their stated order differ");
}

#[test]
fn the_docs_state_the_same_orders() {
    let path = workspace_dir().join("docs/ARCHITECTURE.md");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    for layers in [SIM, SOLVER_FILES_STATED, SCENES, APP] {
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
