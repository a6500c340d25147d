//! `hox record` and `hox inspect`: Rerun recordings written headlessly and read back with the
//! Rerun decoder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hox")).args(args).env_remove("RUST_BACKTRACE").output().expect("hox runs")
}

fn ok_json(args: &[&str]) -> serde_json::Value {
    let out = hox(args);
    assert!(out.status.success(), "hox {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("hox {args:?} printed no JSON: {e}"))
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hox-record-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn entities(file: &Path) -> serde_json::Value {
    ok_json(&["inspect", file.to_str().unwrap(), "--json"])["entities"].clone()
}

#[test]
fn paper_scenes_record_and_read_back() {
    for scene in ["bending", "tension", "torsion"] {
        let file = temp(&format!("{scene}.rrd"));
        let summary =
            ok_json(&["record", "--scene", scene, "--seconds", "0.25", "--out", file.to_str().unwrap(), "--json"]);
        assert_eq!(summary["frames"], 16, "{scene}: 15 steps at 60 fps plus the initial state");
        assert!(summary["bytes"].as_u64().unwrap() > 10_000);
        let checked = ok_json(&["inspect", file.to_str().unwrap(), "--expect-frames", "16", "--json"]);
        let configs = checked["configurations"].as_array().unwrap();
        assert_eq!(configs.len(), 1);
        let c = configs[0].as_str().unwrap();
        let e = &checked["entities"];
        let surface = &e[format!("world/{c}/surface/displacement")];
        assert!(surface["static_components"].as_array().unwrap().iter().any(|v| v == "Mesh3D:triangle_indices"));
        for component in ["Mesh3D:vertex_positions", "Mesh3D:vertex_colors", "Mesh3D:vertex_normals"] {
            assert_eq!(
                surface["frames_per_component"][component].as_array().unwrap().len(),
                16,
                "{scene}: {component}"
            );
        }
        // every probe component and the energies are time series on the frame timeline
        let probe_series: Vec<&String> = e
            .as_object()
            .unwrap()
            .keys()
            .filter(|k| k.starts_with("plots/probe_") && k.ends_with(&format!("/{c}")))
            .collect();
        assert!(
            probe_series.len() >= 3 && probe_series.len().is_multiple_of(3),
            "{scene}: three components per probe: {probe_series:?}"
        );
        for series in probe_series {
            assert_eq!(
                e[series]["frames_per_component"]["Scalars:scalars"].as_array().map(Vec::len),
                Some(16),
                "{scene}: {series}"
            );
        }
        for quantity in ["kinetic_energy_j", "elastic_energy_j", "ms_per_frame", "min_det_f"] {
            let series = &e[format!("plots/{quantity}/{c}")]["frames_per_component"]["Scalars:scalars"];
            assert_eq!(series.as_array().map(Vec::len), Some(16), "{scene}: plots/{quantity}/{c}");
        }
        assert!(
            e["legend/displacement/bar"]["static_components"].as_array().unwrap().iter().any(|v| v == "Image:buffer"),
            "{scene}: the colour bar is an image"
        );
        assert!(e["legend/text"]["static_components"].as_array().unwrap().iter().any(|v| v == "TextDocument:text"));
        // the clamped face is marked
        assert!(e[format!("world/{c}/clamped")]["frames_per_component"]["LineStrips3D:strips"].is_array(), "{scene}");
        // the layout it opens in: a 3D view, the legend, and a chart per quantity
        let views = checked["blueprint"]["views"].as_array().unwrap();
        let named = |class: &str, name: &str| {
            views
                .iter()
                .any(|v| v[0].as_str().unwrap_or_default() == class && v[1].as_str().unwrap_or_default().contains(name))
        };
        assert!(named("3D", "3D: displacement"), "{scene}: {views:?}");
        assert!(named("TextDocument", "Legend"), "{scene}: {views:?}");
        assert!(named("TimeSeries", "u_z (m)") && named("TimeSeries", "kinetic energy"), "{scene}: {views:?}");
        assert_eq!(checked["fields"], serde_json::json!(["displacement"]));
    }
}

/// `--field` records several fields, each on its own surface and in its own 3D view, on ranges
/// shared by the configurations; `hox inspect` lists them. The committed bending reference
/// appears beside the probe's u_z.
#[test]
fn several_fields_are_recorded_each_in_its_own_view() {
    let file = temp("fields.rrd");
    let f = file.to_str().unwrap();
    let summary = ok_json(&[
        "record",
        "--scene",
        "bending",
        "--seconds",
        "0.05",
        "--out",
        f,
        "--field",
        "von-mises,strain",
        "--field",
        "det-f",
        "--colour-max",
        "2e5",
        "--json",
    ]);
    assert_eq!(summary["fields"], serde_json::json!(["von-mises", "strain", "det-f"]));
    let checked = ok_json(&["inspect", f, "--expect-frames", "4", "--json"]);
    assert_eq!(checked["fields"], serde_json::json!(["det-f", "strain", "von-mises"]));
    let e = &checked["entities"];
    for field in ["von-mises", "strain", "det-f"] {
        assert!(e[format!("world/p2_160/surface/{field}")]["frames_per_component"]["Mesh3D:vertex_colors"].is_array());
        assert!(e[format!("legend/{field}/ticks")]["frames_per_component"]["Points2D:labels"].is_array(), "{field}");
    }
    assert!(e["plots/probe_tip_u_z_m/reference_static"]["frames_per_component"]["Scalars:scalars"].is_array());
    let views = checked["blueprint"]["views"].as_array().unwrap();
    let n3d = views.iter().filter(|v| v[0] == "3D").count();
    assert_eq!(n3d, 3, "{views:?}");
    // the text listing names them with what they mean
    let out = hox(&["inspect", f]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("fields: det-f, strain, von-mises") && text.contains("von Mises stress"), "{text}");
    // an unknown field is refused with the list
    let out = hox(&["record", "--scene", "bending", "--out", f, "--field", "stress"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("von-mises") && err.contains("field"), "{err}");
}

#[test]
fn compare_records_p1_and_p2_side_by_side() {
    let file = temp("compare.rrd");
    let f = file.to_str().unwrap();
    let vtk = temp("compare-vtk");
    let summary = ok_json(&[
        "record",
        "--scene",
        "bending",
        "--seconds",
        "0.1",
        "--out",
        f,
        "--compare",
        "element=p1,refine=1",
        "--compare",
        "element=p2",
        "--quadrature-points",
        "--vtk",
        vtk.to_str().unwrap(),
        "--json",
    ]);
    // a VTK series per configuration beside the recording: 7 frames each
    let indexes: Vec<&str> = summary["vtk"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert_eq!(indexes.len(), 2);
    for (index, c) in indexes.iter().zip(["p1_1280", "p2_160"]) {
        assert!(index.contains(c), "{index}");
        let pvd = std::fs::read_to_string(index).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), 7, "{index}");
    }
    let entities: Vec<&str> =
        summary["configurations"].as_array().unwrap().iter().map(|c| c["entity"].as_str().unwrap()).collect();
    assert_eq!(entities, ["world/p1_1280", "world/p2_160"]);
    let checked = ok_json(&["inspect", f, "--expect-frames", "7", "--json"]);
    assert_eq!(checked["configurations"], serde_json::json!(["p1_1280", "p2_160"]));
    let e = &checked["entities"];
    for c in ["p1_1280", "p2_160"] {
        assert!(
            e[format!("world/{c}")]["static_components"]
                .as_array()
                .unwrap()
                .iter()
                .any(|v| v == "Transform3D:translation"),
            "{c} is offset"
        );
        assert_eq!(
            e[format!("world/{c}/quadrature_points")]["frames_per_component"]["Points3D:positions"]
                .as_array()
                .map(Vec::len),
            Some(7)
        );
    }
}

#[test]
fn bad_output_or_options_fail_before_simulating_and_keep_existing_files() {
    let out = hox(&["record", "--scene", "bending", "--out", "/nonexistent-folder/x.rrd"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot write /nonexistent-folder/x.rrd"));
    // an existing file survives a refused command
    let file = temp("keep.rrd");
    std::fs::write(&file, b"precious").unwrap();
    for args in [
        vec!["--compare", "element=p1"],
        vec!["--compare", "element=p1", "--compare", "colour=red"],
        vec!["--poisson", "0.5", "--material", "snh"],
        vec!["--seconds", "nan"],
        vec!["--tessellation", "0"],
    ] {
        let mut all = vec!["record", "--scene", "bending", "--out", file.to_str().unwrap()];
        all.extend(args.iter());
        let out = hox(&all);
        assert!(!out.status.success(), "{all:?} should fail");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error: ") && !err.contains("panicked"), "{all:?}: {err}");
        assert_eq!(std::fs::read(&file).unwrap(), b"precious", "{all:?} touched the existing file");
    }
    // and an .rrd that is not one is named as such
    let out = hox(&["inspect", file.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("not a readable Rerun recording"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[cfg(unix)]
#[test]
fn ctrl_c_leaves_a_playable_file_up_to_the_last_frame() {
    let file = temp("interrupted.rrd");
    let child = Command::new(env!("CARGO_BIN_EXE_hox"))
        .args(["record", "--scene", "bending", "--seconds", "600", "--out", file.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // wait until some frames are on disk
    let started = std::time::Instant::now();
    while std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0) < 200_000 {
        assert!(started.elapsed().as_secs() < 120, "no frames written");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let status = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    assert!(String::from_utf8_lossy(&out.stderr).contains("interrupted"));
    let e = entities(&file);
    let frames = e["world/p2_160/surface/displacement"]["frames_per_component"]["Mesh3D:vertex_positions"]
        .as_array()
        .unwrap()
        .len();
    assert!(frames >= 2, "{frames}");
    // every entity holds the same, complete frames
    ok_json(&["inspect", file.to_str().unwrap(), "--expect-frames", &frames.to_string(), "--json"]);
}

/// A refused option of a single configuration reads "error: builtin:bending: …" (regression: an
/// empty context made it "error: : builtin:bending: …"); a compared one names its --compare value.
#[test]
fn a_refused_record_option_names_the_problem_without_an_empty_prefix() {
    let out_file = temp("refused.rrd");
    let out = hox(&["record", "--scene", "bending", "--out", out_file.to_str().unwrap(), "--tessellation", "0"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error: builtin:bending: display.tessellation (--tessellation) = 0"), "{err}");
    let out = hox(&[
        "record",
        "--scene",
        "bending",
        "--out",
        out_file.to_str().unwrap(),
        "--compare",
        "element=p1",
        "--compare",
        "refine=7",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.starts_with("error: --compare 'refine=7':"), "{err}");
}

#[test]
fn an_implicit_solvers_recording_is_labelled_with_its_solver_and_integrator() {
    let file = temp("newton.rrd");
    let f = file.to_str().unwrap();
    let summary =
        ok_json(&["record", "--scene", "bending", "--seconds", "0.05", "--solver", "newton", "--out", f, "--json"]);
    let entities: Vec<&str> =
        summary["configurations"].as_array().unwrap().iter().map(|c| c["entity"].as_str().unwrap()).collect();
    assert_eq!(entities, ["world/p2_160_newton_bdf2"]);
    let checked = ok_json(&["inspect", f, "--expect-frames", "4", "--json"]);
    assert_eq!(checked["configurations"], serde_json::json!(["p2_160_newton_bdf2"]));
    let summary = ok_json(&[
        "record",
        "--scene",
        "bending",
        "--seconds",
        "0.05",
        "--solver",
        "vbd",
        "--integrator",
        "newmark",
        "--out",
        f,
        "--json",
    ]);
    assert_eq!(summary["configurations"][0]["entity"], "world/p2_160_vbd_newmark");
}

/// Issue #21: `hox lessons --json` lists at least eight lessons; every one records headlessly
/// (`hox lesson NAME --record`) as one file carrying its blueprint (a 3D view, the step text,
/// the measurement), each step's text (its question, then its answer) and its measurements.
#[test]
fn every_lesson_records_with_its_blueprint_and_step_texts() {
    let list = ok_json(&["lessons", "--json"]);
    let lessons = list.as_array().unwrap();
    assert!(lessons.len() >= 8, "{}", lessons.len());
    for l in lessons {
        let name = l["name"].as_str().unwrap();
        let steps = l["steps"].as_array().unwrap().len();
        let file = temp(&format!("lesson-{name}.rrd"));
        let f = file.to_str().unwrap();
        let report = ok_json(&["lesson", name, "--record", f, "--json"]);
        assert_eq!(report["steps"].as_array().unwrap().len(), steps, "{name}");
        let checked = ok_json(&["inspect", f, "--json"]);
        let views = checked["blueprint"]["views"].as_array().unwrap();
        let has = |class: &str, title: &str| views.iter().any(|v| v[0] == class && v[1] == title);
        // one chart per unit of the lesson's measurements, named with it (issue #35: metres and
        // milliseconds shared one axis without units)
        let charts: Vec<&str> = views.iter().filter(|v| v[0] == "TimeSeries").filter_map(|v| v[1].as_str()).collect();
        assert!(has("3D", "3D") && has("TextDocument", "Step") && !charts.is_empty(), "{name}: {views:?}");
        assert!(charts.iter().all(|c| c.starts_with("Measurement")), "{name}: {charts:?}");
        if name == "why-high-order" {
            assert!(charts.contains(&"Measurement (m)") && charts.contains(&"Measurement (ms)"), "{charts:?}");
        }
        // the step text changes twice per step: the question, then the answer with the numbers
        let texts = checked["entities"]["lesson/step"]["frames_per_component"]["TextDocument:text"].as_array().unwrap();
        assert_eq!(texts.len(), 2 * steps, "{name}");
        assert!(
            checked["entities"]
                .as_object()
                .unwrap()
                .keys()
                .any(|k| k.starts_with("lesson/measure/") && k.contains("/step_1/")),
            "{name}: no measurement series"
        );
        // each step's bodies are cleared when it ends, but the last step's: the recording (and
        // a page following the lesson live) ends on them, not on an empty 3D view
        for (entity, info) in checked["entities"].as_object().unwrap() {
            let Some(config) = entity.strip_prefix("world/").filter(|c| !c.contains('/')) else { continue };
            let step: usize = config[1..config.find('_').unwrap()].parse().unwrap();
            let cleared = info["frames_per_component"].get("Clear:is_recursive").is_some();
            assert_eq!(cleared, step < steps, "{name}: {entity} of step {step} of {steps}");
        }
    }
    // an unknown lesson is named
    let out = hox(&["lesson", "nope"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("no such lesson") && err.contains("locking"), "{err}");
}
