//! The robustness suite (issue #8): hard cases stay numerically stable. `docs/STABILITY.md`
//! explains each case, what happens and why, the safeguards, and has the pass/fail table per
//! element type and formulation that these tests print (`PASS`/`FAIL` lines on stderr:
//! `cargo test -p hox-tests --test robustness -- --nocapture`).
//!
//! Every case runs headless on small meshes (a few cells per direction) and asserts, with the
//! tolerances stated at each test:
//! - no NaN or infinity anywhere (the solver's NaN guard would also stop the run);
//! - bounded total energy `H = T + U + V_g` ([`hox_tests::Health`]) at every frame;
//! - once the loads are gone (gravity, prescribed motion and contact removed, velocity damping
//!   added), no element inverted (`det F > 0` at every quadrature point) and the body back at its
//!   rest shape within `REST_TOLERANCE × size` (size: the rest bounding-box diagonal);
//! - a clear error where the input itself is invalid.
//!
//! The 10,000-frame long run is `#[ignore]`d here and run in release by `.ci/run`.

use hox_sim::Vec3;
use hox_sim::effect::{AxisRotation, ContactPlane, Damping, Effect, EffectState, Gravity, Prescribed};
use hox_sim::material::{Material, MaterialModel};
use hox_sim::mesh::Mesh;
use hox_sim::solver::{Integrator, Method, SimError, Simulation, SolverSettings};
use hox_sim::xpbd::constraint::Formulation;
use hox_tests::*;

const SNH: MaterialModel = MaterialModel::StableNeoHookean;
const SNH_LOG: MaterialModel = MaterialModel::StableNeoHookeanLog;
const STVK: MaterialModel = MaterialModel::StVenantKirchhoff;
const NH: MaterialModel = MaterialModel::NeoHookean;
/// XPBD under both formulations: the configurations every family runs in the debug suite.
const BOTH: [Solve; 2] = [Solve::Xpbd(Formulation::Energy), Solve::Xpbd(Formulation::Split)];

/// How a configuration is solved: XPBD (the paper's solver) with a formulation, or an implicit
/// solver of the registry under an integrator (issue #36, item 4: every family with every solver).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Solve {
    Xpbd(Formulation),
    Implicit(Method, Integrator),
    /// Any solver (XPBD's integrator unused) with the mixed formulation (issue #62).
    Mixed(Method, Integrator),
}

impl std::fmt::Display for Solve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Solve::Xpbd(formulation) => write!(f, "{formulation}"),
            Solve::Implicit(method, integrator) => write!(f, "{method} {integrator}"),
            Solve::Mixed(Method::Xpbd, _) => write!(f, "xpbd mixed"),
            Solve::Mixed(method, integrator) => write!(f, "{method} {integrator} mixed"),
        }
    }
}

impl Solve {
    /// The settings: XPBD's `substeps` per frame, or the implicit solver's one step per frame
    /// (`substeps` is then unused: its steps are its own).
    fn settings(self, substeps: u32, fps: f64) -> SolverSettings {
        match self {
            Solve::Xpbd(formulation) => settings(formulation, substeps, fps),
            Solve::Implicit(method, integrator) => {
                SolverSettings { method, integrator, ..settings(Formulation::default(), substeps, fps) }
            }
            Solve::Mixed(method, integrator) => {
                SolverSettings { method, integrator, ..settings(Formulation::Mixed, substeps, fps) }
            }
        }
    }
}

/// The energy a configuration may gain beyond the families' bounds, as a fraction of their
/// energy scale: none for the schemes that only dissipate (XPBD, implicit Euler, BDF2); 2 % for
/// Newmark, which conserves energy exactly only for a linear body (on these strongly nonlinear
/// cases its error reached 0.8–1.1 % of the scale: a sagging ν = 0.49 Q2 beam released, the
/// 1 kPa jelly; the step watch allows 1 % per step).
fn energy_slack(s: &Simulation) -> f64 {
    let settings = s.settings();
    if settings.method.is_implicit() && settings.integrator == Integrator::Newmark { 0.02 } else { 0.0 }
}

/// The implicit solvers and integrators the families run with in `.ci/run`: VBD and Newton under
/// every integrator but VBD under Newmark. Under Newmark VBD sweeps every step to 1e-5 of the load,
/// so it computes Newton's Newmark step (in session 20, 105 of 117 family outcomes were Newton's;
/// docs/STABILITY.md lists the 12 others) at 5–10× Newton's time: it was 70 % of this suite's
/// time; [`full`] adds it (about 30 minutes). Newton-CG minimises the same potential as Newton to
/// the same tolerance at 2–5× its time (tests/tests/robustness_solvers.rs runs both, and VBD under
/// Newmark, in every family).
fn implicit() -> Vec<Solve> {
    [Method::Vbd, Method::Newton]
        .into_iter()
        .flat_map(|m| Integrator::ALL.map(move |i| Solve::Implicit(m, i)))
        .filter(|s| full() || *s != Solve::Implicit(Method::Vbd, Integrator::Newmark))
        .collect()
}

/// `HOX_ROBUSTNESS_FULL=1`: every implicit configuration on every element type, as
/// docs/STABILITY.md's tables were made. Without it (`.ci/run`'s 45-minute budget) VBD skips
/// Newmark ([`implicit`]) and the two most expensive types, P3 and Q2 (58 % of the families' time
/// in session 20: VBD sweeps their 20- and 27-node elements node by node; Newton runs them), and
/// each skipped cell prints a `SKIP` line.
fn full() -> bool {
    std::env::var_os("HOX_ROBUSTNESS_FULL").is_some_and(|v| v == "1")
}

/// Whether [`configurations`] runs `et` under `f` (see [`full`]).
fn runs(et: &str, f: Solve) -> bool {
    full()
        || !(matches!(f, Solve::Implicit(Method::Vbd, _) | Solve::Mixed(Method::Vbd, _)) && matches!(et, "p3" | "q2"))
}

/// After release, every node within this fraction of the body's size of its rest position (or,
/// for a body free to move, of the rigidly aligned rest shape).
const REST_TOLERANCE: f64 = 1e-3;

/// Reference points per unit length where `det F` is sampled besides the quadrature points
/// ([`min_det_f_sampled`]).
const SAMPLE_LEVELS: usize = 12;

/// Fails listing `problems` (what [`configurations`] returned), if any.
fn none(problems: &[String]) {
    assert!(problems.is_empty(), "{} configuration(s):\n{}", problems.len(), problems.join("\n"));
}

/// Runs `run` for every element type in `types` and configuration in `configs`, prints a
/// `PASS`/`FAIL` line per configuration with its figures and seconds (docs/STABILITY.md's
/// tables), and returns the failures not listed in `known` ("p3 energy", "p1 vbd euler", …) —
/// and a listed one that now passes, so the list (and the table) cannot go stale.
fn configurations(
    case: &str,
    types: &[&str],
    configs: &[Solve],
    known: &[&str],
    run: impl Fn(&str, Solve) -> Result<String, String>,
) -> Vec<String> {
    let mut problems = Vec::new();
    for et in types {
        for &f in configs {
            let label = format!("{et} {f}");
            if !runs(et, f) {
                eprintln!("SKIP {case} | {et} | {f} | HOX_ROBUSTNESS_FULL=1 runs it");
                continue;
            }
            let expected_to_fail = known.contains(&label.as_str());
            let clock = std::time::Instant::now();
            let outcome = run(et, f).map(|figures| format!("{figures} [{:.1} s]", clock.elapsed().as_secs_f64()));
            match (outcome, expected_to_fail) {
                (Ok(figures), false) => eprintln!("PASS {case} | {et} | {f} | {figures}"),
                (Ok(figures), true) => {
                    eprintln!("FIXED {case} | {et} | {f} | {figures}");
                    problems.push(format!("{label}: listed as a known failure but passes now ({figures}): update the list and docs/STABILITY.md"));
                }
                (Err(why), true) => eprintln!("FAIL (known) {case} | {et} | {f} | {why}"),
                (Err(why), false) => {
                    eprintln!("FAIL {case} | {et} | {f} | {why}");
                    problems.push(format!("{case}, {label}: {why}"));
                }
            }
        }
    }
    problems
}

/// After the release: no element inverted and back at the rest shape (absolute, or after rigid
/// alignment for a `free` body) within [`REST_TOLERANCE`] × size.
fn recovered(sim: &Simulation, after: &Health, free: bool) -> Result<String, String> {
    let size = size_m(sim.mesh());
    let distance = if free {
        distance_to_rest_shape_m(&sim.mesh().rest_positions, &sim.positions)
    } else {
        after.max_displacement_m
    };
    let m = after.min_det_f;
    if !(m.det_f > 0.0) {
        return Err(format!(
            "element {} of block {} left inverted after release: det F = {:.3e} at quadrature point {}",
            m.element, m.block, m.det_f, m.point
        ));
    }
    let (sampled, block, element, r) = min_det_f_sampled(sim.mesh(), &sim.positions, SAMPLE_LEVELS);
    if !(sampled > 0.0) {
        return Err(format!(
            "element {element} of block {block} left inverted between its quadrature points after release: det F = {sampled:.3e} at r = {r:.3?} (min over quadrature points {:.3})",
            m.det_f
        ));
    }
    if !(distance <= REST_TOLERANCE * size) {
        return Err(format!(
            "{:.2e} × size from the rest shape after release (tolerance {REST_TOLERANCE:e}), min det F {:.3}",
            distance / size,
            m.det_f
        ));
    }
    Ok(format!("back to rest within {:.1e} × size, min det F {:.4}", distance / size, m.det_f.min(sampled)))
}

/// `[0, L] × [0, L/4] × [0, L/4]` cut into `cells_x × 1 × 1` cells.
fn beam(et: &str, length_m: f64, cells_x: usize) -> Mesh {
    box_mesh(et, [length_m, 0.25 * length_m, 0.25 * length_m], [cells_x, 1, 1])
}

fn sim(
    mesh: Mesh,
    material: Material,
    solve: Solve,
    substeps: u32,
    fps: f64,
    effects: Vec<Box<dyn Effect>>,
) -> Simulation {
    Simulation::new(mesh, material, solve.settings(substeps, fps), effects).unwrap_or_else(|e| panic!("{e}"))
}

/// Frames in `secs` seconds at `fps`.
fn frames(secs: f64, fps: f64) -> u64 {
    (secs * fps).round() as u64
}

// ---------------------------------------------------------------------------------------------
// Case 1: elements inverted at the start.

/// A cantilever `[0, 0.5] × [0, 0.125]²` (2 cells) clamped at x = 0 with velocity damping
/// `damping_per_sec`, every node mirrored through the clamped face (`x → −x`): every element
/// inverted, `F = diag(−1, 1, 1)`.
fn mirrored_cantilever(et: &str, model: MaterialModel, formulation: Solve, damping_per_sec: f64) -> Simulation {
    let mesh = beam(et, 0.5, 2);
    let clamp = clamp_x0(&mesh);
    let damping: Box<dyn Effect> = Box::new(Damping { rate_per_sec: damping_per_sec });
    let mut s = sim(mesh, material(model, 1.0e5, 0.3), formulation, 50, 60.0, vec![clamp, damping]);
    s.positions.iter_mut().for_each(|x| x.x = -x.x);
    s
}

/// The free corner `(L, 0, 0)` of the same cantilever (damped at 10/s) mirrored through the cell
/// face `x = L − h` (h: the cell length) to `(L − 2h, 0, 0)`: the elements holding it are
/// inverted (curved and partly inverted for P2/P3, whose edge nodes stay put).
fn corner_pushed_through(et: &str, model: MaterialModel, formulation: Solve) -> Simulation {
    let mut s = mirrored_cantilever(et, model, formulation, 10.0);
    let rest = s.mesh().rest_positions.clone();
    s.positions.copy_from_slice(&rest);
    let (l, h) = (0.5, 0.25);
    let corner = rest.iter().position(|p| (p - Vec3::new(l, 0.0, 0.0)).norm() < 1e-12).expect("corner node");
    s.positions[corner].x = 2.0 * (l - h) - l;
    s
}

/// Runs an inverted start for `secs`. No external work is done, so the total energy may not
/// grow: bound `growth × H(0) + 1 nJ` (`growth` = 1 + 1e-6 unless stated).
fn run_inverted(mut s: Simulation, secs: f64, growth: f64) -> Result<(Simulation, Health, Health, Trace), String> {
    let start = health(&s, Vec3::zeros());
    if !(start.min_det_f.det_f < 0.0) {
        return Err(format!("the start is not inverted: min det F = {}", start.min_det_f.det_f));
    }
    let bound_j = (growth + energy_slack(&s)) * start.total_j() + 1e-9;
    let trace = run_checked(&mut s, frames(secs, 60.0), Vec3::zeros(), bound_j)?;
    let end = health(&s, Vec3::zeros());
    Ok((s, start, end, trace))
}

/// Stable Neo-Hookean is defined for `J ≤ 0` and pushes inverted elements back: the mirrored
/// cantilever unfolds through the clamped face to its rest shape within 5 s at a damping of
/// 10/s — except P3, which needs the lighter damping of 2/s (8 s) to get through; see
/// [`p3_mirrored_under_strong_damping_is_trapped_inverted_between_its_quadrature_points`].
#[test]
fn stable_neo_hookean_recovers_from_elements_mirrored_through_a_face() {
    none(&mirrored_snh(&BOTH, &[]));
}

fn mirrored_snh(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("1 mirrored, snh", &element_types(), configs, known, |et, f| {
        let (damping, secs) = if et == "p3" { (2.0, 8.0) } else { (10.0, 5.0) };
        let (s, start, end, _) = run_inverted(mirrored_cantilever(et, SNH, f, damping), secs, 1.0 + 1e-6)?;
        Ok(format!("damping {damping}/s, U(0) = {:.3e} J; {}", start.elastic_j, recovered(&s, &end, false)?))
    })
}

/// A known limitation, kept visible: under strong damping (10/s) the mirrored P3 cantilever
/// stops, its kinetic energy gone, in a state where every quadrature point has `det F > 0` but
/// the element is inverted between them. Not a quadrature artefact: the same run with the
/// tetrahedron's collapsed Gauss rule of degree 17 (1,000 points per element, reaching to within
/// 0.013 of every face; [`trapped_states_are_minima_of_the_near_exactly_integrated_energy`])
/// stops in the same kind of state with the inversion seen at a quadrature point — a local
/// minimum of the stable Neo-Hookean energy itself, which gives inversion a finite cost. If
/// this test starts failing, the trap is gone: update docs/STABILITY.md.
#[test]
fn p3_mirrored_under_strong_damping_is_trapped_inverted_between_its_quadrature_points() {
    for f in BOTH {
        let (s, _, end, _) = run_inverted(mirrored_cantilever("p3", SNH, f, 10.0), 5.0, 1.0 + 1e-6).unwrap();
        let why = recovered(&s, &end, false).expect_err("P3 mirrored at 10/s damping was expected to be trapped");
        assert!(end.min_det_f.det_f > 0.0 && why.contains("between its quadrature points"), "{f}: {why}");
        assert!(
            end.kinetic_j < 1e-6 * end.elastic_j,
            "{f}: still moving: T = {:.2e} J, U = {:.2e} J",
            end.kinetic_j,
            end.elastic_j
        );
        eprintln!(
            "KNOWN 1 mirrored, snh, damping 10/s | p3 | {f} | {why}; at rest: T = {:.1e} J, U = {:.3e} J",
            end.kinetic_j, end.elastic_j
        );
    }
}

/// The trapped states (P3 mirrored at damping 10/s; P2 and P3 stretched to 3× and released) are
/// local minima of the stable Neo-Hookean energy, not of its quadrature: rerun with the
/// tetrahedron's collapsed Gauss rule of degree 17 (1,000 points per element instead of 11 or 24),
/// each still comes to rest (`T < 10⁻⁶ U`) away from the rest shape with an element inverted,
/// now seen at a quadrature point, or inverted between them. Release only (1,000-point elements);
/// `.ci/run` checks each state with the energy formulation (7–8 minutes for both formulations,
/// session 22), `HOX_ROBUSTNESS_FULL=1` with the split one too.
#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn trapped_states_are_minima_of_the_near_exactly_integrated_energy() {
    let formulations: &[Solve] = if full() { &BOTH } else { &BOTH[..1] };
    if !full() {
        eprintln!("SKIP trapped with degree-17 quadrature | {} | HOX_ROBUSTNESS_FULL=1 runs it", BOTH[1]);
    }
    let near_exact = |mut s: Simulation| {
        let mut settings = *s.settings();
        settings.quadrature_degree = Some(17);
        s.set_settings(settings).unwrap_or_else(|e| panic!("{e}"));
        s
    };
    let mut trapped = Vec::new();
    for &f in formulations {
        let (s, _, end, _) =
            run_inverted(near_exact(mirrored_cantilever("p3", SNH, f, 10.0)), 5.0, 1.0 + 1e-6).unwrap();
        trapped.push((format!("1 mirrored, damping 10/s | p3 | {f}"), recovered(&s, &end, false), end));
    }
    for et in ["p2", "p3"] {
        for &f in formulations {
            let (s, bound_j) = driven_cantilever(et, SNH, f, stretch(2.0, 1.0), 2.0);
            let mut s = near_exact(s);
            let (_, end) = drive_then_release(&mut s, 1.0, bound_j).unwrap_or_else(|e| panic!("{et} {f}: {e}"));
            trapped.push((format!("4 stretch 3× | {et} | {f}"), recovered(&s, &end, false), end));
        }
    }
    for (what, outcome, end) in trapped {
        let why = outcome.expect_err(&format!("{what}: recovered with near-exact integration: the trap is a quadrature artefact after all (update docs/STABILITY.md)"));
        assert!(
            end.kinetic_j < 1e-6 * end.elastic_j,
            "{what}: still moving: T = {:.2e} J, U = {:.2e} J",
            end.kinetic_j,
            end.elastic_j
        );
        eprintln!(
            "KNOWN trapped with degree-17 quadrature | {what} | {why}; at rest: T = {:.1e} J, U = {:.3e} J",
            end.kinetic_j, end.elastic_j
        );
    }
}

#[test]
fn stable_neo_hookean_recovers_from_a_corner_pushed_through_its_element() {
    none(&corner_snh(&BOTH, &[]));
}

fn corner_snh(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("1 corner through, snh", &element_types(), configs, known, |et, f| {
        let (s, start, end, _) = run_inverted(corner_pushed_through(et, SNH, f), 3.0, 1.0 + 1e-6)?;
        Ok(format!("min det F(0) = {:.3}; {}", start.min_det_f.det_f, recovered(&s, &end, false)?))
    })
}

/// StVK's known weakness: `ψ` depends on `FᵀF` only, so a mirrored element (`F = diag(−1,1,1)`,
/// `FᵀF = I`) has zero energy and no restoring force — the mirrored cantilever is a rest state
/// and stays inverted. The suite checks it stays bounded (finite, energy not growing) and that
/// it does stay mirrored, as documented.
#[test]
fn stvk_mirrored_through_a_face_is_a_rest_state_it_stays_in_bounded() {
    none(&mirrored_stvk(&BOTH, &[]));
}

fn mirrored_stvk(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("1 mirrored, stvk", &element_types(), configs, known, |et, f| {
        let (_, start, end, _) = run_inverted(mirrored_cantilever(et, STVK, f, 10.0), 1.0, 1.0 + 1e-6)?;
        if !(start.elastic_j.abs() < 1e-9 && end.max_displacement_m > 0.4) {
            return Err(format!(
                "expected the zero-energy mirrored rest state to stay: U(0) = {:.3e}, displacement {:.3}",
                start.elastic_j, end.max_displacement_m
            ));
        }
        Ok(format!("stays mirrored, U = {:.1e} J, min det F {:.3}", end.elastic_j, end.min_det_f.det_f))
    })
}

/// A corner pushed through its element with StVK: bounded (finite, energy not growing); whether
/// it recovers is reported, not required (docs/STABILITY.md).
#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn stvk_corner_pushed_through_its_element_stays_bounded() {
    none(&corner_stvk(&BOTH, &[]));
}

fn corner_stvk(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("1 corner through, stvk", &element_types(), configs, known, |et, f| {
        let (s, _, end, _) = run_inverted(corner_pushed_through(et, STVK, f), 3.0, 1.0 + 1e-6)?;
        Ok(match recovered(&s, &end, false) {
            Ok(r) => format!("recovers: {r}"),
            Err(e) => format!("bounded, does not recover: {e}"),
        })
    })
}

/// Compressible Neo-Hookean below its `J` floor (`ln J` continued linearly from `J = 0.2`,
/// `hox_sim::material::NEO_HOOKEAN_J_FLOOR`): an inverted element carries a quadratic penalty,
/// which pushes it back. No external work: `H ≤ H(0)` (+ 10⁻⁶) at every frame. Recovery is
/// reported, not required (curved P2/P3 elements can stay folded between their quadrature
/// points): use stable Neo-Hookean when elements may invert.
#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn neo_hookean_inverted_starts_stay_bounded() {
    none(&inverted_nh(&BOTH, &[]));
}

fn inverted_nh(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("1 inverted, nh", &element_types(), configs, known, |et, f| {
        let mut out = Vec::new();
        for (what, s) in
            [("mirrored", mirrored_cantilever(et, NH, f, 10.0)), ("corner", corner_pushed_through(et, NH, f))]
        {
            let (s, start, end, trace) = run_inverted(s, 3.0, 1.0 + 1e-6)?;
            let spike = trace.max_total_j / start.total_j();
            out.push(match recovered(&s, &end, false) {
                Ok(r) => format!("{what}: peak H/H(0) {spike:.2e}, recovers, {r}"),
                Err(e) => format!("{what}: peak H/H(0) {spike:.2e}, bounded, does not recover: {e}"),
            });
        }
        Ok(out.join("; "))
    })
}

// ---------------------------------------------------------------------------------------------
// Loaded cantilevers: gravity, then release.

/// A cantilever `[0, L] × [0, L/4]²` of `cells_x` cells, clamped at x = 0, under gravity.
fn gravity_cantilever(
    et: &str,
    length_m: f64,
    cells_x: usize,
    material: Material,
    formulation: Solve,
    substeps: u32,
    fps: f64,
) -> Simulation {
    let mesh = beam(et, length_m, cells_x);
    let clamp = clamp_x0(&mesh);
    sim(mesh, material, formulation, substeps, fps, vec![clamp, Box::new(Gravity::new(GRAVITY_M_S2))])
}

/// Gravity for `load_secs` (no damping), then released (gravity removed, damping
/// `damping_per_sec`) for `release_secs`. Bound while loaded: `H ≤ 0.01 × |V_g|max` — the
/// body starts at rest with `H = 0` and XPBD only dissipates, so 1 % of the work scale of gravity
/// is the allowance for a non-monotone numerical energy; after release `H` may not exceed its
/// value at release (+1 nJ).
fn load_and_release(s: Simulation, load_secs: f64, damping_per_sec: f64, release_secs: f64) -> Result<String, String> {
    load_and_release_within(s, load_secs, damping_per_sec, release_secs, 0.01)
}

/// [`load_and_release`] with the allowance `H ≤ allowance × |V_g|max` while loaded.
fn load_and_release_within(
    mut s: Simulation,
    load_secs: f64,
    damping_per_sec: f64,
    release_secs: f64,
    allowance: f64,
) -> Result<String, String> {
    let fps = s.settings().frames_per_second;
    // a first pass without a bound finds the work scale; the same run is then checked frame by frame
    let mut probe_run = Simulation::new(
        s.mesh().clone(),
        *s.material(),
        *s.settings(),
        vec![clamp_x0(s.mesh()), Box::new(Gravity::new(GRAVITY_M_S2))],
    )
    .map_err(|e| e.to_string())?;
    let scale = run_checked(&mut probe_run, frames(load_secs, fps), GRAVITY_M_S2, f64::INFINITY)?.max_gravity_work_j;
    let slack = energy_slack(&s);
    let loaded = run_checked(&mut s, frames(load_secs, fps), GRAVITY_M_S2, (allowance + slack) * scale)?;
    let at_release = health(&s, Vec3::zeros());
    let release_bound_j = at_release.total_j() + slack * at_release.total_j().abs().max(scale) + 1e-9;
    let after = release(&mut s, &["gravity"], damping_per_sec, frames(release_secs, fps), release_bound_j)?;
    Ok(format!(
        "{} substeps (h·ω_max {:.2}), max sag {:.3e} m, max H {:.2e} J ({:+.1e} of |V_g| {:.2e} J), min det F loaded {:.3}; {}",
        s.substeps_per_frame(),
        s.stability().omega_max_rad_s * s.substep_dt_secs(),
        loaded.max_displacement_m,
        loaded.max_total_j,
        loaded.max_total_j / scale,
        scale,
        loaded.min_det_f,
        recovered(&s, &after, false)?
    ))
}

// ---------------------------------------------------------------------------------------------
// Case 2: near incompressibility.

/// ν = 0.45, 0.49, 0.499 (λ/μ = 9, 49, 499): a cantilever (1 m, 4 cells, E = 10⁶ Pa) under
/// gravity for 1 s, released (damping 10/s, 3 s); stable Neo-Hookean and StVK. The stiff
/// volumetric response (`h ω_max` grows as `√λ`) lets the energy overshoot by a few % of the
/// work of gravity in the first frames (measured up to 5.3 %: Q2, energy formulation, ν = 0.49,
/// `h ω_max` 1.43): the bound here is 10 % of `|V_g|max`. With the energy formulation at
/// ν ≥ 0.45 the stability guard steps in from `h ω_max` 1.5 on
/// ([`hox_sim::solver::stability::guard_trigger_h_omega`]; at 1.57–2.09 it overshot by 10–17 % with the
/// trigger of 3). P1's locking shows as a much smaller sag (figures printed; the static
/// comparison is in docs/STABILITY.md).
#[test]
fn near_incompressible_cantilevers_do_not_blow_up() {
    none(&near_incompressible(SNH, &BOTH, &[]));
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn near_incompressible_stvk_cantilevers_do_not_blow_up() {
    none(&near_incompressible(STVK, &BOTH, &[]));
}

/// The near-incompressible family; `known` lists the known failures per ν.
fn near_incompressible(model: MaterialModel, configs: &[Solve], known: &[(f64, &[&str])]) -> Vec<String> {
    let mut problems = Vec::new();
    for nu in [0.45, 0.49, 0.499] {
        let known = known.iter().find(|(v, _)| *v == nu).map_or(&[][..], |(_, k)| *k);
        problems.extend(configurations(&format!("2 ν = {nu}, {model}"), &element_types(), configs, known, |et, f| {
            load_and_release_within(
                gravity_cantilever(et, 1.0, 4, material(model, 1.0e6, nu), f, 50, 60.0),
                1.0,
                10.0,
                3.0,
                0.1,
            )
        }));
    }
    if model != SNH {
        // StVK: reported (PASS/FAIL lines); only a solver stop (NaN) fails the test
        problems.retain(|p| p.contains("solver:"));
    }
    problems
}

/// Case 2 with the cure (issue #62): the cantilever of [`near_incompressible`] at ν = 0.499 and
/// 0.4999 (λ/μ = 499, 4999), Neo-Hookean (the mixed formulation refuses stable Neo-Hookean, whose
/// deviatoric term is not stable alone), with the mixed formulation on every solver: P2, P3 and Q2
/// with one pressure per element, P1 with one per node (Newton and Newton-CG through the patch
/// terms, XPBD with a constraint per node patch, VBD's node updates reading every patch around
/// the node). The same bounds as the energy formulation's family.
#[test]
#[ignore = "release: CI runs it with --release --ignored (ν = 0.4999 under XPBD's stability guard)"]
fn near_incompressible_cantilevers_with_the_mixed_formulation_do_not_blow_up() {
    none(&near_incompressible_mixed(&[]));
}

fn near_incompressible_mixed(known: &[(f64, &[&str])]) -> Vec<String> {
    let mut problems = Vec::new();
    for nu in [0.499, 0.4999] {
        let known = known.iter().find(|(v, _)| *v == nu).map_or(&[][..], |(_, k)| *k);
        let case = format!("2 ν = {nu}, {NH}, mixed");
        // VBD at ν = 0.4999 (λ/μ = 4999) converges slowly on the elements with a pressure per
        // element: the P2 cantilever had not finished after 3 minutes (session 34), so only
        // [`full`] runs them; P1's node patches take seconds
        let slow = |m: Method| m == Method::Vbd && nu > 0.499 && !full();
        if Method::ALL.into_iter().any(slow) {
            eprintln!("SKIP {case} | p2, p3, q2 | vbd euler mixed | HOX_ROBUSTNESS_FULL=1 runs it");
        }
        let every: Vec<Solve> = Method::ALL.into_iter().map(|m| Solve::Mixed(m, Integrator::Euler)).collect();
        let quick: Vec<Solve> =
            Method::ALL.into_iter().filter(|&m| !slow(m)).map(|m| Solve::Mixed(m, Integrator::Euler)).collect();
        let run = |et: &str, f: Solve| {
            load_and_release_within(
                gravity_cantilever(et, 1.0, 4, material(NH, 1.0e6, nu), f, 50, 60.0),
                1.0,
                10.0,
                3.0,
                0.1,
            )
        };
        problems.extend(configurations(&case, &["p1"], &every, known, run));
        problems.extend(configurations(&case, &["p2", "p3", "q2"], &quick, known, run));
    }
    problems
}

// ---------------------------------------------------------------------------------------------
// Case 3: stiffness extremes.

/// Runs a gravity-loaded cantilever (1 m, 4 cells, stable Neo-Hookean, ν = 0.3) for 3 s with
/// the stability guard off (exactly the substeps asked for) and returns the largest
/// `H / |V_g|max` (1 % is the bound of the passing cases; NaN when the solver's guard stopped it).
fn energy_gain(et: &str, f: Solve, youngs_modulus_pa: f64, substeps: u32, fps: f64) -> f64 {
    let mut s = unguarded(gravity_cantilever(et, 1.0, 4, material(SNH, youngs_modulus_pa, 0.3), f, substeps, fps));
    run_checked(&mut s, frames(3.0, fps), GRAVITY_M_S2, f64::INFINITY)
        .map(|t| t.max_total_j / t.max_gravity_work_j)
        .unwrap_or(f64::NAN)
}

/// The same simulation with the stability guard off.
fn unguarded(mut s: Simulation) -> Simulation {
    let settings = hox_sim::solver::SolverSettings { stability_guard: false, ..*s.settings() };
    s.set_settings(settings).unwrap();
    assert_eq!(s.substeps_per_frame(), settings.substeps);
    s
}

/// Case 3 and 6 under the stability guard (on by default): the cantilever of
/// [`energy_gain`] with `substeps` asked for at `fps`, loaded by gravity 1 s and released
/// (damping `damping_per_sec` for `release_secs`), with the bound of every gravity case
/// (`H ≤ 1 %` of the work of gravity). The guard takes the substeps the stiffest element needs
/// (`h ω_max ≤ 1`).
fn guarded_cantilever(
    et: &str,
    model: MaterialModel,
    f: Solve,
    youngs_modulus_pa: f64,
    substeps: u32,
    fps: f64,
    damping_per_sec: f64,
    release_secs: f64,
) -> Result<String, String> {
    let mut s = gravity_cantilever(et, 1.0, 4, material(model, youngs_modulus_pa, 0.3), f, substeps, fps);
    if let Solve::Implicit(..) = f {
        // no guard: the implicit solvers take their one step per frame, however stiff
        return Ok(format!("1 step per frame; {}", load_and_release(s, 1.0, damping_per_sec, release_secs)?));
    }
    let guard = s.stability();
    if !guard.raised() {
        return Err(format!("the guard did not raise the substeps: {}", guard.summary()));
    }
    Ok(format!(
        "{} substeps instead of {substeps} (h·ω_max {:.1} asked); {}",
        guard.substeps,
        guard.requested_h_omega,
        load_and_release(s, 1.0, damping_per_sec, release_secs)?
    ))
}

/// Case 3: E = 10⁹ Pa asked for with one substep per frame at 60 fps (`h ω_max ≈ 10²–10³`):
/// the stability guard cuts the frame into the substeps the stiffest element needs, and the
/// cantilever loads and releases within the bounds of the soft cases.
#[test]
#[ignore = "release: CI runs it with --release --ignored (hundreds of substeps per frame)"]
fn a_stiff_cantilever_with_one_substep_per_frame_is_stable_under_the_stability_guard() {
    none(&stiff(&BOTH, &[]));
}

fn stiff(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("3 E = 1e9 Pa, 1 substep asked, guard, snh", &element_types(), configs, known, |et, f| {
        guarded_cantilever(et, SNH, f, 1.0e9, 1, 60.0, 10.0, 2.0)
    })
}

/// **Known failure (case 3) without the stability guard, kept visible.** E = 10⁹ Pa with a
/// single substep per frame at 60 fps (`h ω_max ≈ 10²`): the element constraints are
/// effectively hard and one Gauss–Seidel sweep per frame pumps energy in — the total energy
/// grows by orders of magnitude over the work gravity did, and the beam collapses (positions
/// stay finite over these 3 s). See docs/STABILITY.md for the measured stability limit. If this
/// test fails, the solver itself became stable there: update docs/STABILITY.md.
#[test]
fn known_failure_without_the_guard_a_stiff_cantilever_with_one_substep_per_frame_gains_energy() {
    for et in ["p1", "p2", "q1"] {
        for f in BOTH {
            let gain = energy_gain(et, f, 1.0e9, 1, 60.0);
            eprintln!("KNOWN 3 E = 1e9 Pa, 1 substep, guard off, snh | {et} | {f} | H/|V_g| up to {gain:.2e}");
            assert!(
                !(gain <= 1.0),
                "{et} {f}: E = 1e9 Pa at 1 substep no longer gains energy ({gain:.2e}): update docs/STABILITY.md"
            );
        }
    }
}

/// The same cantilever is stable at 1 substep per frame below the stability limit: P1 at
/// E = 10⁴ Pa (`h ω_max ≈ 0.4`, with `ω_max ≈ 2 c/ℓ`, `c = √(E/ρ)`, `ℓ` = 0.25 m).
#[test]
fn the_one_substep_cantilever_is_stable_below_the_stability_limit() {
    for f in BOTH {
        let gain = energy_gain("p1", f, 1.0e4, 1, 60.0);
        eprintln!("PASS 3 E = 1e4 Pa, 1 substep, snh | p1 | {f} | H/|V_g| up to {gain:.2e}");
        assert!(gain <= 0.01, "{f}: {gain}");
    }
}

/// E = 10³ Pa (a jelly): a 0.1 m cantilever hangs down under its own weight (strains of order
/// one: `ρ g L / E ≈ 1`, and P1 elements invert, `det F` down to −0.56), then springs back
/// (damping 5/s, 6 s). Stable Neo-Hookean with Smith et al.'s log term (`snh-log`): the paper's
/// form is [`known_failure_a_very_soft_p1_cantilever_with_the_papers_stable_neo_hookean_stays_hanging`].
#[test]
fn a_very_soft_cantilever_hangs_and_springs_back() {
    none(&soft_snh_log(&BOTH, &[]));
}

fn soft_snh_log(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("3 E = 1e3 Pa, snh-log", &element_types(), configs, known, |et, f| {
        load_and_release(gravity_cantilever(et, 0.1, 4, material(SNH_LOG, 1.0e3, 0.3), f, 50, 60.0), 2.0, 5.0, 6.0)
    })
}

/// **Known failure (case 3, E = 10³ Pa), kept visible.** With the paper's stable Neo-Hookean (no
/// `log(I_C + 1)` term), every type but P1 springs back; the P1 jelly, whose elements invert
/// under its own weight, settles in a non-rest equilibrium about its own length away (min
/// `det F` ≈ 0.63, not inverted) — the model's energy is not convex there; `snh-log` returns.
#[test]
fn known_failure_a_very_soft_p1_cantilever_with_the_papers_stable_neo_hookean_stays_hanging() {
    none(&soft_snh(&BOTH, &["p1 energy", "p1 split"]));
}

fn soft_snh(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("3 E = 1e3 Pa, snh", &element_types(), configs, known, |et, f| {
        load_and_release(gravity_cantilever(et, 0.1, 4, material(SNH, 1.0e3, 0.3), f, 50, 60.0), 2.0, 5.0, 6.0)
    })
}

// ---------------------------------------------------------------------------------------------
// Case 4: extreme deformation.

/// Drives the face x = L of a clamped beam (`[0, 1] × [0, 0.25]²`, 4 cells, E = 10⁵ Pa,
/// ν = 0.3, light damping 2/s) by `drive` over `ramp_secs`, holds it 0.5 s, releases it
/// (the prescribed nodes get their mass back, damping 5/s) for 5 s. Bound on `H = T + U`:
/// `10 μ V s²`, `s` the load's characteristic strain (the elastic energy of a uniform strain `s`
/// is of order `μ V s²`; a blow-up exceeds it by orders of magnitude).
fn drive_and_release(
    et: &str,
    model: MaterialModel,
    f: Solve,
    drive: impl Fn(Vec<u32>) -> Prescribed,
    ramp_secs: f64,
    strain: f64,
) -> Result<String, String> {
    let (mut s, bound_j) = driven_cantilever(et, model, f, drive, strain);
    let (driven, after) = drive_then_release(&mut s, ramp_secs, bound_j)?;
    Ok(format!(
        "max U {:.3e} J (bound {bound_j:.2e}), min det F driven {:.3}; {}",
        driven.max_elastic_j,
        driven.min_det_f,
        recovered(&s, &after, false)?
    ))
}

/// The cantilever of [`drive_and_release`] with its drive and light damping, and the bound on
/// `H = T + U`.
fn driven_cantilever(
    et: &str,
    model: MaterialModel,
    f: Solve,
    drive: impl Fn(Vec<u32>) -> Prescribed,
    strain: f64,
) -> (Simulation, f64) {
    let mesh = beam(et, 1.0, 4);
    let end = nodes_on_plane(&mesh, 0, 1.0);
    let clamp = clamp_x0(&mesh);
    let mat = material(model, 1.0e5, 0.3);
    let volume_m3 = 0.0625;
    let bound_j = 10.0 * mat.lame().mu_pa * volume_m3 * strain * strain;
    (sim(mesh, mat, f, 50, 60.0, vec![clamp, Box::new(drive(end)), Box::new(Damping { rate_per_sec: 2.0 })]), bound_j)
}

/// Runs a [`driven_cantilever`] through its ramp and 0.5 s of hold, then releases it (drive and
/// light damping removed, damping 5/s) for 5 s, with `H ≤ bound_j` throughout.
fn drive_then_release(s: &mut Simulation, ramp_secs: f64, bound_j: f64) -> Result<(Trace, Health), RunFailure> {
    let driven = run_checked(s, frames(ramp_secs + 0.5, 60.0), Vec3::zeros(), bound_j)?;
    let after = release(s, &["prescribed", "damping"], 5.0, frames(5.0, 60.0), bound_j)?;
    Ok((driven, after))
}

fn twist(turns_deg: f64, ramp_secs: f64) -> impl Fn(Vec<u32>) -> Prescribed {
    move |nodes| Prescribed {
        nodes,
        translation_m: Vec3::zeros(),
        rotation: Some(AxisRotation {
            axis: Vec3::x(),
            origin_m: Vec3::new(1.0, 0.125, 0.125),
            angle_rad: turns_deg.to_radians(),
        }),
        ramp_secs,
    }
}

fn stretch(by_m: f64, ramp_secs: f64) -> impl Fn(Vec<u32>) -> Prescribed {
    move |nodes| Prescribed { nodes, translation_m: Vec3::new(by_m, 0.0, 0.0), rotation: None, ramp_secs }
}

/// Torsion to 720°: shear strain `θ r / L` = 4π × 0.177 ≈ 2.2 at the corners.
#[test]
fn torsion_to_720_degrees_and_back() {
    none(&torsion(&BOTH, &[]));
}

fn torsion(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("4 torsion 720°, snh", &element_types(), configs, known, |et, f| {
        drive_and_release(et, SNH, f, twist(720.0, 2.0), 2.0, 4.0 * std::f64::consts::PI * 0.177)
    })
}

/// Stretch to three times the length (strain 2), released at once. Compressible Neo-Hookean
/// (`ln J` resists the compression of the snap-back, which no element passes through): every
/// type and formulation returns. Stable Neo-Hookean, whose compression energy stays finite down
/// to and through `J = 0`: the P2 and P3 beams snap back past the clamped face and stop in a
/// minimum of that energy with a thin inverted layer (listed; see
/// [`trapped_states_are_minima_of_the_near_exactly_integrated_energy`]).
#[test]
fn stretch_to_three_times_the_length_and_back() {
    none(&stretch_and_back(&BOTH, &[], &["p2 energy", "p2 split", "p3 energy", "p3 split"]));
}

/// The stretch family, `known_nh` and `known_snh` its known failures per material.
fn stretch_and_back(configs: &[Solve], known_nh: &[&str], known_snh: &[&str]) -> Vec<String> {
    let mut problems = configurations("4 stretch 3×, nh", &element_types(), configs, known_nh, |et, f| {
        drive_and_release(et, NH, f, stretch(2.0, 1.0), 1.0, 2.0)
    });
    problems.extend(configurations("4 stretch 3×, snh", &element_types(), configs, known_snh, |et, f| {
        drive_and_release(et, SNH, f, stretch(2.0, 1.0), 1.0, 2.0)
    }));
    problems
}

/// StVK under the same extreme drives: bounded (finite, energy within the bound); recovery
/// reported, not required (StVK softens under compression and can collapse).
#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn stvk_under_extreme_drives_stays_bounded() {
    none(&drives_stvk(&BOTH, &[]));
}

fn drives_stvk(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("4 torsion 720° and stretch 3×, stvk", &element_types(), configs, known, |et, f| {
        let mut out = Vec::new();
        for (what, result) in [
            ("torsion", drive_and_release(et, STVK, f, twist(720.0, 2.0), 2.0, 4.0 * std::f64::consts::PI * 0.177)),
            ("stretch", drive_and_release(et, STVK, f, stretch(2.0, 1.0), 1.0, 2.0)),
        ] {
            out.push(match result {
                Ok(r) => format!("{what}: {r}"),
                Err(e) if e.contains("after release") => format!("{what}: bounded, does not recover: {e}"),
                Err(e) => return Err(format!("{what}: {e}")),
            });
        }
        Ok(out.join("; "))
    })
}

/// A free block `[0, 0.25]³` (2 × 2 × 2 cells) squashed to 10 % of its height between two
/// plates with friction 0.5 (the top plate moves down 0.225 m in 1 s, then stays), held 0.5 s,
/// released (plates removed, damping 10/s) for 3 s; compared with its rest shape after rigid
/// alignment. Bound: `10 μ V s²` with `s` = 0.9.
fn squash(et: &str, model: MaterialModel, f: Solve) -> Result<String, String> {
    let mesh = box_mesh(et, [0.25; 3], [2, 2, 2]);
    let mat = material(model, 1.0e5, 0.3);
    let bound_j = 10.0 * mat.lame().mu_pa * 0.25f64.powi(3) * 0.81;
    let effects: Vec<Box<dyn Effect>> = vec![
        Box::new(ContactPlane::new(Vec3::zeros(), Vec3::z(), Vec3::zeros(), f64::INFINITY, 0.5)),
        Box::new(ContactPlane::new(Vec3::new(0.0, 0.0, 0.25), -Vec3::z(), Vec3::new(0.0, 0.0, -0.225), 1.0, 0.5)),
        Box::new(Damping { rate_per_sec: 2.0 }),
    ];
    let mut s = match Simulation::new(mesh, mat, f.settings(50, 60.0), effects) {
        Ok(s) => s,
        // a solver that cannot honour contact refuses it by name (issue #36: Newton's)
        Err(e @ SimError::Unsupported { .. }) if e.to_string().contains("contact") => {
            return Ok(format!("refused: {e}"));
        }
        Err(e) => return Err(e.to_string()),
    };
    let squashed = run_checked(&mut s, frames(1.5, 60.0), Vec3::zeros(), bound_j)?;
    let height = s.positions.iter().map(|x| x.z).fold(f64::NEG_INFINITY, f64::max)
        - s.positions.iter().map(|x| x.z).fold(f64::INFINITY, f64::min);
    if !(height < 0.1 * 0.25 * 1.05) {
        return Err(format!("squashed height {height:.4} m, not 10 % of 0.25 m"));
    }
    let after = release(&mut s, &["contact", "damping"], 10.0, frames(3.0, 60.0), bound_j)?;
    Ok(format!(
        "height {height:.4} m, max U {:.3e} J, min det F squashed {:.3}; {}",
        squashed.max_elastic_j,
        squashed.min_det_f,
        recovered(&s, &after, true)?
    ))
}

/// Compressible Neo-Hookean's `ln J` term resists collapse (continued below its `J` floor of
/// 0.2 by a quadratic penalty that every element type survives): squashed to 10 % and back.
#[test]
fn squash_to_ten_percent_between_plates_and_back() {
    none(&squash_nh(&BOTH, &[]));
}

fn squash_nh(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("4 squash to 10 %, nh", &element_types(), configs, known, |et, f| squash(et, NH, f))
}

/// Stable Neo-Hookean with Smith et al.'s `log(I_C + 1)` term (`snh-log`): no spurious minimum
/// at `F = 0` (`hox_sim::material::stable_neo_hookean_log`), so squashed elements come back.
#[test]
fn stable_neo_hookean_with_the_log_term_squashed_to_ten_percent_and_back() {
    none(&squash_snh_log(&BOTH, &[]));
}

fn squash_snh_log(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("4 squash to 10 %, snh-log", &element_types(), configs, known, |et, f| squash(et, SNH_LOG, f))
}

/// **Known failure (case 4, squash), kept visible.** Stable Neo-Hookean without Smith et al.'s
/// `log(I_C + 1)` term has a spurious local minimum at `F = 0` (for `F = sI`,
/// `dψ/ds = 3μs + 3λ̂s²(s³ − α) > 0` for small `s`): elements squashed past the barrier
/// (uniform `s ≈ 0.29` at ν = 0.3) collapse to a point and stay there after release.
#[test]
fn known_failure_stable_neo_hookean_squashed_to_ten_percent_keeps_collapsed_elements() {
    for et in ["p1", "q1"] {
        for f in BOTH {
            let why = squash(et, SNH, f).expect_err("SNH squash was expected to leave collapsed elements");
            eprintln!("KNOWN 4 squash to 10 %, snh | {et} | {f} | {why}");
            assert!(why.contains("left inverted"), "{et} {f}: {why}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Case 5: mass and size ratios.

/// A smooth initial deformation: bending `u_z = 0.2 x²/L` and a twist of 0.3 rad per length.
fn bent_and_twisted(rest: &[Vec3], length_m: f64) -> Vec<Vec3> {
    rest.iter()
        .map(|p| {
            let angle = 0.3 * p.x / length_m;
            let (c, s) = (angle.cos(), angle.sin());
            let (y, z) = (p.y - 0.125 * length_m, p.z - 0.125 * length_m);
            Vec3::new(
                p.x,
                0.125 * length_m + c * y - s * z,
                0.125 * length_m + s * y + c * z + 0.2 * p.x * p.x / length_m,
            )
        })
        .collect()
}

/// A free beam `[0, 0.5] × [0, 0.125]²` (2 cells) whose free corner `(0.5, 0, 0)` weighs 10⁴
/// times its lumped mass, started bent and twisted, damped at 10/s for 4 s: back to its rest
/// shape (after rigid alignment). No external work: `H ≤ H(0)`.
#[test]
fn a_node_ten_thousand_times_heavier_than_its_neighbours() {
    none(&heavy_node(&BOTH, &[]));
}

fn heavy_node(configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("5 heavy node ×1e4, snh", &element_types(), configs, known, |et, f| {
        let mesh = beam(et, 0.5, 2);
        let corner =
            mesh.rest_positions.iter().position(|p| (p - Vec3::new(0.5, 0.0, 0.0)).norm() < 1e-12).expect("corner");
        let start = bent_and_twisted(&mesh.rest_positions, 0.5);
        let mut s = sim(mesh, material(SNH, 1.0e5, 0.3), f, 50, 60.0, vec![Box::new(Damping { rate_per_sec: 10.0 })]);
        let heavy_kg = 1e4 * s.masses_kg()[corner];
        s.set_mass_kg(corner, heavy_kg).map_err(|e| e.to_string())?;
        s.positions.copy_from_slice(&start);
        let h0 = health(&s, Vec3::zeros()).total_j();
        let bound_j = h0 * (1.0 + 1e-6 + energy_slack(&s));
        run_checked(&mut s, frames(4.0, 60.0), Vec3::zeros(), bound_j)?;
        let after = health(&s, Vec3::zeros());
        Ok(format!("heavy node {heavy_kg:.1} kg, U(0) = {h0:.3e} J; {}", recovered(&s, &after, true)?))
    })
}

/// Elements 1 mm next to elements 1 m: the box `[0, 2]³` of 2 × 2 × 2 cells mapped per axis
/// (`[0, 1] → [0, 1 mm]`, `[1, 2] → [1 mm, 1.001 m]`), so cells range from 1 mm³ to 1 m³ with
/// 1000:1 slabs between; clamped at x = 0, gravity for 1 s, released. Node masses span nine
/// orders of magnitude and the 1 mm elements have `h ω ≈ 3`: the energy may overshoot up to
/// `|V_g|max` (bound). The 1 mm elements set `h ω_max` above the stability guard's trigger, and with
/// its substeps every configuration passes (before the guard, eight failed: docs/STABILITY.md).
/// `.ci/run` runs P1, P2, Q1, the prism and the pyramid: P3 and Q2, whose 1 mm elements the guard
/// gives thousands of substeps per frame, were 85 % of the test's 7–8 minutes (session 22: P3
/// 164 s for one formulation against 20 s for P2); `HOX_ROBUSTNESS_FULL=1` adds them (`SKIP`
/// lines say so).
#[test]
#[ignore = "release: CI runs it with --release --ignored (the guard takes 309–3,911 substeps per frame)"]
fn elements_one_millimetre_next_to_elements_one_metre() {
    none(&sizes(&types_within_the_ci_budget("5 sizes 1 mm – 1 m, snh"), &BOTH, &[]));
}

/// The element types a family too slow for `.ci/run` on P3 and Q2 runs there (all with
/// [`full`]), each type left out a `SKIP` line.
fn types_within_the_ci_budget(case: &str) -> Vec<&'static str> {
    element_types()
        .into_iter()
        .filter(|et| {
            let kept = full() || !matches!(*et, "p3" | "q2");
            if !kept {
                eprintln!("SKIP {case} | {et} | every formulation | HOX_ROBUSTNESS_FULL=1 runs it");
            }
            kept
        })
        .collect()
}

fn sizes(types: &[&str], configs: &[Solve], known: &[&str]) -> Vec<String> {
    configurations("5 sizes 1 mm – 1 m, snh", types, configs, known, |et, f| {
        let mut mesh = box_mesh(et, [2.0; 3], [2, 2, 2]);
        let map = |c: f64| if c <= 1.0 { 1e-3 * c } else { 1e-3 + (c - 1.0) };
        mesh.rest_positions.iter_mut().for_each(|p| *p = p.map(map));
        let s = gravity_cantilever_from(mesh, material(SNH, 1.0e5, 0.3), f);
        let masses = s.masses_kg();
        let ratio = masses.iter().cloned().fold(0.0, f64::max) / masses.iter().cloned().fold(f64::INFINITY, f64::min);
        Ok(format!("mass ratio {ratio:.1e}; {}", load_and_release_within(s, 1.0, 10.0, 3.0, 1.0)?))
    })
}

fn gravity_cantilever_from(mesh: Mesh, material: Material, formulation: Solve) -> Simulation {
    let clamp = clamp_x0(&mesh);
    sim(mesh, material, formulation, 50, 60.0, vec![clamp, Box::new(Gravity::new(GRAVITY_M_S2))])
}

// ---------------------------------------------------------------------------------------------
// Case 6: large steps.

/// Case 6: 10 frames per second with one substep asked for (`h` = 0.1 s) on the cantilever at
/// E = 10⁵ Pa (`h ω_max` 11–46 asked): the guard's substeps keep it stable; this soft beam hangs
/// far down (strains of order one) and swings back slowly (its first mode is ≈ 2.5 rad/s), so
/// the release is lightly damped (5/s) and 6 s long. Compressible Neo-Hookean: every type and
/// formulation; stable Neo-Hookean: the same but P3, which stops in a minimum of that energy
/// with a thin inverted layer (as in cases 1 and 4), listed.
#[test]
fn ten_frames_per_second_with_one_substep_is_stable_under_the_stability_guard() {
    none(&ten_fps(&BOTH, &[], &["p3 energy", "p3 split"]));
}

/// The large-step family, `known_nh` and `known_snh` its known failures per material.
fn ten_fps(configs: &[Solve], known_nh: &[&str], known_snh: &[&str]) -> Vec<String> {
    let mut problems = configurations(
        "6 10 fps × 1 substep asked, E = 1e5 Pa, guard, nh",
        &element_types(),
        configs,
        known_nh,
        |et, f| guarded_cantilever(et, NH, f, 1.0e5, 1, 10.0, 5.0, 6.0),
    );
    problems.extend(configurations(
        "6 10 fps × 1 substep asked, E = 1e5 Pa, guard, snh",
        &element_types(),
        configs,
        known_snh,
        |et, f| guarded_cantilever(et, SNH, f, 1.0e5, 1, 10.0, 5.0, 6.0),
    ));
    problems
}

/// **Known failure (case 6) without the stability guard, kept visible**: the energy grows by
/// orders of magnitude (see [`known_failure_without_the_guard_a_stiff_cantilever_with_one_substep_per_frame_gains_energy`]).
#[test]
fn known_failure_without_the_guard_ten_frames_per_second_with_one_substep_gains_energy() {
    for et in ["p1", "p2", "q1"] {
        for f in BOTH {
            let gain = energy_gain(et, f, 1.0e5, 1, 10.0);
            eprintln!("KNOWN 6 10 fps × 1 substep, E = 1e5 Pa, guard off, snh | {et} | {f} | H/|V_g| up to {gain:.2e}");
            assert!(
                !(gain <= 1.0),
                "{et} {f}: 10 fps × 1 substep no longer gains energy ({gain:.2e}): update docs/STABILITY.md"
            );
        }
    }
}

/// 10 fps × 1 substep is stable for a soft enough body (`h ω_max ≲ 0.5`): E = 10³ Pa, P1,
/// split formulation; the energy formulation at E = 10³ Pa already gains energy.
#[test]
fn ten_frames_per_second_is_stable_for_a_soft_p1_cantilever_with_the_split_formulation() {
    let gain = energy_gain("p1", Solve::Xpbd(Formulation::Split), 1.0e3, 1, 10.0);
    eprintln!("PASS 6 10 fps × 1 substep, E = 1e3 Pa, snh | p1 | split | H/|V_g| up to {gain:.2e}");
    assert!(gain <= 0.01, "{gain}");
}

// ---------------------------------------------------------------------------------------------
// Case 7: random perturbations of valid rest meshes (property-based).

mod perturbed {
    use super::*;
    use proptest::prelude::*;

    /// The rest mesh moved by a smooth random field (three sinusoids per component, amplitude up
    /// to `amplitude` × the cell size, so that high-order nodes stay consistent with their
    /// elements), plus an independent jitter of the vertex nodes of up to `jitter` × the cell size.
    fn perturb(mesh: &mut Mesh, seed: &[f64], amplitude: f64, jitter: f64, cell_m: f64) {
        let vertex = mesh.vertex_nodes();
        for (i, p) in mesh.rest_positions.iter_mut().enumerate() {
            let q = *p;
            let mut d = Vec3::zeros();
            for c in 0..3 {
                for k in 0..3 {
                    let a = seed[c * 9 + k * 3..c * 9 + k * 3 + 3].to_vec();
                    d[c] += a[0] * (std::f64::consts::PI * (a[1] * q.x + a[2] * q.y + a[0] * q.z) / cell_m).sin() / 3.0;
                }
            }
            *p += d * (amplitude * cell_m);
            if vertex[i] {
                let h = (i as f64 * 12.9898 + seed[27] * 78.233).sin() * 43758.5453;
                let r = [h.fract(), (h * 1.37).fract(), (h * 1.91).fract()];
                *p += Vec3::from(r) * (jitter * cell_m);
            }
        }
    }

    proptest! {
        // a fixed seed: the same 24 meshes on every run and machine (reproducible failures);
        // invalid meshes are checked for a clear error and then rejected, so 24 valid meshes run
        #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0x68_6f_78_08), max_global_rejects: 200, .. ProptestConfig::default() })]
        /// A valid perturbed mesh (or a clear error naming the bad element) that, loaded by gravity
        /// for 0.5 s and released (damping 10/s, 2 s), stays finite, within the energy bound
        /// (`H ≤ 5 % of |V_g|max`) and returns to its rest shape. Stable Neo-Hookean, E = 10⁶ Pa,
        /// ν = 0.3.
        #[test]
        fn randomly_perturbed_rest_meshes_stay_stable(
            et in 0..element_types().len(),
            split in any::<bool>(),
            seed in proptest::collection::vec(-1.0..1.0f64, 28),
            amplitude in 0.0..0.3f64,
            jitter in 0.0..0.2f64,
        ) {
            let et = element_types()[et];
            let f = if split { Formulation::Split } else { Formulation::Energy };
            let mut mesh = beam(et, 0.5, 2);
            perturb(&mut mesh, &seed, amplitude, jitter, 0.125);
            // keep the clamped face planar so the clamp selects it
            let clamped: Vec<u32> = mesh.rest_positions.iter().enumerate().filter(|(_, p)| p.x.abs() < 0.2 * 0.125).map(|(i, _)| i as u32).collect();
            let effects: Vec<Box<dyn Effect>> = vec![Box::new(hox_sim::effect::Clamp { nodes: clamped }), Box::new(Gravity::new(GRAVITY_M_S2))];
            let s = match Simulation::new(mesh, material(SNH, 1.0e6, 0.3), settings(f, 50, 60.0), effects) {
                Ok(s) => s,
                Err(e) => {
                    let message = e.to_string();
                    prop_assert!(message.contains("at rest") && message.contains("element"), "unclear error: {message}");
                    prop_assume!(false, "an invalid rest mesh, refused with a clear error");
                    unreachable!()
                }
            };
            // P3 with the energy formulation overshoots 1 % of |V_g| slightly (1.2 %) even unperturbed
            let result = load_and_release_within(s, 0.5, 10.0, 2.0, 0.05);
            prop_assert!(result.is_ok(), "{et} {f}: {}", result.unwrap_err());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Case 8: the long run.

/// 10,000 frames (167 s) of the bending scene (P2 8×2×2, StVK, 50 substeps, 60 fps) with no
/// damping, both formulations: the total energy `H = T + U + V_g` (0 at the start) never exceeds
/// 5 % of the largest `|V_g|` (it overshoots about 1 % in the first swing), and it does not grow:
/// its largest value over the last 9,000 frames is no more than over the first 1,000.
#[test]
#[ignore = "release: CI runs it with --release --ignored (about a minute)"]
fn ten_thousand_frames_of_the_undamped_bending_scene_do_not_gain_energy() {
    for solve in BOTH {
        long_run(solve, 10_000, 0.0);
    }
}

/// The long run with `solve`: `frames` frames of the undamped bending scene; the largest `H` over
/// the frames after the first 1,000 may exceed the largest over the first 1,000 by at most
/// `growth` × `|V_g|max` (0 for XPBD, which only dissipates).
fn long_run(solve: Solve, frames: u64, growth: f64) {
    let (formulation, method, integrator) = match solve {
        Solve::Xpbd(f) => (Some(f), None, None),
        Solve::Implicit(m, i) => (None, Some(m), Some(i)),
        Solve::Mixed(m, i) => (Some(Formulation::Mixed), Some(m), Some(i)),
    };
    let scene = hox_scenes::by_name("bending")
        .unwrap()
        .with_overrides(&hox_scenes::SceneOverrides { formulation, method, integrator, ..Default::default() })
        .unwrap();
    let mut instance = hox_scenes::Instance::new(scene).unwrap();
    let clock = std::time::Instant::now();
    let (mut early_max, mut late_max) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    let mut last = health(&instance.sim, GRAVITY_M_S2);
    let mut work_j: f64 = 0.0;
    for frame in 1..=frames {
        instance.sim.step_frame().unwrap_or_else(|e| panic!("{solve}: frame {frame}: {e}"));
        last = health(&instance.sim, GRAVITY_M_S2);
        assert!(last.finite, "{solve}: frame {frame}");
        work_j = work_j.max(last.gravity_potential_j.abs());
        if frame <= 1000 {
            early_max = early_max.max(last.total_j());
        } else {
            late_max = late_max.max(last.total_j());
        }
        assert!(
            last.total_j() <= 0.05 * work_j,
            "{solve}: H = {:.4e} J > 5 % of |V_g| = {work_j:.4e} J at frame {frame}",
            last.total_j()
        );
    }
    let max_ratio = early_max.max(late_max) / work_j;
    assert!(
        late_max <= early_max + growth * work_j,
        "{solve}: the energy grows: max H {late_max:.4e} J over frames 1001–{frames} > {early_max:.4e} J over the first 1000 (+ {growth:e} × |V_g|max {work_j:.3e} J)"
    );
    eprintln!(
        "PASS 8 {frames} frames, bending, no damping | p2 | {solve} | max H/|V_g|max {max_ratio:.2e} (frames 1–1000: {early_max:.3e} J, 1001–{frames}: {late_max:.3e} J), H at the end {:.3e} J (|V_g|max {work_j:.3e} J), {} rejected steps, {:.1} s",
        last.total_j(),
        instance.sim.counters().rejected_steps,
        clock.elapsed().as_secs_f64()
    );
}

// ---------------------------------------------------------------------------------------------
// Case 9: invalid input is a clear error (the CLI's side: app/tests/cli.rs).

fn scene_error(edit: impl Fn(&mut String)) -> String {
    let mut text = hox_scenes::BUILTIN.iter().find(|(n, _)| *n == "bending").unwrap().1.to_string();
    edit(&mut text);
    match hox_scenes::Scene::from_toml(&text, "test.toml").and_then(hox_scenes::Instance::new) {
        Ok(_) => panic!("accepted an invalid scene"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn invalid_materials_are_clear_errors_naming_the_parameter() {
    for &model in MaterialModel::ALL {
        for (e, nu, rho, needle) in [
            (1e6, 0.5, 1000.0, "Poisson ratio"),
            (1e6, 0.7, 1000.0, "Poisson ratio"),
            (1e6, f64::NAN, 1000.0, "Poisson ratio"),
            (0.0, 0.3, 1000.0, "Young's modulus"),
            (-1e6, 0.3, 1000.0, "Young's modulus"),
            (f64::INFINITY, 0.3, 1000.0, "Young's modulus"),
            (1e6, 0.3, 0.0, "density"),
            (1e6, 0.3, -5.0, "density"),
            (1e6, 0.3, f64::NAN, "density"),
        ] {
            let err = Material::new(model, e, nu, rho).expect_err("invalid").to_string();
            assert!(err.contains(needle), "{model} E={e} ν={nu} ρ={rho}: {err}");
        }
    }
}

#[test]
fn non_finite_and_invalid_scene_values_are_clear_errors() {
    let cases: [(&str, &str, &str); 8] = [
        ("poisson_ratio = 0.35", "poisson_ratio = 0.5", "material.poisson_ratio"),
        ("poisson_ratio = 0.35", "poisson_ratio = nan", "material.poisson_ratio"),
        ("youngs_modulus_pa = 3.0e6", "youngs_modulus_pa = inf", "material.youngs_modulus_pa"),
        ("youngs_modulus_pa = 3.0e6", "youngs_modulus_pa = -3.0e6", "material.youngs_modulus_pa"),
        ("density_kg_m3 = 1000.0", "density_kg_m3 = 0.0", "material.density_kg_m3"),
        ("substeps = 50", "substeps = 0", "solver.substeps"),
        ("acceleration_m_s2 = [0.0, 0.0, -9.81]", "acceleration_m_s2 = [0.0, nan, -9.81]", "acceleration_m_s2"),
        ("point_m = [2.0, 0.25, 0.25]", "point_m = [3.0, 0.25, 0.25]", "outside the body"),
    ];
    for (from, to, needle) in cases {
        let err = scene_error(|t| {
            assert!(t.contains(from), "the bending scene no longer has `{from}`");
            *t = t.replace(from, to);
        });
        assert!(err.contains(needle) && err.contains("test.toml"), "{to}: {err}");
    }
    let err = scene_error(|t| *t = t.replace("grid = [8, 2, 2]", "grid = [8, 0, 2]"));
    assert!(err.contains("mesh.grid"), "{err}");
    let err = scene_error(|t| *t = t.replace("box_max_m = [2.0, 0.5, 0.5]", "box_max_m = [2.0, 0.0, 0.5]"));
    assert!(err.contains("box_max_m"), "{err}");
}

#[test]
fn degenerate_inverted_and_empty_meshes_and_zero_substeps_are_clear_errors() {
    use hox_sim::mesh::ElementBlock;
    let mat = material(SNH, 1e6, 0.3);
    let tet = |points: [[f64; 3]; 4]| Mesh {
        rest_positions: points.map(Vec3::from).to_vec(),
        blocks: vec![ElementBlock::new(element_type("p1"), vec![0, 1, 2, 3])],
    };
    let new = |mesh: Mesh, st| Simulation::new(mesh, mat, st, Vec::new()).map(|_| ()).expect_err("invalid").to_string();
    let ok = settings(Formulation::Energy, 50, 60.0);
    let flat = new(tet([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]), ok);
    assert!(flat.contains("element 0") && flat.contains("flat"), "{flat}");
    let inverted = new(tet([[0.0; 3], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), ok);
    assert!(inverted.contains("element 0") && inverted.contains("inverted"), "{inverted}");
    // a P2 element whose edge node is pulled through the opposite face: inverted at a quadrature point
    let mut curved = box_mesh("p2", [1.0; 3], [1, 1, 1]);
    let n = curved.blocks[0].element(0)[4] as usize;
    curved.rest_positions[n] += Vec3::new(3.0, 3.0, 3.0);
    let curved = new(curved, ok);
    assert!(curved.contains("inverted") || curved.contains("flat"), "{curved}");
    let empty = new(Mesh { rest_positions: Vec::new(), blocks: Vec::new() }, ok);
    assert!(empty.contains("no elements"), "{empty}");
    let empty_block = new(
        Mesh { rest_positions: vec![Vec3::zeros()], blocks: vec![ElementBlock::new(element_type("p1"), Vec::new())] },
        ok,
    );
    assert!(empty_block.contains("no elements"), "{empty_block}");
    let nan_node = new(tet([[0.0; 3], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0], [0.0, 0.0, 1.0]]), ok);
    assert!(nan_node.contains("non-finite") && nan_node.contains("node 2"), "{nan_node}");
    let unit = tet([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let zero = new(unit.clone(), settings(Formulation::Energy, 0, 60.0));
    // named by the setting's label, from its one declaration (`SolverSettings::RANGES`)
    assert!(zero.to_lowercase().contains("substeps"), "{zero}");
    let fps = new(unit.clone(), settings(Formulation::Energy, 50, f64::NAN));
    assert!(fps.to_lowercase().contains("frames per second"), "{fps}");
    let probe = hox_sim::measure::probe::Probe::locate(&unit, "far", Vec3::new(5.0, 0.0, 0.0))
        .expect_err("outside")
        .to_string();
    assert!(probe.contains("outside the body"), "{probe}");
    let probe = hox_sim::measure::probe::Probe::locate(&unit, "nan", Vec3::new(f64::NAN, 0.0, 0.0))
        .expect_err("non-finite")
        .to_string();
    assert!(probe.contains("non-finite"), "{probe}");
    let mut s = Simulation::new(unit, mat, ok, Vec::new()).unwrap();
    let mass = s.set_mass_kg(0, -1.0).expect_err("negative mass").to_string();
    assert!(mass.contains("node 0") && mass.contains("mass"), "{mass}");
    let mass = s.set_mass_kg(9, 1.0).expect_err("no such node").to_string();
    assert!(mass.contains("node 9"), "{mass}");
}

// ---------------------------------------------------------------------------------------------
// Case 10: the runtime NaN guard.

/// An effect that writes a NaN into one node's position at a given time (a stand-in for any
/// bug or extreme input that brings a NaN into the state).
struct NanAt {
    node: usize,
    at_secs: f64,
}

impl Effect for NanAt {
    fn name(&self) -> &'static str {
        "nan"
    }
    fn after_prediction(&mut self, s: &mut EffectState<'_>) {
        if s.time_secs >= self.at_secs {
            s.positions[self.node].y = f64::NAN;
        }
    }
}

fn guarded(parallel: bool, effects: Vec<Box<dyn Effect>>) -> Simulation {
    let mesh = beam("p2", 1.0, 4);
    let mut st = settings(Formulation::Energy, 50, 60.0);
    st.sweep = if parallel { hox_sim::solver::Sweep::Colour } else { hox_sim::solver::Sweep::Element };
    let mut all: Vec<Box<dyn Effect>> = vec![clamp_x0(&mesh), Box::new(Gravity::new(GRAVITY_M_S2))];
    all.extend(effects);
    Simulation::new(mesh, material(SNH, 1e6, 0.3), st, all).unwrap()
}

/// A NaN appearing in frame 3, substep 7 stops the scene with an error naming the element
/// (block and index), the node, the frame and the substep; the state is put back to the last
/// finite positions, further steps refuse with the same error, and a reset starts over.
#[test]
fn a_nan_stops_the_scene_with_the_element_and_the_step_and_a_reset_recovers() {
    for parallel in [false, true] {
        let h = 1.0 / 3000.0;
        let at_secs = (2.0 * 50.0 + 7.0) * h - 0.5 * h; // substep 7 of frame 3
        let mut s = guarded(parallel, vec![Box::new(NanAt { node: 40, at_secs })]);
        s.step_frame().unwrap();
        s.step_frame().unwrap();
        let err = s.step_frame().expect_err("the NaN must stop the scene");
        let SimError::NonFinite { block, element, node, frame, substep_in_frame, substeps_per_frame, .. } = &err else {
            panic!("not the NaN guard: {err}");
        };
        assert_eq!((*block, *node, *frame, *substep_in_frame, *substeps_per_frame), (0, 40, 3, 7, 50), "{err}");
        assert!(s.mesh().blocks[0].element(*element).contains(&40), "{err}");
        let message = err.to_string();
        for needle in ["frame 3", "substep 7 of 50", &format!("element {element} of block 0 (p2)"), "node 40", "reset"]
        {
            assert!(message.contains(needle), "'{needle}' missing from: {message}");
        }
        eprintln!("PASS 10 NaN guard | p2 | energy{} | {message}", if parallel { " (parallel)" } else { "" });
        assert!(s.positions.iter().all(|x| x.iter().all(|c| c.is_finite())), "the last finite state is kept");
        assert_eq!(s.failure(), Some(&err));
        assert_eq!(s.step_frame().expect_err("stays stopped"), err);
        s.remove_effects_named("nan");
        s.reset();
        assert!(s.failure().is_none());
        for _ in 0..5 {
            s.step_frame().unwrap();
        }
    }
}

/// A non-finite position written from outside (a caller) is named the same way at the next
/// substep.
#[test]
fn a_non_finite_position_from_outside_is_named() {
    let mut s = guarded(false, Vec::new());
    s.step_frame().unwrap();
    s.positions[40].z = f64::INFINITY;
    let message = s.step_frame().expect_err("stopped").to_string();
    assert!(
        message.contains("node 40") && message.contains("frame 2") && message.contains("substep 1 of 50"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// Every family with the implicit solvers (issue #36, item 4).
//
// The families above, their own criteria unchanged (energy bounds, recovery to the rest shape
// within `REST_TOLERANCE`, no element inverted), run with every implicit solver of the registry
// under every integrator ([`implicit`]): one step per frame, however stiff, since the implicit
// solvers have no stability limit to guard. The element-type × formulation tables of
// docs/STABILITY.md get these as columns (`PASS`/`FAIL` lines: `--nocapture`). The known
// failures listed here are each explained there. Release: `.ci/run` runs them with `--ignored`.

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_on_inverted_starts() {
    let configs = implicit();
    let mut problems = mirrored_snh(
        &configs,
        &[
            "p1 newton euler",
            "p2 vbd euler",
            "p2 vbd bdf2",
            "p2 newton euler",
            "p2 newton bdf2",
            "p3 vbd newmark",
            "p3 newton euler",
            "p3 newton newmark",
            "p3 newton bdf2",
            "q2 vbd bdf2",
            "q2 newton euler",
            "q2 newton bdf2",
        ],
    );
    problems.extend(corner_snh(&configs, &[]));
    problems.extend(mirrored_stvk(&configs, &[]));
    problems.extend(corner_stvk(
        &configs,
        &[
            "p2 vbd newmark",
            "p2 newton newmark",
            "p3 vbd newmark",
            "p3 newton newmark",
            "q2 vbd newmark",
            "q2 newton newmark",
        ],
    ));
    problems.extend(inverted_nh(
        &configs,
        &[
            "p1 vbd newmark",
            "p1 newton newmark",
            "p2 vbd newmark",
            "p2 newton newmark",
            "p3 vbd newmark",
            "p3 newton newmark",
            "q1 vbd newmark",
            "q2 vbd euler",
            "q2 vbd newmark",
            "q2 newton newmark",
            "prism vbd newmark",
            "prism newton newmark",
            "pyramid newton newmark",
        ],
    ));
    none(&problems);
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_near_incompressibility() {
    // (BDF2's energy is not monotone step by step: its first step after the release raised H by
    // 0.02 % (Q2, Newton) over the bound of "not above its value at release", where the check
    // stops the run; the prism under VBD did too by 0.9 % until session 29, when the box's nodes
    // were renumbered: round-off, docs/STABILITY.md)
    let mut problems = near_incompressible(SNH, &implicit(), &[(0.499, &["q2 newton bdf2"])]);
    problems.extend(near_incompressible(STVK, &implicit(), &[]));
    none(&problems);
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_on_stiffness_extremes() {
    let configs = implicit();
    let mut problems = stiff(&configs, &[]);
    problems.extend(soft_snh_log(
        &configs,
        &[
            "p2 vbd newmark",
            "p2 vbd bdf2",
            "p2 newton newmark",
            "p2 newton bdf2",
            "p3 vbd newmark",
            "p3 vbd bdf2",
            "p3 newton newmark",
            "p3 newton bdf2",
            "q2 vbd newmark",
            "q2 vbd bdf2",
            "q2 newton newmark",
            "q2 newton bdf2",
        ],
    ));
    problems.extend(soft_snh(
        &configs,
        &[
            "p1 vbd bdf2",
            "p1 newton bdf2",
            "p2 vbd euler",
            "p2 vbd newmark",
            "p2 vbd bdf2",
            "p2 newton euler",
            "p2 newton newmark",
            "p2 newton bdf2",
            "p3 vbd euler",
            "p3 vbd newmark",
            "p3 vbd bdf2",
            "p3 newton euler",
            "p3 newton newmark",
            "p3 newton bdf2",
            "q2 vbd newmark",
            "q2 vbd bdf2",
            "q2 newton newmark",
            "q2 newton bdf2",
            "pyramid vbd bdf2",
            "pyramid newton bdf2",
        ],
    ));
    none(&problems);
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_under_extreme_drives() {
    let configs = implicit();
    let mut problems = torsion(&configs, &["p3 vbd newmark", "p3 newton newmark"]);
    problems.extend(stretch_and_back(
        &configs,
        &["p2 vbd newmark", "p3 vbd newmark", "q2 vbd newmark"],
        &[
            "p1 newton newmark",
            "p2 vbd newmark",
            "p2 vbd bdf2",
            "p2 newton euler",
            "p2 newton newmark",
            "p2 newton bdf2",
            "p3 vbd euler",
            "p3 vbd newmark",
            "p3 vbd bdf2",
            "p3 newton euler",
            "p3 newton newmark",
            "p3 newton bdf2",
            "q2 vbd euler",
            "q2 vbd newmark",
        ],
    ));
    problems.extend(drives_stvk(&configs, &[]));
    problems.extend(squash_nh(
        &configs,
        &[
            "p2 vbd euler",
            "p2 vbd newmark",
            "p2 vbd bdf2",
            "p3 vbd euler",
            "p3 vbd newmark",
            "p3 vbd bdf2",
            "q2 vbd euler",
            "q2 vbd newmark",
            "q2 vbd bdf2",
        ],
    ));
    problems.extend(squash_snh_log(&configs, &["p3 vbd newmark"]));
    none(&problems);
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_with_mass_and_size_ratios() {
    let configs = implicit();
    let mut problems = heavy_node(&configs, &[]);
    problems.extend(sizes(&element_types(), &configs, &["p3 vbd newmark", "p3 newton newmark"]));
    none(&problems);
}

#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_with_large_steps() {
    none(&ten_fps(
        &implicit(),
        &[
            "p2 vbd bdf2",
            "p2 newton bdf2",
            "p3 vbd bdf2",
            "p3 newton bdf2",
            "q2 vbd newmark",
            "q2 vbd bdf2",
            "q2 newton bdf2",
        ],
        &[
            "p2 vbd bdf2",
            "p2 newton bdf2",
            "p3 vbd newmark",
            "p3 vbd bdf2",
            "p3 newton newmark",
            "p3 newton bdf2",
            "q2 vbd bdf2",
            "q2 newton bdf2",
        ],
    ));
}

/// The long run (case 8) with each implicit solver and integrator, 3,000 frames (50 s, about
/// 30 periods of the beam's first mode): Newmark conserves the energy (the growth allowed is
/// 10⁻³ of `|V_g|max`, the nonlinear scheme's wobble), implicit Euler and BDF2 dissipate it.
#[test]
#[ignore = "release: CI runs it with --release --ignored"]
fn every_implicit_solver_keeps_the_undamped_bending_scene_from_gaining_energy() {
    for solve in implicit() {
        long_run(solve, 3_000, 1e-3);
    }
}
