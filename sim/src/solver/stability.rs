//! The stability guard: substeps short enough for the stiffest element (`docs/STABILITY.md`).
//!
//! XPBD with small steps (Macklin et al. 2019) is stable when each substep `h` resolves the
//! mesh's fastest mode, `h ω_max ≲ 1`; far beyond it (a 10⁹ Pa material at one substep per
//! frame, a 0.1 s step, 1 mm elements next to 1 m ones, ν → 0.5 with the energy formulation)
//! one Gauss–Seidel sweep per substep leaves the stiff modes only partly projected and the
//! position-based velocity update `v = (x − x_prev)/h` turns the remainder into growing energy
//! (measured in `docs/STABILITY.md`, case 3: `H` reaches 10⁴–10¹¹ × the work of gravity).
//! The element analysis behind it: with one iteration the energy constraint `C = √(2U_e)`
//! moves an element by `Δx = −s W ∇U_e`, `s = h²/(1 + h² ρ_e)`, which multiplies a mode of
//! frequency ω by `1 − s ω²` — an explicit step for the stiff modes while the soft ones hold the
//! energy.
//!
//! **The guard** is a Courant-type condition, like the time-step limit of explicit dynamics:
//! each element's largest rest frequency `ω_e² = λ_max(W^½ K_e W^½)` (`K_e` the element's
//! Hessian at rest — the same linear-elasticity stiffness for every model —, `W` the inverse
//! lumped masses of its nodes, all free: pinning a node only lowers it) is found by power
//! iteration. When the requested substep has `h ω_max` above [`GUARD_TRIGGER_H_OMEGA`] (3; 1.5
//! for the energy formulation at ν ≥ 0.45, [`guard_trigger_h_omega`]), a
//! frame is cut into `n = ⌈ω_max / (fps · κ)⌉` substeps with [`GUARD_H_OMEGA`] `= κ = 1`. The
//! two values are measured: the paper's scenes run at `h ω_max` up to 2.8 with a few % of
//! energy overshoot and are left as they are (their `h ω_max` are listed in
//! `docs/STABILITY.md`); above 3 cantilevers blow up, and at 1 they stay within the 1 % energy
//! bound of the soft cases. A scene above the trigger runs with more substeps, and the solver reports it
//! ([`crate::solver::Simulation::stability`]). It can be switched off
//! ([`crate::solver::SolverSettings::stability_guard`]) to see the instability itself.
//!
//! `ω_e²` scales exactly with `E/ρ` (the rest stiffness is linear in E at fixed ν, the lumped
//! masses linear in ρ), so a change of E or ρ rescales the cached value instead of recomputing
//! it; ν, the model, the quadrature or a node's mass recompute it (in parallel over elements).

use super::settings::SolverSettings;
use crate::Vec3;
use crate::fem::energy::{element_grads, element_hessian, gather};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;
use crate::xpbd::constraint::Formulation;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// The guard steps in when the requested substep has `h ω_max` above this: every scene and
/// benchmark of the paper is below it at its settings (the largest, the 81,920-tetrahedron beam,
/// at 2.78; `docs/STABILITY.md`), and the split formulation was measured to blow up at 3.
pub const GUARD_TRIGGER_H_OMEGA: f64 = 3.0;

/// The trigger for the energy formulation with a nearly incompressible material (ν at or above
/// [`NEAR_INCOMPRESSIBLE_POISSON_RATIO`], `λ ≥ 9 μ`). Its one constraint per element,
/// `C = √(2U_e)`, steps along `∇U_e` by an amount set by the energy-weighted stiffness
/// (`s = h²/(1 + h² ρ_e)` above): under nearly isochoric deformation that is the deviatoric
/// stiffness `∝ μ`, while the step's volumetric part meets `λ ≫ μ`, so the volumetric mode
/// overshoots at a smaller `h ω_max` than for ν ≤ 0.4. Measured (robustness case 2, cantilever
/// under gravity, 50 substeps): at ν ≥ 0.45 the energy formulation gains 10–17 % of the work of
/// gravity from `h ω_max` = 1.57 on (P3 at 0.45, P2 at 0.49, P1, Q1, pyramid at 0.499), and stays
/// within 5.3 % below 1.45 (Q2 at 0.49: 1.43); the split formulation, which gives the
/// volumetric term its own compliance, stays within 2.5 % up to 2.09. Every scene and benchmark
/// of the paper has ν ≤ 0.4 and keeps the trigger of 3.
pub const GUARD_TRIGGER_NEAR_INCOMPRESSIBLE_ENERGY_H_OMEGA: f64 = 1.5;

/// From this Poisson ratio on (`λ/μ = 2ν/(1 − 2ν) ≥ 9`) the energy formulation uses
/// [`GUARD_TRIGGER_NEAR_INCOMPRESSIBLE_ENERGY_H_OMEGA`].
pub const NEAR_INCOMPRESSIBLE_POISSON_RATIO: f64 = 0.45;

/// The `h ω_max` above which the guard steps in, for a formulation and material:
/// [`GUARD_TRIGGER_H_OMEGA`], or [`GUARD_TRIGGER_NEAR_INCOMPRESSIBLE_ENERGY_H_OMEGA`] for the
/// energy formulation at ν ≥ [`NEAR_INCOMPRESSIBLE_POISSON_RATIO`].
pub fn guard_trigger_h_omega(formulation: Formulation, material: &Material) -> f64 {
    if matches!(formulation, Formulation::Energy | Formulation::Mixed)
        && material.poisson_ratio >= NEAR_INCOMPRESSIBLE_POISSON_RATIO
    {
        GUARD_TRIGGER_NEAR_INCOMPRESSIBLE_ENERGY_H_OMEGA
    } else {
        GUARD_TRIGGER_H_OMEGA
    }
}

/// Once triggered, the guard cuts the frame into substeps with `h ω_max` at most this: the
/// measured value at which the stiff cantilevers of the robustness suite load and release within
/// the energy bound of the soft ones (1 % of the work of gravity; at 2 they overshoot it by up to
/// 15×, at 3 some blow up).
pub const GUARD_H_OMEGA: f64 = 1.0;

/// The most substeps per frame the guard asks for; beyond it the scene runs with this many
/// and [`StabilityReport::capped`] says so.
pub const GUARD_MAX_SUBSTEPS: u32 = 20_000;

/// Safety factor on the power iteration's estimate of the largest eigenvalue (from below).
pub const OMEGA2_SAFETY: f64 = 1.05;

/// The largest rest frequency² of an element, `λ_max(W^½ K_e W^½)` in rad²/s²: `rest` its
/// gathered rest positions, `w` its nodes' inverse masses (0: pinned), `grads`/`volumes` its
/// quadrature data. Power iteration (40 steps) times [`OMEGA2_SAFETY`]; 0 when every node is
/// pinned, infinite when the iteration overflows.
pub fn element_omega2(rest: &[Vec3], w: &[f64], grads: &[Vec3], volumes: &[f64], material: &Material) -> f64 {
    let n = rest.len();
    if w.iter().all(|&wi| wi == 0.0) {
        return 0.0;
    }
    let k = element_hessian(rest, rest, grads, volumes, material, false);
    let sqrt_w: Vec<f64> = (0..3 * n).map(|r| w[r / 3].sqrt()).collect();
    let a = DMatrix::from_fn(3 * n, 3 * n, |r, c| sqrt_w[r] * k[(r, c)] * sqrt_w[c]);
    // a start vector with a component along every mode (no symmetry of the element is shared)
    let mut y = DVector::from_fn(3 * n, |r, _| 1.0 + 0.37 * ((r * 7 + 3) % 11) as f64);
    let mut estimate = 0.0;
    for _ in 0..40 {
        let norm = y.norm();
        if norm == 0.0 {
            return 0.0;
        }
        if !norm.is_finite() {
            // too stiff or too light to represent: the guard's cap (and its report) apply
            return f64::INFINITY;
        }
        y /= norm;
        let ay = &a * &y;
        estimate = y.dot(&ay);
        y = ay;
    }
    OMEGA2_SAFETY * estimate.max(0.0)
}

/// The largest element rest frequency² over the mesh, rad²/s², with every node free
/// (`masses_kg` the lumped masses), and the block and element where it is.
pub fn mesh_omega2_max(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    masses_kg: &[f64],
) -> (f64, usize, usize) {
    let mut best = (0.0, 0, 0);
    for (bi, (block, g)) in mesh.blocks.iter().zip(geometry).enumerate() {
        let n = block.nodes_per_element();
        let (omega2, e) = (0..block.len())
            .into_par_iter()
            .map_init(
                || (vec![Vec3::zeros(); n], vec![0.0; n]),
                |(rest, w), e| {
                    let nodes = block.element(e);
                    gather(&mesh.rest_positions, nodes, rest);
                    for (wi, &node) in w.iter_mut().zip(nodes) {
                        *wi = 1.0 / masses_kg[node as usize];
                    }
                    (element_omega2(rest, w, element_grads(g, e), g.volumes(e), material), e)
                },
            )
            .reduce(|| (0.0, 0), |a, b| if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) { b } else { a });
        if omega2 > best.0 {
            best = (omega2, bi, e);
        }
    }
    best
}

/// The largest rest frequency² of a mesh for one material, per `E/ρ` (what the stability guard
/// scales), computed apart from the simulation by [`crate::Simulation::rest_omega2_job`] (a
/// large mesh's takes seconds: an app computes it off its window's thread) and handed back with
/// [`crate::Simulation::seed_rest_omega2`] before the material changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestOmega2 {
    /// The material model and Poisson ratio it holds for.
    pub model: crate::material::MaterialModel,
    pub poisson_ratio: f64,
    /// `(ω²·ρ/E, block, element)` of the stiffest element.
    pub per_e_over_rho: (f64, usize, usize),
}

/// The substeps per frame `settings` take with `material` on a mesh whose stiffest element has
/// rest `ω²·ρ/E` = `omega2_per_e_over_rho` (more than asked where the guard raises them), and
/// whether [`GUARD_MAX_SUBSTEPS`] capped them; an implicit solver's steps per frame.
pub fn substeps_for(settings: &SolverSettings, material: &Material, omega2_per_e_over_rho: f64) -> (u32, bool) {
    let implicit = settings.method.is_implicit();
    let requested = if implicit { settings.steps_per_frame } else { settings.substeps };
    if !settings.stability_guard || implicit {
        return (requested, false);
    }
    let omega_max_rad_s = (omega2_per_e_over_rho * material.youngs_modulus_pa / material.density_kg_m3).sqrt();
    let trigger = guard_trigger_h_omega(settings.formulation, material);
    guarded_substeps(requested, settings.frames_per_second, omega_max_rad_s, trigger, GUARD_H_OMEGA)
}

/// Substeps per frame the guard uses for a mesh whose fastest mode is `omega_max_rad_s`: the
/// requested ones while their `h ω_max ≤ trigger`, else enough for `h ω_max ≤ target`; and
/// whether [`GUARD_MAX_SUBSTEPS`] capped it.
pub fn guarded_substeps(
    requested: u32,
    frames_per_second: f64,
    omega_max_rad_s: f64,
    trigger: f64,
    target: f64,
) -> (u32, bool) {
    if !(omega_max_rad_s / (frames_per_second * requested as f64) > trigger) {
        return (requested, false);
    }
    let needed = (omega_max_rad_s / (frames_per_second * target)).ceil();
    if !(needed > requested as f64) {
        return (requested, false);
    }
    if needed > GUARD_MAX_SUBSTEPS as f64 {
        return (GUARD_MAX_SUBSTEPS.max(requested), true);
    }
    (needed as u32, false)
}

/// What the guard found for the current mesh, material and settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityReport {
    /// The fastest element mode at rest, rad/s (every node free).
    pub omega_max_rad_s: f64,
    /// Where it is: block and element index.
    pub block: usize,
    pub element: usize,
    /// `h ω_max` with the requested substeps.
    pub requested_h_omega: f64,
    /// The `h ω_max` above which the guard steps in ([`guard_trigger_h_omega`]).
    pub trigger_h_omega: f64,
    /// Substeps per frame asked for and taken.
    pub requested_substeps: u32,
    pub substeps: u32,
    /// Whether the guard is on ([`crate::solver::SolverSettings::stability_guard`]).
    pub guard: bool,
    /// The guard wanted more than [`GUARD_MAX_SUBSTEPS`].
    pub capped: bool,
    /// The solver is implicit (VBD, Newton): no substep guard; `substeps` are its steps per frame.
    pub implicit: bool,
}

impl StabilityReport {
    /// Whether the guard raised the substeps.
    pub fn raised(&self) -> bool {
        self.substeps > self.requested_substeps
    }

    /// One line for a status bar or a log: the substeps taken and why.
    pub fn summary(&self) -> String {
        let cap = if self.capped {
            format!(" (capped at {GUARD_MAX_SUBSTEPS}; the scene may still be unstable)")
        } else {
            String::new()
        };
        if self.implicit {
            return format!(
                "h·ω_max = {:.3} with {} implicit steps per frame (implicit solver: no substep guard)",
                self.requested_h_omega, self.substeps
            );
        }
        if self.raised() {
            format!(
                "stability guard: {} substeps per frame instead of {} (h·ω_max would be {:.3} > {}, now ≤ {GUARD_H_OMEGA}; ω_max = {:.4e} rad/s in element {} of block {}){cap}",
                self.substeps,
                self.requested_substeps,
                self.requested_h_omega,
                self.trigger_h_omega,
                self.omega_max_rad_s,
                self.element,
                self.block
            )
        } else {
            format!(
                "h·ω_max = {:.3} with {} substeps per frame{}",
                self.requested_h_omega,
                self.substeps,
                if self.guard { "" } else { " (stability guard off)" }
            )
        }
    }
}

#[cfg(test)]
mod tests;
