//! The XPBD solver with small steps (Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke &
//! Müller 2019, "Small steps in physics simulation"): a frame of `1/fps` seconds is `n`
//! substeps of `h = 1/(fps · n)`; each substep
//! 1. applies the effects' accelerations, `v ← v + h a`;
//! 2. predicts `x ← x + h v` (keeping `x_prev`), then lets effects place pinned/driven nodes;
//! 3. resets every multiplier `λ ← 0` and runs `k` Gauss–Seidel iterations over the element
//!    constraints ([`crate::constraint`]), each followed by the effects' own projections;
//! 4. updates velocities `v ← (x − x_prev)/h`, then lets effects damp them.
//!
//! Defaults are the paper's: 50 substeps × 1 iteration, 60 frames per second. The solver
//! gathers each element's nodes, calls a pure kernel, and scatters the corrections back.
//! After every substep it checks that all positions are finite; if not, it stops with an error
//! naming an element that holds the first bad node and the substep, instead of going on.

use crate::Vec3;
use crate::constraint::{Formulation, MAX_NODES, project_energy_constraint, project_split_constraints};
use crate::effect::{Effect, EffectState};
use crate::energy::{element_grads, gather, total_energy};
use crate::geometry::{BlockGeometry, GeometryError, precompute};
use crate::mass::lumped_masses_kg;
use crate::material::Material;
use crate::mesh::{Mesh, MeshError};

/// Time stepping and constraint settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    pub substeps: u32,
    pub iterations: u32,
    pub frames_per_second: f64,
    pub formulation: Formulation,
    /// Quadrature degree for the elastic energy; None: each element type's default.
    pub quadrature_degree: Option<usize>,
    /// Project same-colour elements in parallel (rayon's thread pool); otherwise serially in
    /// element order. Both are Gauss–Seidel sweeps, in different orders.
    pub parallel: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self { substeps: 50, iterations: 1, frames_per_second: 60.0, formulation: Formulation::Energy, quadrature_degree: None, parallel: false }
    }
}

impl SolverSettings {
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |what: String| Err(SimError::Settings(what));
        if self.substeps == 0 {
            return bad("substeps must be at least 1, got 0".into());
        }
        if self.iterations == 0 {
            return bad("iterations must be at least 1, got 0".into());
        }
        if !(self.frames_per_second.is_finite() && self.frames_per_second > 0.0) {
            return bad(format!("frames per second must be a finite positive number, got {}", self.frames_per_second));
        }
        Ok(())
    }
    /// The substep length `h`, seconds.
    pub fn substep_dt_secs(&self) -> f64 {
        1.0 / (self.frames_per_second * self.substeps as f64)
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    #[error("invalid solver settings: {0}")]
    Settings(String),
    #[error("effect '{effect}' refers to node {node}, but the mesh has {num_nodes} nodes")]
    EffectNode { effect: &'static str, node: u32, num_nodes: usize },
    #[error(
        "the simulation blew up: node {node} of element {element} ({element_type}) became non-finite at substep {substep} (t = {time_secs:.6} s); reset, or use more substeps, a softer material or stable Neo-Hookean"
    )]
    NonFinite { node: usize, element: usize, element_type: String, substep: u64, time_secs: f64 },
}

/// Counters of the work done, for tests and the status line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolverCounters {
    pub substeps: u64,
    pub element_projections: u64,
    pub effect_hook_calls: u64,
}

/// A running XPBD simulation of one mesh.
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
    lambdas: Vec<Vec<f64>>,
    effects: Vec<Box<dyn Effect>>,
    /// Per block, the elements grouped by colour (no two elements of a colour share a node).
    colours: Vec<Vec<Vec<u32>>>,
    time_secs: f64,
    frames: u64,
    counters: SolverCounters,
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
        let geometry = precompute(&mesh, settings.quadrature_degree)?;
        let masses_kg = lumped_masses_kg(&mesh, material.density_kg_m3)?;
        let inv_mass: Vec<f64> = masses_kg.iter().map(|m| 1.0 / m).collect();
        let positions = mesh.rest_positions.clone();
        let n = positions.len();
        let lambdas = Self::multipliers(&geometry, settings.formulation);
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
            lambdas,
            effects: Vec::with_capacity(effects.len()),
            colours: Vec::new(),
            time_secs: 0.0,
            frames: 0,
            counters: SolverCounters::default(),
        };
        for e in effects {
            sim.add_effect(e)?;
        }
        sim.colours = sim.mesh.blocks.iter().map(|b| crate::colouring::colour_elements(b, sim.mesh.num_nodes())).collect();
        Ok(sim)
    }

    fn multipliers(geometry: &[BlockGeometry], formulation: Formulation) -> Vec<Vec<f64>> {
        geometry
            .iter()
            .map(|g| vec![0.0; g.num_elements() * formulation.multipliers_per_element(g.points_per_element)])
            .collect()
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
    /// Number of element colours per block (elements of one colour share no node).
    pub fn num_colours(&self) -> Vec<usize> {
        self.colours.iter().map(Vec::len).collect()
    }

    /// Number of XPBD constraints per solver iteration.
    pub fn num_constraints(&self) -> usize {
        self.lambdas.iter().map(Vec::len).sum()
    }

    /// Adds an effect to the running simulation (pinning the nodes it positions).
    pub fn add_effect(&mut self, effect: Box<dyn Effect>) -> Result<(), SimError> {
        for node in effect.pinned_nodes(&self.mesh) {
            let slot = self.inv_mass.get_mut(node as usize).ok_or(SimError::EffectNode {
                effect: effect.name(),
                node,
                num_nodes: self.mesh.num_nodes(),
            })?;
            *slot = 0.0;
        }
        self.effects.push(effect);
        Ok(())
    }

    /// Removes the effects named `name` (for example the attachment that exists only while a
    /// node is dragged); nodes they pinned get their mass back. Returns how many were removed.
    pub fn remove_effects_named(&mut self, name: &str) -> usize {
        let before = self.effects.len();
        let (removed, kept): (Vec<_>, Vec<_>) = std::mem::take(&mut self.effects).into_iter().partition(|e| e.name() == name);
        self.effects = kept;
        let still_pinned: std::collections::HashSet<u32> = self.effects.iter().flat_map(|e| e.pinned_nodes(&self.mesh)).collect();
        for e in &removed {
            for node in e.pinned_nodes(&self.mesh) {
                if !still_pinned.contains(&node) {
                    self.inv_mass[node as usize] = 1.0 / self.masses_kg[node as usize];
                }
            }
        }
        before - self.effects.len()
    }

    /// Changes the material, keeping positions and velocities (masses follow the density).
    pub fn set_material(&mut self, material: Material) -> Result<(), SimError> {
        if material.density_kg_m3 != self.material.density_kg_m3 {
            let masses = lumped_masses_kg(&self.mesh, material.density_kg_m3)?;
            for ((w, m_old), m) in self.inv_mass.iter_mut().zip(&mut self.masses_kg).zip(masses) {
                if *w > 0.0 {
                    *w = 1.0 / m;
                }
                *m_old = m;
            }
        }
        self.material = material;
        Ok(())
    }

    /// Changes time stepping (and formulation), keeping the state. A new quadrature degree
    /// recomputes the element geometry.
    pub fn set_settings(&mut self, settings: SolverSettings) -> Result<(), SimError> {
        settings.validate()?;
        if settings.quadrature_degree != self.settings.quadrature_degree {
            self.geometry = precompute(&self.mesh, settings.quadrature_degree)?;
        }
        self.lambdas = Self::multipliers(&self.geometry, settings.formulation);
        self.settings = settings;
        Ok(())
    }

    /// Continues from another run's state: positions copied, velocities zero, clock at
    /// `time_secs` (so prescribed motions are where they were).
    pub fn warm_start(&mut self, positions: &[Vec3], time_secs: f64) {
        self.positions.copy_from_slice(positions);
        self.prev_positions.copy_from_slice(positions);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.time_secs = time_secs;
    }

    /// Back to the rest shape at t = 0.
    pub fn reset(&mut self) {
        self.positions.clone_from(&self.mesh.rest_positions);
        self.prev_positions.clone_from(&self.mesh.rest_positions);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.time_secs = 0.0;
        self.frames = 0;
    }

    /// Advances one frame (`substeps` substeps).
    pub fn step_frame(&mut self) -> Result<(), SimError> {
        for _ in 0..self.settings.substeps {
            self.substep()?;
        }
        self.frames += 1;
        Ok(())
    }

    /// Advances one substep of `h = 1/(fps · substeps)`.
    pub fn substep(&mut self) -> Result<(), SimError> {
        let h = self.settings.substep_dt_secs();
        self.time_secs += h;
        self.counters.substeps += 1;
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
        self.prev_positions.copy_from_slice(&self.positions);
        for (x, v) in self.positions.iter_mut().zip(&self.velocities) {
            *x += v * h;
        }
        hook!(after_prediction);
        self.lambdas.iter_mut().for_each(|l| l.fill(0.0));
        for _ in 0..self.settings.iterations {
            self.project_elements(h);
            hook!(after_projection);
        }
        let inv_h = 1.0 / h;
        for ((v, x), xp) in self.velocities.iter_mut().zip(&self.positions).zip(&self.prev_positions) {
            *v = (x - xp) * inv_h;
        }
        hook!(after_velocity_update);
        self.check_finite()
    }

    /// One Gauss–Seidel sweep over every element constraint: in element order, or colour by
    /// colour with the elements of a colour projected in parallel.
    fn project_elements(&mut self, h: f64) {
        let inv_dt2 = 1.0 / (h * h);
        if self.settings.parallel {
            self.project_elements_parallel(inv_dt2);
            return;
        }
        let mut x = [Vec3::zeros(); MAX_NODES];
        for (bi, lambdas) in self.lambdas.iter_mut().enumerate() {
            let block = &self.mesh.blocks[bi];
            let n = block.nodes_per_element();
            let per_element = lambdas.len() / block.len().max(1);
            for (e, nodes) in block.elements().enumerate() {
                let lambda = &mut lambdas[e * per_element..(e + 1) * per_element];
                let ctx = ProjectionContext { rest: &self.mesh.rest_positions, inv_mass: &self.inv_mass, material: &self.material, formulation: self.settings.formulation, inv_dt2 };
                let positions = &self.positions;
                if ctx.project(|i| positions[i], &self.geometry[bi], e, nodes, lambda, &mut x[..n]) {
                    for (xi, &node) in x.iter().zip(nodes) {
                        self.positions[node as usize] = *xi;
                    }
                    self.counters.element_projections += 1;
                }
            }
        }
    }

    /// The parallel sweep: same-colour elements touch disjoint nodes and multipliers, so they
    /// are projected concurrently and the result does not depend on the scheduling.
    fn project_elements_parallel(&mut self, inv_dt2: f64) {
        use rayon::prelude::*;
        let positions = SharedSlice::new(&mut self.positions);
        for (bi, lambdas) in self.lambdas.iter_mut().enumerate() {
            let block = &self.mesh.blocks[bi];
            let n = block.nodes_per_element();
            let per_element = lambdas.len() / block.len().max(1);
            let lambdas = SharedSlice::new(lambdas);
            for colour in &self.colours[bi] {
                let projected: usize = colour
                    .par_iter()
                    .with_min_len(PARALLEL_MIN_ELEMENTS)
                    .map(|&e| {
                        let e = e as usize;
                        let nodes = block.element(e);
                        // SAFETY: no two elements of a colour share a node (colouring.rs), and
                        // each element owns its multipliers: concurrent writes are disjoint.
                        let lambda = unsafe { lambdas.slice_mut(e * per_element, per_element) };
                        let ctx = ProjectionContext { rest: &self.mesh.rest_positions, inv_mass: &self.inv_mass, material: &self.material, formulation: self.settings.formulation, inv_dt2 };
                        let mut x = [Vec3::zeros(); MAX_NODES];
                        // SAFETY: reads only this element's nodes, which no other thread writes.
                        let read = |i: usize| unsafe { positions.read(i) };
                        if !ctx.project(read, &self.geometry[bi], e, nodes, lambda, &mut x[..n]) {
                            return 0;
                        }
                        for (xi, &node) in x.iter().zip(nodes) {
                            // SAFETY: as above.
                            unsafe { positions.write(node as usize, *xi) };
                        }
                        1
                    })
                    .sum();
                self.counters.element_projections += projected as u64;
            }
        }
    }

    fn check_finite(&self) -> Result<(), SimError> {
        let Some(node) = self.positions.iter().zip(&self.velocities).position(|(x, v)| !(x.iter().chain(v.iter()).all(|c| c.is_finite()))) else {
            return Ok(());
        };
        let (element_type, element) = self
            .mesh
            .blocks
            .iter()
            .find_map(|b| b.elements().position(|el| el.contains(&(node as u32))).map(|e| (b.element_type.to_string(), e)))
            .unwrap_or_else(|| ("none".into(), 0));
        Err(SimError::NonFinite { node, element, element_type, substep: self.counters.substeps, time_secs: self.time_secs })
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

/// Fewest elements a parallel task gets: below this, splitting costs more than it saves.
const PARALLEL_MIN_ELEMENTS: usize = 64;

/// What projecting one element needs to read.
struct ProjectionContext<'a> {
    rest: &'a [Vec3],
    inv_mass: &'a [f64],
    material: &'a Material,
    formulation: Formulation,
    inv_dt2: f64,
}

impl ProjectionContext<'_> {
    /// Gathers element `e`, projects its constraints into `x` (updating its multipliers) and
    /// returns true, or false when all its nodes are pinned.
    #[inline]
    fn project(&self, read: impl Fn(usize) -> Vec3, g: &BlockGeometry, e: usize, nodes: &[u32], lambda: &mut [f64], x: &mut [Vec3]) -> bool {
        let n = x.len();
        let mut w = [0.0; MAX_NODES];
        let mut rest = [Vec3::zeros(); MAX_NODES];
        let (w, rest) = (&mut w[..n], &mut rest[..n]);
        for (wi, &node) in w.iter_mut().zip(nodes) {
            *wi = self.inv_mass[node as usize];
        }
        if w.iter().all(|&wi| wi == 0.0) {
            return false;
        }
        for (xi, &node) in x.iter_mut().zip(nodes) {
            *xi = read(node as usize);
        }
        gather(self.rest, nodes, rest);
        match self.formulation {
            Formulation::Energy => {
                project_energy_constraint(x, rest, w, element_grads(g, e), g.volumes(e), self.material, self.inv_dt2, &mut lambda[0]);
            }
            Formulation::Split => {
                project_split_constraints(x, rest, w, element_grads(g, e), g.volumes(e), self.material, self.inv_dt2, lambda);
            }
        }
        true
    }
}

/// A slice shared across threads for disjoint writes.
struct SharedSlice<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: used only for writes to disjoint indices (guaranteed by the element colouring).
unsafe impl<T: Send> Send for SharedSlice<T> {}
unsafe impl<T: Send> Sync for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    fn new(slice: &mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len() }
    }
    /// # Safety
    /// No other thread may write index `i` at the same time.
    unsafe fn read(&self, i: usize) -> T
    where
        T: Copy,
    {
        assert!(i < self.len);
        unsafe { self.ptr.add(i).read() }
    }
    /// # Safety
    /// The range must not be accessed by any other thread at the same time.
    #[allow(clippy::mut_from_ref)] // disjoint ranges handed to different threads: the point
    unsafe fn slice_mut(&self, start: usize, len: usize) -> &mut [T] {
        assert!(start + len <= self.len);
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(start), len) }
    }
    /// # Safety
    /// No other thread may access index `i` at the same time.
    unsafe fn write(&self, i: usize, value: T) {
        assert!(i < self.len);
        unsafe { self.ptr.add(i).write(value) }
    }
}

#[cfg(test)]
mod tests;
