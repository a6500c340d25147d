//! The paper's solver: extended position-based dynamics (Macklin, Müller & Chentanez 2016) with
//! small steps (Macklin et al. 2019), over the element constraints of Saillant et al.
//! ([`crate::xpbd::constraint`]). Within a substep: every multiplier `λ ← 0`, then `iterations`
//! Gauss–Seidel sweeps (`sweep.rs`), each followed by every effect's own projection.
//!
//! Files: this one (its state and the step), `sweep.rs` (one Gauss–Seidel sweep).
//!
//! Its state: the multipliers, the element colouring, the element data packed for the sweeps and
//! the colour sweep's slabs.

use super::error::SolverCounters;
use super::nan_guard::BadElement;
use super::settings::SolverSettings;
use super::step::{Hooks, StepInput, StepSolver};
use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::mesh::Mesh;
use crate::xpbd::constraint::Formulation;

mod sweep;

pub(crate) struct Xpbd {
    pub(crate) lambdas: Vec<Vec<f64>>,
    /// Per block, the elements grouped by colour (no two elements of a colour share a node).
    pub(crate) colours: Vec<Vec<Vec<u32>>>,
    /// Per block, the element data packed for the sweeps (element order and colour order).
    pub(crate) packed: crate::xpbd::kernels::SolverData,
    /// The colour sweep projects a register of elements at a time ([`crate::xpbd::kernels::p1`],
    /// [`crate::xpbd::kernels::batch`]).
    pub(crate) simd_batches: bool,
    /// Elements per batch, as set ([`super::Simulation::set_simd_lanes`]); None: each block's
    /// own ([`crate::xpbd::kernels::auto_lanes`]).
    pub(crate) lanes: Option<usize>,
    /// Per block, its cut into slabs for the colour sweep and the slab count it was made for
    /// (built on first use; the count depends on the block's size alone; None: the block is too
    /// thin for that many slabs and is swept colour by colour).
    pub(crate) partitions: Vec<(usize, Option<crate::xpbd::kernels::Partition>)>,
    /// Fewest elements per slab ([`crate::xpbd::kernels::slab_count`]).
    pub(crate) partition_min_per_slab: usize,
    /// The node-patch constraints of P1 in the mixed formulation ([`crate::xpbd::patch`]) and
    /// their multipliers, built on the first step that needs them (None: none yet, or the mesh
    /// and material have none).
    pub(crate) patches: Option<(crate::xpbd::patch::Patches, Vec<f64>)>,
}

impl Xpbd {
    pub fn new(mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings) -> Self {
        let colours =
            mesh.blocks.iter().map(|b| crate::xpbd::colouring::colour_elements(b, mesh.num_nodes())).collect();
        let mut xpbd = Self {
            lambdas: Vec::new(),
            colours,
            packed: crate::xpbd::kernels::SolverData::default(),
            simd_batches: true,
            lanes: None,
            partitions: Vec::new(),
            partition_min_per_slab: crate::xpbd::kernels::PARTITION_MIN_ELEMENTS_PER_SLAB,
            patches: None,
        };
        xpbd.pack(mesh, geometry);
        xpbd.lambdas = Self::multipliers(geometry, settings.formulation);
        xpbd
    }

    pub(crate) fn pack(&mut self, mesh: &Mesh, geometry: &[BlockGeometry]) {
        self.packed = crate::xpbd::kernels::SolverData::new(&mesh.blocks, geometry, &self.colours, self.lanes);
        self.partitions = vec![(0, None); mesh.blocks.len()];
    }

    fn multipliers(geometry: &[BlockGeometry], formulation: Formulation) -> Vec<Vec<f64>> {
        geometry
            .iter()
            .map(|g| vec![0.0; g.num_elements() * formulation.multipliers_per_element(g.points_per_element)])
            .collect()
    }

    /// Number of element colours per block.
    pub fn num_colours(&self) -> Vec<usize> {
        self.colours.iter().map(Vec::len).collect()
    }

    /// Number of constraints per iteration.
    pub fn num_constraints(&self) -> usize {
        self.lambdas.iter().map(Vec::len).sum::<usize>() + self.patches.as_ref().map_or(0, |(_, lambdas)| lambdas.len())
    }

    /// Brings the patch constraints in line with the step's mesh and material: built when the
    /// material measures P1 per node patch and they are missing, dropped when it no longer does.
    fn sync_patches(&mut self, input: &StepInput<'_>) {
        let wanted = crate::fem::energy::mixed::patch::has_patches(input.mesh, input.material);
        if wanted != self.patches.is_some() {
            self.patches = crate::xpbd::patch::Patches::new(input.mesh, input.geometry, input.material).map(|p| {
                let lambdas = vec![0.0; 2 * p.len()];
                (p, lambdas)
            });
        }
    }

    /// One sweep over the patch constraints (none without patches).
    fn project_patches(
        &mut self,
        input: &StepInput<'_>,
        positions: &mut [Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let Some((patches, lambdas)) = self.patches.as_mut() else { return Ok(()) };
        let patch_input = crate::xpbd::patch::PatchInput {
            mesh: input.mesh,
            geometry: input.geometry,
            material: input.material,
            inv_mass: input.inv_mass,
            inv_dt2: 1.0 / (input.h * input.h),
        };
        match patches.sweep(&patch_input, positions, lambdas) {
            Ok(projected) => {
                counters.element_projections += projected as u64;
                Ok(())
            }
            Err(bad) => {
                let nodes = input.mesh.blocks[bad.block].element(bad.element);
                Err(BadElement::projected(bad.block, bad.element, bad.node, nodes, |i| positions[i]))
            }
        }
    }
}

/// How many slabs the colour sweep cuts `block` into (1: none, swept colour by colour), at
/// least `min_per_slab` elements each: the block's size alone decides
/// ([`crate::xpbd::kernels::slab_count`]).
pub(crate) fn block_slab_count(
    block: &crate::mesh::ElementBlock,
    geometry: &BlockGeometry,
    min_per_slab: usize,
) -> usize {
    use crate::xpbd::kernels::{p1_equivalents, slab_count};
    slab_count(p1_equivalents(block.len(), block.nodes_per_element(), geometry.points_per_element), min_per_slab)
}

impl StepSolver for Xpbd {
    fn solve_step(
        &mut self,
        input: &StepInput<'_>,
        positions: &mut [Vec3],
        hooks: &mut Hooks<'_>,
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        self.lambdas.iter_mut().for_each(|l| crate::math::par::fill(l, 0.0));
        self.sync_patches(input);
        if let Some((_, lambdas)) = self.patches.as_mut() {
            lambdas.iter_mut().for_each(|l| *l = 0.0);
        }
        for _ in 0..input.settings.iterations {
            self.project_elements(input, positions, counters)?;
            self.project_patches(input, positions, counters)?;
            hooks.after_projection(positions, None);
        }
        Ok(())
    }

    fn rebuild(&mut self, mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings, geometry_changed: bool) {
        if geometry_changed {
            self.pack(mesh, geometry);
        }
        self.lambdas = Self::multipliers(geometry, settings.formulation);
        self.patches = None;
    }

    fn work_summary(&self, _settings: &SolverSettings, _counters: &SolverCounters) -> String {
        format!("xpbd, {} constraints", self.num_constraints())
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}
