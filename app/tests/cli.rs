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

/// `hox solvers` reads the registries: every solver and integrator with its entry, and each
/// solver named there is accepted by `--solver`.
#[test]
fn solvers_lists_every_solver_and_integrator_of_the_registries() {
    let all = json(&["solvers", "--json"]);
    let solvers = all["solvers"].as_array().unwrap();
    assert_eq!(solvers.len(), hox_sim::solver::Method::ALL.len());
    assert_eq!(all["integrators"].as_array().unwrap().len(), hox_sim::solver::Integrator::ALL.len());
    for s in solvers {
        let name = s["name"].as_str().unwrap();
        assert!(!s["long_name"].as_str().unwrap().is_empty() && !s["motion"].as_str().unwrap().is_empty());
        let out = hox(&["simulate", "--scene", "bending", "--seconds", "0.05", "--solver", name]);
        assert!(out.status.success(), "--solver {name}: {}", String::from_utf8_lossy(&out.stderr));
    }
    let text = hox(&["solvers"]);
    assert!(text.status.success() && String::from_utf8_lossy(&text.stdout).contains("newmark"));
}

#[test]
fn mesh_prints_the_papers_counts() {
    let m = json(&["mesh", "--scene", "bending", "--element", "p1", "--grid", "16x4x4", "--split", "five", "--json"]);
    assert_eq!(
        (m["element"].as_str().unwrap(), m["elements"].as_u64().unwrap(), m["nodes"].as_u64().unwrap()),
        ("p1", 1280, 425)
    );
    assert!((m["volume_m3"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    let m = json(&["mesh", "--scene", "torsion", "--element", "p3", "--grid", "4x2x2", "--split", "six", "--json"]);
    assert_eq!((m["elements"].as_u64().unwrap(), m["nodes"].as_u64().unwrap()), (96, 637));
}

#[test]
fn simulate_bending_settles_with_the_tip_sagging_between_a_quarter_and_sixty_centimetres() {
    // XPBD at the paper's settings comes to rest out of equilibrium (its solver bias), and says so
    let r = json(&["simulate", "--scene", "bending", "--settle", "--json"]);
    assert_eq!((r["settled"].as_bool(), r["at_rest"].as_bool()), (Some(false), Some(true)), "{r}");
    assert!(r["residual_rel"].as_f64().unwrap() > 1e-3, "{r}");
    assert_eq!(r["solver"], "xpbd");
    let uz = r["probes"]["tip"][2].as_f64().unwrap();
    assert!((-0.60..=-0.25).contains(&uz), "tip u_z = {uz}");
    for key in [
        "frames",
        "sim_seconds",
        "ms_per_frame",
        "ms_per_frame_p95",
        "ms_per_frame_max",
        "wall_secs",
        "kinetic_energy_j",
        "elastic_energy_j",
    ] {
        assert!(r[key].is_number(), "{key}");
    }
    // the 95th percentile of the frame times: stutter the median hides (issue #37)
    let ms = |k: &str| r[k].as_f64().unwrap();
    assert!(ms("ms_per_frame") <= ms("ms_per_frame_p95") && ms("ms_per_frame_p95") <= ms("ms_per_frame_max"), "{r}");
    // Newton settles in equilibrium, on the static solution of the same mesh
    let n = json(&["simulate", "--scene", "bending", "--settle", "--solver", "newton", "--json"]);
    assert_eq!((n["settled"].as_bool(), n["solver"].as_str()), (Some(true), Some("newton")), "{n}");
    assert!(n["residual_rel"].as_f64().unwrap() <= hox_scenes::SETTLE_RESIDUAL_REL);
    let s = json(&["static", "--scene", "bending", "--json"]);
    let (un, us) = (n["probes"]["tip"][2].as_f64().unwrap(), s["probes"]["tip"][2].as_f64().unwrap());
    assert!(((un - us) / us).abs() < 1e-3, "newton {un} vs static {us}");
}

#[test]
fn simulate_runs_for_the_given_seconds_and_static_solves() {
    let r =
        json(&["simulate", "--scene", "tension", "--element", "p1", "--grid", "6x3x3", "--seconds", "0.5", "--json"]);
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

/// NaN, infinite and out-of-range numbers on the command line (issue #8, case 9): each a clear
/// error naming the option or the scene key, exit 1 or clap's 2, never a run.
#[test]
fn non_finite_and_out_of_range_numbers_on_the_command_line_are_clear_errors() {
    let msh = gmsh_mesh("beam-hex27-v22.msh");
    let rrd = scratch("non-finite").join("never.rrd");
    let rrd = rrd.to_str().expect("utf-8 path");
    let drive = |extra: &[&str]| -> Vec<String> {
        ["simulate", "--mesh", &msh, "--drive", "tip", "--seconds", "0.05"]
            .iter()
            .chain(extra)
            .map(|s| s.to_string())
            .collect()
    };
    for (args, needle) in [
        (vec!["simulate", "--scene", "bending", "--youngs", "inf", "--seconds", "0.05"], "Young's modulus"),
        (vec!["simulate", "--scene", "bending", "--youngs=-inf", "--seconds", "0.05"], "Young's modulus"),
        (vec!["simulate", "--scene", "bending", "--poisson", "nan", "--seconds", "0.05"], "Poisson ratio"),
        (vec!["simulate", "--scene", "bending", "--density", "inf", "--seconds", "0.05"], "density"),
        (vec!["simulate", "--scene", "bending", "--fps", "nan", "--seconds", "0.05"], "frames_per_second"),
        (vec!["simulate", "--scene", "bending", "--fps", "0", "--seconds", "0.05"], "frames_per_second"),
        (vec!["simulate", "--scene", "bending", "--iterations", "0", "--seconds", "0.05"], "iterations"),
        (vec!["simulate", "--scene", "bending", "--quadrature", "0", "--seconds", "0.05"], "quadrature_degree"),
        (vec!["simulate", "--scene", "bending", "--seconds", "nan"], "--seconds"),
        (vec!["simulate", "--scene", "bending", "--seconds", "inf"], "--seconds"),
        (vec!["static", "--scene", "bending", "--tolerance", "nan"], "--tolerance"),
        (vec!["static", "--scene", "bending", "--load-steps", "0"], "--load-steps"),
        (vec!["static", "--scene", "bending", "--material", "snh", "--poisson", "0.5"], "Poisson ratio"),
        (
            vec!["record", "--scene", "bending", "--seconds", "0.05", "--out", rrd, "--colour-max-m", "nan"],
            "--colour-max-m",
        ),
        (
            vec![
                "record",
                "--scene",
                "bending",
                "--seconds",
                "0.05",
                "--out",
                rrd,
                "--compare",
                "element=p1",
                "--compare",
                "youngs=nan",
            ],
            "Young's modulus",
        ),
        (vec!["bench", "--frames", "0"], "--frames"),
    ] {
        fails_with(&args, needle);
    }
    for (extra, needle) in [
        (&["--drive-translation-m", "nan,0,0"][..], "three finite numbers"),
        (&["--drive-translation-m", "inf,0,0"][..], "three finite numbers"),
        (&["--drive-rotation-deg", "nan"][..], "--drive-rotation-deg"),
        (&["--drive-rotation-deg", "90", "--drive-origin-m", "nan,0,0"][..], "three finite numbers"),
        (&["--drive-rotation-deg", "90", "--drive-axis", "0,0,0"][..], "rotation_axis"),
        (&["--drive-ramp-secs", "nan"][..], "--drive-ramp-secs"),
    ] {
        let args = drive(extra);
        fails_with(&args.iter().map(String::as_str).collect::<Vec<_>>(), needle);
    }
    assert!(!std::path::Path::new(rrd).exists(), "a refused record wrote its output");
}

/// A committed Gmsh mesh (assets/meshes/).
fn gmsh_mesh(name: &str) -> String {
    format!("{}/../assets/meshes/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A fresh scratch folder for one test.
fn scratch(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hox-cli-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn mesh_reports_a_gmsh_files_blocks_volume_and_groups() {
    let m = json(&["mesh", "--mesh", &gmsh_mesh("beam-mixed.msh"), "--json"]);
    assert_eq!((m["elements"].as_u64().unwrap(), m["nodes"].as_u64().unwrap()), (174, 101));
    assert_eq!(m["element"], "q1+p1+pyramid+prism");
    assert!((m["volume_m3"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    assert_eq!(m["groups"]["clamp"]["nodes"], 9);
    assert_eq!(m["groups"]["body"]["elements"], 174);
    let out = hox(&["mesh", "--mesh", &gmsh_mesh("beam-tet20.msh")]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("82 p3 elements, 548 nodes") && text.contains("\"body\", \"clamp\", \"tip\""), "{text}");
}

#[test]
fn simulate_a_gmsh_mesh_and_write_a_paraview_series() {
    let dir = scratch("vtk");
    let vtk = dir.join("out");
    let r = json(&[
        "simulate",
        "--mesh",
        &gmsh_mesh("beam-tet10.msh"),
        "--clamp",
        "clamp",
        "--seconds",
        "0.1",
        "--vtk",
        vtk.to_str().unwrap(),
        "--vtk-every",
        "4",
        "--json",
    ]);
    assert_eq!(r["frames"], 6);
    assert_eq!(r["groups"]["clamp"], serde_json::json!([0.0, 0.0, 0.0]));
    assert!(r["groups"]["tip"][2].as_f64().unwrap() < 0.0, "gravity is on by default");
    // the rest state, frame 4 and the last frame (6)
    let index = std::fs::read_to_string(vtk.join("beam-tet10.pvd")).unwrap();
    assert_eq!(index.matches("<DataSet").count(), 3, "{index}");
    assert_eq!(r["vtk"].as_str().unwrap(), vtk.join("beam-tet10.pvd").to_str().unwrap());
    for k in 0..3 {
        let vtu = std::fs::read_to_string(vtk.join(format!("beam-tet10_{k:06}.vtu"))).unwrap();
        assert!(
            vtu.contains("NumberOfPoints=\"495\" NumberOfCells=\"218\"")
                && vtu.contains("Name=\"displacement_m\"")
                && vtu.contains("Name=\"von_mises_stress_pa\"")
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_driven_group_reaches_its_prescribed_position_in_the_static_solution() {
    let s = json(&[
        "static",
        "--mesh",
        &gmsh_mesh("beam-hex8.msh"),
        "--clamp",
        "clamp",
        "--drive",
        "tip",
        "--drive-translation-m",
        "0,0,-0.1",
        "--no-gravity",
        "--json",
    ]);
    let tip = &s["groups"]["tip"];
    assert!((tip[2].as_f64().unwrap() + 0.1).abs() < 1e-12 && tip[0].as_f64().unwrap().abs() < 1e-12, "{tip}");
    assert!(s["groups"]["body"][2].as_f64().unwrap() < 0.0);
    // a rotation about the group's own centre: the tip face turns, its centre stays
    let s = json(&[
        "static",
        "--mesh",
        &gmsh_mesh("beam-hex8.msh"),
        "--clamp",
        "clamp",
        "--drive",
        "tip",
        "--drive-rotation-deg",
        "30",
        "--no-gravity",
        "--json",
    ]);
    assert!(
        s["groups"]["tip"].as_array().unwrap().iter().all(|c| c.as_f64().unwrap().abs() < 1e-12),
        "{}",
        s["groups"]["tip"]
    );
}

#[test]
fn bad_mesh_files_are_clear_errors_naming_the_file_and_the_element() {
    let dir = scratch("bad-msh");
    let head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"clamp\"\n$EndPhysicalNames\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
    let write = |name: &str, elements: &str| {
        let path = dir.join(name);
        std::fs::write(&path, format!("{head}$Elements\n{elements}$EndElements\n")).unwrap();
        path.to_str().unwrap().to_string()
    };
    let cases = [
        (write("unknown.msh", "1\n7 99 2 1 1 1 2 3 4\n"), "unknown.msh:17: element 7 has unknown Gmsh element type 99"),
        (
            write("hex20.msh", "1\n7 17 2 1 1 1 2 3 4 1 2 3 4 1 2 3 4 1 2 3 4 1 2 3 4\n"),
            "element 7 is a 20-node hexahedron (Gmsh type 17)",
        ),
        (write("range.msh", "1\n7 4 2 1 1 1 2 3 44\n"), "range.msh:17: element 7 refers to node 44"),
        (write("inverted.msh", "1\n7 4 2 1 1 2 1 3 4\n"), "element 7 (p1) is inverted"),
        (write("flat.msh", "1\n7 4 2 1 1 1 2 3 3\n"), "element 7 (p1) uses node 3 twice"),
        (write("surface.msh", "1\n7 2 2 1 1 1 2 3\n"), "surface-only mesh"),
        (write("empty.msh", "0\n"), "the mesh is empty: no elements"),
    ];
    for (path, needle) in &cases {
        fails_with(&["mesh", "--mesh", path], needle);
        fails_with(&["mesh", "--mesh", path], path);
    }
    let good = write("good.msh", "2\n6 2 2 1 1 1 3 2\n7 4 2 1 1 1 2 3 4\n");
    fails_with(
        &["simulate", "--mesh", &good, "--clamp", "wall"],
        "physical group \"wall\" does not exist (the file's groups: \"1\", \"clamp\") (the clamp group)",
    );
    fails_with(
        &["simulate", "--mesh", &good, "--drive", "clamp"],
        "--drive clamp: give a --drive-translation-m or a --drive-rotation-deg",
    );
    fails_with(&["simulate", "--mesh", &good, "--drive-translation-m", "1,2"], "three finite numbers");
    fails_with(&["simulate", "--scene", "bending", "--clamp", "x"], "--clamp needs --mesh FILE.msh");
    fails_with(&["simulate", "--scene", "bending", "--vtk-every", "3"], "--vtk-every needs --vtk DIR");
    fails_with(&["mesh", "--mesh", "/nonexistent/beam.msh"], "cannot read /nonexistent/beam.msh");
    let not_msh = dir.join("beam.stl");
    std::fs::write(&not_msh, "solid beam\nendsolid\n").unwrap();
    fails_with(&["mesh", "--mesh", not_msh.to_str().unwrap()], "not a Gmsh mesh file");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unwritable_vtk_folder_is_an_error_before_simulating() {
    let dir = scratch("vtk-unwritable");
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let started = std::time::Instant::now();
    fails_with(
        &["simulate", "--scene", "bending", "--seconds", "1000", "--vtk", file.join("out").to_str().unwrap()],
        "--vtk",
    );
    assert!(started.elapsed().as_secs() < 30, "refused before simulating 1000 s");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Inputs at their edges (issue #10): the parameter table's ranges on the command line, each
/// error naming the option.
#[test]
fn grid_and_refine_at_their_edges_name_the_option() {
    // a negative value reaches the option's parser instead of clap's "unexpected argument"
    fails_with(&["mesh", "--scene", "bending", "--grid", "-4x2x2"], "--grid");
    fails_with(&["mesh", "--scene", "bending", "--refine", "-1"], "--refine");
    // the app's ranges: at most 64 cells per direction, 3 refinements
    fails_with(&["mesh", "--scene", "bending", "--grid", "65x2x2"], "--grid");
    // 5 million elements: refused with the count and the memory, before building anything
    fails_with(&["mesh", "--scene", "bending", "--refine", "5"], "5,242,880 elements");
    fails_with(&["mesh", "--scene", "bending", "--refine", "5"], "GB");
    fails_with(
        &["mesh", "--scene", "bending", "--element", "p1", "--grid", "64x64x64", "--split", "six", "--refine", "1"],
        "12,582,912 elements",
    );
    // the largest the app offers builds
    let m = json(&["mesh", "--scene", "bending", "--element", "p1", "--refine", "3", "--json"]);
    assert_eq!(m["elements"], 81_920);
}

#[test]
fn a_mistyped_compare_key_is_named_even_alone() {
    let rrd = scratch("compare-key").join("never.rrd");
    let rrd = rrd.to_str().expect("utf-8 path");
    fails_with(&["record", "--scene", "bending", "--out", rrd, "--compare", "youngz=1e6"], "'youngz'");
    fails_with(&["record", "--scene", "bending", "--out", rrd, "--compare", "youngz=1e6"], "did you mean 'youngs'");
    fails_with(&["record", "--scene", "bending", "--out", rrd, "--compare", "element=p1"], "two or more");
}

#[test]
fn a_grid_too_large_for_memory_is_refused_naming_the_grid() {
    // 1.3 million P3 elements: under the element limit, over the memory one
    fails_with(&["mesh", "--scene", "bending", "--element", "p3", "--grid", "64x64x64"], "--grid");
    fails_with(&["mesh", "--scene", "bending", "--element", "p3", "--grid", "64x64x64"], "1,310,720 elements");
}

/// `hox bench --solver vbd` prints the implicit solver's table (a positive, finite µs per node
/// update next to the counts); an unknown solver names the flag and the allowed values.
#[test]
fn bench_times_an_implicit_solver_and_refuses_an_unknown_one() {
    let args = ["bench", "--solver", "vbd", "--frames", "2", "--threads", "1", "--only", "P2 8x2x2"];
    let out = hox(&args);
    assert!(out.status.success(), "hox {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8_lossy(&out.stdout);
    let cells =
        |line: &str| line.split('|').map(str::trim).filter(|c| !c.is_empty()).map(String::from).collect::<Vec<_>>();
    // the machine first (issue #58), then the table
    assert!(table.starts_with("Machine: "), "{table}");
    let mut lines = table.lines().skip_while(|l| !l.starts_with('|'));
    let header = cells(lines.next().expect("a header"));
    let row = cells(lines.find(|l| l.starts_with("| P2 8x2x2")).unwrap_or_else(|| panic!("no P2 row in:\n{table}")));
    let column =
        |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no '{name}' in {header:?}"));
    assert_eq!(row[column("solver")], "vbd");
    assert_eq!(row[column("threads")], "1");
    assert_eq!(row[column("sweeps/frame")], "10", "the scene's 10 sweeps per step, 1 step per frame");
    for name in ["ms/frame", "µs per node update", "µs per element visit"] {
        let t: f64 = row[column(name)].parse().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(t.is_finite() && t > 0.0, "{name} = {t}");
    }
    fails_with(&["bench", "--solver", "foo"], "--solver");
    fails_with(&["bench", "--solver", "foo"], "xpbd, vbd, newton");
}

/// Issue #58: the commands behind docs/' tables. `bench --beam-json` gives a peer benchmark the
/// beam hox times (bench/pbd_peer.py), `bench --stability` the guard's table, `study --summary` a
/// study folder's figures; each refuses what it cannot print, by name.
#[test]
fn the_commands_behind_the_docs_tables_print_them_and_refuse_bad_input_by_name() {
    let beam = json(&["bench", "--beam-json", "P1 16x4x4"]);
    let tets = beam["tets"].as_array().unwrap();
    assert_eq!(tets.len(), 4 * 1280, "the paper's P1 1,280 beam");
    let nodes = beam["positions_m"].as_array().unwrap().len();
    assert!(tets.iter().all(|t| (t.as_u64().unwrap() as usize) < nodes));
    // the clamped face at x = 0: a 17 × 5 × 5 grid of nodes has 25 there
    assert_eq!(beam["clamped"].as_array().unwrap().len(), 25);
    fails_with(&["bench", "--beam-json", "P2 8x2x2"], "not a P1 beam");
    fails_with(&["bench", "--beam-json", "P9"], "no beam labelled 'P9' (one of: P1 16x4x4,");

    let out = hox(&["bench", "--stability"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.starts_with("Machine: "), "{table}");
    // the paper's bending scene runs as asked; the 10,240-element P3 beam needs the guard
    assert!(table.contains("| scene bending | 160 | 2725 | 50 | 0.91 | 50 |"), "{table}");
    let p3 = table.lines().find(|l| l.starts_with("| bench P3 32x8x8 |")).expect("the P3 beam's row");
    let taken: u32 = p3.split('|').nth(6).unwrap().trim().parse().unwrap();
    assert!(taken > 50, "{p3}");

    let study = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/study");
    let out = hox(&["study", "--summary", study.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(summary.contains("| P2 8x2x2 five | 160 |") && summary.contains("| bending |"), "{summary}");
    fails_with(&["study"], "--out");
    let empty = scratch("study-summary");
    fails_with(&["study", "--summary", empty.to_str().unwrap()], "study.md");
    std::fs::write(empty.join("study.md"), "# Accuracy versus time\n\nno machine here\n").unwrap();
    fails_with(&["study", "--summary", empty.to_str().unwrap()], "no machine line");
}

/// Issue #20: `simulate --json` and `static --json` report the reference of the physics at hand
/// and the error against it: the committed one for bending as built, one computed (and cached)
/// for ν = 0.49; a swinging run is measured by its last-second mean, and says so.
#[test]
fn simulate_and_static_report_the_reference_of_the_physics_at_hand() {
    let cache = std::env::temp_dir().join(format!("hox-reference-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hox")).args(args).env("HOX_CACHE_DIR", &cache).output().unwrap();
        assert!(out.status.success(), "hox {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let built = run(&["simulate", "--scene", "bending", "--seconds", "0.5", "--json"]);
    assert_eq!(built["reference"]["origin"], "committed");
    assert!(built["reference"]["label"].as_str().unwrap().contains("ν = 0.35"), "{}", built["reference"]);
    assert!(built["error_of"].as_str().unwrap().contains("last-second mean"), "{}", built["error_of"]);
    assert!(built["error_m"].as_f64().unwrap() > 0.0);
    // a timed run does not start a computation of minutes unasked: it uses known references only
    let timed = run(&["simulate", "--scene", "bending", "--poisson", "0.3", "--seconds", "0.1", "--json"]);
    assert!(timed["reference"].is_null() && timed["error_m"].is_null(), "{}", timed["reference"]);
    // another ν: a reference computed for it (small levels keep the debug test quick)
    let args =
        ["static", "--scene", "bending", "--element", "p2", "--poisson", "0.49", "--reference-cells", "64", "--json"];
    let soft = run(&args);
    let r = &soft["reference"];
    assert_eq!((r["origin"].as_str(), r["poisson_ratio"].as_f64()), (Some("computed"), Some(0.49)), "{r}");
    assert!(r["estimated_error_pct"].as_f64().is_some() && r["label"].as_str().unwrap().contains("ν = 0.49"), "{r}");
    assert!(soft["error_of"].as_str().unwrap().contains("discretisation"));
    let cached: Vec<_> = std::fs::read_dir(&cache).expect("the reference was cached").collect();
    assert_eq!(cached.len(), 1);
    // the second time it comes from the cache: the same reference
    assert_eq!(run(&args)["reference"], *r);
    let _ = std::fs::remove_dir_all(&cache);
    fails_with(&["static", "--scene", "bending", "--reference-cells", "8"], "--reference-cells");
    let none = json(&["simulate", "--scene", "bending", "--seconds", "0.1", "--reference", "none", "--json"]);
    assert!(none["reference"].is_null() && none["error_m"].is_null());
}

/// Issue #36: the bad-input cases with every solver and integrator of the registries (XPBD
/// ignores the integrator but still reads the flag), a bad integrator named, and contact refused
/// by name under every solver that cannot honour its projection.
#[test]
fn bad_input_is_a_clear_error_under_every_solver_and_integrator() {
    use hox_sim::effect::ImplicitRole;
    use hox_sim::solver::{Integrator, Method};
    fails_with(&["simulate", "--scene", "bending", "--integrator", "verlet"], "verlet");
    for method in Method::ALL {
        let solver = method.name();
        for integrator in Integrator::ALL.map(Integrator::name) {
            let run = |extra: &[&str], needle: &str| {
                let mut args = vec![
                    "simulate",
                    "--scene",
                    "bending",
                    "--seconds",
                    "0.05",
                    "--solver",
                    solver,
                    "--integrator",
                    integrator,
                ];
                args.extend_from_slice(extra);
                fails_with(&args, needle);
            };
            run(&["--poisson", "0.5"], "Poisson ratio");
            run(&["--youngs", "nan"], "Young's modulus");
            run(&["--density", "-1"], "density");
            run(&["--fps", "inf"], "frames_per_second");
            run(&["--steps", "0"], "steps");
            run(&["--vbd-iterations", "0"], "vbd");
            run(&["--newton-tolerance", "nan"], "newton");
        }
        if method.is_implicit() && !method.honours(ImplicitRole::Projection) {
            fails_with(&["simulate", "--scene", "drop", "--solver", solver, "--seconds", "0.05"], "contact");
        }
    }
}

/// Issue #59: `hox app --link` opens what a page's link opens; a link it cannot use is refused by
/// name before any window opens, and so is `hox serve-app`'s `--link` and a folder that holds no
/// built site.
#[test]
fn a_bad_link_or_a_missing_site_is_refused_by_name() {
    fails_with(&["app", "--link", "http://127.0.0.1:9090/?nu=abc&element=p2"], "nu=abc");
    fails_with(&["app", "--link", "lesson=locking&step=9"], "step=9");
    fails_with(&["serve-app", "--link", "bogus=1", "--seconds", "0"], "unknown key 'bogus'");
    let empty = std::env::temp_dir().join(format!("hox-no-site-{}", std::process::id()));
    std::fs::create_dir_all(&empty).unwrap();
    fails_with(&["serve-app", "--site", empty.to_str().unwrap(), "--web-port", "0", "--seconds", "0"], "build-web.sh");
    // a site's references written where no folder can be made: refused before the lesson runs
    let file = empty.join("a-file");
    std::fs::write(&file, "kept").unwrap();
    let under_a_file = file.join("references");
    fails_with(&["lesson", "locking", "--references-to", under_a_file.to_str().unwrap()], "--references-to");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "kept", "nothing already written is lost");
    let _ = std::fs::remove_dir_all(empty);
}
