//! Colour: the viridis map (one formula for the app, the recordings and `hox paper`'s
//! figures); the colour range of a field, fixed or automatic, with its saturation colours,
//! ticks and legend text; and the colour of each element type in the study's charts.

use hox_sim::measure::field::Field;

/// Viridis at `t ∈ [0, 1]` (clamped; NaN maps to 0), as RGB bytes: the colour map of the figures,
/// the recordings and the app (perceptually uniform, readable in grey and by colour-blind
/// viewers), from the degree-6 polynomial fit of matplotlib's table by Matt Zucker (within 5/255
/// per channel of the table).
pub fn viridis(t: f64) -> [u8; 3] {
    const C: [[f64; 3]; 7] = [
        [0.277_727_327_223_417_7, 0.005_407_344_544_966_578, 0.334_099_805_335_306_1],
        [0.105_093_043_108_577_4, 1.404_613_529_898_575, 1.384_590_162_594_685],
        [-0.330_861_828_725_556_3, 0.214_847_559_468_213, 0.095_095_163_028_236_59],
        [-4.634_230_498_983_486, -5.799_100_973_351_585, -19.332_440_956_279_87],
        [6.228_269_936_347_081, 14.179_933_366_805_09, 56.690_552_600_681_05],
        [4.776_384_997_670_288, -13.745_145_377_746_01, -65.353_032_633_372_34],
        [-5.435_455_855_934_631, 4.645_852_612_178_535, 26.312_435_249_583_2],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    std::array::from_fn(|k| {
        let v = C.iter().rev().fold(0.0, |acc, c| acc * t + c[k]);
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    })
}

/// Drawn where a value is above the top of a fixed range (saturated): a pink no viridis
/// colour is near, as matplotlib's `set_over`.
pub const OVER: [u8; 3] = [255, 105, 180];
/// Drawn where a value is below the bottom of a fixed range.
pub const UNDER: [u8; 3] = [120, 200, 255];
/// Drawn where a field has no value (an inverted point's stress, a vertex without a reference).
pub const NO_VALUE: [u8; 3] = [128, 128, 128];

/// A colour range `[min, max]` of one field ([`Field`]), fixed or automatic, with its legend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourRange {
    pub field: Field,
    pub min: f64,
    pub max: f64,
    /// Whether the range follows the values ([`FieldScale`]) rather than the user's.
    pub automatic: bool,
}

impl ColourRange {
    /// The displacement range `[0, max_m]`, fixed.
    pub fn metres(max_m: f64) -> ColourRange {
        ColourRange { field: Field::Displacement, min: 0.0, max: max_m, automatic: false }
    }

    /// Where `value` sits on the range, 0–1 (outside when saturated).
    pub fn fraction(&self, value: f64) -> f64 {
        (value - self.min) / (self.max - self.min).max(f64::MIN_POSITIVE)
    }

    /// The colour of `value`: viridis inside the range, [`OVER`] above, [`UNDER`] below,
    /// [`NO_VALUE`] for NaN.
    pub fn colour(&self, value: f64) -> [u8; 3] {
        let t = self.fraction(value);
        if value.is_nan() {
            NO_VALUE
        } else if t > 1.0 + 1e-9 {
            OVER
        } else if t < -1e-9 {
            UNDER
        } else {
            viridis(t)
        }
    }

    /// Five evenly spaced tick values from min to max.
    pub fn ticks(&self) -> [f64; 5] {
        std::array::from_fn(|i| self.min + (self.max - self.min) * i as f64 / 4.0)
    }

    /// A value with the field's unit, to the digits that tell the ticks apart (a quarter of
    /// the range): "0.125 m", "2.4 kPa", "1.02".
    pub fn format(&self, value: f64) -> String {
        format_value_to(value, self.field.unit(), 0.25 * (self.max - self.min))
    }

    /// The fractions of `values` above and below the range (what is saturated), 0–1.
    pub fn saturation(&self, values: &[f64]) -> (f64, f64) {
        let n = values.iter().filter(|v| !v.is_nan()).count().max(1) as f64;
        let over = values.iter().filter(|&&v| self.fraction(v) > 1.0 + 1e-9).count() as f64;
        let under = values.iter().filter(|&&v| self.fraction(v) < -1e-9).count() as f64;
        (over / n, under / n)
    }

    /// The legend's heading: "von Mises stress (Pa), automatic".
    pub fn heading(&self) -> String {
        let unit = self.field.unit();
        let unit = if unit.is_empty() { String::new() } else { format!(" ({unit})") };
        format!("{}{unit}, {}", self.field.title(), if self.automatic { "automatic" } else { "fixed" })
    }
}

/// `value` with SI prefixes for pascals and joules per cubic metre ("2.4 kPa"), compact metres,
/// and plain ratios, to four significant digits.
pub fn format_value(value: f64, unit: &str) -> String {
    format_value_to(value, unit, value.abs() * 1e-2)
}

/// [`format_value`] with as many decimals as resolve steps of `resolution` (two significant
/// digits of the step), trailing zeros dropped.
pub fn format_value_to(value: f64, unit: &str, resolution: f64) -> String {
    if value.is_nan() {
        return "—".into();
    }
    let (scale, prefix) = match (unit, value.abs().max(resolution.abs())) {
        ("Pa" | "J/m³", a) if a >= 1e9 => (1e9, "G"),
        ("Pa" | "J/m³", a) if a >= 1e6 => (1e6, "M"),
        ("Pa" | "J/m³", a) if a >= 1e3 => (1e3, "k"),
        _ => (1.0, ""),
    };
    let (v, step) = (value / scale, (resolution / scale).abs());
    let text = if v == 0.0 {
        "0".to_string()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        let decimals = if step > 0.0 { (1.0 - step.log10().floor()).clamp(0.0, 8.0) as usize } else { 4 };
        let s = format!("{v:.decimals$}");
        if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
    } else {
        format!("{v:.2e}")
    };
    match unit {
        "" => text,
        _ => format!("{text} {prefix}{unit}"),
    }
}

/// The share of a frame's values an automatic range holds ([`FieldScale::observe`]).
pub const AUTOMATIC_PERCENTILE: f64 = 0.98;

/// The colour range of one field shared by every configuration on screen: fixed at the user's
/// top (`fixed_max`; for det F a range symmetric about 1), or automatic — growing to hold all
/// but the most extreme 2 % of each frame's values seen since the run started, so colours do
/// not flicker as a body swings ([`FieldScale::observe`]; [`FieldScale::reset`] when the run
/// restarts).
#[derive(Clone, Debug, PartialEq)]
pub struct FieldScale {
    pub field: Field,
    /// The user's top of the range (0 or None: automatic).
    pub fixed_max: Option<f64>,
    /// The smallest automatic span (so a body at rest has a readable legend).
    pub floor: f64,
    /// Largest distance from the field's neutral value seen so far.
    seen: f64,
}

impl FieldScale {
    /// A scale for `field` with the user's top `fixed_max` (≤ 0: automatic); `extent_m` is the
    /// first body's largest extent (the automatic floor of metre fields is a thousandth of it).
    pub fn new(field: Field, fixed_max: f64, extent_m: f64) -> FieldScale {
        let floor = match field.unit() {
            "m" => 1e-3 * extent_m.max(f64::MIN_POSITIVE),
            _ => 1e-9,
        };
        FieldScale { field, fixed_max: (fixed_max > 0.0).then_some(fixed_max), floor, seen: 0.0 }
    }

    /// Takes `values` into the automatic range: its span grows to the 98th percentile of
    /// their distances from the neutral value — not their largest, which a stress singularity
    /// at a clamped edge would make so large that the rest of the body looked unloaded. The
    /// few values beyond are drawn saturated, and the legend says how many.
    pub fn observe(&mut self, values: &[f64]) {
        let neutral = self.field.neutral();
        let mut d: Vec<f64> = values.iter().filter(|v| v.is_finite()).map(|v| (v - neutral).abs()).collect();
        if d.is_empty() {
            return;
        }
        let k = ((d.len() - 1) as f64 * AUTOMATIC_PERCENTILE).round() as usize;
        let (_, p, _) = d.select_nth_unstable_by(k, f64::total_cmp);
        self.seen = self.seen.max(*p);
    }

    /// Forgets what was seen (a new run).
    pub fn reset(&mut self) {
        self.seen = 0.0;
    }

    /// The range now.
    pub fn range(&self) -> ColourRange {
        let neutral = self.field.neutral();
        let (span, automatic) = match self.fixed_max {
            Some(top) if self.field.two_sided() => ((top - neutral).abs().max(f64::MIN_POSITIVE), false),
            Some(top) => (top, false),
            None => (self.seen.max(self.floor), true),
        };
        let min = if self.field.two_sided() { neutral - span } else { neutral };
        ColourRange { field: self.field, min, max: neutral + span, automatic }
    }
}

/// The colour of an element type in the study's charts (`study.svg` and the app's), by its
/// place in the registry: matplotlib's `tab10` colours in the order the built-in types were
/// first drawn (p1 blue, p2 red, p3 green, q1 purple, q2 brown, prism pink, pyramid orange),
/// then olive and cyan, repeating; grey for a name that is not registered.
pub fn element_colour(element: &str) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 9] = [
        [0x1f, 0x77, 0xb4],
        [0xd6, 0x27, 0x28],
        [0x2c, 0xa0, 0x2c],
        [0x94, 0x67, 0xbd],
        [0x8c, 0x56, 0x4b],
        [0xe3, 0x77, 0xc2],
        [0xff, 0x7f, 0x0e],
        [0xbc, 0xbd, 0x22],
        [0x17, 0xbe, 0xcf],
    ];
    hox_sim::element::ElementType::all()
        .position(|e| e.name().eq_ignore_ascii_case(element))
        .map_or([0x7f; 3], |i| PALETTE[i % PALETTE.len()])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_matches_the_table_ends_and_middle() {
        // matplotlib's viridis: 0 → #440154, 0.5 → #21918c, 1 → #fde725 (±5 per channel)
        for (t, want) in [(0.0, [0x44, 0x01, 0x54]), (0.5, [0x21, 0x91, 0x8c]), (1.0, [0xfd, 0xe7, 0x25])] {
            let got = viridis(t);
            for k in 0..3 {
                assert!((got[k] as i32 - want[k]).abs() <= 5, "t = {t}: {got:?} vs {want:?}");
            }
        }
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
    }

    /// An automatic range grows to hold what was seen and never saturates; a fixed one
    /// saturates and says how much; det F is centred on 1.
    #[test]
    fn automatic_ranges_grow_and_fixed_ranges_show_saturation() {
        let mut s = FieldScale::new(Field::Displacement, 0.0, 2.0);
        assert_eq!(s.range().max, 2e-3);
        s.observe(&[0.1, 0.62, f64::NAN]);
        s.observe(&[0.3]);
        let r = s.range();
        assert!(r.automatic && r.max == 0.62 && r.min == 0.0);
        assert_eq!(r.saturation(&[0.1, 0.62]), (0.0, 0.0));
        // a singular peak (1 value in 100) does not set the automatic range: it is saturated
        let mut peaked: Vec<f64> = (0..99).map(|i| i as f64 / 98.0).collect();
        peaked.push(50.0);
        let mut p = FieldScale::new(Field::VonMises, 0.0, 2.0);
        p.observe(&peaked);
        let r = p.range();
        assert!(r.max < 1.0 && r.max > 0.95, "{r:?}");
        // the top 2 %: the peak and the largest regular value
        assert_eq!(r.saturation(&peaked).0, 0.02);
        let fixed = FieldScale::new(Field::Displacement, 0.4, 2.0).range();
        assert!(!fixed.automatic);
        assert_eq!(fixed.colour(0.62), OVER);
        assert_eq!(fixed.saturation(&[0.1, 0.62, 0.5, 0.2]), (0.5, 0.0));
        let mut det = FieldScale::new(Field::DetF, 0.0, 2.0);
        det.observe(&[0.97, 1.01]);
        let r = det.range();
        assert!((r.min - 0.97).abs() < 1e-12 && (r.max - 1.03).abs() < 1e-12);
        let fixed_det = FieldScale::new(Field::DetF, 1.05, 2.0).range();
        assert!((fixed_det.min - 0.95).abs() < 1e-12 && fixed_det.colour(0.9) == UNDER);
        assert_eq!(fixed_det.colour(f64::NAN), NO_VALUE);
        s.reset();
        assert_eq!(s.range().max, 2e-3);
    }

    #[test]
    fn values_carry_their_units() {
        assert_eq!(format_value(2400.0, "Pa"), "2.4 kPa");
        assert_eq!(format_value(3.2e6, "Pa"), "3.2 MPa");
        assert_eq!(format_value(0.125, "m"), "0.125 m");
        assert_eq!(format_value(1.02, ""), "1.02");
        assert_eq!(format_value(12.0, "J/m³"), "12 J/m³");
        assert_eq!(format_value(f64::NAN, "m"), "—");
        // ticks carry the digits that tell them apart, no more
        assert_eq!(format_value_to(392_620.6, "Pa", 130_873.5), "393 kPa");
        assert_eq!(format_value_to(0.3235, "m", 0.1618), "0.32 m");
        assert_eq!(format_value(0.0567484, "m"), "0.05675 m");
        assert_eq!(format_value_to(1.0027, "", 0.0013), "1.0027");
    }

    #[test]
    fn viridis_lightness_increases() {
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        let l: Vec<f64> = (0..=20).map(|i| luma(viridis(i as f64 / 20.0))).collect();
        assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
    }
}
