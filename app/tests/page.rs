//! Issue #59: hox itself in a student's browser — the app compiled to WebAssembly
//! (`scripts/build-web.sh`), served by `hox serve-app` on the loopback address and opened in
//! headless Chromium (software WebGL) by `scripts/browser_shot.py`, which also reads the state the
//! page publishes (`window.hox_state`: scene, configurations, lesson step, message) and the
//! page's console errors. Each check is what a student does: open a link, watch the beam move,
//! open a link with a changed ν, open a lesson step and press A for its answer, open a broken
//! link, drop nothing and expect nothing to break.
//!
//! Ignored in a plain `cargo test` (the web build takes minutes and needs Debian's Rust for the
//! web; the pages need Chromium); `.ci/run` runs them: `cargo test -p hox --test page -- --ignored`.

mod browser;
mod doc_blocks;

use browser::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The site, built once per test process into a scratch folder by the project's script.
fn site() -> PathBuf {
    static SITE: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    SITE.get_or_init(|| {
        let dir = scratch("site");
        // without the lessons' references (minutes of static solves on a cold machine): what
        // the page computes itself is what is checked
        let status = Command::new("bash")
            .arg(root().join("scripts/build-web.sh"))
            .args([dir.to_str().unwrap(), "--no-references"])
            .status()
            .expect("bash");
        assert!(status.success(), "scripts/build-web.sh failed");
        dir
    })
    .clone()
}

/// `hox serve-app` of the site on a free loopback port: the server and the page's address.
fn serve_app(site: &Path) -> (Server, String) {
    start_printing(HOX, &["serve-app", "--site", site.to_str().unwrap(), "--web-port", "0", "--seconds", "3600"])
}

/// The pixels of the app's 3D view at 1280×720: right of the control panel, below the menu
/// bar, above the plots.
fn app_view(image: &Image) -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for y in image.height * 8 / 100..image.height * 58 / 100 {
        for x in image.width * 36 / 100..image.width * 97 / 100 {
            out.push(image.rgb[y * image.width + x]);
        }
    }
    out
}

fn errors(state: &serde_json::Value) -> Vec<String> {
    state["errors"].as_array().map(|e| e.iter().map(|e| e.to_string()).collect()).unwrap_or_default()
}

#[test]
#[ignore = "builds the site and needs headless Chromium; .ci/run runs it"]
fn the_app_runs_in_the_page_driven_by_its_link_and_its_keys_without_an_error() {
    have_browser();
    let site = site();
    let wasm = std::fs::metadata(site.join("hox_bg.wasm")).unwrap().len();
    let gz = std::fs::metadata(site.join("hox_bg.wasm.gz")).unwrap().len();
    println!("hox_bg.wasm: {:.1} MB, {:.1} MB gzipped", wasm as f64 / 1e6, gz as f64 / 1e6);
    assert!(wasm <= 20_000_000 && gz <= 6_000_000, "the page's module is too large: {wasm} B, {gz} B gzipped");
    let (_server, url) = serve_app(&site);
    let dir = scratch("page");

    // the P2 bending beam, playing: coloured, and moving between two pictures 4 s apart
    let (shots, state) =
        page_run(&format!("{url}?scene=bending&play"), &dir.join("bending.png"), 20.0, 2, 4.0, "", None);
    let s = &state["state"];
    assert!(errors(&state).is_empty(), "the page's console: {:?}", errors(&state));
    assert!(s["configurations"][0]["element"].as_str().is_some_and(|e| e.eq_ignore_ascii_case("p2")), "{s}");
    let frames = s["frames_stepped"].as_u64().unwrap_or(0);
    let (a, b) = (app_view(&shots[0]), app_view(&shots[1]));
    let (coloured, moved) = (coloured_fraction(&b), changed_fraction(&a, &b));
    println!(
        "bending: {frames} frames, {:.1} % of the view coloured, {:.2} % changed",
        100.0 * coloured,
        100.0 * moved
    );
    assert!(coloured > 0.03, "no coloured beam ({:.2} %): {}", 100.0 * coloured, dir.display());
    assert!(moved > 0.001 && frames > 30, "the beam does not move ({frames} frames): {}", dir.display());

    // ν from the link
    let (shots, state) =
        page_run(&format!("{url}?scene=bending&element=p2&nu=0.45"), &dir.join("nu.png"), 15.0, 1, 0.0, "", None);
    let s = &state["state"];
    assert!(errors(&state).is_empty(), "the page's console: {:?}", errors(&state));
    assert_eq!(s["configurations"][0]["poisson"].as_str(), Some("0.45"), "{s}");
    assert!(coloured_fraction(&app_view(&shots[0])) > 0.03, "ν 0.45: no coloured beam: {}", dir.display());

    // a lesson step, its question, and its answer after pressing A
    let (_, state) =
        page_run(&format!("{url}?lesson=locking&step=2"), &dir.join("lesson.png"), 25.0, 1, 5.0, "a", None);
    let lesson = &state["state"]["lesson"];
    assert!(errors(&state).is_empty(), "the page's console: {:?}", errors(&state));
    assert_eq!((lesson["name"].as_str(), lesson["step"].as_u64()), (Some("locking"), Some(2)), "{lesson}");
    let text = lesson["text"].as_str().unwrap_or_default();
    let question = lesson["question"].as_str().unwrap_or("?");
    assert!(lesson["revealed"].as_bool() == Some(true) && text.contains("**Answer:**"), "{lesson}");
    assert!(text.contains(question) && text.contains("- **A**"), "question and numbers: {text}");

    // a garbage link: a message naming what is wrong, the app on the rest of the link
    let (_, state) =
        page_run(&format!("{url}?nu=abc&bogus=1&element=q1"), &dir.join("garbage.png"), 15.0, 1, 0.0, "", None);
    let s = &state["state"];
    let message = s["message"].as_str().unwrap_or_default();
    assert!(message.contains("nu=abc") && message.contains("bogus"), "{s}");
    assert!(s["configurations"][0]["element"].as_str().is_some_and(|e| e.eq_ignore_ascii_case("q1")), "{s}");

    // meshes dropped onto the page (a browser's drop events, as a file manager sends them): a
    // broken one is a message naming it and the app plays on; a Gmsh beam opens
    let good = std::fs::read_to_string(root().join("assets/meshes/beam-tet4.msh")).unwrap();
    let eval = format!(
        "(async () => {{
            const drop = async (name, text) => {{
                const files = new DataTransfer();
                files.items.add(new File([text], name));
                const canvas = document.getElementById('hox');
                for (const type of ['dragenter', 'dragover', 'drop'])
                    canvas.dispatchEvent(new DragEvent(type, {{ dataTransfer: files, bubbles: true, cancelable: true }}));
                await new Promise(done => setTimeout(done, 5000));
                return JSON.parse(window.hox_state);
            }};
            const broken = await drop('broken.msh', {});
            const good = await drop('beam-tet4.msh', {});
            return JSON.stringify({{ broken, good }});
        }})()",
        serde_json::to_string("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnot a number\n").unwrap(),
        serde_json::to_string(&good).unwrap()
    );
    let (_, state) =
        page_run(&format!("{url}?scene=bending&play"), &dir.join("drop.png"), 15.0, 1, 0.0, "", Some(&eval));
    assert!(state.get("eval_error").is_none(), "{}", state["eval_error"]);
    assert!(errors(&state).is_empty(), "the page's console: {:?}", errors(&state));
    let dropped: serde_json::Value = serde_json::from_str(state["eval"].as_str().expect("the page's states")).unwrap();
    let (broken, good) = (&dropped["broken"], &dropped["good"]);
    let message = broken["message"].as_str().unwrap_or_default();
    assert!(message.contains("broken.msh") && message.contains("not opened"), "{broken}");
    assert_eq!(broken["scene"].as_str(), Some("bending"), "the scene kept: {broken}");
    assert!(broken["playing"] == true, "it plays on: {broken}");
    assert!(good["scene"].as_str().is_some_and(|s| s.contains("beam-tet4.msh")), "the dropped beam: {good}");
    assert!(errors(&state).is_empty(), "the page's console: {:?}", errors(&state));
}

/// The desktop's `hox lesson NAME --json`.
fn desktop_lesson(name: &str) -> serde_json::Value {
    let out = Command::new(HOX).args(["lesson", name, "--json"]).output().unwrap();
    assert!(out.status.success(), "hox lesson {name}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
#[ignore = "builds the site and needs headless Chromium; .ci/run runs it"]
fn every_lesson_s_answer_in_the_page_equals_the_desktop_s_to_its_shown_digits() {
    have_browser();
    let out = Command::new(HOX).args(["lessons", "--json"]).output().unwrap();
    let lessons: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<String> =
        lessons.as_array().unwrap().iter().map(|l| l["name"].as_str().unwrap().to_string()).collect();
    let site = site();
    let (_server, url) = serve_app(&site);
    let dir = scratch("lessons");
    // the app in the page plays every step of every lesson to its end, as a class would
    let eval = format!(
        "(async () => {{ const out = {{}}; for (const n of {}) {{ out[n] = JSON.parse(await window.hox.lesson_answers(n)); }} return JSON.stringify(out); }})()",
        serde_json::to_string(&names).unwrap()
    );
    let (_, state) = page_run(&url, &dir.join("lessons.png"), 15.0, 1, 0.0, "", Some(&eval));
    assert!(state.get("eval_error").is_none(), "{}", state["eval_error"]);
    let page: serde_json::Value = serde_json::from_str(state["eval"].as_str().expect("the page's answers")).unwrap();
    let (mut compared, mut pending) = (0, Vec::new());
    for name in &names {
        let desktop = desktop_lesson(name);
        let steps = desktop["steps"].as_array().unwrap();
        let shown = page[name].as_array().unwrap_or_else(|| panic!("{name}: no answers from the page: {page}"));
        assert_eq!(shown.len(), steps.len(), "{name}: steps");
        for (k, (step, texts)) in steps.iter().zip(shown).enumerate() {
            let (want, got) = (&step["texts"], texts);
            // a step measuring an error waits a minute at most for its reference from the
            // page's worker; one still computing is named, and fails the check below
            if got.as_array().is_some_and(|t| t.len() == 1 && t[0] == "reference still computing") {
                pending.push(format!("{name} step {}", k + 1));
                continue;
            }
            if step["measure"] == "ms-per-frame" {
                // the machine's time per frame, in the page and on the desktop: measured, not equal
                let all = got.as_array().unwrap();
                assert!(
                    all.iter().all(|t| t.as_str().is_some_and(|t| t.ends_with("ms per frame"))),
                    "{name} {k}: {got}"
                );
                continue;
            }
            assert_eq!(got, want, "{name} step {}: the page against hox lesson --json", k + 1);
            compared += 1;
        }
    }
    println!("{compared} lesson steps show the desktop's numbers in the page; reference still computing: {pending:?}");
    assert!(compared >= names.len(), "{compared} steps compared");
    assert!(pending.is_empty(), "steps whose reference the page computed for over a minute: {pending:?}");
}

/// Issue #59: docs/WEB.md's speed table (the page against the native binary, side by side) is
/// `scripts/web_speed.py`'s output; the committed table keeps the format a short run of it
/// writes on this site (every row, the beam coloured within its wait, the play rate read).
#[test]
#[ignore = "builds the site and needs headless Chromium; .ci/run runs it"]
fn the_page_speed_table_in_the_docs_has_the_format_its_command_writes() {
    have_browser();
    let site = site();
    let blocks = doc_blocks::blocks();
    let speed: Vec<_> = blocks.iter().filter(|(_, c, _)| c.contains("scripts/web_speed.py")).collect();
    assert!(!speed.is_empty(), "docs/WEB.md holds a table written by scripts/web_speed.py");
    for (file, command, body) in speed {
        let words = doc_blocks::quick(command);
        let out = Command::new("python3")
            .args(&words[1..])
            .args(["--rounds", "1", "--site", site.to_str().unwrap(), "--hox", HOX])
            .current_dir(root())
            .output()
            .unwrap();
        assert!(out.status.success(), "{command}: {}", String::from_utf8_lossy(&out.stderr));
        hox_tests::docs::assert_same_shape(file, command, body, &String::from_utf8_lossy(&out.stdout));
    }
}
