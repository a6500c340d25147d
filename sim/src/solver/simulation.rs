//! The stateful simulation of one mesh ([`Simulation`]): its state, the step skeleton every
//! solver shares ([`Simulation::substep`], described in the module doc of [`super`]), the NaN
//! guard's check after a substep and its roll-back to the last finite state, and the stability
//! guard's substep count. The solver moving the free nodes is a [`StepSolver`] made by
//! [`super::registry::make`].

use super::error::{SimError, SolverCounters};
use super::integrator::{History, Integrator, Prediction};
use super::method::Method;
use super::node_loops;
use super::registry;
use super::residual::{StaticResidual, static_residual};
use super::settings::SolverSettings;
use super::stability::{RestOmega2, StabilityReport, guard_trigger_h_omega, mesh_omega2_max, substeps_for};
use super::step::{Hooks, StepInput, StepSolver};
use super::xpbd::Xpbd;

/// The guards of a step: the step watch and the NaN guard's check and roll-back.
mod guard;
mod said;
use crate::Vec3;
use crate::effect::{Effect, EffectState};
use crate::fem::energy::total_energy;
use crate::fem::geometry::{BlockGeometry, precompute};
use crate::fem::mass::lumped_masses_kg;
use crate::material::Material;
use crate::mesh::Mesh;

/// A running simulation of one mesh.
pub struct Simulation {
    mesh: Mesh,
    geometry: Vec<BlockGeometry>,
    material: Material,
    settings: SolverSettings,
    pub positions: Vec<Vec3>,
    pub velocities: Vec<Vec3>,
    prev_positions: Vec<Vec3>,
    masses_kg: Vec<f64>,
    inv_mass: Vec<f64>,
    effects: Vec<Box<dyn Effect>>,
    /// The solver moving the free nodes within a step ([`Method`]).
    solver: Box<dyn StepSolver>,
    /// Bumped whenever the held nodes, the masses or the material change (not when an effect
    /// that holds nothing comes or goes).
    model_version: u64,
    time_secs: f64,
    frames: u64,
    /// Substeps taken in the frame being advanced.
    substeps_in_frame: u32,
    /// Set when the NaN guard stopped the simulation; cleared by reset or warm start.
    failure: Option<SimError>,
    counters: SolverCounters,
    /// The stability guard's `ω_max² ρ / E` (it scales exactly with E/ρ) and where it is;
    /// None until needed after a change of ν, model, quadrature or a node's mass.
    omega2_per_e_over_rho: Option<(f64, usize, usize)>,
    /// A node's mass was set by hand since the masses were last computed from the density.
    masses_overridden: bool,
    /// The rest ω² of the next material, computed apart ([`Simulation::seed_rest_omega2`]).
    omega2_seed: Option<RestOmega2>,
    /// Substeps per frame being taken (the requested ones or the guard's).
    substeps_per_frame: u32,
    /// The implicit solvers' integrator history ([`super::integrator`]).
    history: History,
    /// The rest shape's bounding-box diagonal: the step watch's bound, m.
    body_size_m: f64,
    /// The positions and velocities a watched step started from (`guard.rs`), kept between steps
    /// so that a step allocates nothing (`scenes/tests/no_alloc.rs`).
    watch_start: (Vec<Vec3>, Vec<Vec3>),
}

impl Simulation {
    /// Validates the mesh and settings, precomputes geometry and masses, pins the nodes the
    /// effects position themselves, and starts at rest.
    pub fn new(
        mesh: Mesh,
        material: Material,
        settings: SolverSettings,
        effects: Vec<Box<dyn Effect>>,
    ) -> Result<Self, SimError> {
        mesh.validate()?;
        settings.validate()?;
        let material = settings.formulated(&material, &mesh)?;
        let geometry = precompute(&mesh, settings.quadrature_degree)?;
        let masses_kg = lumped_masses_kg(&mesh, material.density_kg_m3)?;
        let inv_mass: Vec<f64> = masses_kg.iter().map(|m| 1.0 / m).collect();
        let positions = mesh.rest_positions.clone();
        let n = positions.len();
        let solver = registry::make(&mesh, &geometry, &settings);
        let mut sim = Self {
            mesh,
            geometry,
            material,
            settings,
            prev_positions: positions.clone(),
            positions,
            velocities: vec![Vec3::zeros(); n],
            masses_kg,
            inv_mass,
            effects: Vec::with_capacity(effects.len()),
            solver,
            model_version: 0,
            time_secs: 0.0,
            frames: 0,
            substeps_in_frame: 0,
            failure: None,
            counters: SolverCounters::default(),
            omega2_per_e_over_rho: None,
            masses_overridden: false,
            omega2_seed: None,
            substeps_per_frame: settings.substeps,
            history: History::default(),
            body_size_m: 0.0,
            watch_start: (Vec::new(), Vec::new()),
        };
        sim.body_size_m = super::newton_core::body_size_m(&sim.mesh.rest_positions);
        for e in effects {
            sim.add_effect(e)?;
        }
        sim.update_guard();
        Ok(sim)
    }

    /// The solver moving the free nodes.
    pub fn method(&self) -> Method {
        self.settings.method
    }

    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    pub fn geometry(&self) -> &[BlockGeometry] {
        &self.geometry
    }
    pub fn material(&self) -> &Material {
        &self.material
    }
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }
    pub fn masses_kg(&self) -> &[f64] {
        &self.masses_kg
    }
    pub fn inv_mass(&self) -> &[f64] {
        &self.inv_mass
    }
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }
    pub fn frames(&self) -> u64 {
        self.frames
    }
    pub fn counters(&self) -> SolverCounters {
        self.counters
    }
    pub fn effects(&self) -> &[Box<dyn Effect>] {
        &self.effects
    }
    /// Whether the colour sweep ([`Sweep::Colour`]) projects a register of same-colour elements
    /// at a time, one per lane (on by default where the CPU has AVX2 and FMA; every element type
    /// and material; equal to the one-at-a-time colour sweep up to round-off). Off: one at a
    /// time, for comparison.
    pub fn set_simd_batches(&mut self, on: bool) {
        if let Some(x) = self.solver.as_any_mut().downcast_mut::<Xpbd>() {
            x.simd_batches = on;
        }
    }

    /// The colour sweep's register width for every block: 4 elements per batch (AVX2) or 8
    /// (AVX-512). By default each block's own, from its colours and the CPU
    /// ([`crate::xpbd::kernels::auto_lanes`]); the narrower width stays, for CPUs without
    /// AVX-512 and for comparison side by side. Returns false, changing nothing, when this CPU
    /// cannot run `lanes` (or the solver is not XPBD).
    pub fn set_simd_lanes(&mut self, lanes: usize) -> bool {
        if !crate::xpbd::kernels::lanes_available(lanes) {
            return false;
        }
        let Some(x) = self.solver.as_any_mut().downcast_mut::<Xpbd>() else {
            return false;
        };
        if x.lanes != Some(lanes) {
            x.lanes = Some(lanes);
            x.pack(&self.mesh, &self.geometry);
        }
        true
    }

    /// The colour sweep's register width per block (see [`Simulation::set_simd_lanes`]); empty
    /// for a solver other than XPBD.
    pub fn simd_lanes(&self) -> Vec<usize> {
        self.solver
            .as_any()
            .downcast_ref::<Xpbd>()
            .map_or(Vec::new(), |x| x.packed.colour.iter().map(|p| p.lanes).collect())
    }

    /// The colour sweep cuts a block into [`crate::xpbd::kernels::slab_count`]`(size, per_slab)`
    /// slabs (`size` in [`crate::xpbd::kernels::p1_equivalents`]) swept side by side in two
    /// phases ([`crate::xpbd::kernels::Partition`]: two synchronisations per sweep instead of one
    /// per colour) when the block holds at least [`crate::xpbd::kernels::MIN_SLABS`] slabs of
    /// `per_slab`. The count depends on the block alone, never on the thread count, so neither
    /// does the result. Default
    /// [`crate::xpbd::kernels::PARTITION_MIN_ELEMENTS_PER_SLAB`]; `usize::MAX`: never.
    pub fn set_partition_threshold(&mut self, per_slab: usize) {
        if let Some(x) = self.solver.as_any_mut().downcast_mut::<Xpbd>() {
            x.partition_min_per_slab = per_slab;
        }
    }

    /// Number of element colours per block (elements of one colour share no node); empty for
    /// the implicit solvers.
    pub fn num_colours(&self) -> Vec<usize> {
        self.solver.as_any().downcast_ref::<Xpbd>().map(|x| x.num_colours()).unwrap_or_default()
    }

    /// Number of XPBD constraints per solver iteration (0 for the implicit solvers).
    pub fn num_constraints(&self) -> usize {
        self.solver.as_any().downcast_ref::<Xpbd>().map_or(0, |x| x.num_constraints())
    }

    /// The XPBD solver's state, when it is the one running (tests of its schedule).
    /// The step solver, to tell it what the step watch would (tests).
    #[cfg(test)]
    pub(crate) fn step_solver_mut(&mut self) -> &mut dyn super::step::StepSolver {
        self.solver.as_mut()
    }

    #[cfg(test)]
    pub(crate) fn xpbd_solver(&self) -> Option<&Xpbd> {
        self.solver.as_any().downcast_ref::<Xpbd>()
    }

    /// The acceleration every free node feels from the effects (gravity), m/s².
    pub fn body_acceleration_m_s2(&self) -> Vec3 {
        self.effects.iter().map(|e| e.body_acceleration_m_s2()).sum()
    }

    /// How far the current positions are from static equilibrium: the unbalanced force on the
    /// free nodes (elastic force plus body force) relative to the load ([`StaticResidual`]).
    /// Forces of contact and of attachments are not counted.
    pub fn static_residual(&self) -> StaticResidual {
        let grad = self.elastic_gradient(&self.positions);
        let floor_n = super::residual::load_floor_n(self.material.lame().mu_pa, self.body_size_m);
        static_residual(&grad, &self.masses_kg, self.body_acceleration_m_s2(), floor_n, |i| self.inv_mass[i] > 0.0)
    }

    /// `∇U(x)`, the elastic energy's gradient at `x`.
    fn elastic_gradient(&self, x: &[Vec3]) -> Vec<Vec3> {
        let mut grad = vec![Vec3::zeros(); x.len()];
        crate::fem::energy::total_energy_and_gradient(&self.mesh, &self.geometry, &self.material, x, &mut grad);
        grad
    }

    /// Adds an effect to the running simulation (pinning the nodes it positions); refused when
    /// the solver cannot honour it.
    pub fn add_effect(&mut self, effect: Box<dyn Effect>) -> Result<(), SimError> {
        check_effects(self.settings.method, [effect.as_ref()])?;
        for node in effect.pinned_nodes(&self.mesh) {
            let slot = self.inv_mass.get_mut(node as usize).ok_or(SimError::EffectNode {
                effect: effect.name(),
                node,
                num_nodes: self.mesh.num_nodes(),
            })?;
            // only a change of what is held invalidates the implicit solvers' stiffness pattern
            // (a dragged node's attachment, replaced as the mouse moves, holds nothing)
            if *slot != 0.0 {
                *slot = 0.0;
                self.model_version += 1;
            }
        }
        self.effects.push(effect);
        Ok(())
    }

    /// Removes the effects named `name` (for example the attachment that exists only while a
    /// node is dragged); nodes they pinned get their mass back. Returns how many were removed.
    pub fn remove_effects_named(&mut self, name: &str) -> usize {
        let before = self.effects.len();
        let (removed, kept): (Vec<_>, Vec<_>) =
            std::mem::take(&mut self.effects).into_iter().partition(|e| e.name() == name);
        self.effects = kept;
        let still_pinned: std::collections::HashSet<u32> =
            self.effects.iter().flat_map(|e| e.pinned_nodes(&self.mesh)).collect();
        for e in &removed {
            for node in e.pinned_nodes(&self.mesh) {
                if !still_pinned.contains(&node) && self.inv_mass[node as usize] == 0.0 {
                    self.inv_mass[node as usize] = 1.0 / self.masses_kg[node as usize];
                    self.model_version += 1;
                }
            }
        }
        before - self.effects.len()
    }

    /// The error that stopped the simulation, if the NaN guard did (until reset).
    pub fn failure(&self) -> Option<&SimError> {
        self.failure.as_ref()
    }

    /// Sets one node's lumped mass (for example a heavy bead on a soft body). A pinned node
    /// stays pinned. A density change ([`Simulation::set_material`]) recomputes every mass.
    pub fn set_mass_kg(&mut self, node: usize, mass_kg: f64) -> Result<(), SimError> {
        let n = self.masses_kg.len();
        if node >= n {
            return Err(SimError::Mass { node, reason: format!("the mesh has {n} nodes") });
        }
        if !(mass_kg.is_finite() && mass_kg > 0.0) {
            return Err(SimError::Mass {
                node,
                reason: format!("a mass must be a finite positive number of kilograms, got {mass_kg}"),
            });
        }
        self.masses_kg[node] = mass_kg;
        self.model_version += 1;
        if self.inv_mass[node] > 0.0 {
            self.inv_mass[node] = 1.0 / mass_kg;
        }
        self.masses_overridden = true;
        self.omega2_per_e_over_rho = None;
        self.update_guard();
        Ok(())
    }

    /// Changes the material, keeping positions and velocities (masses follow the density).
    pub fn set_material(&mut self, material: Material) -> Result<(), SimError> {
        let material = self.settings.formulated(&material, &self.mesh)?;
        self.model_version += 1;
        if material.density_kg_m3 != self.material.density_kg_m3 {
            let masses = lumped_masses_kg(&self.mesh, material.density_kg_m3)?;
            for ((w, m_old), m) in self.inv_mass.iter_mut().zip(&mut self.masses_kg).zip(masses) {
                if *w > 0.0 {
                    *w = 1.0 / m;
                }
                *m_old = m;
            }
            if self.masses_overridden {
                self.omega2_per_e_over_rho = None;
                self.masses_overridden = false;
            }
        }
        if (material.model, material.poisson_ratio) != (self.material.model, self.material.poisson_ratio) {
            // computed apart for this material ([`Simulation::rest_omega2_job`]), or again here
            let seed = self
                .omega2_seed
                .take()
                .filter(|s| (s.model, s.poisson_ratio) == (material.model, material.poisson_ratio));
            self.omega2_per_e_over_rho = seed.map(|s| s.per_e_over_rho);
        }
        self.omega2_seed = None;
        self.material = material;
        self.update_guard();
        Ok(())
    }

    /// A job computing on another thread the rest ω² the guard needs after [`Simulation::set_material`]
    /// to `material` (seconds on a large mesh), with these masses or a new density's lumped ones.
    pub fn rest_omega2_job(
        &self,
        material: &Material,
    ) -> impl FnOnce() -> Result<RestOmega2, SimError> + Send + 'static {
        let (mesh, geometry, material) = (self.mesh.clone(), self.geometry.clone(), *material);
        let masses = (material.density_kg_m3 == self.material.density_kg_m3).then(|| self.masses_kg.clone());
        move || {
            let masses = masses.map_or_else(|| lumped_masses_kg(&mesh, material.density_kg_m3), Ok)?;
            let (omega2, block, element) = mesh_omega2_max(&mesh, &geometry, &material, &masses);
            let per_e_over_rho = (omega2 * material.density_kg_m3 / material.youngs_modulus_pa, block, element);
            Ok(RestOmega2 { model: material.model, poisson_ratio: material.poisson_ratio, per_e_over_rho })
        }
    }

    /// Hands in a [`Simulation::rest_omega2_job`]'s result for the next [`Simulation::set_material`].
    pub fn seed_rest_omega2(&mut self, omega2: RestOmega2) {
        self.omega2_seed = Some(omega2);
    }

    /// Changes the solver, time stepping and formulation, keeping the state. A new quadrature
    /// degree recomputes the element geometry. A solver that cannot honour one of the effects
    /// is refused (nothing changes).
    pub fn set_settings(&mut self, settings: SolverSettings) -> Result<(), SimError> {
        settings.validate()?;
        let material = settings.formulated(&self.material, &self.mesh)?;
        check_effects(settings.method, self.effects.iter().map(|e| e.as_ref()))?;
        let geometry_changed = settings.quadrature_degree != self.settings.quadrature_degree;
        if material.volume_measure != self.material.volume_measure {
            self.material = material; // another energy: another fastest mode
            self.model_version += 1;
            self.omega2_per_e_over_rho = None;
        }
        if geometry_changed {
            self.geometry = precompute(&self.mesh, settings.quadrature_degree)?;
            self.omega2_per_e_over_rho = None;
        }
        if settings.method != self.settings.method {
            self.solver = registry::make(&self.mesh, &self.geometry, &settings);
            self.history.clear();
        } else {
            self.solver.rebuild(&self.mesh, &self.geometry, &settings, geometry_changed);
        }
        self.settings = settings;
        self.update_guard();
        Ok(())
    }

    /// Continues from another run's state: positions copied, velocities zero, clock at
    /// `time_secs` (so prescribed motions are where they were).
    pub fn warm_start(&mut self, positions: &[Vec3], time_secs: f64) {
        self.positions.copy_from_slice(positions);
        self.prev_positions.copy_from_slice(positions);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.time_secs = time_secs;
        self.substeps_in_frame = 0;
        self.failure = None;
        self.solver.reset_history(true, self.positions.len());
        self.history.clear();
    }

    /// Back to the rest shape at t = 0.
    pub fn reset(&mut self) {
        self.positions.clone_from(&self.mesh.rest_positions);
        self.prev_positions.clone_from(&self.mesh.rest_positions);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.time_secs = 0.0;
        self.frames = 0;
        self.substeps_in_frame = 0;
        self.failure = None;
        self.solver.reset_history(false, self.positions.len());
        self.history.clear();
    }

    /// The stability guard's findings: the fastest element mode, `h ω_max` with the requested
    /// substeps, and the substeps per frame taken ([`crate::solver::stability`]).
    pub fn stability(&mut self) -> StabilityReport {
        let (omega2_normalised, block, element) = self.omega2_normalised();
        let omega_max_rad_s =
            (omega2_normalised * self.material.youngs_modulus_pa / self.material.density_kg_m3).sqrt();
        let s = &self.settings;
        let trigger_h_omega = guard_trigger_h_omega(s.formulation, &self.material);
        let implicit = s.method.is_implicit();
        let requested = if implicit { s.steps_per_frame } else { s.substeps };
        let guard = s.stability_guard && !implicit;
        let (substeps, capped) = substeps_for(s, &self.material, omega2_normalised);
        StabilityReport {
            omega_max_rad_s,
            block,
            element,
            requested_h_omega: omega_max_rad_s * (1.0 / (s.frames_per_second * requested as f64)),
            trigger_h_omega,
            requested_substeps: requested,
            substeps,
            guard,
            capped,
            implicit,
        }
    }

    /// The stiffest element's rest `ω²·ρ/E` the guard last used, if computed.
    pub fn rest_omega2_per_e_over_rho(&self) -> Option<f64> {
        self.omega2_per_e_over_rho.map(|v| v.0)
    }

    /// Substeps per frame being taken: the requested ones, or more (the stability guard).
    pub fn substeps_per_frame(&self) -> u32 {
        self.substeps_per_frame
    }

    /// The substep being taken, `1/(fps · substeps_per_frame)`, seconds.
    pub fn substep_dt_secs(&self) -> f64 {
        1.0 / (self.settings.frames_per_second * self.substeps_per_frame as f64)
    }

    fn omega2_normalised(&mut self) -> (f64, usize, usize) {
        if let Some(v) = self.omega2_per_e_over_rho {
            return v;
        }
        let (omega2, block, element) = mesh_omega2_max(&self.mesh, &self.geometry, &self.material, &self.masses_kg);
        let v = (omega2 * self.material.density_kg_m3 / self.material.youngs_modulus_pa, block, element);
        self.omega2_per_e_over_rho = Some(v);
        v
    }

    /// Recomputes the substeps per frame after a change of settings, material or masses.
    fn update_guard(&mut self) {
        self.substeps_per_frame = if self.settings.method.is_implicit() {
            self.settings.steps_per_frame
        } else if self.settings.stability_guard {
            self.stability().substeps
        } else {
            self.settings.substeps
        };
    }

    /// Advances one frame (`substeps` substeps, or more: the stability guard).
    pub fn step_frame(&mut self) -> Result<(), SimError> {
        if self.settings.method.is_implicit() {
            for _ in 0..self.substeps_per_frame {
                self.substep()?;
            }
        } else {
            // XPBD's frame watch (`guard.rs`): its substeps, then the displacement check
            if let Some(e) = &self.failure {
                return Err(e.clone());
            }
            if self.frame_shares_work() {
                crate::math::par::with_pool_awake(|| self.watched_frame())?;
            } else {
                self.watched_frame()?;
            }
        }
        self.frames += 1;
        self.substeps_in_frame = 0;
        Ok(())
    }

    /// Whether an XPBD frame shares its work between the threads of rayon's current pool: the
    /// colour sweep on several threads, over nodes enough for the node loops to be cut or a block
    /// large enough to be swept by slabs. Such a frame keeps the pool awake while it runs
    /// ([`crate::math::par::with_pool_awake`]).
    pub(crate) fn frame_shares_work(&self) -> bool {
        let Some(xpbd) = self.solver.as_any().downcast_ref::<Xpbd>() else { return false };
        if rayon::current_num_threads() < 2 || !self.settings.sweep.is_colour() {
            return false;
        }
        let slabbed = self
            .mesh
            .blocks
            .iter()
            .zip(&self.geometry)
            .any(|(b, g)| super::xpbd::block_slab_count(b, g, xpbd.partition_min_per_slab) >= 2);
        slabbed || node_loops::chunks(self.positions.len(), self.settings.sweep) > 1
    }

    /// Advances one substep of `h = 1/(fps · substeps_per_frame)`.
    pub fn substep(&mut self) -> Result<(), SimError> {
        if let Some(e) = &self.failure {
            return Err(e.clone());
        }
        let h = self.substep_dt_secs();
        // XPBD keeps its own guards (stability, NaN): watching each of its substeps cost 10–25 %
        // of a P2 8×2×2 frame (docs/STABILITY.md)
        if self.settings.method.is_implicit() { self.watched_step(h, 0) } else { self.advance(h) }
    }

    /// One step of `h` (a substep of XPBD, a step of the implicit solvers).
    fn advance(&mut self, h: f64) -> Result<(), SimError> {
        // the implicit solvers' integrator (XPBD's substeps are its own)
        let integrator = self.integrator();
        let scheme = integrator.scheme();
        self.solver.begin_step(&self.velocities);
        if scheme.keeps_history() {
            self.history.begin(integrator, h, &self.velocities);
        }
        self.time_secs += h;
        self.counters.substeps += 1;
        self.substeps_in_frame += 1;
        macro_rules! hook {
            ($name:ident) => {
                for e in self.effects.iter_mut() {
                    self.counters.effect_hook_calls += 1;
                    e.$name(&mut EffectState {
                        time_secs: self.time_secs,
                        dt_secs: h,
                        rest_positions: &self.mesh.rest_positions,
                        positions: &mut self.positions,
                        prev_positions: &self.prev_positions,
                        velocities: &mut self.velocities,
                        inv_mass: &self.inv_mass,
                    });
                }
            };
        }
        hook!(before_prediction);
        // the node loops of the substep on every thread for large meshes (the colour sweep's
        // threads would otherwise wait on them); each node on its own, so the same bits
        let chunks = node_loops::chunks(self.positions.len(), self.settings.sweep);
        node_loops::predict(&mut self.prev_positions, &mut self.positions, &self.velocities, h, chunks);
        let inertia_h = if !scheme.keeps_history() {
            h
        } else {
            let start_gradient = self.history.needs_start_acceleration(integrator, h).then(|| {
                let mut grad = self.elastic_gradient(&self.prev_positions);
                for sp in self.effects.iter().filter_map(|e| e.spring()) {
                    let i = sp.node as usize;
                    grad[i] += (self.prev_positions[i] - sp.target_m) * sp.stiffness_n_per_m;
                }
                grad
            });
            let step = Prediction {
                h,
                x_n: &self.prev_positions,
                velocities: &self.velocities,
                positions: &mut self.positions,
                inv_mass: &self.inv_mass,
                start_gradient: start_gradient.as_deref(),
            };
            self.history.predict(integrator, step)
        };
        hook!(after_prediction);
        let body_acceleration = self.body_acceleration_m_s2();
        let mut hook_calls = 0;
        let num_nodes = self.positions.len();
        let (guess, projected) = if scheme.keeps_history() {
            let (guess, projected) = self.history.step_views(integrator, num_nodes);
            (guess, Some(projected))
        } else {
            (None, None)
        };
        let input = StepInput {
            mesh: &self.mesh,
            geometry: &self.geometry,
            material: &self.material,
            masses_kg: &self.masses_kg,
            inv_mass: &self.inv_mass,
            prev_positions: &self.prev_positions,
            body_acceleration,
            h,
            inertia_h,
            guess,
            settings: &self.settings,
            model_version: self.model_version,
        };
        let mut hooks = Hooks {
            effects: &mut self.effects,
            velocities: &mut self.velocities,
            prev_positions: &self.prev_positions,
            rest: &self.mesh.rest_positions,
            inv_mass: &self.inv_mass,
            time_secs: self.time_secs,
            h,
            calls: &mut hook_calls,
            projected,
        };
        let solved = self.solver.solve_step(&input, &mut self.positions, &mut hooks, &mut self.counters);
        self.counters.effect_hook_calls += hook_calls;
        if let Err(bad) = solved {
            return Err(self.fail(bad));
        }
        let inv_h = 1.0 / h;
        if scheme.keeps_history() {
            self.history.update(
                integrator,
                h,
                &self.prev_positions,
                &self.positions,
                &mut self.velocities,
                &self.inv_mass,
            );
        } else {
            node_loops::update_velocities(&mut self.velocities, &self.positions, &self.prev_positions, inv_h, chunks);
        }
        hook!(after_velocity_update);
        let all_finite = node_loops::all_finite(&self.positions, &self.velocities, chunks);
        if all_finite {
            return Ok(());
        }
        match self.first_non_finite() {
            Some(bad) => Err(self.fail(bad)),
            None => Ok(()),
        }
    }

    /// The time integrator the steps take: the settings' for the implicit solvers, implicit
    /// Euler's update for XPBD (its substeps are its integrator).
    pub fn integrator(&self) -> Integrator {
        if self.settings.method.is_implicit() { self.settings.integrator } else { Integrator::Euler }
    }

    /// Kinetic energy `½ Σ m_i |v_i|²`, joules.
    pub fn kinetic_energy_j(&self) -> f64 {
        0.5 * self.masses_kg.iter().zip(&self.velocities).map(|(m, v)| m * v.norm_squared()).sum::<f64>()
    }

    /// Elastic energy `Σ_e U_e`, joules.
    pub fn elastic_energy_j(&self) -> f64 {
        total_energy(&self.mesh, &self.geometry, &self.material, &self.positions)
    }

    /// Displacements `x − X` of every node.
    pub fn displacements(&self) -> Vec<Vec3> {
        self.positions.iter().zip(&self.mesh.rest_positions).map(|(x, x0)| x - x0).collect()
    }
}

/// Refuses effects `method` cannot honour, naming the first one and the methods that can.
pub(crate) fn check_effects<'e>(
    method: Method,
    effects: impl IntoIterator<Item = &'e dyn Effect>,
) -> Result<(), SimError> {
    for e in effects {
        let role = e.implicit_role();
        if !method.honours(role) {
            let supported_by: Vec<&str> =
                Method::ALL.into_iter().filter(|m| m.honours(role)).map(Method::name).collect();
            return Err(SimError::Unsupported {
                solver: method.name(),
                effect: e.name(),
                supported_by: supported_by.join(", "),
            });
        }
    }
    Ok(())
}
