use super::*;
use hox_sim::solver::{RangeValue, VbdSettings};

#[test]
fn every_entry_is_complete_and_its_keys_unique() {
    let mut keys = std::collections::HashSet::new();
    let mut paths = std::collections::HashSet::new();
    for p in PARAMS {
        assert!(!p.key.is_empty() && !p.file_key.is_empty() && !p.label.is_empty() && !p.help.is_empty(), "{p:?}");
        assert!(keys.insert(p.key), "key {} twice", p.key);
        assert!(paths.insert(p.file_path()), "file key {} twice", p.file_path());
        // the default is valid and round-trips through Value, TOML and text
        let d = Params::default();
        let v = (p.get)(&d);
        p.kind.check(&v).unwrap_or_else(|e| panic!("{}: default {v}: {e}", p.key));
        let mut q = d.clone();
        assert!((p.set)(&mut q, v.clone()), "{}", p.key);
        assert_eq!(q, d);
        if let Some(t) = v.to_toml() {
            assert_eq!(p.kind.from_toml(&t).as_ref(), Ok(&v), "{}", p.key);
        }
        if !matches!(p.kind, Kind::Point) {
            assert_eq!(p.kind.parse(&v.to_string()).as_ref(), Ok(&v), "{}", p.key);
        }
    }
}

#[test]
fn overrides_set_by_text_name_the_key_and_check_the_range() {
    let mut o = SceneOverrides::default();
    o.set_text("youngs", "6e6").unwrap();
    o.set_text("grid", "16x4x4").unwrap();
    o.set_text("quadrature", "default").unwrap();
    o.set_text("guard", "off").unwrap();
    assert_eq!(o.youngs_modulus_pa, Some(6e6));
    assert_eq!(o.grid, Some([16, 4, 4]));
    assert_eq!(o.quadrature_degree, Some(None));
    assert_eq!(o.stability_guard, Some(false));
    let e = o.set_text("youngz", "1").unwrap_err();
    assert!(e.contains("'youngz'") && e.contains("did you mean 'youngs'"), "{e}");
    let e = o.set_text("grid", "-4x2x2").unwrap_err();
    assert!(e.starts_with("grid:"), "{e}");
    let e = o.set_text("refine", "9").unwrap_err();
    assert!(e.starts_with("refine = 9"), "{e}");
    let e = o.set_text("poisson", "0.5").unwrap_err();
    assert!(e.contains("< 0.5"), "{e}");
}

#[test]
fn a_change_invalidates_what_its_entry_says() {
    let a = Params::default();
    let mut b = a.clone();
    assert_eq!(a.invalidated_by(&b), Invalidates::Nothing);
    b.substeps = 10;
    assert_eq!(a.invalidated_by(&b), Invalidates::Settings);
    b.youngs_modulus_pa = 1e7;
    assert_eq!(a.invalidated_by(&b), Invalidates::Material);
    b.element = ElementType::from_name("q2").unwrap();
    assert_eq!(a.invalidated_by(&b), Invalidates::Mesh);
    assert_eq!(a.changed_keys(&b), ["element", "youngs", "substeps"]);
}

#[test]
fn the_size_of_a_refined_box_is_estimated_before_building_it() {
    let mut p = Params::default();
    assert_eq!(box_elements(&p), Some(160));
    p.refine = 3;
    assert_eq!(box_elements(&p), Some(81_920));
    assert!(check_box_size(&p).is_ok());
    p.refine = 5;
    let e = check_box_size(&p).unwrap_err();
    assert!(e.contains("5,242,880 elements") && e.contains("GB"), "{e}");
    p.refine = 0;
    p.grid = [64, 64, 64];
    p.element = ElementType::from_name("p1").unwrap();
    assert_eq!(box_elements(&p), Some(1_310_720));
    assert!(check_box_size(&p).is_ok());
    p.split = TetSplit::Six;
    p.refine = 1;
    assert!(check_box_size(&p).unwrap_err().contains("12,582,912 elements"));
    assert!(check_grid_size(&p).is_ok(), "reported on the refinement, not the grid");
    // high order reaches the memory limit first, and unrefined it is the grid's
    p.element = ElementType::from_name("p3").unwrap();
    p.split = TetSplit::Five;
    p.refine = 0;
    let e = check_grid_size(&p).unwrap_err();
    assert!(e.contains("1,310,720 elements") && e.contains("GB"), "{e}");
    assert!(check_refine_size(&p).is_ok());
}

#[test]
fn the_typed_choices_persist_by_name_and_an_unknown_name_is_refused() {
    let p = Params {
        element: ElementType::from_name("q2").unwrap(),
        method: Method::Vbd,
        field: vec![Field::Strain, Field::VonMises],
        ..Params::default()
    };
    let json = serde_json::to_value(&p).unwrap();
    assert!(json["element"] == "q2" && json["method"] == "vbd" && json["field"] == "strain,von-mises", "{json}");
    assert_eq!(serde_json::from_value::<Params>(json).unwrap(), p);
    let e = serde_json::from_str::<Params>(r#"{"element": "p7"}"#).unwrap_err().to_string();
    assert!(e.contains("unknown option 'p7'"), "{e}");
    // what a choice's text check passes, its typed field takes
    for param in PARAMS.iter().filter(|p| matches!(p.kind, Kind::Choice(_))) {
        let Kind::Choice(options) = param.kind else { unreachable!() };
        for (name, _) in options() {
            let mut q = Params::default();
            assert!((param.set)(&mut q, Value::Text(name.into())), "{} {name}", param.key);
            assert_eq!((param.get)(&q), Value::Text(name.into()));
        }
        assert!(!(param.set)(&mut Params::default(), Value::Text("no-such-thing".into())), "{}", param.key);
    }
}

#[test]
fn the_solver_entries_default_to_sims_settings() {
    let (p, s) = (Params::default(), SolverSettings::default());
    assert_eq!(
        (p.method, p.substeps, p.iterations, p.sweep, p.formulation),
        (s.method, s.substeps, s.iterations, s.sweep, s.formulation)
    );
    assert_eq!(
        (p.vbd_iterations, p.chebyshev_rho, p.vbd_coarse_cells, p.vbd_init),
        (s.vbd.iterations, s.vbd.chebyshev_rho, s.vbd.coarse_cells, s.vbd.init)
    );
    let mut o = SceneOverrides::default();
    assert!(o.set_text("vbd-coarse-cells", &VbdSettings::MAX_COARSE_CELLS.to_string()).is_ok());
    assert!(o.set_text("vbd-coarse-cells", &(VbdSettings::MAX_COARSE_CELLS + 1).to_string()).is_err());
    assert!(o.set_text("chebyshev-rho", "1").unwrap_err().contains("< 1"));
}

/// Every parameter a solver's entry names is a table entry of the solver group, and each such
/// entry applies to exactly the solvers that list it (the app greys it out for the others).
#[test]
fn solver_parameters_apply_to_the_solvers_that_read_them() {
    use hox_sim::solver::{METHODS, Method};
    for info in METHODS {
        for key in info.parameters {
            let entry = PARAMS.iter().find(|p| p.file_key == *key);
            let entry = entry.unwrap_or_else(|| panic!("{}: no table entry with the file key {key}", info.name));
            assert_eq!(entry.group, Group::Solver, "{key}");
        }
    }
    // a key some solver lists is one of its own parameters: it applies to exactly the solvers
    // listing it (every solver of the registry, with no line here per solver)
    let own: Vec<&str> = METHODS.iter().flat_map(|i| i.parameters.iter().copied()).collect();
    let mut p = Params::default();
    for method in Method::ALL {
        p.method = method;
        let applies = |file_key: &str| PARAMS.iter().find(|e| e.file_key == file_key).unwrap().applies_to(&p);
        for key in &own {
            assert_eq!(applies(key), method.info().parameters.contains(key), "{method}: {key}");
        }
        assert_eq!(applies("substeps"), method == Method::Xpbd, "{method}");
        assert_eq!(applies("vbd_iterations"), method == Method::Vbd, "{method}");
        assert_eq!(applies("steps_per_frame"), method.is_implicit(), "{method}");
        assert!(applies("frames_per_second") && applies("quadrature_degree"), "{method}");
    }
}

/// A solver setting's range is declared once, in sim ([`SolverSettings::RANGES`]): the table's
/// kind and label for it are the declaration's, so its check, its message and
/// [`SolverSettings::validate`]'s agree (a change of the declaration changes both).
#[test]
fn every_solver_settings_kind_and_message_are_sims_declaration() {
    for setting in SolverSettings::RANGES {
        let p = by_key(setting.key).unwrap_or_else(|| panic!("{}: declared in sim, not in the table", setting.key));
        assert_eq!(p.group, Group::Solver, "{}", setting.key);
        assert_eq!((p.kind.range(), p.label), (Some(setting.range), setting.label), "{}", setting.key);
        // the value just past the top (or below the bottom) of the range: the table's message is
        // sim's, word for word
        let (value, outside) = match setting.range {
            hox_sim::solver::Range::Whole { max, .. } => (Value::Whole(max + 1), RangeValue::Whole(max + 1)),
            hox_sim::solver::Range::Number { min, .. } => (Value::Number(min - 1.0), RangeValue::Number(min - 1.0)),
        };
        let table = p.check_value(&value).unwrap_err();
        let sim = setting.check(outside).unwrap_err().to_string();
        assert!(sim.contains(&format!("{table}, got")), "{}: the table says {table:?}, sim {sim:?}", setting.key);
    }
}
