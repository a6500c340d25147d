//! Issue #38: what hox serves, seen in a real browser — headless Chromium (Debian's package,
//! installed by `scripts/setup.sh`) with software WebGL, driven by `scripts/browser_shot.py`.
//! Each test starts a server on the loopback address (any free ports), opens the printed address,
//! and reads the screenshots: the 3D view must show the body in the field's colours (not an
//! empty page or an error), and what changes on the server must reach the browser.
//!
//! Ignored in a plain `cargo test` (each takes 30–90 s and needs Chromium, the app test Xvfb);
//! `.ci/run` runs them where the browser is present: `cargo test -p hox --test web -- --ignored`.

mod doc_blocks;

mod browser;

use browser::*;
use std::process::{Command, Stdio};

/// Issue #58: docs/WEB.md's figures are `scripts/web_figures.py`'s output; the committed table
/// keeps the format a short run of it writes (the page coloured within its wait, every row).
#[test]
#[ignore = "needs headless Chromium and Xvfb; .ci/run runs it"]
fn the_web_figures_table_in_the_docs_has_the_format_its_command_writes() {
    have_browser();
    let blocks = doc_blocks::blocks();
    let web: Vec<_> = blocks.iter().filter(|(_, c, _)| c.contains("scripts/web_figures.py")).collect();
    assert!(!web.is_empty(), "docs/WEB.md holds a table written by scripts/web_figures.py");
    for (file, command, body) in web {
        doc_blocks::check(file, command, body);
    }
}

#[test]
#[ignore = "needs headless Chromium; .ci/run runs it"]
fn a_recording_served_plays_in_a_browser_with_its_body_coloured() {
    have_browser();
    let dir = scratch("serve");
    let rrd = dir.join("bending.rrd");
    let status = Command::new(HOX)
        .args(["record", "--scene", "bending", "--seconds", "0.5", "--out"])
        .arg(&rrd)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let (_server, url) =
        start(HOX, &["serve", rrd.to_str().unwrap(), "--web-port", "0", "--grpc-port", "0", "--seconds", "300"]);
    let image = shot(&url, &dir.join("serve.png"), 25.0);
    let coloured = coloured_fraction(&image.view_3d());
    println!("served recording: {:.1} % of the 3D view in the field's colours", 100.0 * coloured);
    assert!(coloured > 0.05, "the 3D view shows no coloured body ({:.2} %): {}", 100.0 * coloured, dir.display());
}

#[test]
#[ignore = "needs headless Chromium and Xvfb; .ci/run runs it"]
fn the_app_served_live_shows_its_beam_and_what_it_simulates_next_reaches_an_open_page_and_a_later_one() {
    have_browser();
    let dir = scratch("app");
    let home = dir.join("home");
    std::fs::create_dir_all(&home).unwrap();
    let (_server, url) = start(
        "xvfb-run",
        &[
            "-a",
            "-s",
            "-screen 0 1600x900x24",
            "env",
            &format!("HOME={}", home.display()),
            HOX,
            "app",
            "--fresh",
            "--scene",
            "bending",
            "--play",
            "--serve-web",
            "--web-port",
            "0",
            "--grpc-port",
            "0",
            "--size",
            "1280x720",
        ],
    );
    // one browser kept open: two screenshots 8 s apart, the app simulating on meanwhile
    let open = shots(&url, &dir.join("app-open.png"), 25.0, 2, 8.0);
    // a second browser, later
    let late = shot(&url, &dir.join("app-late.png"), 25.0);
    let (a, b, c) = (open[0].view_3d(), open[1].view_3d(), late.view_3d());
    for (what, view) in [("open page, first", &a), ("open page, 8 s on", &b), ("second browser", &c)] {
        let coloured = coloured_fraction(view);
        println!("live app, {what}: {:.1} % of the 3D view coloured", 100.0 * coloured);
        assert!(coloured > 0.05, "{what}: no coloured beam ({:.2} %): {}", 100.0 * coloured, dir.display());
    }
    // what the app simulates reaches the page already open, and a browser opened later
    let (on_open, on_late) = (changed_fraction(&a, &b), changed_fraction(&a, &c));
    println!(
        "live app: {:.1} % of the 3D view's pixels changed on the open page, {:.1} % in the later browser",
        100.0 * on_open,
        100.0 * on_late
    );
    assert!(on_open > 0.01, "nothing the app simulated reached the page already open: {}", dir.display());
    assert!(on_late > 0.01, "nothing the app simulated reached the second browser: {}", dir.display());
}
