//! Did-you-mean: the message for an unknown `--compare` key, naming the key that starts like it
//! and every key there is.

use super::{PARAMS, compare_keys};

/// `unknown option 'youngz', did you mean 'youngs'? (options: …)`.
pub(super) fn unknown_key(key: &str) -> String {
    let near = PARAMS.iter().filter(|p| p.surfaces.cli).find(|p| {
        let prefix: String = key.chars().take(3).collect();
        p.key.starts_with(&prefix)
    });
    format!(
        "unknown option '{key}'{} (options: {})",
        near.map_or(String::new(), |p| format!(", did you mean '{}'?", p.key)),
        compare_keys()
    )
}
