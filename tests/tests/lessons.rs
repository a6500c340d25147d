//! Every built-in lesson's claim, checked with the numbers it shows (issue #21): each step is
//! run headlessly as `hox lesson` and the app run it ([`hox_scenes::lesson::run_step`]) and its
//! measurements compared as the step's answer states. The two lessons that settle a 1,280-element
//! beam run in release (`.ci/run`: `cargo test --release -p hox-tests -- --ignored`).

use hox_scenes::lesson::{Measured, by_name, run_step};

/// The measurements of step `k` (1-based) of `lesson`: A's and B's values. The step's claim, if
/// it has one, holds for them (issue #57: every claim the app judges beside an answer is
/// checked wherever its step runs, as `hox lesson` measures it).
fn step(lesson: &str, k: usize) -> Vec<f64> {
    let l = by_name(lesson).unwrap();
    let (_, measured) = run_step(&l.steps[k - 1], &mut |_, _| {}).unwrap();
    let values: Vec<f64> = measured.iter().map(|m: &Measured| m.value).collect();
    if let Some(claim) = &l.steps[k - 1].claim {
        let judged = claim.judge(&values).unwrap_or_else(|| panic!("{lesson} step {k}: not measured: {values:?}"));
        assert!(judged.holds, "{lesson} step {k}: {} ({values:?})", judged.text);
    }
    values
}

/// Every step with a claim is run by a test of this file (through [`step`]).
#[test]
fn every_lesson_claim_is_checked_by_a_test_here() {
    let source = include_str!("lessons.rs");
    for lesson in hox_scenes::lesson::registry().unwrap() {
        for (k, s) in lesson.steps.iter().enumerate() {
            if s.claim.is_some() {
                let call = format!("step(\"{}\", {})", lesson.name, k + 1);
                assert!(
                    source.contains(&call),
                    "{} step {}'s claim is checked nowhere: add {call}",
                    lesson.name,
                    k + 1
                );
            }
        }
    }
}

#[test]
fn locking_p1_stiffens_as_poisson_goes_to_one_half_and_high_order_does_not() {
    let soft = step("locking", 1);
    let nearly = step("locking", 2);
    let (r_soft, r_nearly) = (soft[0] / soft[1], nearly[0] / nearly[1]);
    // ν = 0.3: P1 sags about a third less than P2; ν = 0.49: only a little over half as far
    assert!((0.6..0.75).contains(&r_soft), "P1/P2 at ν = 0.3: {r_soft} ({soft:?})");
    assert!(r_nearly < 0.6 && r_nearly < r_soft - 0.1, "P1/P2 at ν = 0.49: {r_nearly} ({nearly:?})");
    // P2 and P3 agree within about 2 % and lie within 8 % of the ν = 0.49 reference (−0.3127 m)
    let high = step("locking", 3);
    assert!((high[0] / high[1] - 1.0).abs() < 0.03, "{high:?}");
    assert!(high.iter().all(|u| (u / -0.3127 - 1.0).abs() < 0.08), "{high:?}");
    // ν = 0.499: the pointwise P2 sags about a tenth less than the mixed one (−0.28 m against
    // −0.32 m), which is within about 1 % of the reference for ν = 0.499 (−0.3120 m, P2 mixed
    // levels up to 32×8×8; docs/study/locking.md)
    let cure = step("locking", 4);
    assert!(cure[0] / cure[1] < 0.93, "{cure:?}");
    assert!((cure[0] / -0.28 - 1.0).abs() < 0.02 && (cure[1] / -0.32 - 1.0).abs() < 0.02, "{cure:?}");
    assert!((cure[1] / -0.3120 - 1.0).abs() < 0.015, "{cure:?}");
}

#[test]
fn mesh_bias_the_six_split_bends_sideways_the_five_split_does_not() {
    let p1 = step("mesh-bias", 1);
    assert!(p1[0].abs() < 1e-6, "five-split P1 u_y {}", p1[0]);
    assert!(p1[1].abs() > 0.01, "six-split P1 u_y {}", p1[1]);
    let p2 = step("mesh-bias", 2);
    // quadratic elements: the split matters far less
    assert!(p2[1].abs() < 0.05 * p1[1].abs(), "P2 {p2:?} against P1 {p1:?}");
    // under torsion the five-split's opposite corners are mirror images, the six-split's not
    let twist = step("mesh-bias", 3);
    assert!(twist[0] < 1e-6 && twist[1] > 0.01, "{twist:?}");
}

#[test]
fn quadrature_one_point_per_hexahedron_lets_hourglass_modes_sag_the_beam() {
    let q1 = step("quadrature", 1);
    assert!(q1[0] > 4.0 * q1[1], "one point {} m against eight {} m", q1[0], q1[1]);
    let p2 = step("quadrature", 2);
    assert!((p2[0] / p2[1] - 1.0).abs() < 1e-3, "more points buy nothing: {p2:?}");
    // …and cost time: measured side by side in one run, a ratio
    let ms = step("quadrature", 3);
    assert!(ms[1] > 1.5 * ms[0], "degree 6 against the default: {ms:?} ms per frame");
}

#[test]
fn shape_functions_high_order_ones_dip_below_zero_and_faces_curve() {
    assert!(step("shape-functions", 1)[0].abs() < 1e-12);
    assert!((step("shape-functions", 2)[0] + 0.125).abs() < 1e-3);
    let tip = step("shape-functions", 3)[0];
    assert!(tip < -0.01, "the coarse P2 beam bends: {tip}");
}

#[test]
fn stability_the_guard_takes_the_substeps_a_stiff_beam_needs_and_without_it_it_blows_up() {
    let substeps = step("stability", 1);
    assert!(substeps[0] > 100.0 && substeps[1] == 1.0, "{substeps:?}");
    let moved = step("stability", 2);
    assert!(moved[0] < 0.01, "guarded: {} m", moved[0]);
    assert!(moved[1] > 100.0 * moved[0] && moved[1] > 0.5, "unguarded: {moved:?}");
}

#[test]
fn materials_stvk_inverts_under_squashing_and_neo_hookean_does_not() {
    let det = step("materials", 1);
    assert!(det[0] < 0.0, "StVK min det F {}", det[0]);
    assert!(det[1] > 0.2, "stable Neo-Hookean min det F {}", det[1]);
}

#[test]
#[ignore = "settles a 1,280-element beam: CI runs it with --release --ignored"]
fn why_high_order_p2_160_beats_p1_1280_in_accuracy_and_cost() {
    let swing = step("why-high-order", 1);
    assert!(swing[1] < swing[0] - 0.05, "P2 swings further down: {swing:?}");
    let error = step("why-high-order", 2);
    // about 5.5 cm against 1.3 mm
    assert!(error[0] > 20.0 * error[1], "{error:?}");
    assert!((0.04..0.07).contains(&error[0]) && error[1] < 2e-3, "{error:?}");
    // measured side by side in one run: a ratio, not a time. It depends on the processor: 2.6
    // on an AVX-512 EPYC, 1.31-1.47 on an AVX2-only one (three runs), 1.15-1.20 on an AVX-512
    // Intel Xeon (six runs, session 29; 1.147 once in CI beside another test), so the bound is
    // loose: P2 cheaper, by a margin the noise does not cross
    let ms = step("why-high-order", 3);
    assert!(ms[0] > 1.05 * ms[1], "ms per frame {ms:?}");
}

#[test]
#[ignore = "settles the beam three times and once with Newton: CI runs it with --release --ignored"]
fn accuracy_cost_the_error_splits_into_the_mesh_s_and_the_solver_s() {
    let substeps = step("accuracy-cost", 1);
    assert!(substeps[1] < 0.5 * substeps[0], "100 substeps nearer the mesh's equilibrium: {substeps:?}");
    let iterations = step("accuracy-cost", 2);
    assert!(iterations[1] < 0.1 * iterations[0], "two iterations far nearer: {iterations:?}");
    assert!(iterations[1] < substeps[1], "and nearer than twice the substeps: {iterations:?} {substeps:?}");
    let solver = step("accuracy-cost", 3);
    assert!(solver[1] < 0.01 * solver[0], "Newton settles at the equilibrium: {solver:?}");
    let whole = step("accuracy-cost", 4);
    assert!(whole[0] < whole[1], "XPBD's bias cancels part of the coarse mesh's error: {whole:?}");
    let ms = step("accuracy-cost", 5);
    assert!(ms[1] > 1.4 * ms[0], "twice the substeps, about twice the time: {ms:?}");
}

/// Issue #37: on the hook P1's facets lose 3.4 % of the volume where P2's curved faces lose
/// 0.01 %; on the tube P1 sags 6.2 % less than P2 and is about nineteen times further from the
/// P3 part's static solution (7.6 mm against 0.41 mm).
#[test]
fn curved_boundaries_p1_facets_cost_volume_and_stiffness_that_p2_does_not() {
    let exact_m3 = std::f64::consts::PI * 0.03f64.powi(2) * (0.3 + 0.1 * std::f64::consts::PI);
    let volume = step("curved-boundaries", 1);
    let error = |v: f64| (v / exact_m3 - 1.0).abs();
    assert!((0.02..0.05).contains(&error(volume[0])) && volume[0] < exact_m3, "P1 {volume:?} against {exact_m3}");
    assert!(error(volume[1]) < 5e-4, "P2 {volume:?} against {exact_m3}");
    let sag = step("curved-boundaries", 2);
    let stiffer = 1.0 - sag[0] / sag[1];
    assert!((0.03..0.1).contains(&stiffer), "P1 sags {:.1} % less than P2: {sag:?}", 100.0 * stiffer);
    let error = step("curved-boundaries", 3);
    assert!(error[0] > 10.0 * error[1] && error[1] < 1e-3, "{error:?}");
}
