//! Headless UI tests of the app (egui_kittest: the real widgets, driven through AccessKit; no
//! window, no GPU).

use super::action::Action;
use super::app::HoxApp;
use super::config::SceneSource;
use super::presets::ViewPreset;
use super::*;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use readout::Readout;

fn harness(args: AppArgs) -> Harness<'static, HoxApp> {
    let app = HoxApp::new(&AppArgs { fresh: true, ..args }, None).expect("the app starts on bending");
    Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .allow_missing_glyphs()
        .with_step_dt(1.0 / 60.0)
        .build_ui_state(|ui, app: &mut HoxApp| app.ui_all(ui), app)
}

/// The text of the one node whose text contains `needle`.
fn text(h: &Harness<'_, HoxApp>, needle: &str) -> String {
    let n = h.get_by_label_contains(needle);
    n.accesskit_node().label().or_else(|| n.accesskit_node().value()).unwrap_or_default()
}

fn status(h: &Harness<'_, HoxApp>) -> String {
    text(h, "nodes,")
}

/// Replaces the text of the number field labelled `label` with `value` and presses Enter.
fn type_into(h: &mut Harness<'_, HoxApp>, label: &str, value: &str) {
    h.get_by_label(label).focus();
    h.run_steps(1);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.get_by_label(label).type_text(value);
    h.run_steps(1);
    h.key_press(egui::Key::Enter);
    h.run_steps(3);
}

#[test]
fn app_starts_on_bending_with_its_p2_beam() {
    let mut h = harness(AppArgs::default());
    h.run_steps(3);
    assert_eq!(*h.state().model().scene(), SceneSource::Builtin("bending".into()));
    let s = status(&h);
    assert!(s.starts_with("P2 8×2×2 five: 393 nodes, 160 el"), "{s}");
    h.get_by_label("Young's modulus E (Pa)");
    assert_eq!(h.get_all_by_label("Play").count(), 2, "in the menu bar and the playback controls");
}

#[test]
fn switching_element_type_rebuilds_the_mesh_and_the_node_count_shown() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    h.get_by_label("Element").click();
    h.run_steps(2);
    h.get_by_label_contains("Q2 —").click();
    h.run_steps(3);
    let s = status(&h);
    assert!(s.starts_with("Q2 8×2×2: 425 nodes, 32 el"), "{s}");
    assert_eq!(h.state().model().sessions()[0].instance.sim.mesh().num_nodes(), 17 * 5 * 5);
}

#[test]
fn play_advances_time_and_space_pauses() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    assert_eq!(h.state().model().sessions()[0].instance.sim.time_secs(), 0.0);
    h.get_all_by_label("Play").next().unwrap().click();
    h.run_steps(30);
    let t = h.state().model().sessions()[0].instance.sim.time_secs();
    // the app follows the test's clock (1/60 s per step), whatever the build's speed
    let frames = (t * 60.0).round();
    assert!((28.0..=30.0).contains(&frames), "30 displayed frames at 60 Hz advance 30 simulated frames, got {t} s");
    h.key_press(egui::Key::Space);
    h.run_steps(2);
    let paused = h.state().model().sessions()[0].instance.sim.time_secs();
    h.run_steps(10);
    assert_eq!(h.state().model().sessions()[0].instance.sim.time_secs(), paused, "space paused");
    h.key_press(egui::Key::S);
    h.run_steps(2);
    let stepped = h.state().model().sessions()[0].instance.sim.time_secs();
    assert!((stepped - paused - 1.0 / 60.0).abs() < 1e-9, "S steps exactly one frame");
}

#[test]
fn a_bad_value_is_refused_with_the_reason_and_changes_nothing() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    type_into(&mut h, "Poisson ratio ν", "0.5");
    let refusal = text(&h, "refused:");
    assert!(refusal.to_lowercase().contains("poisson"), "{refusal}");
    // in the panel's words, not the scene file's internals (issue #35)
    assert!(refusal.starts_with("refused: Poisson ratio ν = 0.5: "), "{refusal}");
    assert!(!refusal.contains("builtin:") && !refusal.contains("material.poisson_ratio"), "{refusal}");
    assert_eq!(h.state().model().sessions()[0].config.poisson_ratio, 0.35);
    assert_eq!(h.state().model().sessions()[0].instance.sim.material().poisson_ratio, 0.35);
}

#[test]
fn compare_mode_links_controls_and_shows_both_errors() {
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    let labels: Vec<String> = h.state().model().sessions().iter().map(|s| s.label()).collect();
    assert_eq!(labels, ["P1 8×2×2 five r1", "P2 8×2×2 five"]);
    // a linked material change reaches both; an unlinked element change only the active one
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.youngs_modulus_pa = 6e6;
    app.act(Action::change("youngs", c));
    assert!(app.model().sessions().iter().all(|s| s.instance.sim.material().youngs_modulus_pa == 6e6));
    let mut c = app.model().sessions()[0].config.clone();
    c.element = hox_sim::element::ElementType::from_name("p3").unwrap();
    c.refine = 0;
    app.act(Action::change("element", c));
    assert_eq!(app.model().sessions()[0].config.element.name(), "p3");
    assert_eq!(app.model().sessions()[1].config.element.name(), "p2");
    h.run_steps(2);
    assert!(status_count(&h) == 2);
}

/// Issue #37: a curved part in compare mode is the same part at order 1 and 2 (P1's facets
/// against P2's curved faces), labelled by the part; the element control offers only the orders
/// the part was meshed at, a switch to P3 rebuilds from the P3 file, and a box parameter (refine)
/// is not shown for it.
#[test]
fn a_curved_part_compares_its_orders_and_switches_between_them() {
    let mut h = harness(AppArgs { scene: Some("tube".into()), compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    let labels: Vec<String> = h.state().model().sessions().iter().map(|s| s.label()).collect();
    assert_eq!(labels, ["P1 tube", "P2 tube"]);
    let nodes: Vec<usize> = h.state().model().sessions().iter().map(|s| s.instance.sim.mesh().num_nodes()).collect();
    assert_eq!(nodes, [829, 4911]);
    assert!(h.query_by_label("Refine").is_none(), "no box parameters for a part");
    let app = h.state_mut();
    let mut c = app.model().sessions()[1].config.clone();
    c.element = hox_sim::element::ElementType::from_name("p3").unwrap();
    app.act(Action::SetActive(1));
    app.act(Action::ChangeNow { control: "element".into(), config: Box::new(c) });
    assert_eq!(app.model().sessions()[1].instance.sim.mesh().num_nodes(), 14670, "P3 from its own file");
    assert_eq!(app.model().sessions()[0].instance.sim.mesh().num_nodes(), 829, "the element type is not linked");
    h.run_steps(2);
    assert_eq!(status_count(&h), 2);
}

/// Waits until the lesson step asked for is prepared and installed.
/// Opens the built-in lesson `name` and waits for its first step.
fn open_lesson(h: &mut Harness<'_, HoxApp>, name: &str) {
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == name).unwrap();
    h.state_mut().act(Action::OpenLesson(Box::new(lesson)));
    lesson_ready(h);
}

fn lesson_ready(h: &mut Harness<'_, HoxApp>) {
    h.run_steps(1);
    h.state_mut().act(Action::Poll { wait_for_lesson: true });
    h.run_steps(2);
}

fn status_count(h: &Harness<'_, HoxApp>) -> usize {
    h.query_all_by_label_contains("nodes,").count()
}

#[test]
fn open_mesh_runs_a_gmsh_file_with_its_clamp_group() {
    let beam = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/beam-tet10.msh");
    let mut app = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap();
    let scene = dialogs::mesh_scene_file(&beam, "clamp").expect("a scene for the mesh");
    let scene_path = scene.clone();
    app.act(Action::LoadScene(SceneSource::File(scene)));
    assert_eq!(*app.model().scene(), SceneSource::File(scene_path));
    let sim = &app.model().sessions()[0].instance.sim;
    assert_eq!((sim.mesh().num_nodes(), sim.mesh().num_elements()), (495, 218));
    assert!(
        !crate::display::held_nodes(&app.model().sessions()[0].instance).0.is_empty(),
        "the clamp group holds nodes"
    );
    app.step(5);
    assert!(app.model().sessions()[0].instance.sim.time_secs() > 0.0);
    let err = dialogs::mesh_scene_file(&beam, "no-such-group").unwrap_err();
    assert!(err.contains("no-such-group"), "{err}");
}

#[test]
fn stepping_in_the_background_while_the_window_paints_gives_the_same_motion() {
    // as in the real window (an OpenGL context): the frames are stepped after the UI is built
    let mut h = harness(AppArgs { play: true, ..Default::default() });
    h.state_mut().gl_available = true;
    h.run_steps(20);
    assert!(h.state().model().stepping_in_background(), "the last frame's step runs in the background");
    h.state_mut().act(Action::Poll { wait_for_lesson: false });
    let app = h.state();
    let t = app.model().sessions()[0].instance.sim.time_secs();
    assert!(t > 0.1, "{t}");
    // the same number of frames stepped in place
    let mut reference = harness(AppArgs::default());
    reference.state_mut().step((t * 60.0).round() as usize);
    let r = &reference.state().model().sessions()[0].instance.sim;
    assert!((r.time_secs() - t).abs() < 1e-12);
    assert_eq!(r.positions, app.model().sessions()[0].instance.sim.positions);
}

/// Drags the free top corner of the beam's tip through the 3D view, drawn by the CPU rasteriser
/// (headless) or by OpenGL (picking then renders the depth buffer on the CPU when the drag
/// starts): the node is picked, an attachment pulls it while the button is held, none after.
fn drag_the_tip(gl: bool) {
    let mut h = harness(AppArgs::default());
    h.state_mut().gl_available = gl;
    h.run_steps(3);
    let (node, at) = {
        let app = h.state();
        let sim = &app.model().sessions()[0].instance.sim;
        let tip = sim
            .positions
            .iter()
            .enumerate()
            .filter(|(i, _)| sim.inv_mass()[*i] > 0.0)
            // a node inside the front face (y = 0) near the free end, off every silhouette edge
            .filter(|(_, p)| p.y.abs() < 1e-9)
            .min_by(|a, b| {
                let d = |p: &hox_sim::Vec3| (p - hox_sim::Vec3::new(1.75, 0.0, 0.25)).norm();
                d(a.1).total_cmp(&d(b.1))
            })
            .expect("free nodes");
        (tip.0 as u32, app.ui_state().viewport.screen_position(*tip.1).expect("the tip is in view"))
    };
    h.hover_at(at);
    h.run_steps(1);
    h.drag_at(at);
    h.run_steps(1);
    for k in 1..=5 {
        h.hover_at(at + egui::vec2(0.0, -8.0 * k as f32));
        h.run_steps(1);
    }
    let drag = h.state().model().sessions()[0].drag.expect("a node is being dragged");
    assert_eq!(drag.node, node, "the node under the cursor is picked");
    let start = h.state().model().sessions()[0].instance.sim.positions[node as usize];
    assert!(drag.target_m.z > start.z, "dragging upwards on screen pulls the node up: {drag:?} from {start}");
    h.drop_at(at + egui::vec2(0.0, -40.0));
    h.run_steps(2);
    assert!(h.state().model().sessions()[0].drag.is_none(), "the attachment exists only while dragging");
}

#[test]
fn a_node_can_be_dragged_in_the_cpu_drawn_view() {
    drag_the_tip(false);
}

#[test]
fn a_node_can_be_dragged_in_the_opengl_view() {
    drag_the_tip(true);
}

/// A teacher pushes E to 10⁹ Pa and the substeps to 1: the stability guard takes the substeps
/// the stiffest element needs and the status line says so; unticking it gives exactly what was
/// asked for (docs/STABILITY.md).
#[test]
fn a_stiff_material_at_one_substep_runs_under_the_stability_guard_shown_in_the_status_line() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    assert!(!status(&h).contains("(guard)"), "{}", status(&h));
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.substeps = 1;
    app.act(Action::change("substeps", c));
    h.run_steps(1);
    type_into(&mut h, "Young's modulus E (Pa)", "1e9");
    let sim = &h.state().model().sessions()[0].instance.sim;
    assert_eq!(sim.material().youngs_modulus_pa, 1e9);
    let taken = sim.substeps_per_frame();
    assert!(taken > 100, "{taken}");
    let s = status(&h);
    assert!(s.contains(&format!("{taken} substeps (guard)")), "{s}");
    // the checkbox of the Solver section (below the visible part of the panel at this size)
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.stability_guard = false;
    app.act(Action::change("guard", c));
    h.run_steps(3);
    assert!(!h.state().model().sessions()[0].config.stability_guard);
    assert_eq!(h.state().model().sessions()[0].instance.sim.substeps_per_frame(), 1);
    assert!(!status(&h).contains("(guard)"), "{}", status(&h));
}

/// Steps the harness until no configuration is settling (at most `max_steps` displayed frames).
fn settle_all(h: &mut Harness<'_, HoxApp>, max_steps: usize) {
    for _ in 0..max_steps {
        h.run_steps(1);
        if !h.state().model().settling() {
            break;
        }
    }
    assert!(!h.state().model().settling(), "still settling after {max_steps} displayed frames");
    h.run_steps(2);
}

/// Issue #20: compare P1 (1,280) with P2 (160), press E (*Settle*): each readout is the settled
/// error, within 5 % of what `hox simulate --settle` reports for the same configuration, and the
/// app pauses on the settled state.
#[test]
fn settle_shows_the_settled_errors_that_simulate_settle_gives() {
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    h.key_press(egui::Key::E);
    settle_all(&mut h, 3000);
    assert!(!h.state().model().playing(), "the app pauses on the settled state");
    for s in h.state().model().sessions() {
        assert!(matches!(s.settle_outcome, Some(hox_scenes::SettleState::Settled | hox_scenes::SettleState::AtRest)));
        let readout = s.readout();
        let Readout::Settled { error_m, .. } = readout else { panic!("{}: {readout:?}", s.label()) };
        // what the command line does: `hox simulate --settle` on the same configuration
        let mut instance = hox_scenes::Instance::new(s.instance.scene.clone()).unwrap();
        let report = hox_scenes::run(&mut instance, hox_scenes::RunMode::SETTLE, &mut |_, _| {}).unwrap();
        let probes: Vec<(String, [f64; 3])> = report.probes.into_iter().collect();
        let expected = s.reference.reference().unwrap().error_m(&probes).unwrap();
        assert!(
            (error_m - expected).abs() <= 0.05 * expected,
            "{}: app {error_m:e} m, simulate {expected:e} m",
            s.label()
        );
        assert!(!s.instance.sim.effects().iter().any(|e| e.name() == hox_scenes::SETTLE_DAMPING_NAME));
    }
    let (p1, p2) = (&h.state().model().sessions()[0], &h.state().model().sessions()[1]);
    let e = |s: &session::Session| s.readout().error_with_uncertainty_m().unwrap().0;
    // settled, P2 160 is far nearer the reference than P1 1,280 (about 1.3 mm against 5.4 cm)
    assert!(e(p1) > 10.0 * e(p2), "P1 {} vs P2 {}", e(p1), e(p2));
    assert_eq!(h.query_all_by_label_contains("settled error").count(), 2, "both status lines say settled");
}

/// Issue #20: a swinging beam's readout is the mean of its last oscillation, never the
/// instantaneous distance, and says it is moving.
#[test]
fn a_swinging_beam_reads_out_the_mean_of_its_motion() {
    let mut h = harness(AppArgs::default());
    h.run_steps(1);
    h.state_mut().step(150);
    h.run_steps(1);
    let s = &h.state().model().sessions()[0];
    let Readout::Moving { error_m, amplitude_m, period_secs, .. } = s.readout() else { panic!("{:?}", s.readout()) };
    // the tip swings about 0.3 m around its sag; the mean is much nearer the reference than
    // the swing (an instantaneous value would be off by up to the amplitude)
    assert!(amplitude_m > 0.2 && error_m < 0.1 * amplitude_m, "error {error_m}, amplitude {amplitude_m}");
    assert!((0.7..1.2).contains(&period_secs), "{period_secs}");
    assert!(status(&h).contains("mean error"), "{}", status(&h));
}

/// Issue #20: at ν = 0.49 the reference is computed for ν = 0.49 (in the background, with
/// progress), not the committed ν = 0.35 one; back at ν = 0.35 the committed one returns.
#[test]
fn the_reference_follows_the_poisson_ratio() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let committed =
        h.state().model().sessions()[0].reference.reference().cloned().expect("bending's committed reference");
    assert_eq!(committed.origin, hox_scenes::reference::Origin::Committed);
    type_into(&mut h, "Poisson ratio ν", "0.49");
    assert_eq!(h.state().model().sessions()[0].instance.sim.material().poisson_ratio, 0.49);
    // (another test may have computed ν = 0.49 already: the memory cache is the process's)
    assert!(
        h.state().model().sessions()[0].reference.reference().is_none_or(|r| r.poisson_ratio == 0.49),
        "the ν = 0.35 reference is withdrawn at once"
    );
    h.state_mut().model_mut().sessions_mut()[0].reference.wait();
    h.run_steps(2);
    let r = h.state().model().sessions()[0].reference.reference().cloned().expect("computed");
    assert_eq!((r.origin, r.poisson_ratio), (hox_scenes::reference::Origin::Computed, 0.49));
    assert!(r.probes["tip"][2] > committed.probes["tip"][2], "a nearly incompressible beam sags less");
    assert!(r.estimated_error_m.is_some());
    type_into(&mut h, "Poisson ratio ν", "0.35");
    assert_eq!(h.state().model().sessions()[0].reference.reference(), Some(&committed));
}

/// Issue #20: the surface can be coloured by every field, from the "Colour by" menu or key F;
/// the legend's range follows the field (its unit), stress appears once the beam bends, and the
/// error field measures against the reference's displacement field once it is computed.
#[test]
fn the_colour_field_switches_and_its_range_follows() {
    use hox_sim::measure::field::Field;
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    assert_eq!(h.state().ui_state().viewport.colour_range().map(|r| r.field), Some(Field::Displacement));
    // the "Colour by" menu of the Display section (below the visible part of the panel here)
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.field = vec![Field::VonMises];
    app.act(Action::change("field", c));
    h.run_steps(2);
    assert_eq!(h.state().model().sessions()[0].config.field, [Field::VonMises]);
    h.state_mut().step(20);
    h.run_steps(2);
    let r = h.state().ui_state().viewport.colour_range().unwrap();
    assert_eq!((r.field, r.field.unit(), r.automatic), (Field::VonMises, "Pa", true));
    // a bending beam of E = 3 MPa is stressed by some kPa to a few hundred kPa
    assert!((1e3..1e7).contains(&r.max), "{r:?}");
    // F walks through the fields in order
    h.key_press(egui::Key::F);
    h.run_steps(2);
    assert_eq!(h.state().ui_state().viewport.colour_range().unwrap().field, Field::Strain);
    h.key_press(egui::Key::F);
    h.run_steps(2);
    let det = h.state().ui_state().viewport.colour_range().unwrap();
    assert!(det.field == Field::DetF && det.min < 1.0 && det.max > 1.0, "{det:?}");
    // the error field: the reference's displacement field is solved in the background
    h.state_mut().act(Action::SetField(Field::Error));
    h.state_mut().model_mut().sessions_mut()[0].reference.wait();
    h.run_steps(2);
    let s = &h.state().model().sessions()[0];
    let view = h.state().ui_state().viewport.view(0).expect("drawn");
    assert!(view.field_source.has_reference(), "{}", s.reference.status());
    let r = h.state().ui_state().viewport.colour_range().unwrap();
    assert_eq!((r.field, r.field.unit()), (Field::Error, "m"));
}

/// Issue #20: the camera presets (buttons and keys 1–4) look along the axes and lay the compared
/// configurations apart across the line of sight: in every preset the two bodies' drawn
/// extents do not overlap.
#[test]
fn camera_presets_lay_compared_bodies_apart() {
    use super::presets::ViewPreset;
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    // every preset is a key; the last one also from the View menu
    for (k, preset) in ViewPreset::ALL.into_iter().enumerate() {
        h.key_press([egui::Key::Num1, egui::Key::Num2, egui::Key::Num3, egui::Key::Num4][k]);
        h.run_steps(3);
        let app = h.state();
        assert_eq!(app.ui_state().viewport.preset, preset);
        assert_eq!((app.ui_state().viewport.camera.yaw, app.ui_state().viewport.camera.pitch), preset.yaw_pitch());
        // each body's screen rectangle (its bounding box's corners, offset)
        let offsets = app.model().offsets();
        let rects: Vec<egui::Rect> = app
            .model()
            .sessions()
            .iter()
            .zip(&offsets)
            .map(|(s, o)| {
                let (lo, hi) = s.instance.sim.mesh().bounding_box();
                let corners = (0..8).filter_map(|c| {
                    let p = hox_sim::Vec3::new(
                        if c & 1 == 0 { lo.x } else { hi.x },
                        if c & 2 == 0 { lo.y } else { hi.y },
                        if c & 4 == 0 { lo.z } else { hi.z },
                    );
                    app.ui_state().viewport.screen_position(p + o)
                });
                egui::Rect::from_points(&corners.collect::<Vec<_>>())
            })
            .collect();
        assert!(rects.iter().all(|r| r.is_positive()), "{preset:?}: {rects:?}");
        assert!(!rects[0].intersects(rects[1]), "{preset:?}: the bodies overlap on screen: {rects:?}");
    }
    h.get_by_role_and_label(egui::accesskit::Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Front view").click();
    h.run_steps(3);
    assert_eq!(h.state().ui_state().viewport.preset, ViewPreset::Front);
}

/// Issue #20: what a teacher prepared starts from the command line — two configurations as
/// `record --compare` takes them, a material override, a field and a camera; the plot's legend
/// sits above the plot and each status line fits on one line.
#[test]
fn a_prepared_comparison_starts_from_flags_and_reads_cleanly() {
    use hox_sim::measure::field::Field;
    let args = args::parse_for_test(&[
        "--compare",
        "element=p1,refine=1",
        "--compare",
        "element=p2",
        "--poisson",
        "0.3",
        "--field",
        "von-mises",
        "--camera",
        "front",
    ]);
    let mut h = harness(args);
    h.run_steps(3);
    let app = h.state();
    let labels: Vec<String> = app.model().sessions().iter().map(|s| s.label()).collect();
    assert_eq!(labels, ["P1 8×2×2 five r1", "P2 8×2×2 five"]);
    assert!(app.model().compare() && app.model().sessions().iter().all(|s| s.config.poisson_ratio == 0.3));
    assert_eq!(app.ui_state().viewport.preset, ViewPreset::Front);
    assert_eq!(app.ui_state().viewport.colour_range().unwrap().field, Field::VonMises);
    // the probe plot shows u_z per configuration, its legend a row above the plot
    assert_eq!(app.ui_state().probe_axes(app.model().compare()), [false, false, true]);
    let legend = h.get_by_label("A P1 8×2×2 five r1 u_z").rect();
    let tab = h.get_by_label("Probe displacement").rect();
    let statuses: Vec<egui::Rect> = h.query_all_by_label_contains("nodes,").map(|n| n.rect()).collect();
    // between the tabs and the plot: the plot fills the rest of the panel, down to the status line
    assert!(legend.min.y >= tab.max.y && legend.max.y + 100.0 < statuses[0].min.y, "legend {legend:?}, tab {tab:?}");
    // one line per status entry, both on the same line: no taller than a line of monospace text
    assert_eq!(statuses.len(), 2);
    for r in &statuses {
        assert!(r.height() <= 24.0 && (r.min.y - statuses[0].min.y).abs() < 1.0, "{statuses:?}");
    }
    // a refused value names the option
    let err = HoxApp::new(&args::parse_for_test(&["--compare", "element=p1", "--compare", "refine=9"]), None)
        .err()
        .unwrap_or_default();
    assert!(err.contains("--compare 'refine=9'"), "{err}");
}

/// Issue #21: `--lesson` opens a lesson on its first step — configurations, camera, text,
/// question and the live measurement beside them; A reveals the answer, → goes on, ← back; P is
/// presenter mode (the interface scaled up, the panels away, the caption over the view).
#[test]
fn a_lesson_steps_through_with_its_live_measurement_and_answer() {
    use super::presets::ViewPreset;
    let mut h = harness(args::parse_for_test(&["--lesson", "mesh-bias"]));
    h.run_steps(3);
    h.get_by_label_contains("Step 1 of 3: Five against six");
    // the parameters the lesson's steps change (issue #35)
    h.get_by_label_contains("A: Element p1 · Tet split five");
    h.get_by_label_contains("Question: Does either tip move sideways");
    let labels: Vec<String> = h.state().model().sessions().iter().map(|s| s.label()).collect();
    assert_eq!(labels, ["P1 8×2×2 five", "P1 8×2×2 six"]);
    assert_eq!(h.state().ui_state().viewport.preset, ViewPreset::Top);
    // the static step shows the equilibrium at once: the six-split tip sits 2.7 cm sideways
    let six = text(&h, "B P1 8×2×2 six: 0.0");
    assert!(six.contains("0.027"), "{six}");
    assert!(h.query_by_label_contains("Answer:").is_none(), "the answer waits");
    h.key_press(egui::Key::A);
    h.run_steps(2);
    h.get_by_label_contains("Answer: B does");
    h.key_press(egui::Key::ArrowRight);
    h.run_steps(1);
    // issue #35: while the step is prepared the panel says so, with neither numbers nor answer
    h.get_by_label_contains("Step 2 of 3: Does high order help?");
    if h.state().model().lesson().unwrap().preparing() {
        h.get_by_label_contains("Preparing this step");
        assert!(h.query_by_label_contains("Answer: B does").is_none(), "the last step's answer is gone");
    }
    lesson_ready(&mut h);
    assert!(h.state().model().sessions().iter().all(|s| s.config.element.name() == "p2"));
    assert!(h.query_by_label_contains("Answer:").is_none(), "a new step hides its answer");
    h.key_press(egui::Key::ArrowLeft);
    lesson_ready(&mut h);
    h.get_by_label_contains("Step 1 of 3");
    // presenter mode: no side panels; the caption carries the numbers
    h.key_press(egui::Key::P);
    h.run_steps(3);
    assert!(h.state().model().presenter());
    assert!(h.query_by_label_contains("Compare two configurations").is_none(), "the controls are hidden");
    h.get_by_label_contains("Mesh bias — Five against six");
    h.get_by_label_contains("B probe u_y (sideways): 0.027");
}

/// Issue #21: a lesson that plays for some seconds pauses at its end; the Lessons menu lists
/// every lesson; the very first start offers them; a bad lesson file names the file and key.
#[test]
fn lessons_play_their_seconds_are_listed_and_offered_at_first_start() {
    let mut h = harness(args::parse_for_test(&["--lesson", "why-high-order"]));
    h.run_steps(2);
    assert!(h.state().model().playing());
    // the first step plays 0.45 s (27 frames) and pauses there
    h.state_mut().step(27);
    h.run_steps(3);
    assert!(!h.state().model().playing(), "paused at the bottom of the swing");
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Lessons").click();
    h.run_steps(2);
    // every lesson is in the menu (the open one's title is also the panel's heading)
    for l in hox_scenes::lesson::registry().unwrap() {
        assert!(h.query_all_by_label(&l.title).count() >= 1, "{}", l.title);
    }
    assert!(
        HoxApp::new(&AppArgs::default(), None).unwrap().ui_state().offer_lessons,
        "the first start offers the lessons"
    );
    assert!(!HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap().ui_state().offer_lessons);
    let bad = std::env::temp_dir().join(format!("hox-bad-lesson-{}.toml", std::process::id()));
    std::fs::write(&bad, "title = \"t\"\ngoal = \"g\"\n[[steps]]\ntitle = \"s\"\nscene = \"bending\"\nmeasure = \"tip-uz\"\ntext = \"x\"\nquestion = \"q\"\nanswer = \"a\"\na = { poisson = 0.7 }\n").unwrap();
    let err =
        HoxApp::new(&args::parse_for_test(&["--lesson-file", bad.to_str().unwrap()]), None).err().unwrap_or_default();
    assert!(err.contains("hox-bad-lesson") && err.contains("a.poisson"), "{err}");
}

/// Issue #35, symptom 3: presenter mode's scale leaked into the next ordinary start (egui keeps
/// its zoom in the memory it saves). A new, ordinary app on the same egui memory is at scale 1;
/// a window larger than the screen is shrunk to fit it.
#[test]
fn presenter_scale_does_not_leak_into_the_next_start() {
    let mut h = harness(args::parse_for_test(&["--lesson", "mesh-bias", "--presenter"]));
    h.run_steps(2);
    assert_eq!(h.ctx.zoom_factor(), super::lesson::PRESENTER_ZOOM);
    // the next start: a new app, egui's memory (and so the zoom) restored as it was saved
    *h.state_mut() = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap();
    h.run_steps(2);
    assert_eq!(h.ctx.zoom_factor(), 1.0, "an ordinary start is at the ordinary scale");
    assert!(!h.state().model().presenter());
    // 2560×1440 on a 1600×900 screen is shrunk to fit; a window that fits is left alone
    let fitted = window::fitted_inner_size(egui::vec2(2560.0, 1440.0), egui::vec2(1600.0, 900.0), true).unwrap();
    assert!(fitted.x <= 1600.0 && fitted.y <= 900.0, "{fitted:?}");
    assert_eq!(window::fitted_inner_size(egui::vec2(1400.0, 800.0), egui::vec2(1920.0, 1080.0), true), None);
}

/// Issue #57: a presenter session once left a 784×386 window (the projector's size in presenter
/// mode's points) that the next plain start reopened. A restored window too small to use grows to
/// a usable size the screen has room for; a size asked for with `--size` is kept.
#[test]
fn a_window_left_too_small_by_presenter_mode_reopens_usable() {
    let projector = egui::vec2(1280.0, 720.0);
    let grown = window::fitted_inner_size(egui::vec2(784.0, 386.0), projector, true).expect("grown");
    assert!(grown.x >= 1024.0 && grown.y >= 640.0 - 64.0, "{grown:?}");
    assert!(grown.x <= projector.x && grown.y <= projector.y, "{grown:?}");
    assert_eq!(window::fitted_inner_size(egui::vec2(784.0, 386.0), projector, false), None, "--size 784x386 is kept");
    assert_eq!(window::fitted_inner_size(egui::vec2(1200.0, 700.0), egui::vec2(1920.0, 1080.0), true), None);
    // the start that restores it asks to grow; one given --size does not
    let restored = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap();
    assert!(restored.ui_state().grow_to_usable);
    let sized =
        HoxApp::new(&AppArgs { fresh: true, size: Some("800x500".into()), ..Default::default() }, None).unwrap();
    assert!(!sized.ui_state().grow_to_usable);
}

/// Issue #35, symptom 8: under XPBD the implicit solvers' typed fields (Chebyshev ρ, Newton
/// tolerance) looked active; they are greyed as the sliders of the other solvers' rows are, and
/// come back with their solver.
#[test]
fn another_solvers_typed_fields_are_greyed() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let disabled = |h: &Harness<'_, HoxApp>, label: &str| h.get_by_label(label).accesskit_node().is_disabled();
    assert!(disabled(&h, "Chebyshev ρ"), "Chebyshev ρ active under XPBD");
    assert!(disabled(&h, "Newton tolerance"), "Newton tolerance active under XPBD");
    assert!(!disabled(&h, "Young's modulus E (Pa)"), "a material field is always active");
    let mut c = h.state().model().sessions()[0].config.clone();
    c.method = hox_sim::solver::Method::Newton;
    h.state_mut().act(Action::change("solver", c));
    h.run_steps(2);
    assert!(!disabled(&h, "Newton tolerance"), "Newton's own field under Newton");
    assert!(disabled(&h, "Chebyshev ρ"), "VBD's field under Newton");
}

/// Issue #35, symptom 8: paused, the status line said "0–1 fps" (the window repaints only on
/// input); it says "paused", and the frame rate while playing.
#[test]
fn the_status_line_says_paused_instead_of_a_frame_rate() {
    let mut h = harness(AppArgs::default());
    h.run_steps(3);
    assert!(!h.state().model().playing());
    h.get_by_label("paused");
    assert!(h.query_by_label_contains(" fps").is_none(), "no frame rate while paused");
    h.state_mut().act(Action::SetPlaying(true));
    h.run_steps(3);
    h.get_by_label_contains(" fps");
    assert!(h.query_by_label("paused").is_none());
}

/// Issue #35, symptom 8: the labels above the bodies name A and B, as the status line and the
/// controls' "Editing: A … B …" do.
#[test]
fn the_labels_above_the_bodies_name_a_and_b() {
    let h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    let s = &h.state().model().sessions();
    let a = viewport::body_label(0, &s[0].label(), "x");
    let b = viewport::body_label(1, &s[1].label(), "y");
    assert!(a.starts_with(&format!("A: {}", s[0].label())) && a.ends_with("\nx"), "{a}");
    assert!(b.starts_with(&format!("B: {}", s[1].label())) && b.ends_with("\ny"), "{b}");
}

/// Issue #35, symptom 8: at t = 0 the readouts said "moving"; they say the run has not
/// started, and "moving" once it has.
#[test]
fn a_beam_not_yet_run_is_not_called_moving() {
    let mut h = harness(AppArgs::default());
    h.run_steps(3);
    let s = status(&h);
    assert!(s.contains("not started") && !s.contains("moving"), "{s}");
    h.state_mut().step(3);
    h.run_steps(2);
    // stepped while paused: it is mid-swing, and says it is paused (it read "moving")
    let s = status(&h);
    assert!(s.contains("paused mid-swing") && !s.contains("not started") && !s.contains("moving"), "{s}");
    h.state_mut().act(Action::SetPlaying(true));
    h.run_steps(2);
    let s = status(&h);
    assert!(s.contains("moving") && !s.contains("paused mid-swing"), "{s}");
}

/// Changes configuration A's `key` as a user's control would, and draws two frames.
fn change_a(h: &mut Harness<'_, HoxApp>, key: &str, change: impl FnOnce(&mut crate::gui::config::Config)) {
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    change(&mut c);
    app.act(Action::change(key, c));
    h.run_steps(2);
}

/// Switches configuration A to Newton; the notes under the solver say the motion is its
/// integrator's, and what the default integrator (BDF2) does to it.
fn choose_newton_for_a(h: &mut Harness<'_, HoxApp>) {
    change_a(h, "solver", |c| c.method = hox_sim::solver::Method::Newton);
    h.get_by_label_contains("the motion is its integrator's");
    h.get_by_label_contains("BDF2 (backward differentiation): Second order");
}

/// Issue #35, symptoms 6 and 8: the solver's effect on the motion is said where it is chosen;
/// a lesson's static step reads "static equilibrium", not "moving" or "not started".
#[test]
fn the_solver_says_what_it_does_to_the_motion_and_a_static_step_says_static() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    h.get_by_label_contains("Keeps the motion");
    choose_newton_for_a(&mut h);
    assert!(h.query_by_label_contains("Keeps the motion").is_none());
    // issue #36: implicit Euler, chosen, says it damps
    change_a(&mut h, "integrator", |c| c.integrator = hox_sim::solver::Integrator::Euler);
    h.get_by_label_contains("implicit Euler: First order; damps every mode");
    let mut h = harness(args::parse_for_test(&["--lesson", "mesh-bias"]));
    h.run_steps(3);
    for s in h.state().model().sessions() {
        assert!(s.readout_label().starts_with("static equilibrium: error"), "{}", s.readout_label());
    }
    // in a lesson both status lines give the step's measurement, as its panel (issue #57)
    let title = h.state().model().lesson().unwrap().current().measure.title();
    assert!(h.query_all_by_label_contains(title).count() >= 2, "both status lines give the step's {title}");
}

/// Issue #35, symptoms 1–2: the default comparison (P1 refined once against P2) at ν = 0.49.
/// The refined P1 read "no reference" for good (its Q2 reference levels inherited `refine`),
/// and both read "no reference" while the reference was computed. Now both say what is being
/// computed, then read out against the one reference of their shared physics. (ν = 0.485
/// here: other tests compute ν = 0.49 in the same process, whose memory cache is shared.)
#[test]
fn a_refined_p1_and_p2_at_nu_0_49_both_get_a_reference() {
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    type_into(&mut h, "Poisson ratio ν", "0.485");
    // one computation for the shared physics, not two at half speed each
    let jobs: Vec<_> = h
        .state()
        .model()
        .sessions()
        .iter()
        .map(|s| match &s.reference {
            readout::ReferenceState::Computing { job, .. } => Some(std::sync::Arc::as_ptr(job)),
            _ => None,
        })
        .collect();
    let live: Vec<_> = jobs.iter().flatten().collect();
    assert!(live.windows(2).all(|w| w[0] == w[1]), "{jobs:?}");
    for s in h.state().model().sessions() {
        let label = s.readout_label();
        assert!(!label.contains("no reference"), "{label}");
        // computing (a fast machine may have finished the small test levels already)
        if matches!(s.reference, readout::ReferenceState::Computing { .. }) {
            assert!(label.contains("computing reference") || label.contains("refining"), "{label}");
        }
    }
    for line in h.query_all_by_label_contains("nodes,") {
        let line = line.accesskit_node().label().or_else(|| line.accesskit_node().value()).unwrap_or_default();
        assert!(!line.contains("no reference"), "{line}");
    }
    for k in 0..2 {
        h.state_mut().model_mut().sessions_mut()[k].reference.wait();
    }
    h.state_mut().step(150);
    h.run_steps(2);
    let references: Vec<_> = h.state().model().sessions().iter().map(|s| s.reference.reference().cloned()).collect();
    let a = references[0].clone().expect("the refined P1 has a reference");
    assert_eq!((a.origin, a.poisson_ratio, a.refining), (hox_scenes::reference::Origin::Computed, 0.485, None));
    assert_eq!(references[1].as_ref(), Some(&a), "one reference for the shared physics");
    for s in h.state().model().sessions() {
        assert!(matches!(s.readout(), Readout::Moving { .. }), "{}: {:?}", s.label(), s.readout());
        assert!(s.readout_label().starts_with("mean error"), "{}", s.readout_label());
    }
}

/// Issue #35, symptom 2: a provisional estimate is used as soon as the computation publishes
/// it, labelled with its error bar and the level the computation is at; then the final one.
#[test]
fn a_provisional_reference_is_used_and_labelled_while_it_refines() {
    use hox_scenes::reference::{Origin, Reference, Refining};
    use std::sync::{Arc, Mutex};
    let estimate = Reference {
        origin: Origin::Computed,
        probes: [("tip".to_string(), [0.0, 0.0, -0.25])].into(),
        mesh: "Q2 32×8×8 extrapolated".into(),
        estimated_error_m: Some(0.01),
        estimate: "test".into(),
        poisson_ratio: 0.49,
        field: None,
        refining: Some(Refining { levels_done: 3, levels: 6 }),
    };
    let job = Arc::new(readout::Job {
        progress: Mutex::new(("computing reference, level 4 of 6 (static Q2 20×5×5)".into(), 0.2)),
        ..Default::default()
    });
    let mut state = readout::ReferenceState::Computing { key: "k".into(), job: job.clone(), latest: None };
    assert_eq!(state.short_status().as_deref(), Some("computing reference, level 4 of 6"));
    assert!(!state.poll() && state.reference().is_none());
    *job.estimate.lock().unwrap() = Some(Arc::new(estimate.clone()));
    assert!(state.poll(), "a new estimate is taken in");
    assert!(!state.poll(), "once");
    assert_eq!(state.reference(), Some(&estimate));
    assert_eq!(state.short_status().as_deref(), Some("reference 0.2500 m ± 4.00 % (refining, 4 of 6)"));
    assert!(
        state.status().starts_with("reference: provisional, levels 1–3 of 6 solved, refining"),
        "{}",
        state.status()
    );
    *job.result.lock().unwrap() = Some(Ok(Arc::new(Reference { refining: None, ..estimate })));
    assert!(state.poll() && state.reference().is_some_and(|r| r.refining.is_none()));
    assert_eq!(state.short_status(), None);
}

/// Issue #35: a computation no session wants any more (ν typed again) stops, instead of
/// slowing the one wanted now.
#[test]
fn a_reference_no_longer_wanted_stops_computing() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let scene = |nu: f64| {
        let s = &h.state().model().sessions()[0].instance.scene;
        s.with_overrides(&hox_scenes::SceneOverrides { poisson_ratio: Some(nu), ..Default::default() }).unwrap()
    };
    // a state made now is computing (nothing is cached for ν = 0.471), and a second state for
    // the same physics shares its job
    let wanted = readout::ReferenceState::for_scene(&scene(0.471), false);
    let also = readout::ReferenceState::for_scene(&scene(0.471), false);
    let job_of = |s: &readout::ReferenceState| match s {
        readout::ReferenceState::Computing { job, .. } => Some(std::sync::Arc::as_ptr(job)),
        _ => None,
    };
    assert!(job_of(&wanted).is_some() && job_of(&wanted) == job_of(&also), "one computation, shared");
    drop(also);
    let readout::ReferenceState::Computing { job, .. } = &wanted else { panic!("ν = 0.471 is computed") };
    let abandoned = std::sync::Arc::downgrade(job);
    // ν typed again: the session's state is replaced, and with it the only owner of the job,
    // whose thread stops at its next progress report
    drop(wanted);
    assert!(abandoned.upgrade().is_none(), "no one holds the ν = 0.471 computation");
    type_into(&mut h, "Poisson ratio ν", "0.46");
    h.state_mut().model_mut().sessions_mut()[0].reference.wait();
    let r = h.state().model().sessions()[0].reference.reference().cloned().expect("ν = 0.46 computed");
    assert_eq!((r.poisson_ratio, r.refining), (0.46, None));
}

/// Issue #35, symptom 4: lessons showed other numbers than `hox lesson` (why-high-order step 1
/// stopped at 0.47–0.48 s instead of 0.45 s), and different ones each run. Every lesson, run
/// twice in the app and once headlessly, shows the same numbers to the digits shown; a time per
/// frame (the machine's) only has to be measured.
#[test]
#[ignore = "every lesson three times (minutes): .ci/run runs it with --ignored"]
fn every_lesson_shows_the_same_numbers_in_the_app_as_headlessly() {
    use hox_scenes::lesson::{Measure, Run};
    for lesson in hox_scenes::lesson::registry().unwrap() {
        let headless: Vec<Vec<String>> = lesson
            .steps
            .iter()
            .map(|step| {
                let (_, measured) = hox_scenes::lesson::run_step(step, &mut |_, _| {}).unwrap();
                measured.into_iter().map(|m| m.text).collect()
            })
            .collect();
        let mut runs = Vec::new();
        for _ in 0..2 {
            let mut app = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap();
            let shown = app.lesson_answers(&lesson, &mut |app, k| {
                if let Run::Seconds(secs) = lesson.steps[k].run {
                    let t = app.model().sessions()[0].instance.sim.time_secs();
                    assert!((t - secs).abs() < 1e-9, "{} step {}: ended at {t} s, not {secs} s", lesson.name, k + 1);
                }
            });
            runs.push(shown);
        }
        for (k, step) in lesson.steps.iter().enumerate() {
            let what = format!("{} step {} ({})", lesson.name, k + 1, step.measure.name());
            if step.measure == Measure::MsPerFrame {
                for texts in [&runs[0][k], &runs[1][k], &headless[k]] {
                    assert!(
                        texts.iter().all(|t| t.ends_with("ms per frame") && !t.contains("NaN")),
                        "{what}: {texts:?}"
                    );
                }
                continue;
            }
            assert_eq!(runs[0][k], headless[k], "{what}: the app against hox lesson");
            assert_eq!(runs[1][k], runs[0][k], "{what}: the app's second run against its first");
        }
    }
}

/// Runs frames until a change's meshes, built in the background, are in.
fn built(h: &mut Harness<'_, HoxApp>) {
    for _ in 0..2_000 {
        if h.state().model().building().is_none() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
        h.run_steps(1);
    }
    panic!("still building");
}

/// Issue #35, symptom 7: refine 3 was accepted without a word and froze the window (13.6 s per
/// frame; the next typed value was lost). A change estimated too slow to play asks first,
/// keeping the current configuration until answered; a frame that is slow anyway pauses.
#[test]
fn a_change_too_slow_to_play_asks_first_and_a_slow_frame_pauses() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    // as measured on a machine where the P2 beam takes 5 ms per frame
    h.state_mut().model_mut().sessions_mut()[0].ms_per_frame = 5.0;
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.refine = 2;
    app.act(Action::change("refine", c.clone()));
    built(&mut h);
    let app = h.state_mut();
    assert!(app.model().pending_change().is_some(), "64 times the elements: asked first");
    assert_eq!(app.model().sessions()[0].instance.sim.mesh().num_elements(), 160, "nothing changed yet");
    h.run_steps(2);
    let question = text(&h, "elements, ");
    assert!(question.contains("10240 elements") && question.contains("per frame"), "{question}");
    h.get_by_label("Keep the current configuration").click();
    h.run_steps(2);
    assert!(h.state().model().pending_change().is_none());
    assert_eq!(h.state().model().sessions()[0].config.refine, 0);
    h.state_mut().act(Action::change("refine", c));
    built(&mut h);
    h.run_steps(1);
    h.get_by_label("Apply, paused").click();
    h.run_steps(2);
    assert_eq!(h.state().model().sessions()[0].instance.sim.mesh().num_elements(), 10240);
    assert!(!h.state().model().playing());
    // a solver setting is estimated on the current mesh: 100 times the substeps of a 5 ms frame
    h.state_mut().act(Action::AnswerPending(false));
    h.state_mut().model_mut().sessions_mut()[0].ms_per_frame = 5.0;
    let app = h.state_mut();
    let mut c = app.model().sessions()[0].config.clone();
    c.substeps = 100 * app.model().sessions()[0].instance.sim.substeps_per_frame();
    app.act(Action::change("substeps", c));
    assert!(app.model().pending_change().as_ref().is_some_and(|p| p.estimate.contains("xpbd solver")), "asked first");
    h.state_mut().act(Action::AnswerPending(false));
    // a frame slower than the limit pauses a playing app, saying why
    h.state_mut().act(Action::SetPlaying(true));
    h.state_mut().model_mut().sessions_mut()[0].ms_per_frame = 2.0 * super::cost::SLOW_FRAME_MS;
    h.run_steps(1);
    assert!(!h.state().model().playing(), "paused");
    assert!(h.state().model().message().is_some_and(|m| m.starts_with("Paused: a frame takes")));
}

/// Issue #57: typing "64" into a grid cell rebuilt the beam at 6 cells first (and "32" while
/// playing at 3, which the slowness question then kept, losing the 8 that was there). A typed
/// number applies once, on Enter.
#[test]
fn typing_a_multi_digit_value_applies_it_once_not_digit_by_digit() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let builds = |h: &Harness<'_, HoxApp>| h.state().model().generation();
    let grid = |h: &Harness<'_, HoxApp>| h.state().model().sessions()[0].config.grid;
    let before = builds(&h);
    // the grid's x cell: the widget the label "x" labels (a spin button; a text field while typed in)
    let cell =
        || |n: &egui_kittest::kittest::AccessKitNode<'_>| n.labelled_by().any(|l| l.value().as_deref() == Some("x"));
    h.get_by(cell()).focus();
    h.run_steps(1);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    for digit in ["3", "2"] {
        h.get_by(cell()).type_text(digit);
        h.run_steps(2);
        assert_eq!(grid(&h), [8, 2, 2], "nothing applied while typing");
        assert_eq!(builds(&h), before, "nothing rebuilt while typing");
    }
    h.key_press(egui::Key::Enter);
    h.run_steps(3);
    assert_eq!(grid(&h), [32, 2, 2]);
    assert_eq!(h.state().model().sessions()[0].instance.sim.mesh().num_elements(), 32 * 2 * 2 * 5);
    assert_eq!(builds(&h), before + 1, "built once");
}

/// The drawn labels, legend and bodies of the view: every label inside the view, clear of the
/// legend, the other label and both bodies; every body inside the view (issue #35, symptom 5).
fn assert_layout_fits(h: &Harness<'_, HoxApp>, what: &str) {
    let d = &h.state().ui_state().viewport.drawn;
    let view = d.view.expect("the view was drawn");
    let legend = d.legend.expect("the legend was drawn");
    assert!(view.contains_rect(legend), "{what}: legend {legend:?} outside the view {view:?}");
    for (k, body) in d.bodies.iter().enumerate() {
        assert!(view.expand(1.0).contains_rect(*body), "{what}: body {k} {body:?} leaves the view {view:?}");
        assert!(!body.intersects(legend), "{what}: body {k} {body:?} under the legend {legend:?}");
    }
    // issue #57: in presenter mode a label could sit in a corner far from its body
    let gap = |a: egui::Rect, b: egui::Rect| {
        let dx = (a.min.x - b.max.x).max(b.min.x - a.max.x).max(0.0);
        let dy = (a.min.y - b.max.y).max(b.min.y - a.max.y).max(0.0);
        (dx * dx + dy * dy).sqrt()
    };
    let near = 0.25 * view.width().max(view.height());
    for (k, (label, body)) in d.labels.iter().zip(&d.bodies).enumerate() {
        let g = gap(*label, *body);
        assert!(g <= near, "{what}: label {k} {label:?} is {g:.0} points from its body {body:?} (at most {near:.0})");
    }
    for (k, label) in d.labels.iter().enumerate() {
        assert!(view.contains_rect(*label), "{what}: label {k} {label:?} leaves the view {view:?}");
        assert!(!label.intersects(legend), "{what}: label {k} {label:?} on the legend {legend:?}");
        for (j, other) in d.labels.iter().chain(&d.bodies).enumerate() {
            assert!(j == k || !label.intersects(*other), "{what}: label {k} {label:?} on {other:?}");
        }
    }
}

fn harness_sized(args: AppArgs, size: egui::Vec2) -> Harness<'static, HoxApp> {
    let app = HoxApp::new(&AppArgs { fresh: true, ..args }, None).expect("the app starts");
    Harness::builder()
        .with_size(size)
        .allow_missing_glyphs()
        .with_step_dt(1.0 / 60.0)
        .build_ui_state(|ui, app: &mut HoxApp| app.ui_all(ui), app)
}

/// Plays until the app pauses (a settle ends, a lesson step ends), as the window would.
fn play_until_paused(h: &mut Harness<'_, HoxApp>) {
    for _ in 0..2_000 {
        if !h.state().model().playing() {
            return;
        }
        h.run_steps(1);
    }
    panic!("still playing");
}

/// Issue #35's scenario, the session a teacher runs, at a projector's 1280×720 and at
/// 1920×1080: compare P1 refined once against P2, type ν, settle, switch solver, a lesson
/// stepped forward and back with its answer, presenter mode on and off, a restart. At every
/// stage the readouts say what they are and nothing drawn overlaps.
#[test]
fn a_classroom_session_at_projector_and_full_hd_sizes() {
    for size in [egui::vec2(1280.0, 720.0), egui::vec2(1920.0, 1080.0)] {
        let at = |what: &str| format!("{}×{}: {what}", size.x, size.y);
        let mut h = harness_sized(AppArgs { compare: vec![String::new()], ..Default::default() }, size);
        h.run_steps(3);
        assert_layout_fits(&h, &at("start"));
        assert_eq!(h.state().ui_state().viewport.drawn.labels.len(), 2, "{}", at("both bodies labelled"));
        // ν typed: both say what the reference is doing, never "no reference"
        type_into(&mut h, "Poisson ratio ν", "0.45");
        for s in h.state().model().sessions() {
            assert!(!s.readout_label().contains("no reference"), "{}: {}", at("ν typed"), s.readout_label());
        }
        for k in 0..2 {
            h.state_mut().model_mut().sessions_mut()[k].reference.wait();
        }
        // settle: both read their settled error, the app pauses
        h.state_mut().act(Action::Settle);
        play_until_paused(&mut h);
        h.run_steps(2);
        for s in h.state().model().sessions() {
            assert!(s.readout_label().starts_with("settled: error"), "{}: {}", at("settled"), s.readout_label());
        }
        assert_layout_fits(&h, &at("settled"));
        // another solver for A: said under the solver what it does to the motion
        choose_newton_for_a(&mut h);
        // a lesson, forward and back, with its answer
        let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == "locking").unwrap();
        h.state_mut().act(Action::OpenLesson(Box::new(lesson)));
        lesson_ready(&mut h);
        h.get_by_label_contains("A: Element p1 · Grid 8x2x2 · Poisson ratio ν 0.3");
        assert_layout_fits(&h, &at("lesson step 1"));
        h.key_press(egui::Key::ArrowRight);
        lesson_ready(&mut h);
        h.get_by_label_contains("Step 2 of 4");
        assert_eq!(h.query_all_by_label_contains("Poisson ratio ν 0.49").count(), 2, "A and B at ν = 0.49");
        h.key_press(egui::Key::A);
        h.run_steps(2);
        h.get_by_label_contains("Answer:");
        assert_layout_fits(&h, &at("lesson step 2, answered"));
        h.key_press(egui::Key::ArrowLeft);
        lesson_ready(&mut h);
        h.get_by_label_contains("Step 1 of 4");
        // presenter mode: the caption below the view, the labels short, nothing overlapping
        h.key_press(egui::Key::P);
        h.run_steps(3);
        h.key_press(egui::Key::A);
        h.run_steps(3);
        assert!(h.state().model().presenter());
        assert_layout_fits(&h, &at("presenter, answered"));
        h.key_press(egui::Key::P);
        h.run_steps(3);
        assert_eq!(h.ctx.zoom_factor(), 1.0, "{}", at("presenter off"));
        assert_layout_fits(&h, &at("presenter off"));
        // the next day: a new app on the same egui memory starts at the ordinary scale
        *h.state_mut() = HoxApp::new(&AppArgs { fresh: true, ..Default::default() }, None).unwrap();
        h.run_steps(3);
        assert_eq!(h.ctx.zoom_factor(), 1.0);
        assert_layout_fits(&h, &at("restart"));
    }
}

/// `--lesson-step N` opens a lesson on step N (a class resuming); a step the lesson does not
/// have is refused naming the option.
#[test]
fn a_lesson_opens_on_the_step_asked_for() {
    let h = harness(args::parse_for_test(&["--lesson", "why-high-order", "--lesson-step", "3"]));
    let state = h.state().model().lesson().unwrap();
    assert_eq!((state.step, state.preparing()), (2, false));
    let err = HoxApp::new(&args::parse_for_test(&["--lesson", "why-high-order", "--lesson-step", "9"]), None)
        .err()
        .unwrap_or_default();
    assert!(err.contains("--lesson-step 9") && err.contains("steps 1 to 3"), "{err}");
    let err = HoxApp::new(&args::parse_for_test(&["--lesson-step", "2"]), None).err().unwrap_or_default();
    assert!(err.contains("--lesson-step needs a lesson"), "{err}");
}

/// Issue #38: `hox app --serve-web` in presenter mode serves at once and shows the address with
/// its QR code in a panel at the window's right edge (beside the bodies, never over them); a
/// port in use is a message in the app, which runs on without serving.
#[test]
fn serving_browsers_shows_the_address_beside_the_view_and_a_busy_port_is_a_message() {
    let free = crate::web::ServeArgs { web_port: 0, grpc_port: 0, ..Default::default() };
    let args = AppArgs { presenter: true, serve_web: true, serve: free, ..Default::default() };
    let mut h = harness(args);
    h.run_steps(4);
    let url = h.state().rerun.web_url().expect("serving from the start").to_string();
    assert!(url.starts_with("http://127.0.0.1:") && url.contains("?url=rerun"), "{url}");
    let qr = h.get_by_label("Follow in your browser:").rect();
    let width = h.ctx.content_rect().width();
    assert!(qr.min.x > width - 240.0, "the address panel sits at the right edge of {width} points: {qr:?}");
    // with a lesson's caption below the view at 1280×720 less the window's decorations, the code
    // and the address under it fit above the caption (issue #57: both were cut off)
    let args = AppArgs {
        presenter: true,
        serve_web: true,
        lesson: Some("locking".into()),
        serve: crate::web::ServeArgs { web_port: 0, grpc_port: 0, ..Default::default() },
        ..Default::default()
    };
    let mut low = harness_sized(args, egui::vec2(1264.0, 680.0));
    low.run_steps(4);
    let url = low.state().rerun.web_url().expect("serving").to_string();
    let caption = low.get_by_label_contains("Locking — ").rect();
    let address = low.get_by_label(&url).rect();
    let zoom = low.ctx.zoom_factor();
    assert!(
        address.max.y <= caption.min.y + 1.0,
        "address {address:?} under the caption's top {caption:?} (zoom {zoom})"
    );
    // a port in use: refused by name, the app runs on
    let held = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = held.local_addr().unwrap().port();
    let busy = crate::web::ServeArgs { web_port: port, grpc_port: 0, ..Default::default() };
    let mut h = harness(AppArgs { serve_web: true, serve: busy, ..Default::default() });
    h.run_steps(3);
    assert!(h.state().rerun.web_url().is_none());
    let message = h.state().model().message().unwrap_or_default().to_string();
    assert!(message.contains(&format!("127.0.0.1:{port}")) && message.contains("in use"), "{message}");
    assert!(h.query_by_label("Follow in your browser:").is_none());
}

/// Issue #38: the browsers get at most `--serve-fps` frames a second, and always the frame the
/// app stops on: played, then paused with Space, the frame logged last is the frame shown, also
/// when the cap held it back (sent once the app paused); every frame with `--serve-fps 0`.
#[test]
fn served_browsers_end_on_the_frame_the_app_paused_on() {
    let logged = |h: &Harness<'_, HoxApp>| h.state().rerun.sent().and_then(|l| l.last_logged_frame);
    let frame = |h: &Harness<'_, HoxApp>| h.state().model().sessions()[0].instance.sim.frames();
    for fps in [1, 0] {
        let free = crate::web::ServeArgs { web_port: 0, grpc_port: 0, ..Default::default() };
        let mut h = harness(AppArgs { serve_web: true, serve: free, serve_fps: fps, ..Default::default() });
        h.run_steps(2);
        assert_eq!(logged(&h), Some(0), "the first frame is sent at once");
        h.get_all_by_label("Play").next().unwrap().click();
        h.run_steps(20);
        assert!(frame(&h) >= 18, "played {} frames", frame(&h));
        if fps == 0 {
            assert_eq!(logged(&h), Some(frame(&h)), "every frame sent while playing");
        }
        h.key_press(egui::Key::Space);
        h.run_steps(2);
        assert!(!h.state().model().playing());
        assert_eq!(logged(&h), Some(frame(&h)), "--serve-fps {fps}: the browsers end on the frame paused on");
        assert!(!h.state().rerun.sent().unwrap().pending);
        let count = h.state().rerun.sent().unwrap().frames_logged;
        h.run_steps(10);
        assert_eq!(h.state().rerun.sent().unwrap().frames_logged, count, "nothing new is sent while paused");
    }
}

/// Issue #38: with a lesson open and the app paused, revealing the answer reaches the browsers
/// at once (the step's text logged again), once.
#[test]
fn revealing_the_answer_while_paused_reaches_the_browsers() {
    let free = crate::web::ServeArgs { web_port: 0, grpc_port: 0, ..Default::default() };
    let args = AppArgs { lesson: Some("why-high-order".into()), serve_web: true, serve: free, ..Default::default() };
    let mut h = harness(args);
    h.run_steps(3);
    h.key_press(egui::Key::Space);
    h.run_steps(2);
    assert!(!h.state().model().playing(), "paused");
    let sent = |h: &Harness<'_, HoxApp>| h.state().rerun.sent().unwrap().lesson_text.unwrap_or_default();
    let before = sent(&h);
    assert!(!before.is_empty(), "the step's text is sent");
    h.state_mut().act(Action::RevealAnswer);
    h.run_steps(2);
    let after = sent(&h);
    assert_ne!(after, before, "the revealed answer is sent while paused");
    let count = h.state().rerun.sent().unwrap().frames_logged;
    h.run_steps(5);
    assert_eq!(h.state().rerun.sent().unwrap().frames_logged, count, "once");
}

/// Issue #39: *Export figure* draws the configurations on screen — here A and B of the torsion
/// scene in compare mode, after a few frames — in the paper's figure style against the reference
/// of their physics, as SVG and PNG in the folder named; on a scene that is not one of the
/// paper's the button is off and says why.
#[test]
fn export_figure_writes_the_papers_figure_of_the_configurations_on_screen() {
    let folder = std::env::temp_dir().join(format!("hox-figure-export-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    let mut h = harness(AppArgs { scene: Some("torsion".into()), compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    h.state_mut().step(20);
    h.state_mut().ui.figure_folder = folder.display().to_string();
    h.get_by_label("Export figure").scroll_to_me();
    h.run_steps(2);
    h.get_by_label("Export figure").click_accesskit();
    // the screen's reference (committed: its probes only) gets its field first, in the background
    let message = wait_for_message(&mut h, "wrote ");
    assert!(message.contains("fig2-torsion.png"), "{message}");
    let svg = std::fs::read_to_string(folder.join("fig2-torsion.svg")).expect("the SVG");
    assert!(svg.contains(r##"stroke="#e00000""##), "the reference's outline in red");
    let labels: Vec<String> = h.state().model().sessions().iter().map(|s| s.label()).collect();
    for (k, label) in labels.iter().enumerate() {
        let panel = format!(">{}: {label}<", ["A", "B"][k]);
        assert!(svg.contains(&panel), "no panel {panel} in the figure");
    }
    // issue #57: the figure measured against its own coarse Q2 solution ("Q2 8×2×2", 16.33 %)
    // where the screen measured against the reference (17.19 %): the same reference, by name
    let screen = h.state().model().active_session().reference.reference().expect("a reference").label();
    let short = super::figure::short_label(h.state().model().active_session().reference.reference().unwrap());
    assert!(screen.starts_with(&short) && short.contains(" Q2 "), "{short} / {screen}");
    assert!(svg.contains(&format!(">reference: {}<", xml_escaped(&short))), "not the screen's reference {screen}");
    assert!(svg.contains("mm from the reference"), "the cases are measured against the reference");
    let png = std::fs::read(folder.join("fig2-torsion.png")).expect("the PNG");
    assert!(png.starts_with(b"\x89PNG") && png.len() > 20_000, "{} bytes", png.len());
    let _ = std::fs::remove_dir_all(&folder);
    // the tube is not one of the paper's scenes
    let mut h = harness(AppArgs { scene: Some("tube".into()), ..Default::default() });
    h.run_steps(2);
    assert!(h.get_by_label("Export figure").accesskit_node().is_disabled(), "the export is off for the tube");
}

/// The app's message once it starts with `start` (a background job's result), frames run meanwhile.
fn wait_for_message(h: &mut Harness<'_, HoxApp>, start: &str) -> String {
    for _ in 0..3000 {
        h.run_steps(1);
        let message = h.state().model().message().unwrap_or_default().to_string();
        if message.starts_with(start) {
            return message;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    panic!("no message starting {start:?}: {:?}", h.state().model().message());
}

/// `text` as it is written inside an SVG text element.
fn xml_escaped(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// A software renderer has no vertical sync: while playing, the window waits until the next
/// simulated frame is due before painting again (a display running at 120 Hz without vsync waits
/// a frame of 1/60 s or what is left of it), paints at once while settling or measuring the
/// frame rate, and not at all paced in a window with vsync (`pace_paint` off).
#[test]
fn with_a_software_renderer_the_playing_window_paints_when_a_simulated_frame_is_due() {
    let frame = 1.0 / 60.0;
    let mut h = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .allow_missing_glyphs()
        .with_step_dt(1.0 / 120.0)
        .build_ui_state(
            |ui, app: &mut HoxApp| app.ui_all(ui),
            HoxApp::new(&AppArgs { fresh: true, play: true, ..Default::default() }, None).unwrap(),
        );
    assert_eq!(h.state().paint_pace(), None, "a window with vsync is not paced");
    h.state_mut().pace_paint = true;
    let t0 = h.state().model().sessions()[0].instance.sim.time_secs();
    let mut waits = Vec::new();
    for _ in 0..40 {
        h.run_steps(1);
        waits.push(h.state().paint_pace().expect("paced while playing").as_secs_f64());
    }
    assert!(waits.iter().all(|w| *w > 0.0 && *w <= frame + 1e-6), "{waits:?}");
    assert!(waits.iter().any(|w| (w - frame).abs() < 1e-6), "just after a frame: a whole frame to wait, {waits:?}");
    let t = h.state().model().sessions()[0].instance.sim.time_secs() - t0;
    assert!((t - 40.0 / 120.0).abs() <= frame + 1e-9, "simulated time follows the clock: {t} s in 1/3 s");
    // settling goes as fast as the CPU allows
    h.key_press(egui::Key::E);
    h.run_steps(1);
    assert!(h.state().model().settling());
    assert_eq!(h.state().paint_pace(), None, "settling is not paced");
    // measuring the frame rate is not paced either
    let mut m =
        HoxApp::new(&AppArgs { fresh: true, play: true, measure_secs: Some(1.0), ..Default::default() }, None).unwrap();
    m.pace_paint = true;
    assert_eq!(m.paint_pace(), None, "a frame-rate measurement is not paced");
}

#[test]
fn the_wait_for_the_next_frame_follows_the_clock_s_remainder_and_the_time_scale() {
    let frame = 1.0 / 60.0;
    let mut p = playback::Playback::new(true, 1.0);
    assert!((p.until_next_frame(frame).as_secs_f64() - frame).abs() < 1e-6);
    p.frame_budget_secs = 0.75 * frame;
    assert!((p.until_next_frame(frame).as_secs_f64() - 0.25 * frame).abs() < 1e-6);
    p.frame_budget_secs = frame;
    assert_eq!(p.until_next_frame(frame).as_secs_f64(), 0.0, "a frame owed: paint now");
    let mut slow = playback::Playback::new(true, 0.25);
    slow.frame_budget_secs = 0.0;
    assert!((slow.until_next_frame(frame).as_secs_f64() - 4.0 * frame).abs() < 1e-6, "a quarter of real time");
    let crawl = playback::Playback::new(true, 0.001);
    assert_eq!(crawl.until_next_frame(frame).as_secs_f64(), 0.25, "at most a quarter second between paints");
}

#[test]
fn a_cheap_frame_keeps_real_time_when_the_window_draws_slowly() {
    // the page without a GPU shows a frame every 100 ms: P2 bending's 3 ms frames keep up
    let frame = 1.0 / 60.0;
    let mut p = playback::Playback::new(true, 1.0);
    let stepped: usize = (0..10).map(|_| p.frames_due(0.1, frame, 3.0)).sum();
    assert!((59..=61).contains(&stepped), "{stepped} frames in a second of 100 ms paints");
    // a 30 ms frame slows down: four frames a paint, not the six real time owes
    let mut slow = playback::Playback::new(true, 1.0);
    assert_eq!(slow.frames_due(0.1, frame, 30.0), 4);
    assert_eq!(slow.frames_due(0.1, frame, 30.0), 4, "what it could not step is dropped, not owed");
}

/// What a viewer following `path` (an .rrd file) shows at its latest `frame`, as Rerun's own
/// store answers (latest-at queries, with its clears and static data): the configurations
/// (`world/<name>`) with a body, rest shape, edges or probes drawn, and the chart lines
/// (`plots/…`) with a value.
fn shown_at_latest_frame(path: &std::path::Path) -> (std::collections::BTreeSet<String>, Vec<String>) {
    use rerun::external::re_entity_db::{EntityDb, external::re_chunk_store::LatestAtQuery};
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::external::re_log_types::StoreKind;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut db: Option<EntityDb> = None;
    for msg in DecoderApp::decode_lazy(file) {
        let msg = msg.unwrap();
        if msg.store_id().kind() != StoreKind::Recording {
            continue;
        }
        db.get_or_insert_with(|| EntityDb::new(msg.store_id().clone())).add_log_msg(&msg).unwrap();
    }
    let db = db.expect("a recording");
    let frame = rerun::external::re_log_types::TimelineName::from_static_str("frame");
    let latest = db.time_range_for(&frame).expect("frames").max();
    let query = LatestAtQuery::new(frame, latest);
    let drawn = [
        rerun::Mesh3D::descriptor_vertex_positions().component,
        rerun::LineStrips3D::descriptor_strips().component,
        rerun::Points3D::descriptor_positions().component,
        rerun::Scalars::descriptor_scalars().component,
    ];
    let (mut bodies, mut lines) = (std::collections::BTreeSet::new(), Vec::new());
    for entity in db.sorted_entity_paths() {
        let results = db.latest_at(&query, entity, drawn);
        let shown = drawn.iter().any(|&c| results.component_batch_raw(c).is_some_and(|a| !a.is_empty()));
        let name = entity.to_string().trim_start_matches('/').to_string();
        if !shown {
            continue;
        }
        if let Some(root) = name.strip_prefix("world/") {
            bodies.insert(root.split('/').next().unwrap_or(root).to_string());
        } else if name.starts_with("plots/") {
            lines.push(name);
        }
    }
    (bodies, lines)
}

/// The entity names (`world/<name>`) of the configurations on screen in the app's stream.
/// Each is its session's label (`a_…`, `b_…`), or that with a suffix where an earlier step's
/// configuration of that name was retired from the stream.
fn stream_names(h: &Harness<'_, HoxApp>) -> std::collections::BTreeSet<String> {
    let sessions = h.state().model().sessions();
    let labels = sessions.iter().enumerate().map(|(k, s)| format!("{}_{}", ["a", "b"][k.min(1)], s.label()));
    let streamed = h.state().rerun.streamed_names();
    assert_eq!(streamed.len(), sessions.len(), "{streamed:?}");
    for (name, label) in streamed.iter().zip(labels) {
        let own = crate::recording::entity_name(&label);
        let suffix = name.strip_prefix(own.as_str()).unwrap_or_else(|| panic!("{name} streams {label}"));
        assert!(suffix.is_empty() || suffix.strip_prefix('_').is_some_and(|k| k.parse::<u32>().is_ok()), "{name}");
    }
    streamed.into_iter().collect()
}

/// Issue #57: after → to the next lesson step, the class's browsers drew the last step's beams
/// over the new ones (two "tip" labels, the rest shapes' ghosts) and the charts' legends listed
/// four configurations, their clock going back to 0 inside the old step's time. The app's Rerun
/// stream (here saved to a file, read back into Rerun's own store) now runs on: each step's
/// configurations start after the last one's frames, the last one's bodies are cleared there,
/// and what they logged as static data or as chart lines is retired (`recording/retire.rs`), so
/// a viewer at the stream's latest time shows only the current step's bodies and lines. Every
/// step of two lessons: one with a pair of beams on most steps, one with one beam.
#[test]
fn a_browser_following_a_lesson_shows_only_the_current_step_s_bodies() {
    for name in ["why-high-order", "locking"] {
        let (streamed, on_screen) = follow_lesson_stream(name);
        assert!(streamed.len() > on_screen.len(), "{name}: several steps' configurations were streamed: {streamed:?}");
    }
}

/// [`a_browser_following_a_lesson_shows_only_the_current_step_s_bodies`] for every lesson (the
/// app's ignored tests: `.ci/run`).
#[test]
#[ignore = "every lesson's steps, about two minutes in a debug build; .ci/run runs it"]
fn a_browser_following_every_lesson_shows_only_the_current_step_s_bodies() {
    for lesson in hox_scenes::lesson::registry().unwrap() {
        follow_lesson_stream(&lesson.name);
    }
}

/// Streams the app to a file through every step of lesson `name` and checks, in Rerun's own
/// store, that at the latest frame only the configurations on screen are drawn (bodies and chart
/// lines); returns the configurations streamed and those on screen at the end.
fn follow_lesson_stream(name: &str) -> (std::collections::BTreeSet<String>, std::collections::BTreeSet<String>) {
    let dir = std::env::temp_dir().join(format!("hox-lesson-stream-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lesson.rrd");
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    h.state_mut().ui.rerun_file = path.display().to_string();
    h.state_mut().act(super::action::Command::Rerun(Some(super::action::RerunTarget::File)));
    h.run_steps(2);
    let mut streamed = stream_names(&h);
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == name).unwrap();
    let steps = lesson.steps.len();
    h.state_mut().act(Action::OpenLesson(Box::new(lesson)));
    lesson_ready(&mut h);
    for step in 0..steps {
        h.run_steps(20);
        // every step's configurations go into the stream (its file is read once, at the end)
        streamed.extend(stream_names(&h));
        if step + 1 < steps {
            h.key_press(egui::Key::ArrowRight);
            lesson_ready(&mut h);
        }
    }
    h.run_steps(20);
    let on_screen = stream_names(&h);
    h.state_mut().act(super::action::Command::Rerun(None));
    let (bodies, lines) = shown_at_latest_frame(&path);
    println!("{name}: streamed {streamed:?}, on screen at the end {on_screen:?}");
    assert_eq!(bodies, on_screen, "{name}: only the current step's bodies at the latest frame");
    for line in &lines {
        let owner = line.rsplit('/').next().unwrap();
        assert!(
            on_screen.contains(owner) || owner == "reference_static",
            "{name}: a chart still draws {line}, not on screen ({on_screen:?})"
        );
    }
    assert!(lines.iter().any(|l| l.starts_with("plots/kinetic_energy_j/")), "{name}: the charts draw: {lines:?}");
    let _ = std::fs::remove_dir_all(&dir);
    (streamed, on_screen)
}

/// Issue #57: a lesson's configurations (two "P2 8×2×2 five" beams of 50 and 100 substeps) came
/// back at the next plain start. What persists during a lesson is what ran before it.
#[test]
fn a_lesson_s_configurations_do_not_leak_into_the_next_plain_start() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let mut c = h.state().model().sessions()[0].config.clone();
    c.youngs_modulus_pa = 2.5e6;
    h.state_mut().act(Action::change("youngs", c.clone()));
    open_lesson(&mut h, "accuracy-cost");
    assert_eq!(h.state().model().sessions().len(), 2, "the lesson's pair on screen");
    let kept = h.state().persisted();
    assert_eq!((kept.configs, kept.compare), (vec![c.clone()], false), "what ran before the lesson");
    // the next start on those settings runs it again
    let again = HoxApp::new(&AppArgs::default(), Some(h.state().persisted())).unwrap();
    assert_eq!(again.model().sessions().len(), 1);
    assert_eq!(again.model().sessions()[0].config, c);
    // a lesson closed: what is on screen persists again
    h.state_mut().act(Action::CloseLesson);
    assert_eq!(h.state().persisted().configs.len(), 2);
}

/// Issue #57, opening a part: a relative path failed with a bare "os error 2"; the scene box then
/// showed a temporary path; compare mode and ν were dropped; the probe plot stayed flat at 0
/// while the part moved; "no reference" although the part's static solution is its reference.
#[test]
fn opening_a_part_keeps_compare_and_the_material_and_it_gets_a_probe_and_a_reference() {
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    let mut c = h.state().model().sessions()[0].config.clone();
    c.poisson_ratio = 0.45;
    h.state_mut().act(Action::change("poisson", c));
    // a relative path is read from the folder hox runs in; a missing file says where it looked
    let err = dialogs::resolve("no/such/part.msh").unwrap_err();
    let cwd = std::env::current_dir().unwrap();
    assert!(err.contains(&cwd.join("no/such/part.msh").display().to_string()) && err.contains("relative"), "{err}");
    let beam = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/beam-tet10.msh");
    let relative = pathdiff(&beam, &cwd);
    let path = dialogs::resolve(&relative).expect("a relative path to the part");
    let (folder, entries) = dialogs::browse(&relative, "msh");
    assert!(entries.iter().any(|(n, dir)| n == "beam-tet10.msh" && !dir), "{folder:?}: {entries:?}");
    h.state_mut().act(super::action::Command::OpenFile { mesh: true, path, clamp_group: "clamp".into() });
    h.run_steps(2);
    let model = h.state().model();
    assert_eq!(model.scene().label(), "beam-tet10.msh (mesh file)");
    assert!(model.compare(), "compare mode kept");
    assert!(model.sessions().iter().all(|s| s.config.poisson_ratio == 0.45), "ν kept");
    let s = &model.sessions()[0];
    assert_eq!(s.instance.probes.len(), 1, "a probe at the tip");
    assert!(!matches!(s.reference, readout::ReferenceState::Unavailable(_)), "{}", s.reference.status());
    h.state_mut().step(20);
    let moved = h.state().model().sessions()[0].history.probe_m.iter().map(|u| u[2].abs()).fold(0.0, f64::max);
    assert!(moved > 1e-4, "the probe plot follows the part: {moved}");
}

/// `path` relative to `base` (both absolute), for a test typing a relative path.
fn pathdiff(path: &std::path::Path, base: &std::path::Path) -> String {
    let path = std::fs::canonicalize(path).unwrap();
    let base = std::fs::canonicalize(base).unwrap();
    let common = path.components().zip(base.components()).take_while(|(a, b)| a == b).count();
    let ups = base.components().count() - common;
    let rest: std::path::PathBuf = path.components().skip(common).collect();
    format!("{}{}", "../".repeat(ups), rest.display())
}

/// Issue #57: in a lesson the labels above the bodies gave the error against the reference
/// while the panel gave another quantity, both called "error", and a static step's label read
/// "paused mid-swing". The labels now show the step's measurement, under its name, with the
/// panel's text; presenter mode's caption keeps the step's explanation.
#[test]
fn a_lesson_s_body_labels_show_the_panel_s_numbers_under_the_same_name() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == "accuracy-cost").unwrap();
    let explanation = lesson.steps[0].text.clone();
    h.state_mut().act(Action::OpenLesson(Box::new(lesson)));
    lesson_ready(&mut h);
    play_until_paused(&mut h);
    h.run_steps(2);
    let state = h.state().model().lesson().unwrap();
    let title = state.current().measure.title();
    let measured = state.measured(h.state().model().sessions());
    let labels = h.state().ui_state().viewport.lesson_labels.clone().expect("lesson labels");
    assert_eq!(labels.len(), 2);
    for (k, (label, m)) in labels.iter().zip(&measured).enumerate() {
        assert_eq!(*label, format!("{title}: {}", m.text), "body {k}");
        // the panel shows the same text, and so does the status line, under the same name
        assert!(h.query_all_by_label_contains(&m.text).count() >= 2, "the panel and the status line: {}", m.text);
        assert!(!label.contains("mid-swing"), "{label}");
        let line = format!("{title} {}", m.text);
        let in_status_line = h.query_all_by_label_contains(&line).any(|n| {
            let a = n.accesskit_node();
            a.label().or_else(|| a.value()).is_some_and(|l| l.contains("nodes,"))
        });
        assert!(in_status_line, "the status line: {line}");
    }
    h.key_press(egui::Key::P);
    h.run_steps(3);
    let first_line = explanation.lines().next().unwrap();
    h.get_by_label_contains(first_line);
}

/// Issue #57's classroom session, replayed at a projector's 1280×720 and at 1920×1080: a huge
/// mesh asked for while paused (built in the background, asked about first, kept), a multi-digit
/// value typed, ν typed in a lesson's static step (never the old shape called equilibrium), a
/// part opened (compare mode and ν kept), every step of every lesson with presenter mode on and
/// off (nothing drawn overlapping, the labels the panel's numbers), and a restart (no lesson
/// configuration leaking). Minutes in a debug build: `.ci/run` runs it with `--ignored`.
#[test]
#[ignore = "every lesson step at two sizes (minutes): .ci/run runs it with --ignored"]
fn the_second_round_classroom_session_replays_at_both_sizes() {
    for size in [egui::vec2(1280.0, 720.0), egui::vec2(1920.0, 1080.0)] {
        let at = |what: &str| format!("{}×{}: {what}", size.x, size.y);
        let mut h = harness_sized(AppArgs { compare: vec![String::new()], ..Default::default() }, size);
        h.run_steps(3);
        let before = h.state().model().sessions()[0].config.clone();
        // a huge mesh while paused, nothing measured: built in the background, asked about first
        let mut huge = before.clone();
        huge.refine = 3;
        h.state_mut().act(Action::change("refine", huge));
        assert!(h.state().model().building().is_some(), "{}", at("built in the background"));
        built(&mut h);
        assert!(h.state().model().pending_change().is_some(), "{}", at("asked first"));
        h.run_steps(2);
        h.get_by_label("Keep the current configuration").click();
        h.run_steps(2);
        assert_eq!(h.state().model().sessions()[0].config, before, "{}", at("kept"));
        // a multi-digit value, applied once
        type_into(&mut h, "Poisson ratio ν", "0.45");
        assert!(h.state().model().sessions().iter().all(|s| s.config.poisson_ratio == 0.45), "{}", at("ν"));
        // every step of every lesson, presenter mode on every other step
        let mut presenter = false;
        for lesson in hox_scenes::lesson::registry().unwrap() {
            let (name, steps) = (lesson.name.clone(), lesson.steps.len());
            h.state_mut().act(Action::OpenLesson(Box::new(lesson)));
            lesson_ready(&mut h);
            for k in 0..steps {
                if k > 0 {
                    h.key_press(egui::Key::ArrowRight);
                    lesson_ready(&mut h);
                }
                let what = at(&format!("{name} step {}{}", k + 1, if presenter { ", presenter" } else { "" }));
                h.run_steps(3);
                assert_eq!(h.state().model().lesson().map(|l| l.step), Some(k), "{what}");
                if h.state().model().sessions().len() > 1 && !presenter {
                    let labels = h.state().ui_state().viewport.lesson_labels.clone().unwrap_or_default();
                    assert_eq!(labels.len(), h.state().model().sessions().len(), "{what}");
                }
                for s in h.state().model().sessions() {
                    let label = s.readout_label();
                    let at_rest = s.shown_static || s.rest.at_rest();
                    assert!(
                        at_rest || !(label.contains("equilibrium:") || label.contains("settled")),
                        "{what}: {label}"
                    );
                }
                assert_layout_fits(&h, &what);
                if name == "locking" && k == 1 {
                    // ν typed in the static step: solved again, never the old shape's numbers
                    let mut c = h.state().model().sessions()[0].config.clone();
                    c.poisson_ratio = 0.499;
                    h.state_mut().act(Action::change("poisson", c));
                    for _ in 0..5_000 {
                        let text = h.state().model().lesson_text().unwrap_or_default();
                        for (j, s) in h.state().model().sessions().iter().enumerate() {
                            let line = format!("**{}**: solving", ["A", "B"][j.min(1)]);
                            assert!(
                                !s.solving_static || text.contains(&line),
                                "{what}: old numbers while solving: {text}"
                            );
                        }
                        let solving = h.state().model().sessions().iter().any(|s| s.solving_static);
                        if !solving {
                            break;
                        }
                        std::thread::sleep(std::time::Duration::from_millis(5));
                        h.run_steps(1);
                    }
                    assert!(
                        h.state().model().sessions().iter().all(|s| s.shown_static && s.config.poisson_ratio == 0.499)
                    );
                }
                h.key_press(egui::Key::P);
                h.run_steps(3);
                presenter = !presenter;
            }
            h.state_mut().act(Action::CloseLesson);
            h.run_steps(2);
        }
        if presenter {
            h.key_press(egui::Key::P);
            h.run_steps(3);
        }
        // a part opened: compare mode and ν kept
        h.state_mut().act(Action::SetCompare(true));
        let mut c = h.state().model().sessions()[0].config.clone();
        c.poisson_ratio = 0.42;
        h.state_mut().act(Action::change("poisson", c));
        let beam = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/beam-tet10.msh");
        h.state_mut().act(super::action::Command::OpenFile { mesh: true, path: beam, clamp_group: "clamp".into() });
        h.run_steps(3);
        assert!(h.state().model().compare(), "{}", at("part opened in compare mode"));
        assert!(h.state().model().sessions().iter().all(|s| s.config.poisson_ratio == 0.42), "{}", at("ν kept"));
        assert_layout_fits(&h, &at("part"));
        // the restart on what was saved: the part, at the ordinary scale
        let kept = h.state().persisted();
        *h.state_mut() = HoxApp::new(&AppArgs::default(), Some(kept)).unwrap();
        h.run_steps(3);
        assert!(h.state().model().compare(), "{}", at("restart"));
        assert_eq!(h.ctx.zoom_factor(), 1.0, "{}", at("restart"));
        assert!(h.state().model().lesson().is_none());
        assert_layout_fits(&h, &at("restart"));
    }
}

/// Issue #57: why-high-order's answer said "1.15 to 2.6 times less" under 1.07× measured on
/// screen. The answer's claim is judged under it against the numbers on screen, and says when
/// this machine's value is outside it.
#[test]
fn a_revealed_answer_judges_its_claim_against_the_numbers_on_screen() {
    let mut h = harness(AppArgs::default());
    h.run_steps(2);
    open_lesson(&mut h, "locking");
    h.key_press(egui::Key::A);
    h.run_steps(2);
    let state = h.state().model().lesson().unwrap();
    let values: Vec<f64> = state.measured(h.state().model().sessions()).iter().map(|m| m.value).collect();
    let judged = state.judge_claim(&state.measured(h.state().model().sessions())).expect("the step claims a ratio");
    assert!((judged.value - values[0] / values[1]).abs() < 1e-12);
    assert!(judged.holds, "{}", judged.text);
    h.get_by_label_contains("measured here: A/B = ");
    assert!(h.state().model().lesson_text().unwrap().contains(&judged.text), "the browsers' view too");
}

/// Issue #57: at 1280×720 the lesson's Next and Previous scrolled out of view once the answer
/// was revealed. They stand above the step's text now, in view whatever its length.
#[test]
fn the_step_buttons_stay_in_view_after_a_long_answer_at_1280x720() {
    // a 1280×720 screen less the window's decorations (scripts/classroom-screenshots.sh)
    let size = egui::vec2(1264.0, 680.0);
    let mut h = harness_sized(AppArgs::default(), size);
    h.run_steps(2);
    // the step with the longest text, question and answer
    open_lesson(&mut h, "curved-boundaries");
    h.key_press(egui::Key::A);
    h.run_steps(3);
    h.get_by_label_contains("Answer:");
    // the lesson panel ends where the plots begin: a button below that is scrolled out of view
    let plots_top = h.get_by_label("Probe displacement").rect().top();
    for button in ["< Previous (left arrow)", "Next (right arrow) >", "Close lesson"] {
        let r = h.get_by_label(button).rect();
        assert!(r.top() >= 0.0 && r.bottom() <= plots_top, "{button} at {r:?}, below the panel's end at {plots_top}");
    }
}

/// Issue #57: after about a minute of swinging the probe plot turned to dashes: egui_plot drew
/// the line as per-pixel bands once several samples fell in some pixel columns, covering only
/// those columns. The time plots draw lines, never bands.
#[test]
fn a_minute_of_swinging_is_plotted_as_a_line_not_as_dashes() {
    let mut h = harness(AppArgs { compare: vec![String::new()], ..Default::default() });
    h.run_steps(2);
    // 70 s of a 0.9 s swing at 60 frames a second, as the history holds it
    for s in h.state_mut().model_mut().sessions_mut() {
        let history = &mut s.history;
        for i in 0..4200 {
            let t = i as f64 / 60.0;
            history.time_secs.push(t);
            history.probe_m.push([0.0, 0.0, -0.3 + 0.3 * (t * std::f64::consts::TAU / 0.9).cos()]);
            history.kinetic_j.push(1.0);
            history.elastic_j.push(1.0);
        }
    }
    h.run_steps(2);
    let bands = h.output().shapes.iter().filter(|c| matches!(c.shape, egui::Shape::Band(_))).count();
    assert_eq!(bands, 0, "the probe plot drawn as bands (dashes)");
}

/// Issue #57: the stability lesson's unguarded beam blew up out of the view. The camera backs
/// off to keep a body that grows out of the view in it.
#[test]
fn a_beam_blowing_up_stays_in_view() {
    let mut h = harness_sized(AppArgs::default(), egui::vec2(1280.0, 720.0));
    h.run_steps(2);
    open_lesson(&mut h, "stability");
    // in presenter mode, as the class sees it
    h.key_press(egui::Key::P);
    h.run_steps(3);
    h.key_press(egui::Key::ArrowRight);
    lesson_ready(&mut h);
    play_until_paused(&mut h);
    h.run_steps(40);
    let d = &h.state().ui_state().viewport.drawn;
    let view = d.view.expect("drawn");
    for (k, body) in d.bodies.iter().enumerate().filter(|(_, b)| b.is_positive()) {
        assert!(view.expand(1.0).contains_rect(*body), "body {k} {body:?} out of the view {view:?}");
    }
}

/// Issue #57: at 1280×720 without presenter mode a lesson left about 300 px for the 3D view
/// (the controls on the left, the lesson on the right). In a lesson on a narrow window the
/// controls fold to a strip (a » button), a click away; the view gets the room.
#[test]
fn a_lesson_at_1280_by_720_leaves_the_3d_view_room() {
    let mut h = harness_sized(AppArgs::default(), egui::vec2(1280.0, 720.0));
    h.run_steps(2);
    let plain = h.state().ui.viewport.rect().width();
    assert!(h.query_by_label("Poisson ratio ν").is_some(), "the controls out of a lesson");
    open_lesson(&mut h, "why-high-order");
    h.run_steps(2);
    let in_lesson = h.state().ui.viewport.rect().width();
    assert!(in_lesson >= 0.55 * 1280.0, "the 3D view is {in_lesson} points wide in a lesson (out of one: {plain})");
    assert!(h.query_by_label("Poisson ratio ν").is_none(), "the controls folded");
    h.get_by_label("»").click();
    h.run_steps(2);
    assert!(h.query_by_label("Poisson ratio ν").is_some(), "the controls a click away");
    h.get_by_label("« Hide controls").click();
    h.run_steps(2);
    assert!(h.query_by_label("Poisson ratio ν").is_none());
    // a wide window keeps them
    let mut wide = harness_sized(AppArgs::default(), egui::vec2(1920.0, 1080.0));
    wide.run_steps(2);
    open_lesson(&mut wide, "why-high-order");
    wide.run_steps(2);
    assert!(wide.query_by_label("Poisson ratio ν").is_some());
}

/// Issue #57: a page opened late on the app's live stream replayed it from t = 0 and ran 48 s
/// behind the app. A live stream's blueprint (the app streaming to a viewer or to browsers) has
/// the viewer follow the newest frame; a file (`hox record`, *Save to file*) still opens at its
/// start.
#[test]
fn a_page_opened_late_on_the_live_stream_starts_at_the_present() {
    use rerun::external::re_sdk_types::blueprint::components::PlayState;
    let instance = hox_scenes::Instance::new(hox_scenes::by_name("bending").unwrap()).unwrap();
    let configs = [crate::recording::Configuration {
        name: "a".into(),
        instance: &instance,
        offset_m: hox_sim::Vec3::zeros(),
        reference: None,
    }];
    let mut play_states = Vec::new();
    for live in [false, true] {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("hox").memory().unwrap();
        let mut settings = crate::recording::LogSettings::new(instance.scene.params());
        settings.follow_latest = live;
        crate::recording::Recorder::new(&rec, &configs, &settings, &[]).unwrap();
        rec.flush_blocking().unwrap();
        let mut states = Vec::new();
        for m in storage.take() {
            let rerun::log::LogMsg::ArrowMsg(_, arrow) = m else { continue };
            let chunk = rerun::log::Chunk::from_arrow_msg(&arrow).unwrap();
            for d in chunk.component_descriptors().filter(|d| d.component.to_string().ends_with("play_state")) {
                states.extend(chunk.iter_component::<PlayState>(d.component).flat_map(|s| s.to_vec()));
            }
        }
        play_states.push(states);
    }
    assert_eq!(play_states, [vec![], vec![PlayState::Following]], "a file opens at its start; a live stream follows");
}

/// Found in the page (issue #59): a browser that prefers a light theme showed presenter mode's
/// caption — white title and question, light grey text — on the light panel, unreadable. Every
/// colour of the lesson's panels reads on both themes' panels (WCAG contrast at least 4.5:1).
#[test]
fn the_lesson_s_colours_read_on_a_light_theme_as_on_a_dark_one() {
    fn luminance(c: egui::Color32) -> f64 {
        let lin = |v: u8| {
            let v = v as f64 / 255.0;
            if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
        };
        0.2126 * lin(c.r()) + 0.7152 * lin(c.g()) + 0.0722 * lin(c.b())
    }
    for visuals in [egui::Visuals::dark(), egui::Visuals::light()] {
        let p = lesson_panel::Palette::of(&visuals);
        let background = luminance(visuals.panel_fill);
        for (name, c) in [
            ("title", p.title),
            ("text", p.text),
            ("numbers", p.numbers),
            ("answer", p.answer),
            ("holds", p.holds),
            ("warning", p.warning),
        ] {
            let (a, b) = (luminance(c), background);
            let ratio = (a.max(b) + 0.05) / (a.min(b) + 0.05);
            assert!(
                ratio >= 4.5,
                "{name} on the {} theme: contrast {ratio:.1}",
                if visuals.dark_mode { "dark" } else { "light" }
            );
        }
    }
}

/// Issue #59, a mesh dropped onto the window (the page's only way to open one): a broken file is
/// a message naming it, and the app keeps its scene and plays on; a good one opens with its
/// group `clamp` held, the material kept.
#[test]
fn a_broken_mesh_dropped_in_is_a_message_and_a_good_one_opens() {
    let mut h = harness(AppArgs { fresh: true, ..Default::default() });
    h.run_steps(2);
    let before = h.state().model().scene().label();
    h.state_mut().act(super::action::Command::OpenMeshBytes {
        name: "broken.msh".into(),
        bytes: b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnot a number\n".to_vec().into(),
    });
    h.run_steps(2);
    let model = h.state().model();
    let message = model.message().unwrap_or_default().to_string();
    assert!(message.contains("broken.msh") && message.contains("not opened"), "{message}");
    assert_eq!(model.scene().label(), before, "the scene kept");
    h.state_mut().step(3);
    assert!(h.state().model().sessions()[0].instance.sim.time_secs() > 0.0, "it plays on");
    let beam = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/meshes/beam-tet4.msh");
    let bytes = std::fs::read(beam).unwrap();
    h.state_mut().act(super::action::Command::OpenMeshBytes { name: "beam-tet4.msh".into(), bytes: bytes.into() });
    h.run_steps(2);
    let model = h.state().model();
    assert!(model.scene().label().contains("beam-tet4.msh"), "{}", model.scene().label());
    assert_eq!(model.sessions()[0].instance.probes.len(), 1, "a probe at the tip");
}
