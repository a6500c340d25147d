//! `hox paper`: the paper's experiments, Table 1 and Figs. 1–3 written to a folder
//! (`hox_scenes::paper`), each figure as SVG and as PNG (rasterised here by resvg, with the
//! Ubuntu font egui ships, so no system font is needed).

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

/// The CPU's name, the machine's logical cores, for every figure's caption.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("\"{cpu}\", {cores} logical cores")
}

/// The SVG `svg` rasterised to PNG bytes at its own size (twice over for sharpness).
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>> {
    let mut options = resvg::usvg::Options::default();
    options.fontdb_mut().load_font_data(epaint_default_fonts::UBUNTU_LIGHT.to_vec());
    options.fontdb_mut().set_sans_serif_family("Ubuntu");
    let tree = resvg::usvg::Tree::from_str(svg, &options).context("the figure's SVG does not parse")?;
    let scale = 2.0;
    let size = tree.size();
    let (w, h) = ((size.width() * scale).ceil() as u32, (size.height() * scale).ceil() as u32);
    let mut pixmap = resvg::tiny_skia::Pixmap::new(w, h).context("the figure is too large to rasterise")?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(&tree, resvg::tiny_skia::Transform::from_scale(scale, scale), &mut pixmap.as_mut());
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, w, h);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().context("PNG header")?;
        // opaque white background: premultiplied RGBA is plain RGBA
        writer.write_image_data(pixmap.data()).context("PNG data")?;
    }
    Ok(bytes)
}

pub fn paper(quick: bool, out: &std::path::Path) -> Result<()> {
    // refuse an unwritable folder before spending minutes
    std::fs::create_dir_all(out).with_context(|| format!("cannot create the output folder {}", out.display()))?;
    let probe = out.join(".hox-write-test");
    std::fs::write(&probe, b"").with_context(|| format!("cannot write to the output folder {}", out.display()))?;
    let _ = std::fs::remove_file(&probe);
    let bar = ProgressBar::new_spinner();
    bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed}] {msg}").expect("valid template"));
    bar.enable_steady_tick(Duration::from_millis(200));
    let started = Instant::now();
    let mut report = |message: &str| {
        if bar.is_hidden() {
            eprintln!("[{:>6.1} s] {message}", started.elapsed().as_secs_f64());
        }
        bar.set_message(message.to_string());
    };
    let result = hox_scenes::paper::run_paper(quick, &mut report)?;
    bar.finish_and_clear();
    let machine = machine();
    let secs = started.elapsed().as_secs_f64();
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    for figure in &result.figures {
        files.push((format!("{}.svg", figure.name), figure.svg.clone().into_bytes()));
        files.push((format!("{}.png", figure.name), svg_to_png(&figure.svg)?));
    }
    files.push(("table1.md".into(), hox_scenes::paper::table_markdown(&result.table, &machine, quick).into_bytes()));
    files.push(("PAPER.md".into(), hox_scenes::paper::paper_markdown(&result, &machine, secs).into_bytes()));
    for (name, bytes) in files {
        let path = out.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    eprintln!("hox paper{} took {secs:.0} s", if quick { " --quick" } else { "" });
    Ok(())
}
