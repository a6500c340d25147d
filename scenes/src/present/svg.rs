//! SVG drawing shared by the lab's figures and charts (`hox paper`'s Figs. 1–3, `study.svg`,
//! `pareto-SCENE.svg`): colours as `#rrggbb`, the viridis colour bar, a chart's plot frame, its
//! decades and its element-type legend.

use super::colour::{element_colour, viridis};
use std::fmt::Write;

/// A colour as `#rrggbb`.
pub fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// An element type's chart colour ([`element_colour`]) as `#rrggbb`.
pub fn element_hex(element: &str) -> String {
    hex(element_colour(element))
}

/// The viridis colour bar: `label` from `lo` to `hi` at `(x, y)`, `w` wide, appended to `s`.
pub fn colour_bar(s: &mut String, x: f64, y: f64, w: f64, lo: f64, hi: f64, label: &str) {
    let steps = 40;
    for k in 0..steps {
        let t = k as f64 / (steps - 1) as f64;
        let _ = write!(
            s,
            r#"<rect x="{:.1}" y="{y:.1}" width="{:.2}" height="12" fill="{}"/>"#,
            x + w * k as f64 / steps as f64,
            w / steps as f64 + 0.5,
            hex(viridis(t))
        );
    }
    let _ = write!(
        s,
        r#"<text x="{x:.1}" y="{:.1}" font-size="12">{lo:.3}</text><text x="{:.1}" y="{:.1}" font-size="12" text-anchor="end">{hi:.3}</text><text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle">{label}</text>"#,
        y + 26.0,
        x + w,
        y + 26.0,
        x + w / 2.0,
        y + 26.0
    );
}

/// The element-colour legend of a chart: a dot and the name of each of `elements` from
/// (`lx`, `ly`) down, 18 px apart, appended to `s`; returns the y below the last entry.
pub fn element_legend<'e>(s: &mut String, elements: impl IntoIterator<Item = &'e str>, lx: f64, mut ly: f64) -> f64 {
    for e in elements {
        s.push_str(&format!(
            "<circle cx=\"{lx}\" cy=\"{ly}\" r=\"5\" fill=\"{}\"/><text x=\"{}\" y=\"{}\">{}</text>\n",
            element_hex(e),
            lx + 10.0,
            ly + 4.0,
            e.to_uppercase()
        ));
        ly += 18.0;
    }
    ly
}

/// The enclosing decades of a log axis, `(floor log10 min, ceil log10 max)`; (0, 1) for none.
pub fn decades<'a>(values: impl Iterator<Item = &'a f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v.log10());
        hi = hi.max(v.log10());
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let (lo, hi) = (lo.floor(), hi.ceil());
    if hi > lo { (lo, hi) } else { (lo, lo + 1.0) }
}

/// A chart's plot frame and its axis labels: `margins` `[left, top, right, bottom]` inside a
/// `size` `[w, h]` picture.
pub fn plot_frame(margins: [f64; 4], size: [f64; 2], x_label: &str, y_label: &str) -> String {
    let ([left, top, right, bottom], [w, h]) = (margins, size);
    let middle_y = top + (h - top - bottom) / 2.0;
    format!(
        "<rect x=\"{left}\" y=\"{top}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n\
         <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{x_label}</text>\n\
         <text x=\"18\" y=\"{middle_y}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {middle_y})\">{y_label}</text>\n",
        w - left - right,
        h - top - bottom,
        left + (w - left - right) / 2.0,
        h - 14.0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_are_written_as_hex_and_axes_span_whole_decades() {
        assert_eq!(hex([0x44, 0x01, 0x54]), "#440154");
        assert_eq!(element_hex("p1"), "#1f77b4");
        assert_eq!(decades([0.02, 3.0].iter()), (-2.0, 1.0));
        assert_eq!(decades([10.0].iter()), (1.0, 2.0));
        assert_eq!(decades([].iter()), (0.0, 1.0));
    }
}
