//! A field's colour bar in a recording's legend column: the viridis bar as an image
//! (`legend/<field>/bar`) and its tick labels in the field's unit (`legend/<field>/ticks`).

use super::retire;
use hox_scenes::present::colour::ColourRange;
use rerun::RecordingStream;

/// Pixel size of a colour-bar image (its tick labels sit to its right, [`log_ticks`]).
const BAR_PX: [u32; 2] = [20, 200];

/// A vertical viridis bar, bottom to top, as an RGB image.
pub fn colour_bar_image() -> rerun::Image {
    let [w, h] = BAR_PX;
    let mut bytes = Vec::with_capacity((w * h * 3) as usize);
    for row in 0..h {
        let c = hox_scenes::present::colour::viridis(1.0 - (row as f64 + 0.5) / h as f64);
        for _ in 0..w {
            bytes.extend_from_slice(&c);
        }
    }
    rerun::Image::from_rgb24(bytes, BAR_PX)
}

/// The tick labels of `range` beside its colour bar: five, a quarter of the bar apart, centred
/// right of it (labels are drawn centred on their points, so a label never covers the bar or
/// its neighbour at the view sizes of the blueprint); a fixed range's end labels say how much of
/// the surface is saturated. An invisible corner point keeps the labels inside the view.
pub fn log_ticks(
    rec: &RecordingStream,
    logged: &mut retire::Logged,
    range: &ColourRange,
    values: &[f64],
) -> Result<(), rerun::RecordingStreamError> {
    let [w, h] = BAR_PX.map(|v| v as f32);
    let (over, under) = range.saturation(values);
    let ticks = range.ticks();
    let label_x = w + 48.0;
    let mut positions: Vec<[f32; 2]> =
        ticks.iter().enumerate().map(|(i, _)| [label_x, h * (1.0 - i as f32 / 4.0)]).collect();
    let mut labels: Vec<String> = ticks.iter().map(|&t| range.format(t)).collect();
    if over > 0.0 || !range.automatic {
        labels[4] = format!("{} ({:.0} % above)", labels[4], 100.0 * over);
    }
    if range.field.two_sided() && (under > 0.0 || !range.automatic) {
        labels[0] = format!("{} ({:.0} % below)", labels[0], 100.0 * under);
    }
    let mut colours = vec![rerun::Color::from_rgb(40, 40, 40); 5];
    positions.push([label_x + 70.0, -10.0]);
    labels.push(String::new());
    colours.push(rerun::Color::from_unmultiplied_rgba(0, 0, 0, 0));
    logged.at(
        rec,
        format!("legend/{}/ticks", range.field.name()),
        &rerun::Points2D::new(positions)
            .with_labels(labels)
            .with_colors(colours)
            .with_radii([rerun::Radius::new_ui_points(1.5)]),
    )
}
