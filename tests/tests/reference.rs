//! The committed reference solutions (`assets/reference/*.json`, made by
//! `scripts/reference.sh`) are reproduced by the static solver from their recipe: the coarse
//! levels in every test run, the medium and fine levels (minutes) in the release run CI makes with
//! `--ignored`: one test per scene, so that the test harness runs them side by side (the static
//! solver alone keeps about 1.4 of the 2 cores busy; torsion's fine level takes about five
//! minutes).

use hox_scenes::SceneOverrides;
use std::path::PathBuf;

fn reference_files(scene: Option<&str>, level: &str) -> Vec<(PathBuf, serde_json::Value)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/reference");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .map(|p| {
            let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            (p, v)
        })
        .filter(|(_, v)| v["level"] == level && scene.is_none_or(|scene| v["scene"] == scene))
        .collect();
    files.sort_by(|a, b| a.0.cmp(&b.0));
    files
}

/// Solves the `level` reference of `scene` (every paper scene when None) from its recipe and
/// compares its probes with the committed values.
fn reproduce(scene: Option<&str>, level: &str) {
    let files = reference_files(scene, level);
    assert_eq!(files.len(), if scene.is_some() { 1 } else { 3 }, "one {level} reference per paper scene");
    for (path, reference) in files {
        let scene = hox_scenes::by_name(reference["scene"].as_str().unwrap()).unwrap();
        let grid: Vec<usize> = reference["grid"].as_str().unwrap().split('x').map(|v| v.parse().unwrap()).collect();
        let scene = scene
            .with_overrides(&SceneOverrides {
                element: Some(
                    hox_sim::element::ElementType::from_name(reference["element"].as_str().unwrap()).unwrap(),
                ),
                grid: Some([grid[0], grid[1], grid[2]]),
                ..Default::default()
            })
            .unwrap();
        let mesh = scene.build_mesh().unwrap();
        let solution = hox_scenes::solve_static(&scene, &mesh, 1e-10, 1, &mut |_, _, _| {}).unwrap();
        assert_eq!(solution.free_dofs as u64, reference["dofs"].as_u64().unwrap(), "{}", path.display());
        for p in &scene.file.probes {
            let probe = hox_sim::measure::probe::Probe::locate(&mesh, &p.name, hox_sim::Vec3::from(p.point_m)).unwrap();
            let u = probe.displacement(&solution.positions, &mesh.rest_positions);
            let want: Vec<f64> =
                reference["probes"][&p.name].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            for d in 0..3 {
                assert!(
                    (u[d] - want[d]).abs() < 1e-8,
                    "{} probe {} component {d}: {} vs committed {}",
                    path.display(),
                    p.name,
                    u[d],
                    want[d]
                );
            }
        }
    }
}

#[test]
fn the_coarse_reference_levels_are_reproduced_from_their_recipe() {
    reproduce(None, "coarse");
}

#[test]
#[ignore = "minutes in release: CI runs it with --release --ignored"]
fn the_medium_and_fine_bending_references_are_reproduced_from_their_recipe() {
    reproduce(Some("bending"), "medium");
    reproduce(Some("bending"), "fine");
}

#[test]
#[ignore = "minutes in release: CI runs it with --release --ignored"]
fn the_medium_and_fine_tension_references_are_reproduced_from_their_recipe() {
    reproduce(Some("tension"), "medium");
    reproduce(Some("tension"), "fine");
}

#[test]
#[ignore = "minutes in release: CI runs it with --release --ignored"]
fn the_medium_and_fine_torsion_references_are_reproduced_from_their_recipe() {
    reproduce(Some("torsion"), "medium");
    reproduce(Some("torsion"), "fine");
}
