//! The study's locking table (issues #20 and #62): volumetric locking of the bending beam as
//! ν → 0.5, measured statically, and what its cure costs.
//!
//! For each Poisson ratio of [`LOCKING_POISSON_RATIOS`] and each mesh (P1 1,280 and 10,240, P2
//! 160, P3 80), the static tip deflection `u_z` ([`hox_sim::solver::statics`], 4 load steps, the
//! scene's StVK) with the volume measured at every quadrature point (the `energy` formulation)
//! and, where the element admits it, once per element (`mixed`: one constant pressure per
//! element, condensed; [`hox_sim::fem::energy::mixed`]). Each is set against the **computed
//! reference** at the same ν ([`crate::reference`]: the committed fine Q2 solution at the
//! paper's ν, Q2 levels below ν = 0.45 and P2 mixed levels from it, extrapolated), which no
//! longer locks itself: the share of its sag a mesh misses is the mesh's locking and
//! discretisation error, not a lower bound. P1's mixed formulation is one pressure and one averaged strain per node
//! patch ([`hox_sim::fem::energy::mixed::patch`]). The cost of each is the median ms per frame of
//! XPBD at the scene's settings (50 substeps × 1 iteration, 60 fps; P1 mixed with a deviatoric
//! constraint per element and a hydrostatic and a deviatoric one per node patch,
//! [`hox_sim::xpbd::patch`]; none
//! where XPBD refuses the formulation) and of Newton (one implicit Euler step per frame), on one thread over
//! half a simulated second from rest, measured in the same run as its neighbours (compare them as
//! ratios).

use super::StudyConfig;
use crate::error::SceneError;
use crate::params::SceneOverrides;
use crate::run::{RunMode, run};
use hox_sim::Vec3;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::Method;
use hox_sim::xpbd::constraint::Formulation;

/// The Poisson ratios of the locking table: the paper's 0.35 and the near-incompressible ones of
/// the robustness suite (docs/STABILITY.md, case 2).
pub const LOCKING_POISSON_RATIOS: [f64; 4] = [0.35, 0.45, 0.49, 0.499];

/// The formulations of the locking table, side by side.
pub const LOCKING_FORMULATIONS: [Formulation; 2] = [Formulation::Energy, Formulation::Mixed];

/// One cell of the locking table: the static tip deflection of the bending beam on one mesh and
/// formulation at one Poisson ratio, against the computed reference at the same ν, and XPBD's
/// cost per frame there.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LockingRow {
    pub poisson_ratio: f64,
    pub config: String,
    /// `--formulation`: "energy" (the volume at every quadrature point) or "mixed".
    pub formulation: String,
    pub elements: usize,
    /// Vertical displacement of the tip probe, m (negative: down).
    pub tip_z_m: f64,
    /// The reference's at this ν, m.
    pub reference_tip_z_m: f64,
    /// What the reference was solved on ("P2 mixed 32×8×8 extrapolated").
    pub reference_mesh: String,
    /// Share of the reference's sag that this mesh misses, % (positive: stiffer, i.e. locking).
    pub missing_pct: f64,
    /// XPBD's median ms per frame at the scene's settings, one thread (module docs); None in
    /// tables written when XPBD refused P1 mixed (every solver runs every formulation the
    /// element admits today).
    pub ms_per_frame: Option<f64>,
    /// Newton's median ms per frame (implicit Euler, one step per frame), one thread.
    pub newton_ms_per_frame: f64,
}

/// The meshes of the locking table (P1 10,240 is heavy).
fn meshes() -> [StudyConfig; 4] {
    use TetSplit::Five;
    let c = StudyConfig::new;
    [
        c("p1", [16, 4, 4], Five, 0, false),
        c("p1", [16, 4, 4], Five, 1, true),
        c("p2", [8, 2, 2], Five, 0, false),
        c("p3", [4, 2, 2], Five, 0, false),
    ]
}

/// Volumetric locking and its cure (module docs) at every ν of [`LOCKING_POISSON_RATIOS`]
/// (P1 10,240 left out when `quick`).
pub fn locking(quick: bool, progress: &mut dyn FnMut(&str)) -> Result<Vec<LockingRow>, SceneError> {
    let mut rows = Vec::new();
    for nu in LOCKING_POISSON_RATIOS {
        rows.extend(locking_at(nu, quick, progress)?);
    }
    Ok(rows)
}

/// The locking table's rows at one Poisson ratio `nu` (a cell of [`super::shard::Plan`]): every
/// mesh of [`locking`] in each formulation it admits (P1 10,240 left out when `quick`).
pub fn locking_at(nu: f64, quick: bool, progress: &mut dyn FnMut(&str)) -> Result<Vec<LockingRow>, SceneError> {
    let bending = crate::scene::builtin::by_name("bending")?
        .with_overrides(&SceneOverrides { poisson_ratio: Some(nu), ..Default::default() })?;
    progress(&format!("locking: the reference at ν = {nu}"));
    let reference = crate::reference::for_scene(&bending, &mut |_, _| {})?;
    let fail = |m: String| SceneError::Simulation { source_name: format!("bending at ν = {nu}"), message: m };
    let reference_tip_z_m =
        reference.probes.get("tip").ok_or_else(|| fail("the reference has no probe named tip".into()))?[2];
    let mut rows = Vec::new();
    for config in meshes().iter().filter(|m| !(quick && m.heavy)) {
        for formulation in LOCKING_FORMULATIONS {
            let element = hox_sim::element::ElementType::from_name(config.element);
            if formulation == Formulation::Mixed && element.and_then(hox_sim::fem::energy::mixed::refusal).is_some() {
                continue;
            }
            let overrides =
                SceneOverrides { poisson_ratio: Some(nu), formulation: Some(formulation), ..config.overrides() };
            let scene = crate::scene::builtin::by_name("bending")?.with_overrides(&overrides)?;
            let label = format!("{} {}", config.label(), formulation.name());
            progress(&format!("locking: bending {label} at ν = {nu}: static solution"));
            let (tip_z_m, elements) = static_tip_z(&scene, &label, nu)?;
            progress(&format!("locking: bending {label} at ν = {nu}: XPBD and Newton, one thread"));
            let ms_per_frame = Some(median_ms_per_frame(&scene, Method::Xpbd)?);
            let newton_ms_per_frame = median_ms_per_frame(&scene, Method::Newton)?;
            rows.push(LockingRow {
                poisson_ratio: nu,
                config: config.label(),
                formulation: formulation.name().to_string(),
                elements,
                tip_z_m,
                reference_tip_z_m,
                reference_mesh: reference.mesh.replace(',', ";"),
                missing_pct: 100.0 * (1.0 - tip_z_m / reference_tip_z_m),
                ms_per_frame,
                newton_ms_per_frame,
            });
        }
    }
    Ok(rows)
}

/// The static vertical displacement of `scene`'s "tip" probe, and the element count.
fn static_tip_z(scene: &crate::scene::Scene, label: &str, nu: f64) -> Result<(f64, usize), SceneError> {
    let fail = |m: String| SceneError::Simulation { source_name: format!("bending {label} at ν = {nu}"), message: m };
    let mesh = scene.build_mesh()?;
    let solution =
        crate::instance::solve_static(scene, &mesh, 1e-8, 4, &mut |_, _, _| {}).map_err(|e| fail(e.to_string()))?;
    let tip = scene
        .file
        .probes
        .iter()
        .find(|p| p.name == "tip")
        .ok_or_else(|| fail("the scene has no probe named tip".into()))?;
    let probe = hox_sim::measure::probe::Probe::locate(&mesh, &tip.name, Vec3::from(tip.point_m))
        .map_err(|e| fail(e.to_string()))?;
    Ok((probe.displacement(&solution.positions, &mesh.rest_positions).z, mesh.num_elements()))
}

/// The median ms per frame of `method` on `scene` at its settings, one thread, over half a
/// simulated second from rest.
fn median_ms_per_frame(scene: &crate::scene::Scene, method: Method) -> Result<f64, SceneError> {
    let solver = scene.with_overrides(&SceneOverrides { method: Some(method), ..Default::default() })?;
    let mut instance = crate::instance::Instance::new(solver)?;
    Ok(super::one_thread()?.install(|| run(&mut instance, RunMode::Seconds(0.5), &mut |_, _| {}))?.ms_per_frame)
}

/// `study.md`'s locking section: one row per mesh and formulation, one column per ν, and the
/// cost per frame at the last ν.
pub fn locking_markdown(rows: &[LockingRow]) -> String {
    let mut s = String::from(
        "## Near incompressibility: volumetric locking and its cure (bending, static)\n\nStatic tip deflection `u_z` of the bending beam (the scene's StVK, E = 3 MPa, 4 load steps) with the volume measured at every quadrature point (`energy`) and once per element (`mixed`: one constant pressure per element on P2 and P3; on P1, whose one quadrature point already measures the element's volume, one pressure per node, the mean over the elements around it, and the deviatoric term at the nodes' averaged deformation gradients, a tenth left on the elements), against the computed reference at the same ν; in brackets the share of the reference's sag the mesh misses (negative: stiffer, i.e. locking). The last columns: the median ms per frame of XPBD at the scene's settings (50 substeps × 1 iteration, the substep shortened by the stability guard near incompressibility; — where XPBD refuses the formulation) and of Newton (one implicit Euler step per frame), one thread, over half a second from rest at the last ν.\n\n| configuration | formulation |",
    );
    let nus: Vec<f64> =
        LOCKING_POISSON_RATIOS.iter().copied().filter(|nu| rows.iter().any(|r| r.poisson_ratio == *nu)).collect();
    for nu in &nus {
        s.push_str(&format!(" ν = {nu} |"));
    }
    let last = nus.last().copied();
    let at = last.map(|nu| format!(" (ν = {nu})")).unwrap_or_default();
    s.push_str(&format!(" XPBD ms/frame{at} | Newton ms/frame{at} |\n|---|---|"));
    s.push_str(&"---|".repeat(nus.len() + 2));
    s.push_str("\n| reference | |");
    for nu in &nus {
        match rows.iter().find(|r| r.poisson_ratio == *nu) {
            Some(r) => s.push_str(&format!(" {:.4} m |", r.reference_tip_z_m)),
            None => s.push_str(" — |"),
        }
    }
    s.push_str(" | |\n");
    let mut lines: Vec<(&str, &str, usize)> = Vec::new();
    for r in rows {
        if !lines.iter().any(|(c, f, _)| *c == r.config && *f == r.formulation) {
            lines.push((&r.config, &r.formulation, r.elements));
        }
    }
    for (config, formulation, elements) in &lines {
        s.push_str(&format!("| {config} ({elements}) | {formulation} |"));
        let of = |nu: f64| {
            rows.iter().find(|r| r.config == *config && r.formulation == *formulation && r.poisson_ratio == nu)
        };
        for nu in &nus {
            match of(*nu) {
                Some(r) => s.push_str(&format!(" {:.4} m ({:+.1} %) |", r.tip_z_m, -r.missing_pct)),
                None => s.push_str(" — |"),
            }
        }
        let ms = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.1}"));
        match last.and_then(of) {
            Some(r) => s.push_str(&format!(" {} | {} |\n", ms(r.ms_per_frame), ms(Some(r.newton_ms_per_frame)))),
            None => s.push_str(" — | — |\n"),
        }
    }
    s.push_str("\nReferences:");
    for (k, nu) in nus.iter().enumerate() {
        if let Some(r) = rows.iter().find(|r| r.poisson_ratio == *nu) {
            s.push_str(&format!("{} ν = {nu}: {}", if k == 0 { "" } else { ";" }, r.reference_mesh));
        }
    }
    s.push_str(".\n\n");
    s
}

/// `locking.csv`: the locking rows.
pub fn locking_csv(rows: &[LockingRow]) -> String {
    let mut s = String::from(
        "poisson_ratio,configuration,formulation,elements,tip_z_m,reference_tip_z_m,reference_mesh,missing_pct,ms_per_frame_1_thread,newton_ms_per_frame_1_thread\n",
    );
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            r.poisson_ratio,
            r.config,
            r.formulation,
            r.elements,
            r.tip_z_m,
            r.reference_tip_z_m,
            r.reference_mesh,
            r.missing_pct,
            r.ms_per_frame.map_or(String::new(), |v| v.to_string()),
            r.newton_ms_per_frame
        ));
    }
    s
}
