//! The one median of the workspace: frame timings (`hox bench`, `hox simulate`, the app) and
//! run reports use it; and the quantile a run report's 95th percentile of frame times is.

/// Median of `values` (sorted in place, by [`f64::total_cmp`]): the middle value, or the mean
/// of the two middle values for an even count.
///
/// **Empty input gives NaN**: there is no measurement, and a 0 would read as a frame that took
/// no time (serde_json writes the NaN as `null`). NaN inputs sort after +∞ (positive NaN) or
/// before −∞ (negative NaN), so they count as extreme values, not as errors.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) }
}

/// The `q`-quantile of `values` (sorted in place), `q` in [0, 1]: the smallest value with at
/// least a fraction `q` of the values at or below it (the nearest-rank definition: the 95th
/// percentile of 100 frame times is the 95th smallest, never an interpolation between frames).
/// Empty input gives NaN, as for [`median`].
pub fn quantile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let rank = (q.clamp(0.0, 1.0) * values.len() as f64).ceil() as usize;
    values[rank.clamp(1, values.len()) - 1]
}

#[cfg(test)]
mod tests {
    use super::{median, quantile};

    #[test]
    fn quantiles_are_nearest_rank() {
        let mut v: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(quantile(&mut v, 0.95), 95.0);
        assert_eq!(quantile(&mut v, 1.0), 100.0);
        assert_eq!(quantile(&mut v, 0.0), 1.0);
        // one slow frame in twenty is the 95th percentile of twenty frames
        let mut frames = vec![10.0; 19];
        frames.push(80.0);
        assert_eq!(quantile(&mut frames, 0.95), 10.0);
        frames.push(80.0);
        assert_eq!(quantile(&mut frames, 0.95), 80.0);
        assert!(quantile(&mut [], 0.5).is_nan());
    }

    #[test]
    fn median_of_odd_even_and_empty_input() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [7.0]), 7.0);
        assert!(median(&mut []).is_nan());
    }
}
