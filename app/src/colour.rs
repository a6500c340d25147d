//! The colour map shared by the recordings and the app: viridis (perceptually uniform,
//! readable in grey and by colour-blind viewers), from the degree-6 polynomial fit of
//! matplotlib's table by Matt Zucker (within 5/255 per channel of the table).

/// Viridis at `t ∈ [0, 1]` (clamped; NaN maps to 0), as RGB bytes.
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

/// A fixed colour range `[0, max]` for a magnitude in metres, with its legend ticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourRange {
    pub max_m: f64,
}

impl ColourRange {
    /// The colour of magnitude `value_m`.
    pub fn colour(&self, value_m: f64) -> [u8; 3] {
        viridis(value_m / self.max_m)
    }
    /// Five evenly spaced tick values from 0 to max, metres.
    pub fn ticks_m(&self) -> [f64; 5] {
        std::array::from_fn(|i| self.max_m * i as f64 / 4.0)
    }
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

    #[test]
    fn viridis_lightness_increases() {
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        let l: Vec<f64> = (0..=20).map(|i| luma(viridis(i as f64 / 20.0))).collect();
        assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
    }
}
