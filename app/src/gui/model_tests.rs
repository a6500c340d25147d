//! The model alone, without a window and without threads of its own (the jobs it hands off run
//! in place: [`Background::Inline`], [`InlineStepper`]), driven through a classroom session of
//! actions: compare P1 with P2, play, change a linked material mid-run, a refused value, the
//! camera's layout, frames stepped "in the background" and in place giving the same motion, a
//! settle, a lesson stepped through with its answer, a reset.

use super::action::Action;
use super::background::{Background, InlineStepper};
use super::config::SceneSource;
use super::model::{Model, Start};
use super::presets::{ViewOptions, ViewPreset};

fn model(scene: &str) -> Model {
    model_with(scene, Background::Inline)
}

/// The model on `scene` with its one-off jobs run by `background` (frames always in place).
fn model_with(scene: &str, background: Background) -> Model {
    let start = Start {
        links: Default::default(),
        view: ViewOptions::default(),
        playing: false,
        time_scale: 1.0,
        show_reference_element: false,
        background,
        stepper: Box::new(InlineStepper::default()),
    };
    Model::new(SceneSource::Builtin(scene.into()), None, start).expect("the scene loads")
}

/// A tick of the window's clock at 60 Hz.
fn tick(m: &mut Model, in_background: bool) {
    m.apply(Action::Tick { real_dt_secs: 1.0 / 60.0, one_frame_per_tick: false, in_background }).unwrap();
    if in_background {
        // the window hands the deferred frames over once its frame is built, and takes them
        // back at the next
        m.apply(Action::StepDeferred).unwrap();
        m.apply(Action::Poll { wait_for_lesson: false }).unwrap();
    }
}

fn time(m: &Model) -> f64 {
    m.sessions()[0].instance.sim.time_secs()
}

#[test]
fn a_classroom_session_of_actions_runs_on_the_model_alone() {
    let mut m = model("bending");
    let labels = |m: &Model| m.sessions().iter().map(|s| s.label()).collect::<Vec<_>>();
    assert_eq!(labels(&m), ["P2 8×2×2 five"]);
    let layout = m.layout();

    // the teacher compares P1 refined once with P2, and plays
    m.apply(Action::SetCompare(true)).unwrap();
    assert_eq!(labels(&m), ["P1 8×2×2 five r1", "P2 8×2×2 five"]);
    assert!(m.layout() > layout, "a new layout: the camera frames both bodies");
    m.apply(Action::SetPlaying(true)).unwrap();
    for _ in 0..31 {
        tick(&mut m, false);
    }
    // the first tick is no real interval; thirty at 60 Hz step thirty frames
    assert!((time(&m) * 60.0 - 30.0).abs() < 1e-6, "t = {}", time(&m));
    assert_eq!(m.frames_stepped(), 30);

    // a stiffer material mid-run: linked, both change, the motion goes on from where it was
    let positions = m.sessions()[1].instance.sim.positions.clone();
    let mut c = m.sessions()[0].config.clone();
    c.youngs_modulus_pa = 6e6;
    m.apply(Action::change("youngs", c)).unwrap();
    assert!(m.sessions().iter().all(|s| s.instance.sim.material().youngs_modulus_pa == 6e6));
    assert_eq!(m.sessions()[1].instance.sim.positions, positions, "a material change keeps the state");

    // ν = 0.5 is refused with the reason, for the control, and changes nothing
    let mut c = m.sessions()[0].config.clone();
    c.poisson_ratio = 0.5;
    let reason = m.apply(Action::change("poisson", c)).unwrap_err();
    assert!(reason.starts_with("Poisson ratio ν = 0.5: "), "{reason}");
    assert_eq!(m.refusal().map(|r| r.0.as_str()), Some("poisson"));
    assert!(m.sessions().iter().all(|s| s.config.poisson_ratio == 0.35));

    // the front view lays the bodies apart along x
    m.apply(Action::SetPreset(ViewPreset::Front)).unwrap();
    let offsets = m.offsets();
    assert!(offsets[1].x > offsets[0].x && offsets[0].y == offsets[1].y, "{offsets:?}");

    // frames handed to the stepper give the same motion as frames stepped in place
    let mut twin = model("bending");
    for a in [Action::SetCompare(true), Action::SetPlaying(true), Action::Step(30)] {
        twin.apply(a).unwrap();
    }
    let mut c = twin.sessions()[0].config.clone();
    c.youngs_modulus_pa = 6e6;
    twin.apply(Action::change("youngs", c)).unwrap();
    for _ in 0..12 {
        tick(&mut m, true);
    }
    twin.apply(Action::Step(m.frames_stepped() as usize - 30)).unwrap();
    assert_eq!(time(&m), time(&twin));
    for (a, b) in m.sessions().iter().zip(twin.sessions()) {
        assert!(a.instance.sim.positions == b.instance.sim.positions, "the same motion either way");
    }

    // Settle: damped to rest, then paused on the settled state
    m.apply(Action::Settle).unwrap();
    assert!(m.settling() && m.playing());
    let mut ticks = 0;
    while m.settling() || m.playing() {
        tick(&mut m, false);
        ticks += 1;
        assert!(ticks < 2000, "still settling after {ticks} ticks");
    }
    assert!(m.sessions().iter().all(|s| s.settle_outcome.is_some()));

    // the class opens a lesson: its first step is prepared in place, installed at the next poll
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == "why-high-order").unwrap();
    m.apply(Action::OpenLesson(Box::new(lesson))).unwrap();
    m.apply(Action::Poll { wait_for_lesson: false }).unwrap();
    let state = m.lesson().expect("a lesson is open");
    assert!(!state.preparing(), "prepared in place");
    assert_eq!((state.step, m.preset()), (0, ViewPreset::Front));
    assert_eq!(time(&m), 0.0, "the step's own configurations, from rest");
    // the step plays its 0.45 s and pauses on its last frame
    assert!(m.playing());
    while m.playing() {
        tick(&mut m, false);
    }
    assert!((time(&m) - 0.45).abs() < 1e-9, "paused at {} s", time(&m));
    m.apply(Action::RevealAnswer).unwrap();
    assert!(m.lesson().unwrap().revealed);
    assert!(m.lesson_text().unwrap().contains("**Answer:**"));
    m.apply(Action::LessonStep(1)).unwrap();
    m.apply(Action::Poll { wait_for_lesson: false }).unwrap();
    let state = m.lesson().unwrap();
    assert_eq!((state.step, state.revealed), (1, false));
    assert!(m.settling(), "the second step settles");

    // closing the lesson and resetting: back to t = 0
    m.apply(Action::CloseLesson).unwrap();
    m.apply(Action::Reset).unwrap();
    assert!(m.lesson().is_none());
    assert_eq!(time(&m), 0.0);
    assert!(!m.stepping_in_background());
}

/// Issue #57: in the locking lesson's static step, ν = 0.499 typed left the ν = 0.49 shape on
/// screen labelled "static equilibrium" with the old numbers; and after a Settle, ν typed back
/// showed "settled" with the other value's numbers. A static step now solves the new values'
/// equilibrium (in the background; in place here), and every label on a state that is not the
/// solution of the values shown says so.
#[test]
fn a_value_typed_in_a_static_step_never_leaves_the_old_shape_labelled_equilibrium() {
    let mut m = model("bending");
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == "locking").unwrap();
    m.apply(Action::OpenLesson(Box::new(lesson))).unwrap();
    m.apply(Action::GoToStep(1)).unwrap();
    m.apply(Action::Poll { wait_for_lesson: true }).unwrap();
    let tip = |m: &Model, k: usize| m.sessions()[k].instance.probe_displacements()[0].1[2];
    let at_049 = tip(&m, 0);
    assert!(m.sessions()[0].shown_static);

    let mut c = m.sessions()[0].config.clone();
    c.poisson_ratio = 0.499;
    m.apply(Action::change("poisson", c)).unwrap();
    m.apply(Action::Poll { wait_for_lesson: false }).unwrap();
    // ν is linked: both configurations were solved again, at the new value
    for k in 0..2 {
        let s = &m.sessions()[k];
        assert_eq!(s.config.poisson_ratio, 0.499);
        assert!(s.shown_static && !s.solving_static, "{}", s.label());
        let fresh = super::session::static_positions(&s.instance.scene, s.instance.sim.mesh()).unwrap();
        assert_eq!(s.instance.sim.positions, fresh, "{}: the equilibrium of ν 0.499 on screen", s.label());
    }
    assert!(tip(&m, 0) > at_049 + 1e-3, "P1 locks more at 0.499: {} vs {at_049}", tip(&m, 0));
    let text = m.lesson_text().unwrap();
    assert!(text.contains(&format!("{:.4} m", tip(&m, 0))), "the panel shows the new numbers: {text}");
}

fn threaded_model(scene: &str) -> Model {
    model_with(scene, Background::Threads)
}

/// Waits for the change's meshes built in the background.
fn wait_built(m: &mut Model) {
    while m.building().is_some() {
        std::thread::sleep(std::time::Duration::from_millis(10));
        m.apply(Action::Poll { wait_for_lesson: false }).unwrap();
    }
}

/// Issue #57: while paused (no frame measured yet), P1 refine 3 then 64 cells along x
/// (655,360 elements) was accepted without a question, and Play froze the window for minutes.
/// A new mesh is now built in the background (the model goes on with the old one meanwhile)
/// and estimated once built, paused or not: a huge one asks first, and "keep" keeps what was
/// there before.
#[test]
fn a_huge_mesh_asked_for_while_paused_is_built_in_the_background_and_asked_about_first() {
    let mut m = threaded_model("bending");
    assert!(!m.playing() && m.sessions()[0].frame_ms.is_empty(), "paused, nothing measured yet");
    let mut c = m.sessions()[0].config.clone();
    c.element = hox_sim::element::ElementType::from_name("p1").unwrap();
    c.refine = 2;
    m.apply(Action::change("refine", c.clone())).unwrap();
    assert!(m.building().is_none(), "a small mesh is built at once");
    assert!(m.pending_change().is_none(), "10,240 elements play: {:?}", m.pending_change().map(|p| &p.estimate));
    assert_eq!(m.sessions()[0].instance.sim.mesh().num_elements(), 10_240);
    // 32 cells along x: 40,960 elements at the guard's substeps: built in the background
    let mut big = c.clone();
    big.grid = [32, 2, 2];
    m.apply(Action::change("grid", big.clone())).unwrap();
    assert!(m.building().is_some_and(|b| b.contains("P1 32×2×2")), "built in the background: {:?}", m.building());
    m.apply(Action::Step(1)).unwrap();
    assert_eq!(m.sessions()[0].instance.sim.mesh().num_elements(), 10_240, "the old mesh runs meanwhile");
    // that step measured a frame; the estimate then scales it by the work (×4). The measured
    // time is set, not taken from this machine's clock (CI's faster machine measured under
    // 62 ms and was not asked): 100 ms on 10,240 elements make about 400 ms on 40,960
    m.sessions_mut()[0].ms_per_frame = 100.0;
    wait_built(&mut m);
    let question = m.pending_change().map(|p| p.estimate.clone()).expect("asked first");
    assert!(question.contains("40960 elements") && question.contains("per frame"), "{question}");
    assert_eq!(m.sessions()[0].config.grid, [8, 2, 2], "nothing changed before the answer");
    // "keep the current configuration" keeps the 8 cells there before
    m.apply(Action::AnswerPending(false)).unwrap();
    assert_eq!(m.sessions()[0].config.grid, [8, 2, 2]);
    assert_eq!(m.sessions()[0].instance.sim.mesh().num_elements(), 10_240);
    // asked again and applied: installed as built, paused
    m.apply(Action::change("grid", big)).unwrap();
    wait_built(&mut m);
    m.apply(Action::AnswerPending(true)).unwrap();
    assert_eq!(m.sessions()[0].instance.sim.mesh().num_elements(), 40_960);
    assert!(!m.playing());
}

/// Issue #57: the "Paused: a frame takes 18.4 s" banner stayed after going back to a small
/// mesh; and a window that shows a frame only every half second (drawing, not computing) played
/// on at 2 fps, unasked.
#[test]
fn a_slow_display_pauses_and_the_pause_message_goes_with_the_next_change() {
    let mut m = model("bending");
    m.apply(Action::SetPlaying(true)).unwrap();
    for _ in 0..3 {
        tick(&mut m, false);
    }
    assert!(m.playing(), "60 frames per second play");
    // the machine busy for a moment (a browser starting beside a served app on two cores paused
    // it in CI): 1.6 s of slow frames play on
    for _ in 0..4 {
        m.apply(Action::Tick { real_dt_secs: 0.4, one_frame_per_tick: false, in_background: false }).unwrap();
    }
    assert!(m.playing(), "a busy moment is not a slow configuration");
    for _ in 0..3 {
        tick(&mut m, false);
    }
    // a display slow for three seconds pauses
    for _ in 0..7 {
        m.apply(Action::Tick { real_dt_secs: 0.5, one_frame_per_tick: false, in_background: false }).unwrap();
    }
    assert!(!m.playing(), "paused");
    let message = m.message().unwrap_or_default().to_string();
    assert!(message.starts_with("Paused: a frame takes 0.5 s on screen"), "{message}");
    // one slow interval alone (the machine busy a moment, the first after a pause) does not pause
    m.apply(Action::SetPlaying(true)).unwrap();
    m.apply(Action::Tick { real_dt_secs: 30.0, one_frame_per_tick: false, in_background: false }).unwrap();
    m.apply(Action::Tick { real_dt_secs: 0.6, one_frame_per_tick: false, in_background: false }).unwrap();
    assert!(m.playing());
    for _ in 0..20 {
        tick(&mut m, false);
    }
    // another configuration: the message was about the one before
    let mut c = m.sessions()[0].config.clone();
    c.grid = [4, 2, 2];
    m.apply(Action::change("grid", c)).unwrap();
    assert_eq!(m.message(), None);
}

/// Issue #57: accuracy-cost's two beams were both named "P2 8×2×2 five" though their substeps
/// differ; each label now says what tells them apart.
#[test]
fn two_configurations_that_differ_only_in_settings_are_named_apart() {
    let mut m = model("bending");
    let lesson = hox_scenes::lesson::registry().unwrap().into_iter().find(|l| l.name == "accuracy-cost").unwrap();
    m.apply(Action::OpenLesson(Box::new(lesson))).unwrap();
    m.apply(Action::Poll { wait_for_lesson: true }).unwrap();
    let labels = super::session::labels(m.sessions());
    assert_eq!(labels, ["P2 8×2×2 five · substeps 50", "P2 8×2×2 five · substeps 100"]);
    // labels that differ already are left as they are
    let mut p = model("bending");
    p.apply(Action::SetCompare(true)).unwrap();
    assert_eq!(super::session::labels(p.sessions()), ["P1 8×2×2 five r1", "P2 8×2×2 five"]);
}

/// Issue #57: a new ν on a large mesh held the window for seconds (4 s on 655,360 P1 elements,
/// 2.2 s on 81,920 P2): the stability guard visits every element again for another ν or model.
/// On a mesh above the in-place bound its guard is now computed in the background, the old
/// material running meanwhile, and installed with exactly the substeps a computation in place
/// gives; E alone (which only scales the guard) still applies at once.
#[test]
fn a_new_poisson_ratio_on_a_large_mesh_computes_its_stability_guard_in_the_background() {
    let mut m = threaded_model("bending");
    let mut c = m.sessions()[0].config.clone();
    c.element = hox_sim::element::ElementType::from_name("p1").unwrap();
    c.refine = 2;
    c.grid = [16, 2, 2];
    m.apply(Action::ChangeNow { control: "grid".into(), config: Box::new(c.clone()) }).unwrap();
    wait_built(&mut m);
    assert_eq!(m.sessions()[0].instance.sim.mesh().num_elements(), 20_480);
    let before = m.sessions()[0].instance.sim.substeps_per_frame();
    let mut stiff = c.clone();
    stiff.poisson_ratio = 0.49;
    m.apply(Action::change("poisson", stiff.clone())).unwrap();
    let status = m.building().expect("prepared in the background");
    assert!(status.starts_with("preparing ") && status.contains("poisson"), "{status}");
    assert_eq!(m.sessions()[0].config.poisson_ratio, c.poisson_ratio, "the old material runs meanwhile");
    m.apply(Action::Step(1)).unwrap();
    wait_built(&mut m);
    // estimated from the guard's substeps once its ω² is known: a slow one asks first
    if m.pending_change().is_some() {
        m.apply(Action::AnswerPending(true)).unwrap();
    }
    let s = &m.sessions()[0];
    assert_eq!(s.config.poisson_ratio, 0.49);
    // the same substeps as the guard computed in place on a simulation of its own
    let mut own = hox_scenes::Instance::new(s.instance.scene.clone()).unwrap();
    let substeps = own.sim.stability().substeps;
    assert_eq!(s.instance.sim.substeps_per_frame(), substeps);
    assert!(substeps > before, "ν 0.49 is stiffer: {substeps} substeps against {before}");
    // E only scales the guard: at once
    let mut stiffer = stiff.clone();
    stiffer.youngs_modulus_pa *= 2.0;
    m.apply(Action::change("youngs", stiffer)).unwrap();
    assert!(m.building().is_none(), "nothing to prepare in the background");
    // twice the stiffness, √2 the substeps: estimated from the guard at once, asked if slow
    if m.pending_change().is_some() {
        m.apply(Action::AnswerPending(true)).unwrap();
    }
    assert_eq!(m.sessions()[0].config.youngs_modulus_pa, 2.0 * stiff.youngs_modulus_pa);
}

/// Issue #57, "a change estimated slower than the machine can play asks first": a new material
/// was never estimated, and ν → 0.4999 has the stability guard take many times the substeps. It
/// is now estimated by the substeps the guard will take with it, asked about first when slow
/// ("keep" keeps the material), on a mesh small enough to compute its guard in place as on one
/// whose guard is computed in the background; E alone at the same ν is estimated from the
/// current guard and plays.
#[test]
fn a_much_stiffer_material_is_estimated_by_its_guard_s_substeps_and_asked_about_first() {
    for (refine, grid) in [(2, [8, 2, 2]), (2, [16, 2, 2])] {
        let mut m = threaded_model("bending");
        let mut c = m.sessions()[0].config.clone();
        c.element = hox_sim::element::ElementType::from_name("p1").unwrap();
        c.refine = refine;
        c.grid = grid;
        m.apply(Action::ChangeNow { control: "grid".into(), config: Box::new(c.clone()) }).unwrap();
        wait_built(&mut m);
        let elements = m.sessions()[0].instance.sim.mesh().num_elements();
        let mut soft = c.clone();
        soft.youngs_modulus_pa *= 0.5;
        m.apply(Action::change("youngs", soft.clone())).unwrap();
        wait_built(&mut m);
        assert!(m.pending_change().is_none(), "{elements}: a softer E plays");
        assert_eq!(m.sessions()[0].config.youngs_modulus_pa, soft.youngs_modulus_pa);
        let mut stiff = soft.clone();
        stiff.poisson_ratio = 0.4999;
        m.apply(Action::change("poisson", stiff.clone())).unwrap();
        wait_built(&mut m);
        let question = m.pending_change().map(|p| p.estimate.clone()).expect("asked first");
        assert!(question.contains("substeps per frame (the stability guard's"), "{elements}: {question}");
        assert_eq!(m.sessions()[0].config.poisson_ratio, soft.poisson_ratio, "{elements}: nothing changed yet");
        m.apply(Action::AnswerPending(false)).unwrap();
        assert_eq!(m.sessions()[0].config.poisson_ratio, soft.poisson_ratio, "{elements}: kept");
    }
}
