//! The `hox` binary, run as a user would.

use std::process::Command;

fn hox(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hox")).args(args).output().expect("hox runs")
}

#[test]
fn elements_lists_all_seven_types_as_json() {
    let out = hox(&["elements", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = rows.as_array().unwrap().iter().map(|r| r["element"].as_str().unwrap()).collect();
    assert_eq!(names, ["p1", "p2", "p3", "q1", "q2", "prism", "pyramid"]);
    assert_eq!(rows[0]["quadrature_points"], 1, "P1 uses one point, as in the paper");
}

#[test]
fn an_unknown_subcommand_fails_with_a_message() {
    let out = hox(&["frobnicate"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unrecognized subcommand"));
}
