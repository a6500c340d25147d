//! Output files: checked before any work is done, so an unwritable path costs nothing and
//! nothing already written is lost. Shared by the command line and the app.

use anyhow::{Context, Result, bail};
use std::path::Path;

/// Fails unless `path` can be written, without truncating an existing file and without leaving
/// a new one behind.
pub fn check_writable(path: &Path) -> Result<()> {
    let existed = path.exists();
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}
