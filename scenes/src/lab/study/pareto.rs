//! The study's accuracy-versus-time chart of the solver axis (`pareto-SCENE.svg`): every row's
//! time per frame against its error, one colour per element type and one marker per solver of
//! the registry, with the Pareto frontier drawn through the rows no other beats on both.

use super::solver_axis::{REAL_TIME_MS, SolverRow, TARGET_ERROR_PCT, pareto_frontier};
use crate::present::svg::{decades, element_hex, element_legend, plot_frame};
use hox_sim::solver::Method;

/// The marker of a solver in the chart, by its place in the registry ([`Method::ALL`]): XPBD
/// circles, VBD squares, Newton triangles, Newton-CG diamonds, then inverted triangles.
fn marker(r: &SolverRow, x: f64, y: f64, fill: &str, title: &str) -> String {
    let name = r.solver.split(' ').next().unwrap_or("");
    let place = Method::ALL.iter().position(|m| m.name() == name).unwrap_or(0);
    if place == 1 {
        format!(
            r#"<rect x="{}" y="{}" width="10" height="10" fill="{fill}"><title>{title}</title></rect>"#,
            x - 5.0,
            y - 5.0
        )
    } else if place == 2 {
        format!(
            r#"<path d="M{x} {} L{} {} L{} {} Z" fill="{fill}"><title>{title}</title></path>"#,
            y - 6.0,
            x + 6.0,
            y + 5.0,
            x - 6.0,
            y + 5.0
        )
    } else if place == 3 {
        format!(
            r#"<path d="M{x} {} L{} {y} L{x} {} L{} {y} Z" fill="{fill}"><title>{title}</title></path>"#,
            y - 6.0,
            x + 6.0,
            y + 6.0,
            x - 6.0
        )
    } else if place > 3 {
        format!(
            r#"<path d="M{x} {} L{} {} L{} {} Z" fill="{fill}"><title>{title}</title></path>"#,
            y + 6.0,
            x + 6.0,
            y - 5.0,
            x - 6.0,
            y - 5.0
        )
    } else {
        format!(r#"<circle cx="{x}" cy="{y}" r="4.5" fill="{fill}"><title>{title}</title></circle>"#)
    }
}

/// `pareto-{scene}.svg`: total error (% of the reference) against ms per frame on one thread,
/// log–log, every element type (colour) and solver (marker), the Pareto frontier drawn, the
/// 1 % target and the 16.7 ms frame budget as dashed lines.
pub fn pareto_svg(rows: &[SolverRow], scene: &str) -> String {
    let colour = element_hex;
    let points: Vec<&SolverRow> = rows
        .iter()
        .filter(|r| r.scene == scene && r.failure.is_none() && r.ms_per_frame > 0.0 && r.error_pct > 0.0)
        .filter(|r| r.ms_per_frame.is_finite() && r.error_pct.is_finite())
        .collect();
    let xs: Vec<f64> = points.iter().map(|r| r.ms_per_frame).chain([REAL_TIME_MS]).collect();
    let ys: Vec<f64> = points.iter().map(|r| r.error_pct).chain([TARGET_ERROR_PCT]).collect();
    let (x0, x1) = decades(xs.iter());
    let (y0, y1) = decades(ys.iter());
    let (w, h, left, right, top, bottom) = (820.0, 540.0, 80.0, 190.0, 40.0, 60.0);
    let px = |x: f64| left + (x.log10() - x0) / (x1 - x0) * (w - left - right);
    let py = |y: f64| top + (y1 - y.log10()) / (y1 - y0) * (h - top - bottom);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<rect width="{w}" height="{h}" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">{scene}: total error vs time per frame, one thread (log–log)</text>
"#,
        w / 2.0
    );
    for d in (x0 as i32)..=(x1 as i32) {
        let x = px(10f64.powi(d));
        s.push_str(&format!(
            "<line x1=\"{x}\" y1=\"{top}\" x2=\"{x}\" y2=\"{}\" stroke=\"#ddd\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{d}</text>\n",
            h - bottom,
            h - bottom + 16.0
        ));
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = py(10f64.powi(d));
        s.push_str(&format!(
            "<line x1=\"{left}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{d}</text>\n",
            w - right,
            left - 6.0,
            y + 4.0
        ));
    }
    s.push_str(&plot_frame(
        [left, top, right, bottom],
        [w, h],
        "ms per frame, one thread",
        "total error vs reference (%)",
    ));
    // the 1 % target and the 60 fps budget
    let (ty, tx) = (py(TARGET_ERROR_PCT), px(REAL_TIME_MS));
    s.push_str(&format!(
        "<line x1=\"{left}\" y1=\"{ty}\" x2=\"{}\" y2=\"{ty}\" stroke=\"#888\" stroke-dasharray=\"6,4\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\" fill=\"#666\">1 % of the reference</text>\n<line x1=\"{tx}\" y1=\"{top}\" x2=\"{tx}\" y2=\"{}\" stroke=\"#888\" stroke-dasharray=\"6,4\"/><text x=\"{}\" y=\"{}\" fill=\"#666\">16.7 ms (60 fps)</text>\n",
        w - right,
        w - right - 4.0,
        ty - 4.0,
        h - bottom,
        tx + 4.0,
        top + 14.0
    ));
    // the Pareto frontier: a staircase through the non-dominated rows
    let frontier = pareto_frontier(rows, scene);
    if !frontier.is_empty() {
        let mut d = String::new();
        for (k, r) in frontier.iter().enumerate() {
            let (x, y) = (px(r.ms_per_frame), py(r.error_pct));
            if k == 0 {
                d.push_str(&format!("M{x} {y}"));
            } else {
                d.push_str(&format!(" H{x} V{y}"));
            }
        }
        s.push_str(&format!(
            "<path class=\"pareto\" d=\"{d}\" fill=\"none\" stroke=\"black\" stroke-width=\"1.5\"><title>Pareto frontier</title></path>\n"
        ));
    }
    for r in &points {
        let title = format!(
            "{} {}: {:.2} ms, {:.3} % ({:.2} % the mesh's)",
            r.config, r.solver, r.ms_per_frame, r.error_pct, r.discretisation_pct
        );
        s.push_str(&marker(r, px(r.ms_per_frame), py(r.error_pct), &colour(&r.element), &title));
        s.push('\n');
    }
    // legend: element colours, then solver markers
    let lx = w - right + 15.0;
    let mut seen: Vec<&str> = Vec::new();
    for r in &points {
        if !seen.contains(&r.element.as_str()) {
            seen.push(&r.element);
        }
    }
    let mut ly = element_legend(&mut s, seen, lx, top + 10.0) + 8.0;
    for method in Method::ALL {
        let name = if method.is_implicit() { method.name() } else { "xpbd (substeps × iterations)" };
        let fake = SolverRow { solver: method.name().into(), ..dummy_row() };
        s.push_str(&marker(&fake, lx, ly, "#555", name));
        s.push_str(&format!("<text x=\"{}\" y=\"{}\">{name}</text>\n", lx + 10.0, ly + 4.0));
        ly += 18.0;
    }
    s.push_str(&format!(
        "<line x1=\"{}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"black\" stroke-width=\"1.5\"/><text x=\"{}\" y=\"{}\">Pareto frontier</text>\n",
        lx - 6.0,
        lx + 6.0,
        lx + 10.0,
        ly + 4.0
    ));
    s.push_str("</svg>\n");
    s
}

pub(crate) fn dummy_row() -> SolverRow {
    SolverRow {
        scene: String::new(),
        config: String::new(),
        element: String::new(),
        elements: 0,
        nodes: 0,
        solver: String::new(),
        sweeps_per_frame: 0.0,
        ms_per_frame: 0.0,
        solver_error_pct: 0.0,
        error_m: 0.0,
        error_pct: 0.0,
        discretisation_pct: 0.0,
        settled: false,
        at_rest: false,
        residual_rel: 0.0,
        secs_to_1pct: None,
        sim_secs: 0.0,
        period_error_pct: None,
        amplitude_error_pct: None,
        failure: None,
    }
}
