//! The stability guard's figures (`hox_sim::solver::stability`) for every built-in scene and every
//! benchmark beam at their own settings: the fastest element mode ω_max, `h ω_max` with the
//! requested substeps, and the substeps the guard takes. docs/STABILITY.md quotes this table.
//!
//! `cargo run --release -p hox-scenes --example stability_scan`

fn main() {
    println!("| configuration | elements | ω_max (rad/s) | substeps asked | h·ω_max | substeps taken |");
    println!("|---|---|---|---|---|---|");
    let row = |label: String, elements: usize, r: hox_sim::solver::stability::StabilityReport| {
        println!(
            "| {label} | {elements} | {:.4e} | {} | {:.3} | {} |",
            r.omega_max_rad_s, r.requested_substeps, r.requested_h_omega, r.substeps
        );
    };
    for (name, _) in hox_scenes::BUILTIN {
        let scene = hox_scenes::by_name(name).expect("built-in scene");
        let mut instance = hox_scenes::Instance::new(scene).expect("built-in scene builds");
        let elements = instance.sim.mesh().num_elements();
        row(format!("scene {name}"), elements, instance.sim.stability());
    }
    for case in hox_scenes::bench::CASES.iter() {
        let mut sim = hox_scenes::bench::bending_beam(case, hox_sim::solver::Sweep::Element).expect("benchmark beam");
        let elements = sim.mesh().num_elements();
        row(format!("bench {}", case.label()), elements, sim.stability());
    }
}
