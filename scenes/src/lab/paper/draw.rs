//! The figures of `hox paper` as SVG: deformed sample grids on one colour scale with the
//! reference's outline (Figs. 1 and 2), undeformed strips with the crossings of the vertical
//! displacement's levels (Fig. 3), and their colour bar.

use super::{Panel, ring};
use crate::present::colour::viridis;
use crate::present::svg::{colour_bar, hex};
use hox_sim::Vec3;
use std::fmt::Write;

/// The largest of 1, 2, 5, 10, 20, 50, … not above `x` (at least 1).
fn nice_factor(x: f64) -> f64 {
    let mut best = 1.0;
    for decade in [1.0, 10.0, 100.0, 1000.0] {
        for m in [1.0, 2.0, 5.0] {
            if m * decade <= x {
                best = m * decade;
            }
        }
    }
    best
}

/// Deformed sample grids drawn as filled cells coloured by `|u|`, each panel in its own box on
/// one scale, the reference's outline in red over every case.
#[allow(clippy::too_many_arguments)]
pub(super) fn draw_deformed(
    title: &str,
    panels: &[Panel],
    rest: &[Vec3],
    nu: usize,
    nv: usize,
    project: fn(&Vec3) -> [f64; 2],
    ref_outline: &[[f64; 2]],
    columns: usize,
) -> String {
    let magnitude = |p: &Panel| p.deformed.iter().zip(rest).map(|(x, r)| (x - r).norm()).collect::<Vec<_>>();
    let u_max = panels.iter().flat_map(magnitude).fold(0.0f64, f64::max).max(f64::MIN_POSITIVE);
    // the view box of every panel: the union of all deformed samples
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in panels {
        for x in &p.deformed {
            let q = project(x);
            for a in 0..2 {
                lo[a] = lo[a].min(q[a]);
                hi[a] = hi[a].max(q[a]);
            }
        }
    }
    let (box_w, box_h) = (300.0, 300.0 * ((hi[1] - lo[1]) / (hi[0] - lo[0])).clamp(0.3, 1.5));
    let scale = 0.9 * (box_w / (hi[0] - lo[0])).min(box_h / (hi[1] - lo[1]));
    let rows = panels.len().div_ceil(columns);
    let boundary = ring(nu, nv);
    let largest_gap = panels
        .iter()
        .filter(|p| p.measure.is_some())
        .flat_map(|p| {
            boundary.iter().zip(ref_outline).map(|(&k, r)| {
                let q = project(&p.deformed[k]);
                ((q[0] - r[0]).powi(2) + (q[1] - r[1]).powi(2)).sqrt()
            })
        })
        .fold(0.0f64, f64::max);
    let exaggeration = nice_factor(0.06 * (hi[0] - lo[0]).max(hi[1] - lo[1]) / largest_gap.max(f64::MIN_POSITIVE));
    let (width, height) = (columns as f64 * (box_w + 20.0) + 20.0, 60.0 + rows as f64 * (box_h + 50.0) + 60.0);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="Ubuntu, Liberation Sans, sans-serif"><rect width="100%" height="100%" fill="white"/><text x="20" y="28" font-size="15">{title}</text>"#
    );
    for (k, p) in panels.iter().enumerate() {
        let (ox, oy) = (20.0 + (k % columns) as f64 * (box_w + 20.0), 50.0 + (k / columns) as f64 * (box_h + 50.0));
        let at = |q: [f64; 2]| {
            let cx = ox + box_w / 2.0 + scale * (q[0] - (lo[0] + hi[0]) / 2.0);
            let cy = oy + box_h / 2.0 - scale * (q[1] - (lo[1] + hi[1]) / 2.0);
            (cx, cy)
        };
        let _ = write!(
            s,
            r##"<g><rect x="{ox:.1}" y="{oy:.1}" width="{box_w:.1}" height="{box_h:.1}" fill="none" stroke="#ccc"/>"##
        );
        let m = magnitude(p);
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                let ids = [j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i];
                let value = ids.iter().map(|&k| m[k]).sum::<f64>() / 4.0;
                let points: Vec<String> = ids
                    .iter()
                    .map(|&k| {
                        let (x, y) = at(project(&p.deformed[k]));
                        format!("{x:.2},{y:.2}")
                    })
                    .collect();
                let colour = hex(viridis(value / u_max));
                let _ = write!(
                    s,
                    r#"<polygon points="{}" fill="{colour}" stroke="{colour}" stroke-width="0.6"/>"#,
                    points.join(" ")
                );
            }
        }
        let outline: Vec<String> = ref_outline
            .iter()
            .map(|&q| {
                let (x, y) = at(q);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let _ =
            write!(s, r##"<polygon points="{}" fill="none" stroke="#e00000" stroke-width="2"/>"##, outline.join(" "));
        if p.measure.is_some() {
            // the beam's own outline, its deviation from the reference's (same material points)
            // exaggerated so that millimetres show
            let own: Vec<String> = boundary
                .iter()
                .zip(ref_outline)
                .map(|(&k, r)| {
                    let q = project(&p.deformed[k]);
                    let (x, y) = at([r[0] + exaggeration * (q[0] - r[0]), r[1] + exaggeration * (q[1] - r[1])]);
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = write!(s, r#"<polygon points="{}" fill="none" stroke="black" stroke-width="1.2"/>"#, own.join(" "));
        }
        let (first, second) = match (p.measure, p.ms_per_frame) {
            (Some(d), Some(ms)) => (
                p.label.clone(),
                format!(
                    "{:.2} mm from the reference · {ms:.1} ms/frame{}",
                    1e3 * d,
                    if p.settled { "" } else { " · moving" }
                ),
            ),
            _ => (p.label.clone(), if p.nodes > 0 { format!("{} nodes", p.nodes) } else { String::new() }),
        };
        let _ = write!(
            s,
            r#"<text x="{ox:.1}" y="{:.1}" font-size="13">{first}</text><text x="{ox:.1}" y="{:.1}" font-size="11">{second}</text></g>"#,
            oy + box_h + 17.0,
            oy + box_h + 32.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="360" y="{:.1}" font-size="12">red: the reference's outline; black: each beam's, its distance from the red drawn ×{exaggeration}</text>"#,
        height - 33.0
    );
    colour_bar(&mut s, 20.0, height - 45.0, 300.0, 0.0, u_max, "|u|, m");
    s.push_str("</svg>\n");
    s
}

/// Undeformed top faces drawn as strips coloured by `u_z` on one scale, one per row, the
/// reference's last.
pub(super) fn draw_strips(title: &str, panels: &[Panel], rest: &[Vec3], nu: usize, nv: usize) -> String {
    let uz = |p: &Panel| p.deformed.iter().zip(rest).map(|(x, r)| x.z - r.z).collect::<Vec<_>>();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in panels {
        for v in uz(p) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    let (strip_w, strip_h) = (640.0, 160.0);
    let width = strip_w + 380.0;
    let height = 60.0 + panels.len() as f64 * (strip_h + 30.0) + 50.0;
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="Ubuntu, Liberation Sans, sans-serif"><rect width="100%" height="100%" fill="white"/><text x="20" y="28" font-size="15">{title}</text>"#
    );
    let (dx, dy) = (strip_w / (nu - 1) as f64, strip_h / (nv - 1) as f64);
    let ref_values = uz(panels.last().expect("the reference"));
    let levels: Vec<f64> = (1..8).map(|k| lo + (hi - lo) * k as f64 / 8.0).collect();
    for (k, p) in panels.iter().enumerate() {
        let oy = 50.0 + k as f64 * (strip_h + 30.0);
        let values = uz(p);
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                let ids = [j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i];
                let value = ids.iter().map(|&k| values[k]).sum::<f64>() / 4.0;
                let colour = hex(viridis((value - lo) / (hi - lo).max(f64::MIN_POSITIVE)));
                let _ = write!(
                    s,
                    r#"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="{colour}" stroke="{colour}" stroke-width="0.4"/>"#,
                    20.0 + i as f64 * dx,
                    oy + (nv - 2 - j) as f64 * dy,
                    dx,
                    dy
                );
            }
        }
        if p.measure.is_none() {
            let _ = write!(
                s,
                r##"<rect x="20" y="{oy:.1}" width="{strip_w:.1}" height="{strip_h:.1}" fill="none" stroke="#e00000" stroke-width="2"/>"##
            );
        }
        // where the displacement along the middle row crosses each level: black for the beam,
        // red for the reference (the colours' alignment, drawn)
        for (values, colour, from, to) in [(&values, "black", 0.0, 0.5), (&ref_values, "#e00000", 0.5, 1.0)] {
            for x in crossings(&values[(nv / 2) * nu..(nv / 2 + 1) * nu], &levels) {
                let px = 20.0 + x * dx;
                let _ = write!(
                    s,
                    r#"<line x1="{px:.2}" y1="{:.2}" x2="{px:.2}" y2="{:.2}" stroke="{colour}" stroke-width="1.5"/>"#,
                    oy + from * strip_h,
                    oy + to * strip_h
                );
            }
        }
        let (first, second) = match (p.measure, p.ms_per_frame) {
            (Some(offset), Some(ms)) => (
                p.label.clone(),
                format!("offset {offset:.2} % · {ms:.1} ms/frame{}", if p.settled { "" } else { " · moving" }),
            ),
            _ => (p.label.clone(), if p.nodes > 0 { format!("{} nodes", p.nodes) } else { String::new() }),
        };
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="14">{first}</text><text x="{:.1}" y="{:.1}" font-size="12">{second}</text>"#,
            strip_w + 35.0,
            oy + strip_h / 2.0 - 4.0,
            strip_w + 35.0,
            oy + strip_h / 2.0 + 14.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="360" y="{:.1}" font-size="12">ticks along the middle: where u_z crosses each eighth of its range; black the beam's, red the reference's</text>"#,
        height - 33.0
    );
    colour_bar(&mut s, 20.0, height - 45.0, 300.0, lo, hi, "u_z, m");
    s.push_str("</svg>\n");
    s
}

/// Where the samples `values` (at unit spacing) cross each of `levels`, by linear interpolation.
fn crossings(values: &[f64], levels: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for &level in levels {
        for (i, w) in values.windows(2).enumerate() {
            if (w[0] - level) * (w[1] - level) <= 0.0 && w[0] != w[1] {
                out.push(i as f64 + (level - w[0]) / (w[1] - w[0]));
                break;
            }
        }
    }
    out
}
