//! What the browser tests share (app/tests/web.rs, app/tests/page.rs): servers started in their
//! own process group, screenshots of a page by `scripts/browser_shot.py` (headless Chromium,
//! software WebGL) and what the tests read in them.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

pub const HOX: &str = env!("CARGO_BIN_EXE_hox");

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hox-web-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A server process (and its children: xvfb-run's display, the app) stopped when dropped.
pub struct Server(pub Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = Command::new("kill").arg("--").arg(format!("-{}", self.0.id())).status();
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `program args` in its own process group and returns it with the address it prints
/// first on stdout (the Rerun web viewer's, with its data stream's address in it).
pub fn start(program: &str, args: &[&str]) -> (Server, String) {
    let (server, url) = start_printing(program, args);
    assert!(url.contains("?url=rerun"), "no viewer address printed: {url:?}");
    (server, url)
}

/// Starts `program args` in its own process group and returns it with the loopback address it
/// prints first on stdout.
pub fn start_printing(program: &str, args: &[&str]) -> (Server, String) {
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
    assert!(url.starts_with("http://127.0.0.1:"), "no address printed: {line:?}");
    (server, url)
}

/// A screenshot of `url` after `wait` seconds, one page load.
pub fn shot(url: &str, out: &Path, wait: f64) -> Image {
    shots(url, out, wait, 1, 0.0).remove(0)
}

/// `count` screenshots of one page of `url` kept open: the first after `wait` seconds, the
/// others `every` seconds apart (`OUT-1.png`, `OUT-2.png`, … when several).
pub fn shots(url: &str, out: &Path, wait: f64, count: usize, every: f64) -> Vec<Image> {
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
pub fn changed_fraction(a: &[[u8; 3]], b: &[[u8; 3]]) -> f64 {
    let changed = a.iter().zip(b).filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 24)).count();
    changed as f64 / a.len() as f64
}

pub struct Image {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<[u8; 3]>,
}

impl Image {
    pub fn read(path: &Path) -> Image {
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
    pub fn view_3d(&self) -> Vec<[u8; 3]> {
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
pub fn field_coloured(p: [u8; 3]) -> bool {
    let max = p.iter().copied().max().unwrap() as f64;
    let min = p.iter().copied().min().unwrap() as f64;
    max > 40.0 && (max - min) / max > 0.45
}

pub fn coloured_fraction(pixels: &[[u8; 3]]) -> f64 {
    pixels.iter().filter(|p| field_coloured(**p)).count() as f64 / pixels.len() as f64
}

pub fn have_browser() {
    let found = ["chromium", "chromium-browser", "google-chrome"].iter().any(|b| {
        Command::new("sh").arg("-c").arg(format!("command -v {b}")).output().is_ok_and(|o| o.status.success())
    });
    assert!(found, "no Chromium: scripts/setup.sh installs Debian's package (root), or run without --ignored");
}

/// One page of `url` as `scripts/browser_shot.py` sees it: `count` screenshots (the first after
/// `wait` seconds, then `every` seconds apart; `press` typed first), and its `--state` file:
/// hox's page state, the page's errors, `eval`'s value.
pub fn page_run(
    url: &str,
    out: &Path,
    wait: f64,
    count: usize,
    every: f64,
    press: &str,
    eval: Option<&str>,
) -> (Vec<Image>, serde_json::Value) {
    let state = out.with_extension("json");
    let mut command = Command::new("python3");
    command
        .arg(root().join("scripts/browser_shot.py"))
        .arg(url)
        .arg(out)
        .args(["--size", "1280x720", "--wait", &wait.to_string()])
        .args(["--shots", &count.to_string(), "--every", &every.to_string()])
        .arg("--state")
        .arg(&state);
    if !press.is_empty() {
        command.args(["--press", press]);
    }
    if let Some(e) = eval {
        command.args(["--eval", e]);
    }
    let status = command.status().expect("python3");
    assert!(status.success(), "browser_shot failed for {url}");
    let images = if count == 1 {
        vec![Image::read(out)]
    } else {
        let stem = out.with_extension("");
        (1..=count).map(|k| Image::read(&PathBuf::from(format!("{}-{k}.png", stem.display())))).collect()
    };
    let text = std::fs::read_to_string(&state).unwrap_or_else(|e| panic!("{}: {e}", state.display()));
    (images, serde_json::from_str(&text).unwrap())
}
