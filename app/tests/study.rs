//! `hox study --quick`: the accuracy-versus-time study on the coarse configurations.

use hox_sim::solver::{Integrator, Method};
use std::process::Command;

#[test]
fn the_quick_study_writes_its_three_files_and_ranks_p2_ahead_of_p1() {
    let out = std::env::temp_dir().join(format!("hox-study-{}", std::process::id()));
    let status = Command::new(env!("CARGO_BIN_EXE_hox"))
        .args(["study", "--quick", "--out"])
        .arg(&out)
        .status()
        .expect("hox runs");
    assert!(status.success());
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    for scene in ["## bending", "## tension", "## torsion"] {
        assert!(md.contains(scene), "study.md lacks {scene}");
    }
    let svg = std::fs::read_to_string(out.join("study.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("paper P1 1280"), "the paper's Table 1 points are drawn");
    let csv = std::fs::read_to_string(out.join("study.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() >= 20);
    let error_of = |config: &str| -> f64 {
        let row = rows.iter().find(|r| r[col("scene")] == "bending" && r[col("configuration")] == config).unwrap();
        assert_eq!(row.len(), header.len());
        row[col("error_m")].parse().unwrap()
    };
    let (p2, p1) = (error_of("P2 8x2x2 five"), error_of("P1 16x4x4 five"));
    assert!(p2 < p1, "P2 160 ({p2} m) must be more accurate than P1 1,280 ({p1} m)");
    for r in &rows {
        let ms: f64 = r[col("ms_per_frame_1_thread")].parse().unwrap();
        assert!(ms > 0.0 && ms.is_finite());
    }
    // the locking table: P1 misses far more of the reference's sag than P2 and P3 as ν → 0.5,
    // and more than at ν = 0.35; the mixed P2 160 is within 1.5 % of it at ν = 0.499 (issue #62)
    assert!(
        md.contains("## Near incompressibility: volumetric locking and its cure"),
        "study.md lacks the locking table"
    );
    let locking = std::fs::read_to_string(out.join("locking.csv")).unwrap();
    let mut lines = locking.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no locking column {name}"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let cell = |nu: &str, config: &str, formulation: &str, column: &str| -> f64 {
        let row = rows
            .iter()
            .find(|r| {
                r[at("poisson_ratio")] == nu && r[at("configuration")] == config && r[at("formulation")] == formulation
            })
            .unwrap_or_else(|| panic!("no locking row {nu} {config} {formulation}"));
        assert_eq!(row.len(), header.len());
        row[at(column)].parse().unwrap()
    };
    let missing = |nu: &str, config: &str| cell(nu, config, "energy", "missing_pct");
    let (p1, p2, p3) =
        (missing("0.499", "P1 16x4x4 five"), missing("0.499", "P2 8x2x2 five"), missing("0.499", "P3 4x2x2 five"));
    assert!(p1 > 3.0 * p2 && p2 > 0.0 && p3 > 0.0 && p3 < p2, "locking at ν = 0.499: P1 {p1} %, P2 {p2} %, P3 {p3} %");
    assert!(p1 > missing("0.35", "P1 16x4x4 five") + 10.0, "P1 must stiffen as ν → 0.5");
    let cured = cell("0.499", "P2 8x2x2 five", "mixed", "missing_pct");
    assert!(cured.abs() < 1.5, "P2 160 mixed at ν = 0.499: {cured} % from the reference");
    let cured_p1 = cell("0.499", "P1 16x4x4 five", "mixed", "missing_pct");
    assert!(cured_p1.abs() < 5.0, "P1 1,280 mixed (node patches) at ν = 0.499: {cured_p1} % against {p1} % plain");
    for r in &rows {
        let newton: f64 = r[at("newton_ms_per_frame_1_thread")].parse().unwrap();
        assert!(newton > 0.0 && newton.is_finite(), "{r:?}");
        // XPBD runs every cell, P1 mixed with its node-patch constraints
        let ms: f64 = r[at("ms_per_frame_1_thread")].parse().unwrap();
        assert!(ms > 0.0 && ms.is_finite(), "{r:?}");
    }
    // the solver axis: every solver on the quick meshes, the Pareto chart, the cheapest sentence
    assert!(md.contains("## The solver axis"), "study.md lacks the solver axis");
    assert!(md.contains("**bending**"), "study.md names no cheapest bending configuration");
    let solvers = std::fs::read_to_string(out.join("solvers.csv")).unwrap();
    let mut lines = solvers.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let value = |config: &str, solver: &str, column: &str| -> f64 {
        let row = rows
            .iter()
            .find(|r| {
                // a grid point the stability guard raised is labelled "xpbd 46x5 (guard; asked 10)"
                let (asked, label) = (solver.rsplit_once('x'), r[col("solver")]);
                r[col("configuration")] == config
                    && (label == solver
                        || asked.is_some_and(|(s, i)| {
                            label.starts_with("xpbd ") && label.ends_with(&format!("x{i} (guard; asked {})", &s[5..]))
                        }))
            })
            .unwrap_or_else(|| panic!("no row {config} {solver}"));
        row[col(column)].parse().unwrap_or_else(|_| panic!("{config} {solver} {column}: {}", row[col(column)]))
    };
    // every implicit solver of the registry under every integrator (a new solver is held to the
    // same bounds without a line here)
    let implicit: Vec<(String, Integrator)> = Method::ALL
        .into_iter()
        .filter(|m| m.is_implicit())
        .flat_map(|m| Integrator::ALL.map(|i| (format!("{m} {i}"), i)))
        .collect();
    assert!(implicit.len() >= 6);
    let xpbd = ["xpbd 50x1", "xpbd 25x2", "xpbd 10x5", "xpbd 100x1", "xpbd 50x2"].map(String::from);
    for solver in xpbd.iter().chain(implicit.iter().map(|(s, _)| s)) {
        let ms = value("P2 8x2x2 five", solver, "ms_per_frame_1_thread");
        assert!(ms > 0.0 && ms.is_finite(), "{solver}: {ms} ms");
        let period = value("P2 8x2x2 five", solver, "period_error_pct");
        // VBD follows the motion since its coarse correction (+23 to +165 % without it)
        assert!(period.abs() < 20.0, "{solver}: period {period} %");
    }
    // the converged solvers sit on the static solution; XPBD at the paper's settings does not
    for (solver, _) in &implicit {
        assert!(value("P2 8x2x2 five", solver, "solver_error_pct") < 0.1, "{solver}");
    }
    assert!(value("P2 8x2x2 five", "xpbd 50x1", "solver_error_pct") > 1.0);
    // implicit Euler damps the motion the reference (Newmark) keeps; Newmark and BDF2 keep it
    // (issue #36: Newmark's period within 1 % and amplitude within 2 % on this mesh; measured:
    // Newmark −0.07 / +0.65 %, BDF2 +1.4–1.8 / −2.7 (Newton) and −4.3 % (VBD, whose sweeps under
    // BDF2 no longer lean towards an explicit scheme, which had gained energy over long runs))
    for (solver, integrator) in &implicit {
        let (period, amplitude) =
            (value("P2 8x2x2 five", solver, "period_error_pct"), value("P2 8x2x2 five", solver, "amplitude_error_pct"));
        match integrator.name() {
            "euler" => assert!(amplitude < -5.0, "{solver}: amplitude {amplitude} %"),
            "newmark" => {
                assert!(period.abs() < 1.0 && amplitude.abs() < 2.0, "{solver}: {period} / {amplitude} %")
            }
            "bdf2" => {
                assert!(period.abs() < 2.5 && amplitude.abs() < 5.0, "{solver}: {period} / {amplitude} %")
            }
            other => unreachable!("{other}: no expected motion"),
        }
    }
    let pareto = std::fs::read_to_string(out.join("pareto-bending.svg")).unwrap();
    assert!(pareto.contains("class=\"pareto\"") && pareto.trim_end().ends_with("</svg>"));
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn an_unwritable_output_folder_is_refused_before_any_work() {
    let out = Command::new(env!("CARGO_BIN_EXE_hox"))
        .args(["study", "--quick", "--out", "/proc/hox-study"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/proc/hox-study"), "{err}");
}
