//! The accuracy-versus-time chart of the study (`hox study`, docs/STUDY.md) for the scene on
//! screen, with the configuration(s) running now marked.
//!
//! Every configuration of the study is a point `(ms per frame, probe error)`: x is the median
//! time per frame on one thread at the paper's settings (50 substeps × 1 iteration, 60 fps), y the
//! largest probe-displacement difference against the committed fine-Q2 static reference
//! `max_p |u_p − u_p^ref|` (m). Filled dots are those settings; hollow dots are the same mesh run
//! with the substeps that bring the solver error under 1 % (drawn where that changed the
//! substeps). One colour per element type; lower left is better (fast and accurate). For the
//! bending scene the paper's Table 1 is shown as crosses (timed on the authors' machine).
//!
//! Both axes are logarithmic: the plot's coordinates are `log10(ms)` and `log10(m)`, with grid
//! lines at the decades (and at 2…9 × 10^k) and tick labels written as powers of ten.
//!
//! Data: `docs/study/study.csv`, embedded at build time and parsed once.

use eframe::egui;
use egui_plot::{GridInput, GridMark, HoverPosition, Legend, MarkerShape, Plot, PlotPoint, PlotPoints, Points, Text};
use hox_sim::element::ElementType;
use std::ops::RangeInclusive;
use std::sync::OnceLock;

/// A configuration measured live, to mark on the chart.
pub struct StudyPoint {
    pub label: String,
    pub ms_per_frame: f64,
    pub error_m: f64,
    /// ± metres (0 for a settled state), drawn as a vertical bar.
    pub uncertainty_m: f64,
}

/// The study's output, as committed.
const STUDY_CSV: &str = include_str!("../../../docs/study/study.csv");

/// One row of `study.csv` (the columns the chart uses).
#[derive(Clone, Debug, PartialEq)]
struct StudyRecord {
    scene: String,
    configuration: String,
    element: String,
    /// Median ms per frame at the paper's settings, one thread.
    ms_per_frame: f64,
    /// Probe error against the reference at those settings, m.
    error_m: f64,
    substeps_for_1pct: u32,
    /// Median ms per frame with the substeps for a solver error under 1 %.
    ms_per_frame_1pct: f64,
    /// Probe error against the reference with those substeps, m.
    error_1pct_m: f64,
}

/// Parses `study.csv` by its header's column names.
fn parse_study_csv(text: &str) -> Result<Vec<StudyRecord>, String> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().ok_or("study.csv is empty")?.split(',').map(str::trim).collect();
    let column =
        |name: &str| header.iter().position(|h| *h == name).ok_or_else(|| format!("study.csv has no column '{name}'"));
    let [scene, configuration, element, ms, error, substeps, ms_1pct, error_1pct] = [
        "scene",
        "configuration",
        "element",
        "ms_per_frame_1_thread",
        "error_m",
        "substeps_for_1pct",
        "ms_per_frame_1pct",
        "error_1pct_m",
    ]
    .map(column);
    let (scene, configuration, element, ms, error, substeps, ms_1pct, error_1pct) =
        (scene?, configuration?, element?, ms?, error?, substeps?, ms_1pct?, error_1pct?);
    lines
        .enumerate()
        .map(|(row, line)| {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            let field =
                |i: usize| fields.get(i).copied().ok_or_else(|| format!("study.csv row {}: too few columns", row + 1));
            let number = |i: usize| -> Result<f64, String> {
                let text = field(i)?;
                text.parse::<f64>()
                    .map_err(|_| format!("study.csv row {}, column '{}': '{text}' is not a number", row + 1, header[i]))
            };
            Ok(StudyRecord {
                scene: field(scene)?.to_string(),
                configuration: field(configuration)?.to_string(),
                element: field(element)?.to_string(),
                ms_per_frame: number(ms)?,
                error_m: number(error)?,
                substeps_for_1pct: field(substeps)?
                    .parse()
                    .map_err(|_| format!("study.csv row {}: bad substeps_for_1pct", row + 1))?,
                ms_per_frame_1pct: number(ms_1pct)?,
                error_1pct_m: number(error_1pct)?,
            })
        })
        .collect()
}

/// The study's rows, parsed once.
fn study_records() -> &'static Result<Vec<StudyRecord>, String> {
    static RECORDS: OnceLock<Result<Vec<StudyRecord>, String>> = OnceLock::new();
    RECORDS.get_or_init(|| parse_study_csv(STUDY_CSV))
}

/// The colour of `study.svg` for an element type ([`hox_scenes::study::element_colour`]).
fn element_colour(element: &str) -> egui::Color32 {
    let [r, g, b] = hox_scenes::study::element_colour(element);
    egui::Color32::from_rgb(r, g, b)
}

/// `10^exponent` written with superscript digits, e.g. `10⁻³`.
fn power_of_ten(exponent: i32) -> String {
    const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if exponent < 0 {
        s.push('⁻');
    }
    s.extend(
        exponent.unsigned_abs().to_string().chars().filter_map(|d| d.to_digit(10).map(|d| SUPERSCRIPTS[d as usize])),
    );
    s
}

/// The tick label of a grid mark at `log10(value)`: decades always, `k·10^d` marks only when
/// less than two decades are in view (else the axis would be crowded).
fn log_tick_label(mark: GridMark, range: &RangeInclusive<f64>) -> String {
    let decade = mark.value.round();
    if (mark.value - decade).abs() < 1e-9 {
        return power_of_ten(decade as i32);
    }
    if range.end() - range.start() < 2.0 {
        let floor = mark.value.floor();
        let mantissa = 10f64.powf(mark.value - floor).round();
        return format!("{mantissa}·{}", power_of_ten(floor as i32));
    }
    String::new()
}

/// Grid marks of a log10 axis: the decades (step 1) and `k·10^d`, k = 2…9 (step 0.1, so the
/// plot draws them thinner). Far zoomed out, only every n-th decade.
fn log_grid_marks(input: GridInput) -> Vec<GridMark> {
    let (lo, hi) = input.bounds;
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let decades = hi - lo;
    let every = (decades / 30.0).ceil().max(1.0);
    let mut marks = Vec::new();
    let mut d = (lo / every).floor() * every;
    while d <= hi {
        if d >= lo {
            marks.push(GridMark { value: d, step_size: every });
        }
        if every == 1.0 && decades < 12.0 {
            for k in 2..=9 {
                let v = d + (k as f64).log10();
                if v >= lo && v <= hi {
                    marks.push(GridMark { value: v, step_size: 0.1 });
                }
            }
        }
        d += every;
    }
    marks
}

/// A plotted point with what its hover label says.
struct Labelled {
    series: String,
    at: [f64; 2],
    text: String,
}

/// `[log10 x, log10 y]`, or `None` unless both are finite and positive.
fn log_point(x: f64, y: f64) -> Option<[f64; 2]> {
    (x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()).then(|| [x.log10(), y.log10()])
}

/// The chart of the study's rows for `scene`, with the `current` configurations marked.
pub fn study_chart_ui(ui: &mut egui::Ui, scene: &str, current: &[StudyPoint]) {
    let records = match study_records() {
        Ok(r) => r,
        Err(e) => {
            ui.colored_label(ui.visuals().error_fg_color, format!("the study could not be read: {e}"));
            return;
        }
    };
    let rows: Vec<&StudyRecord> = records.iter().filter(|r| r.scene == scene).collect();
    if rows.is_empty() {
        let mut scenes: Vec<&str> = records.iter().map(|r| r.scene.as_str()).collect();
        scenes.dedup();
        ui.label(format!("The accuracy study covers the {} scenes; '{scene}' is not one of them.", scenes.join(", ")));
        return;
    }
    ui.label(format!(
        "{scene}: probe error against the fine-Q2 reference vs time per frame (one thread, log–log). \
         Filled: 50 substeps; hollow: substeps for a solver error < 1 %. Lower left is better."
    ));

    let mut labelled: Vec<Labelled> = Vec::new();
    let mut series: Vec<Points<'static>> = Vec::new();
    for element in ElementType::all().map(|e| e.name()) {
        let of_element: Vec<&&StudyRecord> = rows.iter().filter(|r| r.element.eq_ignore_ascii_case(element)).collect();
        if of_element.is_empty() {
            continue;
        }
        let name = element.to_uppercase();
        let colour = element_colour(element);
        let mut filled = Vec::new();
        let mut hollow = Vec::new();
        for r in of_element {
            if let Some(p) = log_point(r.ms_per_frame, r.error_m) {
                filled.push(p);
                labelled.push(Labelled {
                    series: name.clone(),
                    at: p,
                    text: format!(
                        "{}, 50 substeps\n{:.2} ms per frame, error {:.2e} m",
                        r.configuration, r.ms_per_frame, r.error_m
                    ),
                });
            }
            if r.substeps_for_1pct != 50
                && let Some(p) = log_point(r.ms_per_frame_1pct, r.error_1pct_m)
            {
                hollow.push(p);
                labelled.push(Labelled {
                    series: name.clone(),
                    at: p,
                    text: format!(
                        "{}, {} substeps (solver error < 1 %)\n{:.2} ms per frame, error {:.2e} m",
                        r.configuration, r.substeps_for_1pct, r.ms_per_frame_1pct, r.error_1pct_m
                    ),
                });
            }
        }
        // same name: one legend entry for both
        series.push(
            Points::new(name.clone(), PlotPoints::from(filled))
                .id(format!("{element} 50"))
                .color(colour)
                .radius(4.5)
                .shape(MarkerShape::Circle),
        );
        if !hollow.is_empty() {
            series.push(
                Points::new(name, PlotPoints::from(hollow))
                    .id(format!("{element} 1pct"))
                    .color(colour)
                    .radius(4.5)
                    .filled(false)
                    .shape(MarkerShape::Circle),
            );
        }
    }
    if scene == "bending" {
        let paper_name = "paper, Table 1";
        let mut crosses = Vec::new();
        for (label, elements, ms, error_m) in hox_scenes::study::PAPER_TABLE_1 {
            if let Some(p) = log_point(ms, error_m) {
                crosses.push(p);
                labelled.push(Labelled {
                    series: paper_name.into(),
                    at: p,
                    text: format!("paper's Table 1: {label}, {elements} elements\n{ms} ms per frame (their machine), error {error_m:.1e} m"),
                });
            }
        }
        series.push(
            Points::new(paper_name, PlotPoints::from(crosses))
                .color(egui::Color32::GRAY)
                .radius(5.0)
                .shape(MarkerShape::Cross),
        );
    }
    let highlight = ui.visuals().strong_text_color();
    let now: Vec<(&StudyPoint, [f64; 2])> =
        current.iter().filter_map(|c| log_point(c.ms_per_frame, c.error_m).map(|p| (c, p))).collect();
    for (c, p) in &now {
        labelled.push(Labelled {
            series: "now".into(),
            at: *p,
            text: if c.uncertainty_m > 0.0 {
                format!(
                    "{}\n{:.2} ms per frame, error {:.2e} ± {:.1e} m",
                    c.label, c.ms_per_frame, c.error_m, c.uncertainty_m
                )
            } else {
                format!("{}\n{:.2} ms per frame, error {:.2e} m", c.label, c.ms_per_frame, c.error_m)
            },
        });
    }

    let label_formatter = move |position: &HoverPosition<'_>| -> Option<String> {
        let HoverPosition::NearDataPoint { plot_name, position, .. } = position else { return None };
        labelled
            .iter()
            .filter(|l| l.series == *plot_name)
            .min_by(|a, b| {
                let d = |l: &Labelled| (l.at[0] - position.x).powi(2) + (l.at[1] - position.y).powi(2);
                d(a).total_cmp(&d(b))
            })
            .map(|l| l.text.clone())
    };
    let height = ui.available_height().clamp(200.0, 600.0);
    Plot::new("hox-study-chart")
        .show_background(false)
        .height(height)
        .legend(Legend::default())
        .x_axis_label("ms per frame (one thread)")
        .y_axis_label("probe error vs reference (m)")
        .x_grid_spacer(log_grid_marks)
        .y_grid_spacer(log_grid_marks)
        .x_axis_formatter(log_tick_label)
        .y_axis_formatter(log_tick_label)
        .label_formatter(label_formatter)
        .show(ui, |plot| {
            for s in series {
                plot.points(s);
            }
            if !now.is_empty() {
                let at: Vec<[f64; 2]> = now.iter().map(|(_, p)| *p).collect();
                plot.points(
                    Points::new("now", PlotPoints::from(at.clone()))
                        .id("now ring")
                        .color(highlight)
                        .radius(11.0)
                        .filled(false)
                        .shape(MarkerShape::Diamond),
                );
                plot.points(
                    Points::new("now", PlotPoints::from(at))
                        .id("now fill")
                        .color(egui::Color32::GOLD)
                        .radius(7.0)
                        .shape(MarkerShape::Diamond),
                );
                for (i, (c, p)) in now.iter().enumerate() {
                    // the uncertainty of a time average, as a vertical bar (log axes: clipped
                    // at a decade below the value)
                    if c.uncertainty_m > 0.0 {
                        let lo = (c.error_m - c.uncertainty_m).max(0.1 * c.error_m).log10();
                        let hi = (c.error_m + c.uncertainty_m).log10();
                        plot.line(
                            egui_plot::Line::new("now", PlotPoints::from(vec![[p[0], lo], [p[0], hi]]))
                                .id(("now bar", i))
                                .color(highlight)
                                .width(2.0),
                        );
                    }
                    // a little right of the marker: 0.04 decades
                    let text = egui::RichText::new(&c.label).color(highlight).strong();
                    plot.text(
                        Text::new("", PlotPoint::new(p[0] + 0.04, p[1]), text)
                            .id(("now label", i))
                            .anchor(egui::Align2::LEFT_BOTTOM)
                            .allow_hover(false),
                    );
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_study_has_finite_positive_rows_for_every_paper_scene() {
        let records = study_records().as_ref().expect("study.csv parses");
        for scene in hox_scenes::PAPER_SCENES {
            let rows: Vec<&StudyRecord> = records.iter().filter(|r| r.scene == scene).collect();
            assert!(!rows.is_empty(), "no rows for {scene}");
            for r in rows {
                for v in [r.ms_per_frame, r.error_m, r.ms_per_frame_1pct, r.error_1pct_m] {
                    assert!(v.is_finite() && v > 0.0, "{scene} {}: {v}", r.configuration);
                }
                assert!(r.substeps_for_1pct > 0, "{scene} {}", r.configuration);
                assert!(ElementType::from_name(&r.element).is_some(), "unknown element {}", r.element);
            }
        }
    }

    #[test]
    fn parsing_goes_by_the_header_and_reports_bad_rows() {
        let text = "error_m,scene,configuration,element,ms_per_frame_1_thread,substeps_for_1pct,ms_per_frame_1pct,error_1pct_m\n\
                    0.5,bending,P2 8x2x2 five,p2,2.5,70,3.25,0.25\n";
        let rows = parse_study_csv(text).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!((rows[0].error_m, rows[0].ms_per_frame, rows[0].substeps_for_1pct), (0.5, 2.5, 70));
        assert_eq!(rows[0].configuration, "P2 8x2x2 five");
        let bad = text.replace("2.5,70", "fast,70");
        assert!(parse_study_csv(&bad).unwrap_err().contains("'fast' is not a number"));
        assert!(parse_study_csv("scene,element\nbending,p1\n").unwrap_err().contains("no column"));
        assert!(parse_study_csv("").is_err());
    }

    #[test]
    fn log_axes_are_labelled_in_powers_of_ten() {
        assert_eq!(power_of_ten(-3), "10⁻³");
        assert_eq!(power_of_ten(0), "10⁰");
        assert_eq!(power_of_ten(12), "10¹²");
        let wide = -4.0..=3.0;
        assert_eq!(log_tick_label(GridMark { value: -2.0, step_size: 1.0 }, &wide), "10⁻²");
        assert_eq!(log_tick_label(GridMark { value: 2f64.log10() - 2.0, step_size: 0.1 }, &wide), "");
        assert_eq!(log_tick_label(GridMark { value: 2f64.log10() - 2.0, step_size: 0.1 }, &(-2.5..=-1.0)), "2·10⁻²");
        let marks = log_grid_marks(GridInput { bounds: (-2.5, 1.2), base_step_size: 0.01 });
        let decades: Vec<f64> = marks.iter().filter(|m| m.step_size == 1.0).map(|m| m.value).collect();
        assert_eq!(decades, vec![-2.0, -1.0, 0.0, 1.0]);
        assert!(marks.iter().all(|m| (-2.5..=1.2).contains(&m.value)));
        assert!(log_grid_marks(GridInput { bounds: (-400.0, 400.0), base_step_size: 1.0 }).len() <= 62);
    }
}
