//! The robustness families with every solver and integrator (issue #36, item 4, first part):
//! stiff, soft, near-incompressible, inverted starts, extreme drives, coarse time steps and
//! contact, each run with every solver of the registry (`xpbd`, `vbd`, `newton`, `newton-cg`), the
//! implicit ones under each integrator.
//!
//! The one demand here is the issue's: **never finite but absurd with success**. A run either
//! ends finite and sane — every node within ten body sizes of its rest position, no node of the
//! body further from its mean displacement than five body sizes (the soft beam, 1 kPa, hangs
//! 4.7 sizes long under its weight with every solver) — or stops with a clear error
//! naming the solver (the NaN guard, the step watch's divergence or unsolved step) or the
//! effect it cannot honour (contact under the Newton-type solvers). Which configurations stop instead of
//! recovering is printed (`PASS` / `STOP` lines), and the run's table of farthest nodes is
//! docs/STABILITY.md's (checked against it; written there by `scripts/docs_tables.py`); the
//! families' own recovery criteria (tests/tests/robustness.rs) still run with XPBD only.

use hox_sim::Vec3;
use hox_sim::effect::{AxisRotation, ContactPlane, Damping, Effect, Gravity, Prescribed};
use hox_sim::material::MaterialModel;
use hox_sim::mesh::Mesh;
use hox_sim::solver::{Integrator, Method, SimError, Simulation, SolverSettings};
use hox_tests::*;

const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

/// One family's case: the mesh, material, effects, frames per second and seconds to run, and
/// how the positions start.
struct Case {
    family: &'static str,
    mesh: Mesh,
    model: MaterialModel,
    youngs_modulus_pa: f64,
    poisson_ratio: f64,
    effects: fn(&Mesh) -> Vec<Box<dyn Effect>>,
    fps: f64,
    secs: f64,
    start: fn(&Mesh, &mut [Vec3]),
}

fn beam(et: &str) -> Mesh {
    box_mesh(et, [1.0, 0.25, 0.25], [4, 1, 1])
}

fn hanging(mesh: &Mesh) -> Vec<Box<dyn Effect>> {
    vec![Box::new(Gravity::new(G)), clamp_x0(mesh)]
}

fn at_rest(_: &Mesh, _: &mut [Vec3]) {}

/// The P2 beam hanging from its clamp, from rest.
fn hanging_case(
    family: &'static str,
    model: MaterialModel,
    youngs_modulus_pa: f64,
    poisson_ratio: f64,
    fps: f64,
    secs: f64,
) -> Case {
    Case {
        family,
        mesh: beam("p2"),
        model,
        youngs_modulus_pa,
        poisson_ratio,
        effects: hanging,
        fps,
        secs,
        start: at_rest,
    }
}

fn cases() -> Vec<Case> {
    vec![
        hanging_case("stiff (E = 1 GPa)", MaterialModel::StVenantKirchhoff, 1e9, 0.3, 60.0, 1.0),
        hanging_case("soft (E = 1 kPa)", MaterialModel::StableNeoHookean, 1e3, 0.3, 60.0, 1.0),
        hanging_case("near-incompressible (ν = 0.499, StVK)", MaterialModel::StVenantKirchhoff, 1e6, 0.499, 60.0, 1.0),
        Case {
            family: "inverted start (half the beam mirrored)",
            mesh: beam("p1"),
            model: MaterialModel::StableNeoHookean,
            youngs_modulus_pa: 1e5,
            poisson_ratio: 0.3,
            effects: |mesh| vec![clamp_x0(mesh), Box::new(Damping { rate_per_sec: 5.0 })],
            fps: 60.0,
            secs: 1.0,
            start: |_, x| {
                for p in x.iter_mut().filter(|p| p.x > 0.5) {
                    p.x = 1.0 - p.x;
                }
            },
        },
        Case {
            family: "extreme drive (the end turned half a turn in 0.2 s)",
            mesh: beam("p2"),
            model: MaterialModel::StableNeoHookean,
            youngs_modulus_pa: 1e6,
            poisson_ratio: 0.35,
            effects: |mesh| {
                vec![
                    clamp_x0(mesh),
                    Box::new(Prescribed {
                        nodes: nodes_on_plane(mesh, 0, 1.0),
                        translation_m: Vec3::zeros(),
                        rotation: Some(AxisRotation {
                            axis: Vec3::x(),
                            origin_m: Vec3::new(1.0, 0.125, 0.125),
                            angle_rad: std::f64::consts::PI,
                        }),
                        ramp_secs: 0.2,
                    }),
                ]
            },
            fps: 60.0,
            secs: 0.5,
            start: at_rest,
        },
        hanging_case("coarse time step (5 frames per second)", MaterialModel::StVenantKirchhoff, 3e6, 0.35, 5.0, 2.0),
        Case {
            family: "contact (falling on a plane)",
            mesh: box_mesh("p1", [0.5, 0.5, 0.5], [2, 2, 2]),
            model: MaterialModel::StableNeoHookean,
            youngs_modulus_pa: 1e5,
            poisson_ratio: 0.3,
            effects: |_| {
                vec![
                    Box::new(Gravity::new(G)),
                    Box::new(ContactPlane::new(Vec3::new(0.0, 0.0, -0.2), Vec3::z(), Vec3::zeros(), 0.0, 0.5)),
                ]
            },
            fps: 60.0,
            secs: 1.0,
            start: at_rest,
        },
    ]
}

/// Every (solver, integrator) pair: XPBD once (it ignores the integrator), each implicit solver
/// under each.
fn solvers() -> Vec<(Method, Integrator)> {
    // every solver of the registry: the implicit ones under each integrator
    let mut v = Vec::new();
    for m in Method::ALL {
        if m.is_implicit() {
            v.extend(Integrator::ALL.map(|i| (m, i)));
        } else {
            v.push((m, Integrator::default()));
        }
    }
    v
}

/// Runs one case; Ok(figures) when it ends finite and sane, Err(why) when it ended finite but
/// absurd or stopped with an error that is not a clear stop.
fn run(case: &Case, method: Method, integrator: Integrator) -> Result<String, String> {
    let material = material(case.model, case.youngs_modulus_pa, case.poisson_ratio);
    let settings = SolverSettings {
        method,
        integrator,
        frames_per_second: case.fps,
        ..settings(Default::default(), 50, case.fps)
    };
    let mut sim = match Simulation::new(case.mesh.clone(), material, settings, (case.effects)(&case.mesh)) {
        Ok(sim) => sim,
        Err(e @ SimError::Unsupported { .. }) => return Ok(format!("refused: {e}")),
        Err(e) => return Err(format!("could not start: {e}")),
    };
    (case.start)(&case.mesh, &mut sim.positions);
    let size = size_m(&case.mesh);
    let frames = (case.secs * case.fps).round() as u64;
    for _ in 0..frames {
        match sim.step_frame() {
            Ok(()) => {}
            Err(e @ (SimError::NonFinite { .. } | SimError::Diverged { .. } | SimError::Unsolved { .. })) => {
                let text = e.to_string();
                if !text.contains(method.name()) {
                    return Err(format!("a stop that does not name the solver: {text}"));
                }
                if !sim.positions.iter().all(|p| p.iter().all(|c| c.is_finite())) {
                    return Err(format!("stopped but left non-finite positions: {text}"));
                }
                return Ok(format!("STOP: {text}"));
            }
            Err(e) => return Err(format!("stopped by an unexpected error: {e}")),
        }
    }
    let rest = &case.mesh.rest_positions;
    if !sim.positions.iter().chain(&sim.velocities).all(|p| p.iter().all(|c| c.is_finite())) {
        return Err("ended with non-finite values and no error".into());
    }
    let moved: Vec<Vec3> = sim.positions.iter().zip(rest).map(|(x, x0)| x - x0).collect();
    let mean = moved.iter().sum::<Vec3>() / moved.len() as f64;
    let farthest = moved.iter().map(|u| u.norm()).fold(0.0, f64::max);
    let spread = moved.iter().map(|u| (u - mean).norm()).fold(0.0, f64::max);
    if farthest > 10.0 * size || spread > 5.0 * size {
        return Err(format!(
            "ended finite but absurd with success: a node {:.2} sizes from rest, {:.2} sizes from the mean motion",
            farthest / size,
            spread / size
        ));
    }
    Ok(format!(
        "PASS: farthest node {:.3} sizes from rest, {} steps rejected, {} unconverged",
        farthest / size,
        sim.counters().rejected_steps,
        sim.counters().unconverged_steps
    ))
}

/// docs/STABILITY.md's cell for one run's figures: the farthest node in body sizes and the steps
/// taken again, `refused` or `stops`.
fn cell(figures: &str) -> String {
    if figures.starts_with("refused") {
        return "refused".into();
    }
    if figures.starts_with("STOP") {
        return "stops".into();
    }
    let words: Vec<&str> = figures.split_whitespace().collect();
    let before = |w: &str| words.iter().position(|x| *x == w).and_then(|k| k.checked_sub(1)).map_or("?", |k| words[k]);
    let after = |w: &str| words.iter().position(|x| *x == w).and_then(|k| words.get(k + 1)).copied().unwrap_or("?");
    match before("steps") {
        "0" => after("node").to_string(),
        rejected => format!("{}, {rejected} rej.", after("node")),
    }
}

/// The command whose table docs/STABILITY.md holds.
const COMMAND: &str = "cargo test --release -p hox-tests --test robustness_solvers -- --ignored";

#[test]
#[ignore = "heavy: release, .ci/run"]
fn no_solver_ends_a_hard_case_finite_but_absurd() {
    let mut problems = Vec::new();
    let labels: Vec<String> = solvers()
        .into_iter()
        .map(
            |(method, integrator)| {
                if method.is_implicit() { format!("{method} {integrator}") } else { method.to_string() }
            },
        )
        .collect();
    let mut table = format!(
        "{}\n\n| family | {} |\n|---|{}\n",
        docs::machine_line(),
        labels.join(" | "),
        "---|".repeat(labels.len())
    );
    for case in cases() {
        let mut row = format!("| {} |", case.family);
        for ((method, integrator), label) in solvers().into_iter().zip(&labels) {
            match run(&case, method, integrator) {
                Ok(figures) => {
                    eprintln!("{} | {label} | {figures}", case.family);
                    row.push_str(&format!(" {} |", cell(&figures)));
                }
                Err(why) => {
                    eprintln!("FAIL {} | {label} | {why}", case.family);
                    problems.push(format!("{}, {label}: {why}", case.family));
                    row.push_str(" absurd |");
                }
            }
        }
        table.push_str(&row);
        table.push('\n');
    }
    assert!(problems.is_empty(), "{} run(s):\n{}", problems.len(), problems.join("\n"));
    // docs/STABILITY.md's table is this run's (issue #58)
    docs::publish("docs/STABILITY.md", COMMAND, &table);
}

#[test]
fn a_runs_cell_gives_its_farthest_node_and_the_steps_taken_again() {
    assert_eq!(cell("PASS: farthest node 0.287 sizes from rest, 0 steps rejected, 0 unconverged"), "0.287");
    assert_eq!(cell("PASS: farthest node 0.289 sizes from rest, 279 steps rejected, 3 unconverged"), "0.289, 279 rej.");
    assert_eq!(cell("refused: contact is not supported by newton"), "refused");
    assert_eq!(cell("STOP: newton: step unsolved at frame 3"), "stops");
}
