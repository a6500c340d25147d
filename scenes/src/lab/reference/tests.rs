use super::*;
use crate::{SceneOverrides, by_name};
use hox_sim::mesh::structured::TetSplit;

fn with(scene: &Scene, o: SceneOverrides) -> Scene {
    scene.with_overrides(&o).unwrap()
}

#[test]
fn the_physics_key_ignores_mesh_solver_and_damping_but_not_the_material() {
    let b = by_name("bending").unwrap();
    let key = physics_key(&b);
    let same = [
        SceneOverrides {
            element: hox_sim::element::ElementType::from_name("q1"),
            grid: Some([4, 1, 1]),
            ..Default::default()
        },
        SceneOverrides { method: Some(hox_sim::solver::Method::Newton), substeps: Some(7), ..Default::default() },
        SceneOverrides { damping_per_sec: Some(3.0), quadrature_degree: Some(Some(2)), ..Default::default() },
    ];
    for o in same {
        assert_eq!(physics_key(&with(&b, o.clone())), key, "{o:?}");
    }
    let other = [
        SceneOverrides { poisson_ratio: Some(0.49), ..Default::default() },
        SceneOverrides { youngs_modulus_pa: Some(1e6), ..Default::default() },
        SceneOverrides { density_kg_m3: Some(500.0), ..Default::default() },
        SceneOverrides { material: hox_sim::material::MaterialModel::from_name("snh"), ..Default::default() },
    ];
    for o in other {
        assert_ne!(physics_key(&with(&b, o.clone())), key, "{o:?}");
    }
}

/// Issue #20: the reference follows ν (and any other physics), not the scene's name.
#[test]
fn the_committed_reference_is_offered_only_for_the_physics_it_was_solved_for() {
    let b = by_name("bending").unwrap();
    let r = committed(&b).unwrap().expect("the bending scene as built has its committed reference");
    assert_eq!((r.origin, r.mesh.as_str()), (Origin::Committed, "Q2 32×8×8"));
    assert!((r.probes["tip"][2] + 0.3199).abs() < 1e-3, "{:?}", r.probes);
    // another mesh or solver of the same beam: the same reference
    let p1 = with(
        &b,
        SceneOverrides {
            element: hox_sim::element::ElementType::from_name("p1"),
            grid: Some([16, 4, 4]),
            ..Default::default()
        },
    );
    assert_eq!(committed(&p1).unwrap(), Some(r.clone()));
    let nu = with(&b, SceneOverrides { poisson_ratio: Some(0.49), ..Default::default() });
    assert_eq!(committed(&nu).unwrap(), None);
    // (nothing computed in this process; the disk cache left out: a machine that ran the bending
    // beam at ν = 0.4999 before holds its computed reference there)
    let no_disk = Lookup { cache_dir: None, ..Lookup::default() };
    let at_4999 = with(&nu, SceneOverrides { poisson_ratio: Some(0.4999), ..Default::default() });
    assert_eq!(no_disk.known(&at_4999).unwrap(), None);
    // a scene with no committed reference at all
    assert_eq!(committed(&by_name("squash").unwrap()).unwrap(), None);
}

/// The committed estimates are those assets/reference/README.md derives by hand (bending:
/// 5.0e-4 m, 0.16 %, observed order 1.56).
#[test]
fn the_committed_references_carry_their_richardson_estimates() {
    let r = committed(&by_name("bending").unwrap()).unwrap().unwrap();
    let e = r.estimated_error_m.unwrap();
    assert!((4.5e-4..5.5e-4).contains(&e), "{e:e} ({})", r.estimate);
    assert!(r.estimate.contains("1.5"), "{}", r.estimate);
    let pct = r.estimated_error_pct().unwrap();
    assert!((0.14..0.18).contains(&pct), "{pct}");
    assert!(r.label().contains("± 0.16 %") && r.label().contains("ν = 0.35"), "{}", r.label());
    for scene in ["tension", "torsion"] {
        let r = committed(&by_name(scene).unwrap()).unwrap().unwrap();
        let pct = r.estimated_error_pct().unwrap();
        assert!(pct < 0.05, "{scene}: {pct} %");
    }
}

#[test]
fn richardson_recovers_the_order_and_error_of_a_power_law() {
    for (p, ratio) in [(1.5, 2.0), (2.0, 2.0), (3.0, 1.5)] {
        let exact = -0.3;
        let at = |h: f64| -> Probes { [("tip".to_string(), [0.0, 0.0, exact + 0.2 * h.powf(p)])].into() };
        let hs = [0.4, 0.4 / ratio, 0.4 / ratio / ratio];
        let levels = hs.map(|h| (h, at(h)));
        let (e, how) = mesh_error(&levels);
        let truth = 0.2 * hs[2].powf(p);
        assert!((e - truth).abs() < 1e-9 * truth.max(1e-12), "p {p}: {e} vs {truth}");
        assert!(how.contains(&format!("{p:.2}")), "{how}");
        let found = observed_order(&levels).unwrap();
        assert!((found - p).abs() < 1e-9, "{found}");
        let limit = extrapolate(&levels[1], &levels[2], found);
        assert!((limit["tip"][2] - exact).abs() < 1e-9, "{limit:?}");
    }
    // levels that do not converge monotonically fall back to the finest difference, saying so
    let flat: [(f64, Probes); 3] =
        [0.4f64, 0.2, 0.1].map(|h: f64| (h, [("tip".to_string(), [0.0, 0.0, 0.1 * (h * 40.0).sin()])].into()));
    let (e, how) = mesh_error(&flat);
    assert!(e > 0.0 && how.contains("monotonically"), "{e} {how}");
}

#[test]
fn the_levels_halve_the_cells_and_follow_the_box() {
    assert_eq!(levels([0.0; 3], [2.0, 0.5, 0.5], FINEST_CELLS), [[8, 2, 2], [16, 4, 4], [32, 8, 8]]);
    let [c, m, f] = levels([0.0; 3], [1.0, 0.5, 0.5], FINEST_CELLS);
    assert_eq!((m, c), (f.map(|n| n / 2), f.map(|n| n / 4)));
    assert!(f.iter().all(|n| n % 4 == 0) && f[0] > f[1] && f[1] == f[2], "{f:?}");
    let cells = f.iter().product::<usize>();
    assert!((1500..=3500).contains(&cells), "{cells}");
    // a small budget still has four cells per direction
    assert_eq!(levels([0.0; 3], [1.0, 1.0, 1.0], 8)[2], [4, 4, 4]);
}

/// A computed reference on small levels: it solves the scene at six Q2 levels, extrapolates,
/// and states an uncertainty.
#[test]
fn a_computed_reference_solves_three_levels_and_estimates_its_own_error() {
    let b = by_name("bending").unwrap();
    let soft = with(&b, SceneOverrides { poisson_ratio: Some(0.3), ..Default::default() });
    let mut calls = 0;
    let mut last = 0.0;
    let mut estimates = Vec::new();
    let r = compute_with(
        &soft,
        64,
        &mut |what, fraction| {
            assert!(what.contains("Q2") && fraction >= last - 1e-12 && fraction <= 1.0 + 1e-12, "{what} {fraction}");
            assert!(what.starts_with("computing reference, level "), "{what}");
            last = fraction;
            calls += 1;
        },
        &mut |e| estimates.push(e.clone()),
    )
    .unwrap();
    // issue #35: a provisional estimate after the third level and each one after, each within
    // its stated error of the final one
    assert_eq!(estimates.len(), 3, "{estimates:?}");
    for (k, e) in estimates.iter().enumerate() {
        assert_eq!(e.refining, Some(Refining { levels_done: 3 + k, levels: 6 }));
        assert!(
            e.label().starts_with(&format!("provisional, levels 1–{} of 6 solved, refining", 3 + k)),
            "{}",
            e.label()
        );
        let stated = e.estimated_error_m.unwrap() + r.estimated_error_m.unwrap();
        let off = distance(&e.probes, &r.probes);
        assert!(off <= stated, "estimate {k}: {off:e} off the final, stated {stated:e} ({})", e.estimate);
    }
    assert_eq!(r.refining, None);
    assert!(calls > 3 && last > 0.99, "{calls} calls, last {last}");
    assert_eq!((r.origin, r.mesh.as_str(), r.poisson_ratio), (Origin::Computed, "Q2 12×4×4 extrapolated", 0.3));
    let tip = r.probes["tip"][2];
    assert!((-0.34..-0.30).contains(&tip), "{tip}");
    let e = r.estimated_error_m.unwrap();
    assert!(e > 0.0 && e < 0.01, "{e} ({})", r.estimate);
    assert!(r.label().starts_with("static, computed, Q2 12×4×4 extrapolated, ν = 0.3, ± "), "{}", r.label());
    let json = r.to_json();
    assert_eq!(json["origin"], "computed");
    assert!(json["estimated_error_pct"].as_f64().is_some());
    assert!(json.get("field").is_none(), "the field stays out of the JSON report");
    // the finest level's displacement field comes with it: at the tip it is that level's
    // probe, within the extrapolation's correction of the reference
    let field = r.field.as_ref().expect("a computed reference carries its field");
    let at_tip = field.lattice_at(&hox_sim::Vec3::from(b.file.probes[0].point_m));
    assert!((at_tip.z - tip).abs() < 0.01 && at_tip.z < -0.25, "{at_tip} vs {tip}");
}

/// A committed reference holds probes only; asking for its field solves the finest level once
/// and keeps the committed probes.
#[test]
fn a_committed_reference_gets_its_field_on_request() {
    let b = by_name("bending").unwrap();
    let lookup = Lookup { finest_cells: 64, cache_dir: None };
    let plain = lookup.for_scene(&b, &mut |_, _| {}).unwrap();
    assert_eq!((plain.origin, plain.field.is_none()), (Origin::Committed, true));
    let with = lookup.with_field(&b, &mut |what, _| assert!(what.contains("reference field"), "{what}")).unwrap();
    assert_eq!(with.probes, plain.probes);
    let field = with.field.expect("solved");
    let tip = field.lattice_at(&hox_sim::Vec3::from(b.file.probes[0].point_m)).z;
    assert!((tip / plain.probes["tip"][2] - 1.0).abs() < 0.05, "{tip} vs {:?}", plain.probes["tip"]);
}

/// Issue #35, symptom 1: compare P1 refined once against P2, type ν = 0.49 — A's readout said
/// "cannot build the mesh: … refinement applies to tetrahedra only, not to q2" because the Q2
/// levels inherited the configuration's refinement. A reference depends on the physics alone.
#[test]
fn a_refined_p1_gets_the_same_reference_as_p2() {
    let b = by_name("bending").unwrap();
    let nu = |element: &str, refine: usize, split: TetSplit| {
        let o = SceneOverrides {
            element: hox_sim::element::ElementType::from_name(element),
            refine: Some(refine),
            split: Some(split),
            poisson_ratio: Some(0.49),
            ..Default::default()
        };
        with(&b, o)
    };
    let lookup = Lookup { finest_cells: 64, cache_dir: None };
    let (p1, p2) = (nu("p1", 1, TetSplit::Six), nu("p2", 0, TetSplit::Five));
    assert_eq!(lookup.key(&p1), lookup.key(&p2));
    let r = lookup.for_scene(&p1, &mut |_, _| {}).expect("the refined P1's reference");
    assert_eq!((r.origin, r.poisson_ratio), (Origin::Computed, 0.49));
    assert_eq!(lookup.known(&p2).unwrap(), Some(r));
}

#[test]
fn the_levels_of_a_computed_reference_grow_and_start_small() {
    assert_eq!(
        grids([0.0; 3], [2.0, 0.5, 0.5], FINEST_CELLS),
        vec![[8, 2, 2], [12, 3, 3], [16, 4, 4], [20, 5, 5], [24, 6, 6], [32, 8, 8]]
    );
    // the first provisional estimate needs the three coarsest: a fifth of the finest's cells
    let g = grids([0.0; 3], [2.0, 0.5, 0.5], FINEST_CELLS);
    let cells = |g: &[usize; 3]| g.iter().product::<usize>();
    assert!(g[..3].iter().map(cells).sum::<usize>() * 5 < cells(&g[5]));
    // a small box repeats no level
    let small = grids([0.0; 3], [1.0, 1.0, 1.0], 8);
    assert!(small.windows(2).all(|w| w[0] != w[1] && cells(&w[0]) < cells(&w[1])), "{small:?}");
}

#[test]
fn a_scene_with_contact_or_without_probes_has_no_reference() {
    let drop = by_name("drop").unwrap();
    if drop.file.effects.iter().any(|e| matches!(e, EffectSpec::Contact { .. })) {
        assert!(unavailable(&drop).unwrap().contains("contact"));
        let err = for_scene(&drop, &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("no reference") && err.contains("contact"), "{err}");
    }
    let mut bare = by_name("bending").unwrap();
    bare.file.probes.clear();
    assert!(unavailable(&bare).unwrap().contains("probes"));
}

/// The disk cache is keyed by the physics and never trusted blindly: a file whose key differs
/// (a hash collision, or a hand edit) is recomputed.
#[test]
fn the_cache_file_names_its_key() {
    let a = fnv1a("box [0,0,0]; nu=0.49");
    assert_ne!(a, fnv1a("box [0,0,0]; nu=0.35"));
    assert_eq!(a, fnv1a("box [0,0,0]; nu=0.49"));
}

/// Issue #59: a computed reference written out for a site (`hox lesson --references-to`) is the
/// cache file the page reads back through its read-only cache, under the same key, whole; a
/// committed reference is not written (the page's module has it).
#[test]
fn a_reference_exported_for_a_site_is_read_back_through_the_read_only_cache() {
    let b = by_name("bending").unwrap();
    let nu = with(&b, SceneOverrides { poisson_ratio: Some(0.42), ..Default::default() });
    let computed = Lookup { finest_cells: 64, cache_dir: None };
    let r = computed.for_scene(&nu, &mut |_, _| {}).unwrap();
    let site = std::env::temp_dir().join(format!("hox-site-references-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&site);
    assert_eq!(computed.export(&nu, &site).unwrap(), 1, "the probes' reference, no field solved");
    assert_eq!(computed.export(&b, &site).unwrap(), 0, "a committed reference stays in the module");
    // the page's lookup: the same levels' key, nothing in memory, no cache folder
    let page = Lookup { finest_cells: 64, cache_dir: None };
    let name = cache_file_name(&page.key(&nu));
    assert!(site.join(&name).is_file(), "{name}");
    memory().lock().unwrap().remove(&page.key(&nu));
    assert_eq!(page.known(&nu).unwrap(), None, "nothing read yet");
    read_only_cache(|name| {
        std::fs::read_to_string(
            std::env::temp_dir().join(format!("hox-site-references-{}", std::process::id())).join(name),
        )
        .ok()
    });
    assert_eq!(page.known(&nu).unwrap(), Some(r));
    let _ = std::fs::remove_dir_all(&site);
}

/// Issue #59: the page's Web Worker rebuilds the scene it computes a reference for from its TOML
/// (`scene.file.to_toml()`); a paper scene as built keeps its committed reference through the
/// trip, as on the desktop.
#[test]
fn a_scene_rebuilt_from_its_toml_keeps_its_committed_reference() {
    for name in ["bending", "tension", "torsion"] {
        let scene = by_name(name).unwrap();
        let rebuilt = crate::Scene::from_toml(&scene.file.to_toml(), &scene.source).unwrap();
        assert_eq!(physics_key(&rebuilt), physics_key(&scene), "{name}");
        let r = committed(&rebuilt).unwrap().unwrap_or_else(|| panic!("{name}: no committed reference after the trip"));
        assert_eq!(r.origin, Origin::Committed);
    }
}

/// A reference follows the physics, not the name: the paper's bending beam renamed (a lesson's
/// or a user's scene file with the paper's physics) has the committed reference; with another
/// ν it has none.
#[test]
fn a_beam_with_the_paper_s_physics_under_another_name_has_the_committed_reference() {
    let mut renamed = by_name("bending").unwrap();
    renamed.file.name = "my beam".into();
    let r = committed(&renamed).unwrap().expect("the paper's bending physics");
    assert_eq!((r.origin, r.poisson_ratio), (Origin::Committed, 0.35));
    let other = with(&renamed, SceneOverrides { poisson_ratio: Some(0.3), ..Default::default() });
    assert_eq!(committed(&other).unwrap(), None, "ν = 0.3 is not the paper's");
}
