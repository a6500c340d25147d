//! The colour map and colour ranges the app's views use: hox-scenes' presentation module
//! ([`hox_scenes::present::colour`]: viridis, `ColourRange`, `FieldScale`, the saturation
//! colours and the legend's values), re-exported for `gui/`; the rest of the app names it there.

pub use hox_scenes::present::colour::*;
