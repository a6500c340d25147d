//! The reference a run's error is measured against ([`hox_scenes::reference`]): committed for
//! a paper scene as built, computed (and cached) for other physics, the static solution of the
//! mesh itself for a mesh file. `simulate` and `static` report it and the error against it.

use super::DelayedBar;
use clap::Args;
use hox_scenes::Scene;
use hox_scenes::reference::{Origin, Reference};

/// When a reference is computed (`--reference`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum When {
    /// Committed or cached references always; a new one is computed for `static` and `--settle`
    /// runs (whose error compares equilibria), not for a timed run.
    Auto,
    /// Also compute one for a timed run.
    Compute,
    /// No reference and no error.
    None,
}

#[derive(Args, Clone, Debug)]
pub struct ReferenceArgs {
    /// The error is measured against the committed reference when the physics are a paper
    /// scene's as built; otherwise against one computed with hox's static solver on six Q2
    /// levels and extrapolated (a minute or more the first time, then cached in
    /// ~/.cache/hox/references or HOX_CACHE_DIR), or, for a mesh file, its own static solution.
    #[arg(long, value_enum, default_value_t = When::Auto)]
    pub reference: When,
    /// Cells of the finest Q2 level of a computed reference (the five coarser levels have ¼,
    /// ⅜, ½, ⅝ and ¾ as many per direction): more, a better reference at more cost.
    #[arg(long, default_value_t = hox_scenes::reference::FINEST_CELLS)]
    pub reference_cells: usize,
}

/// Refuses bad reference options before anything runs.
pub fn check(args: &ReferenceArgs) -> anyhow::Result<()> {
    if args.reference_cells < 64 {
        anyhow::bail!("--reference-cells must be at least 64 (four cells per direction), got {}", args.reference_cells);
    }
    Ok(())
}

/// The reference of `scene`, or None (skipped, unavailable or failed: said on stderr).
/// `equilibrium`: the run compares an equilibrium (`static`, `--settle`), which `--reference
/// auto` computes a reference for.
pub fn find(args: &ReferenceArgs, scene: &Scene, equilibrium: bool) -> Option<Reference> {
    if args.reference == When::None {
        return None;
    }
    if let Some(why) = hox_scenes::reference::unavailable(scene) {
        eprintln!("note: no reference: {why}");
        return None;
    }
    let lookup = hox_scenes::reference::Lookup { finest_cells: args.reference_cells, ..Default::default() };
    if args.reference == When::Auto && !equilibrium {
        return match lookup.known(scene) {
            Ok(Some(r)) => Some(r),
            Ok(None) => {
                eprintln!(
                    "note: no reference for these physics yet; a timed run does not compute one (--reference compute, or --settle)"
                );
                None
            }
            Err(e) => {
                eprintln!("warning: no reference: {e}");
                None
            }
        };
    }
    with_progress(|progress| lookup.for_scene(scene, progress))
}

/// Runs a reference computation with a progress bar (shown if it lasts); None with a warning
/// when it fails.
fn with_progress(
    compute: impl FnOnce(hox_scenes::reference::Progress<'_>) -> Result<Reference, hox_scenes::SceneError>,
) -> Option<Reference> {
    let mut bar = DelayedBar::new();
    let found = compute(&mut |what, fraction| {
        bar.reveal("{spinner} {bar:30} {msg} [{elapsed}]");
        bar.bar.set_position((1000.0 * fraction) as u64);
        bar.bar.set_message(what.to_string());
    });
    bar.bar.finish_and_clear();
    found.map_err(|e| eprintln!("warning: no reference: {e}")).ok()
}

/// The reference a recording shows: as [`find`] for a timed run, and with its displacement
/// field (computed when missing, with progress) when `with_field` (`--field error`).
pub fn find_for_record(args: &ReferenceArgs, scene: &Scene, with_field: bool) -> Option<Reference> {
    if !with_field {
        return find(args, scene, false);
    }
    if let Some(why) = hox_scenes::reference::unavailable(scene) {
        eprintln!("note: no reference: {why}");
        return None;
    }
    let lookup = hox_scenes::reference::Lookup { finest_cells: args.reference_cells, ..Default::default() };
    with_progress(|progress| lookup.with_field(scene, progress))
}

/// `"reference"`, `"error_m"`, `"error_pct"` and `"error_of"` for `--json` (nulls without a
/// reference).
pub fn json(out: &mut serde_json::Value, reference: Option<&Reference>, probes: &[(String, [f64; 3])], of: &str) {
    out["reference"] = reference.map(Reference::to_json).unwrap_or(serde_json::Value::Null);
    out["error_m"] = reference.and_then(|r| r.error_m(probes)).into();
    out["error_pct"] = reference.and_then(|r| r.error_pct(probes)).into();
    out["error_of"] = if reference.is_some() { of.into() } else { serde_json::Value::Null };
}

/// The human-readable lines: the reference and the error of `of`.
pub fn print(reference: Option<&Reference>, probes: &[(String, [f64; 3])], of: &str) {
    let Some(r) = reference else { return };
    if let (Some(m), Some(pct)) = (r.error_m(probes), r.error_pct(probes)) {
        let what = if r.origin == Origin::OwnMesh { "solver error" } else { "error" };
        println!("  {what} of the {of}: {m:.3e} m ({pct:.3} %)");
    }
    println!("  reference: {}", r.label());
}
