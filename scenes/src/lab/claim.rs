//! A lesson step's claim about its numbers (issue #57: why-high-order's answer said "1.15 to 2.6
//! times less" under 1.07× measured on screen, accuracy-cost's "about twice" under 3.2×): the
//! quantity the answer speaks of — configuration A's or B's measurement, or their ratio — and the
//! range it claims. The app and `hox lesson` show it beside the answer with the value measured
//! there and then, and say so when this machine's value is outside it; a test checks every claim
//! as `hox lesson` measures it.
//!
//! In a lesson file: `claim = { of = "a/b", min = 1.05, max = 3.0 }` (`of`: `a`, `b`, `a/b` or
//! `b/a`; at least one bound).

use serde::Deserialize;

/// What a step's answer claims of its numbers.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    /// `a`, `b`, `a/b` or `b/a`.
    pub of: String,
    pub min: Option<f64>,
    pub max: Option<f64>,
}

/// A claim judged against the values measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Judged {
    pub value: f64,
    pub holds: bool,
    /// "measured here: A/B = 1.07 (claimed: 1.05 to 3); …".
    pub text: String,
}

impl Claim {
    /// Checks the claim's form: a known quantity, at least one finite bound, min ≤ max.
    pub fn check(&self, configurations: usize) -> Result<(), String> {
        let needs_b = self.of != "a";
        if !["a", "b", "a/b", "b/a"].contains(&self.of.as_str()) {
            return Err(format!("of = '{}': one of a, b, a/b, b/a", self.of));
        }
        if needs_b && configurations < 2 {
            return Err(format!("of = '{}' needs a configuration b", self.of));
        }
        let finite = |v: Option<f64>| v.is_none_or(f64::is_finite);
        if !finite(self.min) || !finite(self.max) || (self.min.is_none() && self.max.is_none()) {
            return Err("needs a finite min, max or both".into());
        }
        if let (Some(lo), Some(hi)) = (self.min, self.max)
            && lo > hi
        {
            return Err(format!("min {lo} is above max {hi}"));
        }
        Ok(())
    }

    /// The claimed quantity of `values` (A's, B's) and whether it is in the claimed range;
    /// None while a value is not measured (NaN) or missing.
    pub fn judge(&self, values: &[f64]) -> Option<Judged> {
        let (a, b) = (values.first().copied(), values.get(1).copied());
        let value = match self.of.as_str() {
            "a" => a?,
            "b" => b?,
            "a/b" => a? / b?,
            "b/a" => b? / a?,
            _ => return None,
        };
        if !value.is_finite() {
            return None;
        }
        let holds = self.min.is_none_or(|lo| value >= lo) && self.max.is_none_or(|hi| value <= hi);
        let range = match (self.min, self.max) {
            (Some(lo), Some(hi)) => format!("{} to {}", short(lo), short(hi)),
            (Some(lo), None) => format!("at least {}", short(lo)),
            (None, Some(hi)) => format!("at most {}", short(hi)),
            (None, None) => "anything".into(),
        };
        let verdict = if holds { "as claimed" } else { "outside the claim on this machine now" };
        Some(Judged {
            value,
            holds,
            text: format!("measured here: {} = {} (claimed: {range}), {verdict}", self.of.to_uppercase(), short(value)),
        })
    }
}

/// A number in a few significant digits: 1.07, 0.0123, 2.6.
fn short(v: f64) -> String {
    let text = format!("{v:.3}");
    if v.abs() >= 0.01 { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { format!("{v:.2e}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn claim(of: &str, min: Option<f64>, max: Option<f64>) -> Claim {
        Claim { of: of.into(), min, max }
    }

    #[test]
    fn a_ratio_is_judged_against_its_range_and_says_so() {
        let c = claim("a/b", Some(1.05), Some(3.0));
        let j = c.judge(&[3.06, 2.69]).unwrap();
        assert!(j.holds && (j.value - 3.06 / 2.69).abs() < 1e-12);
        assert_eq!(j.text, "measured here: A/B = 1.138 (claimed: 1.05 to 3), as claimed");
        let j = c.judge(&[2.0, 2.0]).unwrap();
        assert!(!j.holds && j.text.ends_with("outside the claim on this machine now"), "{}", j.text);
        assert_eq!(claim("b", None, Some(-0.3)).judge(&[0.0, -0.2884]).map(|j| j.holds), Some(false));
        assert_eq!(c.judge(&[f64::NAN, 1.0]), None, "not measured yet");
        assert_eq!(c.judge(&[1.0]), None);
    }

    #[test]
    fn a_claim_of_the_wrong_form_is_refused_naming_it() {
        assert!(claim("a/c", Some(1.0), None).check(2).unwrap_err().contains("a/c"));
        assert!(claim("a/b", Some(1.0), None).check(1).unwrap_err().contains("configuration b"));
        assert!(claim("a", None, None).check(1).is_err());
        assert!(claim("a", Some(2.0), Some(1.0)).check(1).unwrap_err().contains("above"));
        assert!(claim("a", Some(f64::NAN), None).check(1).is_err());
        assert!(claim("b/a", Some(1.4), Some(4.0)).check(2).is_ok());
    }
}
