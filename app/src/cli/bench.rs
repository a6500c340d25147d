//! `hox bench`: time the XPBD loop on the paper's Table 1 beams and the other element types, or
//! (`--solver NAME`, a solver of the registry) an implicit solver on the same beams and the
//! curved parts (`--only tube`).

use anyhow::{Result, bail};
use hox_sim::solver::Sweep;

pub fn bench(frames: usize, threads: &[usize], only: &str, sweeps: &[String], solver: &str) -> Result<()> {
    let method = hox_scenes::bench::solver::parse_solver(solver)?;
    let sweeps = sweeps
        .iter()
        .map(|s| {
            Sweep::from_name(s.trim())
                .ok_or_else(|| anyhow::anyhow!("--sweep: unknown sweep '{s}' (colour or element)"))
        })
        .collect::<Result<Vec<_>>>()?;
    if frames == 0 || threads.contains(&0) {
        bail!("--frames and every --threads count must be at least 1");
    }
    let matching = if method.is_implicit() {
        hox_scenes::bench::matching_solver_cases(only)
    } else {
        hox_scenes::bench::matching_cases(only)
    };
    if matching.is_empty() {
        bail!("no configuration matches '{only}'");
    }
    if !method.is_implicit() {
        let rows = hox_scenes::bench::run(only, threads, &sweeps, frames, &mut |r| eprintln!("{}", r.progress_line()))?;
        print!("{}", hox_scenes::bench::markdown(&rows, hox_scenes::bench::peak_gflops_per_core()));
    } else {
        let rows =
            hox_scenes::bench::solver::run(only, method, threads, frames, &mut |r| eprintln!("{}", r.progress_line()))?;
        print!("{}", hox_scenes::bench::solver::markdown(&rows));
    }
    Ok(())
}
