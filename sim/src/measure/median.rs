//! The one median of the workspace: frame timings (`hox bench`, `hox simulate`, the app) and
//! run reports use it.

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

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_odd_even_and_empty_input() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [7.0]), 7.0);
        assert!(median(&mut []).is_nan());
    }
}
