//! Output files: checked before any work is done, so an unwritable path costs nothing and
//! nothing already written is lost. Shared by the command line and the app.

use anyhow::{Context, Result, bail};
use std::path::Path;

/// Fails unless `path` can be written, without truncating an existing file and without leaving
/// a new one behind.
pub fn check_writable(path: &Path) -> Result<()> {
    let existed = path.exists();
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// The SVG `svg` rasterised to PNG bytes at twice its own size (resvg, with the Ubuntu font
/// egui ships, so no system font is needed): `hox paper`'s figures and the app's export.
#[cfg(not(target_arch = "wasm32"))]
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
