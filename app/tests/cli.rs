//! The `hox` binary, run as a user would.

use std::process::Command;

fn hox(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hox")).args(args).env_remove("RUST_BACKTRACE").output().expect("hox runs")
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = hox(args);
    assert!(out.status.success(), "hox {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("hox {args:?} printed no JSON: {e}"))
}

fn fails_with(args: &[&str], needle: &str) {
    let out = hox(args);
    assert!(!out.status.success(), "hox {args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "hox {args:?}: expected '{needle}' in: {err}");
    assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
}

#[test]
fn elements_lists_all_seven_types_as_json() {
    let rows = json(&["elements", "--json"]);
    let names: Vec<&str> = rows.as_array().unwrap().iter().map(|r| r["element"].as_str().unwrap()).collect();
    assert_eq!(names, ["p1", "p2", "p3", "q1", "q2", "prism", "pyramid"]);
    assert_eq!(rows[0]["quadrature_points"], 1, "P1 uses one point, as in the paper");
}

#[test]
fn mesh_prints_the_papers_counts() {
    let m = json(&["mesh", "--scene", "bending", "--element", "p1", "--grid", "16x4x4", "--split", "five", "--json"]);
    assert_eq!((m["element"].as_str().unwrap(), m["elements"].as_u64().unwrap(), m["nodes"].as_u64().unwrap()), ("p1", 1280, 425));
    assert!((m["volume_m3"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    let m = json(&["mesh", "--scene", "torsion", "--element", "p3", "--grid", "4x2x2", "--split", "six", "--json"]);
    assert_eq!((m["elements"].as_u64().unwrap(), m["nodes"].as_u64().unwrap()), (96, 637));
}

#[test]
fn simulate_bending_settles_with_the_tip_sagging_between_a_quarter_and_sixty_centimetres() {
    let r = json(&["simulate", "--scene", "bending", "--settle", "--json"]);
    assert_eq!(r["settled"], true);
    let uz = r["probes"]["tip"][2].as_f64().unwrap();
    assert!((-0.60..=-0.25).contains(&uz), "tip u_z = {uz}");
    for key in ["frames", "sim_seconds", "ms_per_frame", "kinetic_energy_j", "elastic_energy_j"] {
        assert!(r[key].is_number(), "{key}");
    }
}

#[test]
fn simulate_runs_for_the_given_seconds_and_static_solves() {
    let r = json(&["simulate", "--scene", "tension", "--element", "p1", "--grid", "6x3x3", "--seconds", "0.5", "--json"]);
    assert_eq!(r["frames"], 30);
    assert!(r["probes"]["side_y"].is_array() && r["probes"]["side_z"].is_array());
    let s = json(&["static", "--scene", "bending", "--element", "p1", "--grid", "8x2x2", "--json"]);
    assert!(s["residual"].as_f64().unwrap() <= 1e-8);
    assert!(s["probes"]["tip"][2].as_f64().unwrap() < 0.0);
    for key in ["newton_iterations", "seconds", "dofs"] {
        assert!(s[key].is_number(), "{key}");
    }
}

#[test]
fn bad_input_is_a_clear_error_with_a_non_zero_exit() {
    fails_with(&["simulate", "--scene", "bendnig"], "unknown scene 'bendnig'");
    fails_with(&["simulate", "--scene", "bending", "--poisson", "0.5", "--seconds", "0.1"], "Poisson ratio");
    fails_with(&["simulate", "--scene", "bending", "--youngs", "nan", "--seconds", "0.1"], "Young's modulus");
    fails_with(&["simulate", "--scene", "bending", "--density", "-1", "--seconds", "0.1"], "density");
    fails_with(&["simulate", "--scene", "bending", "--substeps", "0", "--seconds", "0.1"], "substeps");
    fails_with(&["simulate", "--scene", "bending", "--seconds", "-1"], "--seconds");
    fails_with(&["simulate", "--scene", "bending", "--fps", "inf", "--seconds", "1"], "frames_per_second");
    fails_with(&["simulate", "--scene", "bending", "--element", "p9"], "p9");
    fails_with(&["mesh", "--scene", "bending", "--element", "q1", "--refine", "1"], "tetrahedra only");
    fails_with(&["mesh", "--scene", "bending", "--grid", "4x0x1"], "grid");
    fails_with(&["simulate", "--scene-file", "/nonexistent/scene.toml"], "/nonexistent/scene.toml");
    fails_with(&["static", "--scene", "drop"], "contact");
    fails_with(&["frobnicate"], "unrecognized subcommand");
}
