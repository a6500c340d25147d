//! Issue #58: every command README.md shows runs, so that a README command that stops working
//! fails CI. The commands are read from README's `sh` blocks, not copied here:
//! - `cargo test --workspace`, `bash scripts/setup.sh` and the Python package's two commands
//!   (`bash scripts/setup-python.sh`, its pytest) must be what `.ci/run` runs;
//! - `cargo run --release` (the app) and every `hox app …` run under Xvfb with a screenshot
//!   taken after a few seconds (`--fresh`, a home of their own; a served app on free ports);
//! - `bash scripts/build-web.sh --open` builds the app's site into the scratch folder with
//!   `--no-references` (the lessons' references are minutes of static solves on a cold machine;
//!   their export and reading back are hox-scenes' tests); the serving it would start is `hox
//!   serve-app`'s, checked next: `hox serve-app …` serves that site for two seconds on a free port;
//! - every other `hox …` runs as written, in a scratch folder that sees the repository's
//!   `assets/`, and must exit 0.
//!
//! Ignored in a plain `cargo test` (the paper and the study take minutes in a debug build, the
//! app needs Xvfb); `.ci/run` runs it: `cargo test -p hox --test readme -- --ignored`.

use std::path::{Path, PathBuf};
use std::process::Command;

const HOX: &str = env!("CARGO_BIN_EXE_hox");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// README's Python commands: the package built and its tests run, as .ci/run runs them (after
/// the workspace's tests, sharing their build).
const PYTHON: [&str; 2] = ["bash scripts/setup-python.sh", "python/.venv/bin/python -m pytest python/tests"];

/// The command lines of README's `sh` blocks, in order (a trailing `# comment` dropped).
fn readme_commands() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let mut commands = Vec::new();
    let mut in_sh = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_sh = !in_sh && t == "```sh";
            continue;
        }
        if in_sh && !t.is_empty() {
            let command = t.split("  #").next().unwrap_or(t).trim();
            commands.push(command.to_string());
        }
    }
    commands
}

/// `hox`'s arguments in a command written `hox …` or `cargo run --release -- …` (None: another
/// program); a bare `cargo run --release` is the app.
fn hox_args(command: &str) -> Option<Vec<String>> {
    let words: Vec<String> = command.split_whitespace().map(|w| w.trim_matches('"').to_string()).collect();
    match words.first().map(String::as_str) {
        Some("hox") => Some(words[1..].to_vec()),
        Some("cargo") if words.get(1).is_some_and(|w| w == "run") => {
            let rest: Vec<String> = words.iter().skip_while(|w| *w != "--").skip(1).cloned().collect();
            Some(if rest.is_empty() { vec!["app".to_string()] } else { rest })
        }
        _ => None,
    }
}

/// A scratch folder with the repository's `assets/` linked in.
fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hox-readme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let assets = dir.join("assets");
    if !assets.exists() {
        std::os::unix::fs::symlink(root().join("assets"), &assets).unwrap();
    }
    dir
}

fn run_app(args: &[String], dir: &Path, k: usize) {
    let home = dir.join(format!("home-{k}"));
    std::fs::create_dir_all(&home).unwrap();
    let shot = dir.join(format!("app-{k}.png"));
    let mut full: Vec<String> = args.to_vec();
    full.extend(["--fresh", "--after-secs", "4", "--screenshot"].map(String::from));
    full.push(shot.display().to_string());
    if args.iter().any(|a| a == "--serve-web") {
        full.extend(["--web-port", "0", "--grpc-port", "0"].map(String::from));
    }
    let status = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1600x900x24"])
        .arg("env")
        .arg(format!("HOME={}", home.display()))
        .arg(HOX)
        .args(&full)
        .current_dir(dir)
        .status()
        .expect("xvfb-run (scripts/setup.sh installs it)");
    assert!(status.success(), "README's `hox {}` failed", args.join(" "));
    let png = std::fs::read(&shot).unwrap_or_else(|e| panic!("README's `hox {}`: no screenshot: {e}", args.join(" ")));
    assert!(png.starts_with(b"\x89PNG"), "README's `hox {}`: not a PNG", args.join(" "));
}

#[test]
#[ignore = "minutes in a debug build, and Xvfb for the app; .ci/run runs it"]
fn every_command_in_the_readme_runs() {
    let commands = readme_commands();
    assert!(commands.len() >= 8, "README's commands: {commands:?}");
    let ci = std::fs::read_to_string(root().join(".ci/run")).expect(".ci/run");
    let dir = scratch();
    for (k, command) in commands.iter().enumerate() {
        for part in command.split("&&").map(str::trim) {
            if PYTHON.contains(&part) || part == "cargo test --workspace" || part == "bash scripts/setup.sh" {
                assert!(ci.lines().any(|l| l.trim() == part), "README's `{part}` is not what .ci/run runs");
                continue;
            }
            if part.starts_with("bash scripts/build-web.sh") {
                let status = Command::new("bash")
                    .arg(root().join("scripts/build-web.sh"))
                    .arg(dir.join("site"))
                    .arg("--no-references")
                    .status()
                    .expect("bash");
                assert!(status.success(), "README's `{part}` failed");
                continue;
            }
            let Some(mut args) = hox_args(part) else { panic!("README's `{part}`: not a hox command this test knows") };
            if args.first().is_some_and(|a| a == "serve-app") {
                args.extend(["--web-port", "0", "--seconds", "2", "--site"].map(String::from));
                args.push(dir.join("site").display().to_string());
            }
            if args.first().is_some_and(|a| a == "app") {
                run_app(&args, &dir, k);
                continue;
            }
            let out = Command::new(HOX).args(&args).current_dir(&dir).output().expect("hox");
            assert!(out.status.success(), "README's `{part}` failed: {}", String::from_utf8_lossy(&out.stderr));
            println!("ok: {part}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_readme_s_commands_are_read_and_its_first_screen_has_the_four_readers() {
    let commands = readme_commands();
    assert!(commands.contains(&"cargo test --workspace".to_string()), "{commands:?}");
    let known = |part: &str| {
        hox_args(part).is_some()
            || ["cargo test --workspace", "bash scripts/setup.sh", "bash scripts/build-web.sh --open"].contains(&part)
            || PYTHON.contains(&part)
    };
    assert!(commands.iter().all(|c| c.split("&&").map(str::trim).all(known)), "{commands:?}");
    assert_eq!(hox_args("bash scripts/setup.sh && cargo run --release"), None);
    assert_eq!(hox_args("cargo run --release"), Some(vec!["app".to_string()]));
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let first: String = text.lines().take(60).collect::<Vec<_>>().join("\n");
    for needed in ["![", "cargo run --release", "cargo test --workspace", "Teachers", "Students", "Researchers", "CI"] {
        assert!(first.contains(needed), "README's first 60 lines lack {needed:?}");
    }
}
