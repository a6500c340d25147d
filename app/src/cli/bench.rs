//! `hox bench`: time the XPBD loop on the paper's Table 1 beams and the other element types.

use anyhow::{Result, bail};

pub fn bench(frames: usize, threads: &[usize], only: &str, colour_on_one: bool) -> Result<()> {
    if frames == 0 || threads.contains(&0) {
        bail!("--frames and every --threads count must be at least 1");
    }
    let rows =
        hox_scenes::bench::run(only, threads, colour_on_one, frames, &mut |r| eprintln!("{}", r.progress_line()))?;
    if rows.is_empty() {
        bail!("no configuration matches '{only}'");
    }
    print!("{}", hox_scenes::bench::markdown(&rows));
    Ok(())
}
