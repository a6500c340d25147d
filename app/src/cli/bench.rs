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
    println!("Machine: {}.\n", hox_scenes::bench::machine());
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

/// `hox bench --beam-json LABEL`: the beam's P1 mesh as JSON (`positions_m`, `tets` with four
/// node indices each, `clamped`: the nodes at x = 0), for a peer benchmark to solve the same mesh.
pub fn beam_json(label: &str) -> Result<()> {
    let Some(case) = hox_scenes::bench::CASES.iter().find(|c| c.label().eq_ignore_ascii_case(label)) else {
        let labels: Vec<String> = hox_scenes::bench::CASES.iter().map(|c| c.label()).collect();
        bail!("--beam-json: no beam labelled '{label}' (one of: {})", labels.join(", "));
    };
    if case.element != "p1" {
        bail!("--beam-json: '{label}' is not a P1 beam: a peer benchmark solves linear tetrahedra");
    }
    let sim = hox_scenes::bench::bending_beam(case, Sweep::Element)?;
    let mesh = sim.mesh();
    let positions: Vec<String> = mesh.rest_positions.iter().map(|p| format!("[{},{},{}]", p.x, p.y, p.z)).collect();
    let tets: Vec<String> = mesh.blocks[0].connectivity.iter().map(u32::to_string).collect();
    let clamped: Vec<String> = mesh.nodes_where(|p| p.x.abs() < 1e-12).iter().map(u32::to_string).collect();
    println!(
        "{{\"positions_m\":[{}],\"tets\":[{}],\"clamped\":[{}]}}",
        positions.join(","),
        tets.join(","),
        clamped.join(",")
    );
    Ok(())
}

/// `hox bench --stability`: the stability guard's figures (`hox_sim::solver::stability`) for
/// every built-in scene and every benchmark beam at their own settings. They depend on the mesh
/// and the material, not on the machine; the machine line keeps the format of the tables in docs/.
pub fn stability() -> Result<()> {
    println!("Machine: {}.\n", hox_scenes::bench::machine());
    println!("| configuration | elements | ω_max (rad/s) | substeps asked | h·ω_max | substeps taken |");
    println!("|---|---|---|---|---|---|");
    let row = |label: String, elements: usize, r: hox_sim::solver::stability::StabilityReport| {
        println!(
            "| {label} | {elements} | {:.0} | {} | {:.2} | {} |",
            r.omega_max_rad_s, r.requested_substeps, r.requested_h_omega, r.substeps
        );
    };
    for (name, _) in hox_scenes::BUILTIN {
        let mut instance = hox_scenes::Instance::new(hox_scenes::by_name(name)?)?;
        let elements = instance.sim.mesh().num_elements();
        row(format!("scene {name}"), elements, instance.sim.stability());
    }
    for case in hox_scenes::bench::CASES.iter() {
        let mut sim = hox_scenes::bench::bending_beam(case, Sweep::Element)?;
        let elements = sim.mesh().num_elements();
        row(format!("bench {}", case.label()), elements, sim.stability());
    }
    Ok(())
}
