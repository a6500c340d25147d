use super::*;

fn locking_row(nu: f64, config: &str) -> LockingRow {
    LockingRow {
        poisson_ratio: nu,
        config: config.into(),
        formulation: "energy".into(),
        elements: 160,
        tip_z_m: -0.1 * nu,
        reference_tip_z_m: -0.11,
        reference_mesh: "Q2 32×8×8 extrapolated".into(),
        missing_pct: 3.0,
        ms_per_frame: Some(2.5),
        newton_ms_per_frame: 1.5,
    }
}

fn failed_solver_row() -> SolverRow {
    SolverRow {
        scene: "bending".into(),
        config: "P2 8x2x2 five".into(),
        element: "p2".into(),
        elements: 160,
        nodes: 1_000,
        solver: "vbd euler".into(),
        sweeps_per_frame: f64::NAN,
        ms_per_frame: f64::NAN,
        solver_error_pct: f64::INFINITY,
        error_m: 0.1 + 0.2,
        error_pct: 1.0 / 3.0,
        discretisation_pct: 0.5,
        settled: false,
        at_rest: false,
        residual_rel: f64::NAN,
        secs_to_1pct: None,
        sim_secs: 0.0,
        period_error_pct: Some(-1e-300),
        amplitude_error_pct: None,
        failure: Some("blew up at t = 0.5 s".into()),
    }
}

/// Parts of a made-up plan of `n_cells` locking cells cut `of` ways (no cell run).
fn parts(n_cells: usize, of: usize) -> Vec<StudyPart> {
    let plan_cells: Vec<String> = (0..n_cells).map(|i| format!("locking ν = 0.{i}")).collect();
    (1..=of)
        .map(|k| {
            let shard = Shard { index: k, count: of };
            StudyPart {
                format: PART_FORMAT.into(),
                quick: true,
                tables: vec![Table::Locking],
                shard: k,
                of,
                machine: "test machine".into(),
                plan_cells: plan_cells.clone(),
                cells: (0..n_cells)
                    .filter(|i| shard.holds(*i))
                    .map(|i| PartCell {
                        index: i,
                        label: plan_cells[i].clone(),
                        rows: Tables {
                            locking: vec![locking_row(i as f64 / 10.0, "P2 8x2x2 five")],
                            ..Default::default()
                        },
                    })
                    .collect(),
            }
        })
        .collect()
}

#[test]
fn a_shard_is_k_of_n_and_bad_text_is_refused_naming_the_form() {
    assert_eq!(Shard::parse("2/8"), Ok(Shard { index: 2, count: 8 }));
    for bad in ["0/3", "4/3", "a/b", "3", "1/0", "-1/2", ""] {
        let e = Shard::parse(bad).unwrap_err();
        assert!(e.contains("K/N"), "{bad}: {e}");
    }
}

#[test]
fn every_cell_of_the_plan_is_in_exactly_one_part() {
    let cells = Plan::all(true).cells();
    assert!(cells.len() > 10, "{}", cells.len());
    for count in 1..=5 {
        for i in 0..cells.len() {
            let holders = (1..=count).filter(|&index| Shard { index, count }.holds(i)).count();
            assert_eq!(holders, 1, "cell {i} of {count} parts");
        }
    }
    let full = Plan::all(false).cells();
    assert!(full.len() > cells.len(), "the full study has the heavy meshes too");
    let labels: std::collections::BTreeSet<String> = full.iter().map(Cell::label).collect();
    assert_eq!(labels.len(), full.len(), "cell labels are unique");
}

#[test]
fn the_plan_lists_only_the_tables_asked_for_and_names_its_command() {
    let plan = Plan { quick: true, tables: Table::parse_list("locking").unwrap() };
    assert!(plan.cells().iter().all(|c| matches!(c, Cell::Locking { .. })));
    assert_eq!(plan.cells().len(), LOCKING_POISSON_RATIOS.len());
    assert_eq!(plan.command(), "hox study --quick --only locking");
    assert_eq!(Plan::all(false).command(), "hox study");
    let e = Table::parse_list("locking,speed").unwrap_err().to_string();
    assert!(e.contains("speed") && e.contains("accuracy, locking, solvers"), "{e}");
}

#[test]
fn a_part_file_keeps_nan_infinity_and_absent_values() {
    let mut part = parts(3, 2).remove(0);
    part.cells[0].rows.solvers.push(failed_solver_row());
    // a cell XPBD refused would have no XPBD ms per frame, and keeps none
    let refused =
        LockingRow { formulation: "mixed".into(), ms_per_frame: None, ..locking_row(0.499, "P1 16x4x4 five") };
    part.cells[0].rows.locking.push(refused);
    let text = part.to_toml().unwrap();
    let back = StudyPart::from_toml(&text, "part.toml").unwrap();
    let (a, b) = (&part.cells[0].rows.solvers[0], &back.cells[0].rows.solvers[0]);
    assert!(b.sweeps_per_frame.is_nan() && b.residual_rel.is_nan() && b.solver_error_pct == f64::INFINITY);
    assert_eq!((b.error_m, b.error_pct, b.period_error_pct), (a.error_m, a.error_pct, a.period_error_pct));
    assert_eq!((&b.failure, b.secs_to_1pct, b.amplitude_error_pct), (&a.failure, None, None));
    assert_eq!(back.cells[0].rows.locking, part.cells[0].rows.locking);
}

#[test]
fn a_file_that_is_no_part_is_refused_naming_it() {
    let e = StudyPart::from_toml("title = 'x'", "notes.toml").unwrap_err().to_string();
    assert!(e.contains("notes.toml") && e.contains("not a study part"), "{e}");
    let text = parts(2, 1)[0].to_toml().unwrap().replace(PART_FORMAT, "hox study part, version 9");
    let e = StudyPart::from_toml(&text, "old.toml").unwrap_err().to_string();
    assert!(e.contains("old.toml") && e.contains("version 9"), "{e}");
}

#[test]
fn parts_merged_in_any_order_give_the_rows_in_cell_order() {
    let whole = merge(&parts(7, 1), &[]).unwrap().1;
    let mut cut = parts(7, 3);
    cut.reverse();
    let (plan, merged, machine) = merge(&cut, &[]).unwrap();
    assert_eq!(merged, whole);
    assert_eq!(merged.locking.iter().map(|r| r.poisson_ratio).collect::<Vec<_>>(), [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    assert_eq!((plan.quick, plan.tables, machine), (true, vec![Table::Locking], "test machine".to_string()));
}

#[test]
fn a_merge_names_the_part_missing_given_twice_or_of_another_study() {
    let names: Vec<String> = ["a.toml", "b.toml", "c.toml"].map(String::from).to_vec();
    let cut = parts(7, 3);
    let e = merge(&[cut[0].clone(), cut[2].clone()], &names).unwrap_err().to_string();
    assert!(e.contains("part 2/3 missing"), "{e}");
    let e = merge(&[cut[0].clone(), cut[1].clone(), cut[1].clone()], &names).unwrap_err().to_string();
    assert!(e.contains("b.toml and c.toml are both part 2/3"), "{e}");
    let mut other = cut[2].clone();
    other.quick = false;
    let e = merge(&[cut[0].clone(), cut[1].clone(), other], &names).unwrap_err().to_string();
    assert!(e.contains("c.toml") && e.contains("another study"), "{e}");
    let e = merge(&[], &[]).unwrap_err().to_string();
    assert!(e.contains("no part files"), "{e}");
}

#[test]
fn a_locking_only_study_writes_the_locking_files_and_says_how_it_was_made() {
    let plan = Plan { quick: true, tables: vec![Table::Locking] };
    let tables = merge(&parts(4, 2), &[]).unwrap().1;
    let files = tables.files(&plan, "test machine");
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["study.md", "locking.csv"]);
    assert!(
        files[0].1.contains("Machine: test machine.") && files[0].1.contains("volumetric locking"),
        "{}",
        files[0].1
    );
    let all = Tables::default().files(&Plan::all(true), "m");
    assert!(all[0].1.contains("Produced by `hox study --quick`"), "{}", all[0].1);
}
