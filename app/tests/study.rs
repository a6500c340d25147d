//! `hox study --quick`: the accuracy-versus-time study on the coarse configurations.

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
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn an_unwritable_output_folder_is_refused_before_any_work() {
    let out = Command::new(env!("CARGO_BIN_EXE_hox")).args(["study", "--quick", "--out", "/proc/hox-study"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/proc/hox-study"), "{err}");
}
