use super::*;

#[test]
fn every_built_in_lesson_parses_and_there_are_at_least_eight() {
    let lessons = registry().unwrap();
    assert!(lessons.len() >= 8, "{}", lessons.len());
    let mut names: Vec<&str> = lessons.iter().map(|l| l.name.as_str()).collect();
    names.dedup();
    assert_eq!(names.len(), lessons.len(), "names are unique");
    for l in &lessons {
        assert!(!l.title.is_empty() && !l.goal.is_empty() && !l.steps.is_empty(), "{}", l.name);
        for s in &l.steps {
            assert!(!s.text.is_empty() && !s.question.is_empty() && !s.answer.is_empty(), "{}: {}", l.name, s.title);
            assert!((1..=2).contains(&s.configurations.len()));
        }
        let json = l.summary_json();
        assert_eq!(json["steps"].as_array().unwrap().len(), l.steps.len());
    }
    assert!(by_name("locking").is_ok());
    let err = by_name("nope").unwrap_err().to_string();
    assert!(err.contains("no such lesson") && err.contains("why-high-order"), "{err}");
}

fn lesson_error(step_extra: &str) -> String {
    let text = format!(
        "title = \"t\"\ngoal = \"g\"\n[[steps]]\ntitle = \"first\"\nscene = \"bending\"\nmeasure = \"tip-uz\"\ntext = \"x\"\nquestion = \"q\"\nanswer = \"a\"\n{step_extra}\n"
    );
    Lesson::from_toml("mine", &text, "mine.toml").unwrap_err().to_string()
}

/// A bad lesson file names the file, the step and the key.
#[test]
fn a_bad_lesson_names_the_file_the_step_and_the_key() {
    let e = lesson_error("a = { poisson = 0.5 }");
    assert!(e.contains("mine.toml") && e.contains("step 1 ('first')") && e.contains("a.poisson"), "{e}");
    let e = lesson_error("a = { colour = \"red\" }");
    assert!(e.contains("a.colour") && e.contains("not a parameter"), "{e}");
    let e = lesson_error("b = { element = \"p9\" }");
    assert!(e.contains("step 1") && e.contains("b"), "{e}");
    let e = lesson_error("camera = \"below\"");
    assert!(e.contains("camera") && e.contains("iso"), "{e}");
    let e = lesson_error("run = \"forever\"");
    assert!(e.contains("run") && e.contains("settle"), "{e}");
    let e = lesson_error("run = -1.0");
    assert!(e.contains("run"), "{e}");
    let e = lesson_error("colour = 1");
    assert!(e.contains("mine.toml") && e.contains("colour"), "{e}");
    let text = "title = \"t\"\ngoal = \"g\"\n[[steps]]\ntitle = \"s\"\nscene = \"nowhere\"\nmeasure = \"tip-uz\"\ntext = \"x\"\nquestion = \"q\"\nanswer = \"a\"\n";
    let e = Lesson::from_toml("mine", text, "mine.toml").unwrap_err().to_string();
    assert!(e.contains("scene") && e.contains("nowhere"), "{e}");
    let e = Lesson::from_toml("mine", &text.replace("tip-uz", "speed"), "mine.toml").unwrap_err().to_string();
    assert!(e.contains("measure") || e.contains("scene"), "{e}");
    // a grid may be written as on the command line
    let ok = Lesson::from_toml(
        "mine",
        &text.replace("nowhere", "bending").replace("measure", "a = { grid = \"4x1x1\" }\nmeasure"),
        "mine.toml",
    )
    .unwrap();
    assert_eq!(ok.steps[0].configurations[0].params().grid, [4, 1, 1]);
}

/// The shape-function lesson's claim: linear shape functions stay in [0, 1]; quadratic and cubic
/// ones dip below zero (P2's corner functions to −1/8).
#[test]
fn high_order_shape_functions_have_negative_lobes() {
    use hox_sim::element::ElementType;
    let p = |n: &str| shape_minimum(ElementType::from_name(n).unwrap());
    assert!(p("p1").abs() < 1e-12, "{}", p("p1"));
    assert!((p("p2") + 0.125).abs() < 1e-3, "{}", p("p2"));
    assert!(p("p3") < -0.05, "{}", p("p3"));
}

/// Issue #35: a lesson shows the parameters its steps change (the locking lesson never showed
/// ν, its one parameter).
#[test]
fn a_lesson_names_the_parameters_its_steps_change() {
    let locking = registry().unwrap().into_iter().find(|l| l.name == "locking").unwrap();
    let keys: Vec<&str> = locking.parameters_changed().iter().map(|p| p.key).collect();
    assert!(keys.contains(&"poisson") && keys.contains(&"element") && keys.contains(&"grid"), "{keys:?}");
    assert!(!keys.contains(&"youngs") && !keys.contains(&"substeps"), "{keys:?}");
    let lines = locking.step_parameters(1);
    assert_eq!(lines.len(), 2);
    assert!(lines[0].contains("Poisson ratio ν 0.49") && lines[0].contains("p1"), "{lines:?}");
    assert!(lines[1].contains("Poisson ratio ν 0.49") && lines[1].contains("p2"), "{lines:?}");
}

/// Issue #59: mesh-bias's sideways tip (±1e-17 m) read "-0.0000 m" in the page and "0.0000 m" on
/// the desktop: a value that rounds to zero is shown without a sign.
#[test]
fn a_sideways_tip_that_rounds_to_zero_shows_no_minus_sign() {
    assert_eq!(metres_text(-1e-17), "0.0000 m");
    assert_eq!(metres_text(1e-17), "0.0000 m");
    assert_eq!(metres_text(-0.0), "0.0000 m");
    assert_eq!(metres_text(-0.00012), "-0.0001 m");
    assert_eq!(metres_text(-0.2884), "-0.2884 m");
}
