//! Issue #38: what hox serves, seen in a real browser — headless Chromium (Debian's package,
//! installed by `scripts/setup.sh`) with software WebGL, driven by `scripts/browser_shot.py`.
//! Each test starts a server on the loopback address (any free ports), opens the printed address,
//! and reads the screenshots: the 3D view must show the body in the field's colours (not an
//! empty page or an error), and what changes on the server must reach the browser.
//!
//! Ignored in a plain `cargo test` (each takes 30–90 s and needs Chromium, the app test Xvfb);
//! `.ci/run` runs them where the browser is present: `cargo test -p hox --test web -- --ignored`.

mod doc_blocks;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

const HOX: &str = env!("CARGO_BIN_EXE_hox");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hox-web-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A server process (and its children: xvfb-run's display, the app) stopped when dropped.
struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = Command::new("kill").arg("--").arg(format!("-{}", self.0.id())).status();
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `program args` in its own process group and returns it with the address it prints
/// first on stdout.
fn start(program: &str, args: &[&str]) -> (Server, String) {
    use std::os::unix::process::CommandExt as _;
    let mut child = Command::new(program)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .process_group(0)
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {program}: {e}"));
    let stdout = child.stdout.take().unwrap();
    let server = Server(child);
    let mut line = String::new();
    BufReader::new(stdout).read_line(&mut line).unwrap();
    let url = line.trim().to_string();
    assert!(url.starts_with("http://127.0.0.1:") && url.contains("?url=rerun"), "no address printed: {line:?}");
    (server, url)
}

/// A screenshot of `url` after `wait` seconds, one page load.
fn shot(url: &str, out: &Path, wait: f64) -> Image {
    shots(url, out, wait, 1, 0.0).remove(0)
}

/// `count` screenshots of one page of `url` kept open: the first after `wait` seconds, the
/// others `every` seconds apart (`OUT-1.png`, `OUT-2.png`, … when several).
fn shots(url: &str, out: &Path, wait: f64, count: usize, every: f64) -> Vec<Image> {
    let status = Command::new("python3")
        .arg(root().join("scripts/browser_shot.py"))
        .arg(url)
        .arg(out)
        .args(["--size", "1280x720", "--wait", &wait.to_string()])
        .args(["--shots", &count.to_string(), "--every", &every.to_string()])
        .status()
        .expect("python3");
    assert!(status.success(), "browser_shot failed for {url}");
    if count == 1 {
        return vec![Image::read(out)];
    }
    let stem = out.with_extension("");
    (1..=count).map(|k| Image::read(&PathBuf::from(format!("{}-{k}.png", stem.display())))).collect()
}

/// The share of `a`'s pixels that differ from `b`'s by more than a rounding of the colours.
fn changed_fraction(a: &[[u8; 3]], b: &[[u8; 3]]) -> f64 {
    let changed = a.iter().zip(b).filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 24)).count();
    changed as f64 / a.len() as f64
}

struct Image {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

impl Image {
    fn read(path: &Path) -> Image {
        let decoder = png::Decoder::new(BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let channels = info.color_type.samples();
        let rgb = buf[..info.buffer_size()].chunks(channels).map(|p| [p[0], p[1], p[2]]).collect();
        Image { width: info.width as usize, height: info.height as usize, rgb }
    }

    /// The pixels of the 3D view: the left half, below the viewer's top bar and above its
    /// timeline (the recordings' blueprint gives it 54 % of the width).
    fn view_3d(&self) -> Vec<[u8; 3]> {
        let mut out = Vec::new();
        for y in self.height * 10 / 100..self.height * 90 / 100 {
            for x in 0..self.width / 2 {
                out.push(self.rgb[y * self.width + x]);
            }
        }
        out
    }
}

/// Whether a pixel is one of the field's colours (viridis: dark purple through blue and green
/// to yellow, all strongly saturated), not the view's pale background, a grey line or text.
fn field_coloured(p: [u8; 3]) -> bool {
    let max = p.iter().copied().max().unwrap() as f64;
    let min = p.iter().copied().min().unwrap() as f64;
    max > 40.0 && (max - min) / max > 0.45
}

fn coloured_fraction(pixels: &[[u8; 3]]) -> f64 {
    pixels.iter().filter(|p| field_coloured(**p)).count() as f64 / pixels.len() as f64
}

fn have_browser() {
    let found = ["chromium", "chromium-browser", "google-chrome"].iter().any(|b| {
        Command::new("sh").arg("-c").arg(format!("command -v {b}")).output().is_ok_and(|o| o.status.success())
    });
    assert!(found, "no Chromium: scripts/setup.sh installs Debian's package (root), or run without --ignored");
}

/// Issue #58: docs/WEB.md's figures are `scripts/web_figures.py`'s output; the committed table
/// keeps the format a short run of it writes (the page coloured within its wait, every row).
#[test]
#[ignore = "needs headless Chromium and Xvfb; .ci/run runs it"]
fn the_web_figures_table_in_the_docs_has_the_format_its_command_writes() {
    have_browser();
    let blocks = doc_blocks::blocks();
    let web: Vec<_> = blocks.iter().filter(|(_, c, _)| doc_blocks::needs_browser(c)).collect();
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
