//! `hox bench`: time the XPBD loop on the paper's Table 1 beams and the other element types, or
//! (`--solver NAME`, a solver of the registry) an implicit solver on the same beams and the
//! curved parts (`--only tube`).

use anyhow::{Result, bail};
use hox_sim::solver::Sweep;

pub fn bench(
    frames: usize,
    threads: &[usize],
    only: &str,
    sweeps: &[String],
    lanes: &[usize],
    solver: &str,
) -> Result<()> {
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
    for &l in lanes {
        if l != 4 && l != 8 {
            bail!("--lanes: {l} is not a register width (4 for AVX2, 8 for AVX-512)");
        }
        if !hox_sim::xpbd::kernels::lanes_available(l) {
            bail!(
                "--lanes: this CPU cannot run {l} lanes ({}); it runs {}",
                if l == 8 { "AVX-512 F" } else { "AVX2 and FMA" },
                hox_sim::xpbd::kernels::widest_available().map_or("none".to_string(), |w| format!("up to {w}"))
            );
        }
    }
    if !lanes.is_empty() && (method.is_implicit() || !sweeps.contains(&Sweep::Colour)) {
        bail!("--lanes times XPBD's colour sweep: use it with --solver xpbd and --sweep colour");
    }
    let matching = if method.is_implicit() {
        hox_scenes::bench::matching_solver_cases(only)
    } else {
        hox_scenes::bench::matching_cases(only)
    };
    if matching.is_empty() {
        bail!("no configuration matches '{only}'");
    }
    // the machine first: every figure table in docs/ names its machine (issue #58)
    println!("Machine: {}.\n", super::paper::machine());
    if !method.is_implicit() {
        let rows =
            hox_scenes::bench::run(only, threads, &sweeps, lanes, frames, &mut |r| eprintln!("{}", r.progress_line()))?;
        print!("{}", hox_scenes::bench::markdown(&rows, hox_scenes::bench::peak_gflops_per_core()));
    } else {
        let rows =
            hox_scenes::bench::solver::run(only, method, threads, frames, &mut |r| eprintln!("{}", r.progress_line()))?;
        print!("{}", hox_scenes::bench::solver::markdown(&rows));
    }
    Ok(())
}
