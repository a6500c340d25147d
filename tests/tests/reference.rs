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

/// Issue #35's acceptance: with an empty cache, compare P1 refined once against P2 at ν = 0.49:
/// a reference number comes from the three coarsest levels (since issue #62 P2 mixed on the even
/// grids: 1,152 of the 3,200 cells the recipe solves; about 3 s on the project's 2-core machine),
/// and it agrees with the full recipe's value within its stated error; so does each estimate
/// after it.
/// The time is printed, not asserted (machines differ).
#[test]
#[ignore = "a minute and a half in release: CI runs it with --release --ignored"]
fn the_first_reference_estimate_at_nu_0_49_holds_against_the_full_recipe() {
    let p1 = hox_scenes::by_name("bending")
        .unwrap()
        .with_overrides(&SceneOverrides {
            element: hox_sim::element::ElementType::from_name("p1"),
            refine: Some(1),
            poisson_ratio: Some(0.49),
            ..Default::default()
        })
        .unwrap();
    let lookup = hox_scenes::reference::Lookup { finest_cells: hox_scenes::reference::FINEST_CELLS, cache_dir: None };
    let start = std::time::Instant::now();
    let mut estimates = Vec::new();
    let mut level_started = Vec::new();
    let full = lookup
        .get(
            &p1,
            false,
            &mut |what, _| {
                if level_started.last().is_none_or(|(w, _): &(String, f64)| w != what) {
                    level_started.push((what.to_string(), start.elapsed().as_secs_f64()));
                }
            },
            &mut |e| estimates.push((e.clone(), start.elapsed().as_secs_f64())),
        )
        .unwrap();
    for (what, secs) in &level_started {
        eprintln!("{secs:7.2} s  {what}");
    }
    // near incompressibility the levels are P2 mixed on the even grids (four for bending)
    let p = p1.params();
    let kind = hox_scenes::reference::compute::Levels::of(&p1);
    assert_eq!(kind, hox_scenes::reference::compute::Levels::P2Mixed);
    let grids = kind.grids(p.box_min_m, p.box_max_m, lookup.finest_cells);
    assert_eq!(estimates.len(), grids.len() - 3);
    let size = full.size_m();
    for (e, secs) in &estimates {
        let r = e.refining.unwrap();
        let off = full.error_m(&e.probes.iter().map(|(n, u)| (n.clone(), *u)).collect::<Vec<_>>()).unwrap();
        let stated = e.estimated_error_m.unwrap() + full.estimated_error_m.unwrap();
        eprintln!(
            "{secs:7.2} s  after level {} of {}: off the full recipe by {:.3} %, stated ± {:.3} % ({})",
            r.levels_done,
            r.levels,
            100.0 * off / size,
            100.0 * e.estimated_error_m.unwrap() / size,
            e.estimate
        );
        assert!(off <= stated, "{}: {off:e} off the full recipe's value, stated {stated:e}", e.label());
    }
    eprintln!("{:7.2} s  final: {}", start.elapsed().as_secs_f64(), full.label());
    // the first estimate came after the three coarsest levels: under half the recipe's cells
    let cells: Vec<usize> = grids.iter().map(|g| g.iter().product()).collect();
    assert_eq!(estimates[0].0.refining.unwrap().levels_done, 3);
    assert!(2 * cells[..3].iter().sum::<usize>() < cells.iter().sum::<usize>(), "{cells:?}");
}

/// Issue #62's acceptance: near incompressibility the reference no longer locks and its levels
/// converge. At ν = 0.499 and 0.4999 the bending reference is solved on P2 mixed levels (one
/// pressure per element), and from 16×4×4 on successive levels' tips agree within 0.2 % of the
/// sag (measured on an Intel Xeon: ν = 0.499 8×2×2 −0.315106 m, 16×4×4 −0.312126, 24×6×6
/// −0.312014, so 0.95 % then 0.036 %); the first step is the larger (they converge, they do not
/// wander). The same recipe's static solves as `--reference compute` (its tolerance and load
/// steps); 32×8×8, the finest, is left to the release run of the study.
#[test]
fn near_incompressibility_the_reference_levels_agree_to_a_fifth_of_a_percent() {
    use hox_scenes::reference::compute::{LOAD_STEPS, Levels, TOLERANCE, level_scene};
    for nu in [0.499, 0.4999] {
        let scene = hox_scenes::by_name("bending")
            .unwrap()
            .with_overrides(&SceneOverrides { poisson_ratio: Some(nu), ..Default::default() })
            .unwrap();
        assert_eq!(Levels::of(&scene), Levels::P2Mixed, "ν = {nu}");
        let tip = scene.file.probes.iter().find(|p| p.name == "tip").expect("the bending scene's tip probe");
        let tips: Vec<f64> = [[8, 2, 2], [16, 4, 4], [24, 6, 6]]
            .iter()
            .map(|&grid| {
                let level = level_scene(&scene, grid).unwrap();
                let mesh = level.build_mesh().unwrap();
                let solution =
                    hox_scenes::instance::solve_static(&level, &mesh, TOLERANCE, LOAD_STEPS, &mut |_, _, _| {})
                        .unwrap();
                let probe =
                    hox_sim::measure::probe::Probe::locate(&mesh, &tip.name, hox_sim::Vec3::from(tip.point_m)).unwrap();
                probe.displacement(&solution.positions, &mesh.rest_positions).z
            })
            .collect();
        let step = |k: usize| 100.0 * ((tips[k + 1] - tips[k]) / tips[k + 1]).abs();
        let seen = format!("ν = {nu}: tips {tips:?} m, steps {:.3} % then {:.3} %", step(0), step(1));
        eprintln!("{seen}");
        assert!(step(1) < 0.2, "successive levels from 16×4×4 on agree within 0.2 %: {seen}");
        assert!(step(1) < step(0), "the levels converge: {seen}");
        assert!(tips.iter().all(|z| (-0.33..-0.30).contains(z)), "the sag of about 0.31 m: {seen}");
    }
}
