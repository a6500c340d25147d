//! One Gauss–Seidel sweep of [`Xpbd`] over every element constraint: in element order,
//! or colour by colour with the elements of a colour projected in parallel ([`crate::solver::Sweep`]). The energy
//! formulation goes through the specialised sweep ([`crate::xpbd::kernels`]); the split
//! formulation (and any node count without a specialised sweep) through the generic kernels of
//! [`crate::xpbd::constraint`], element by element: gather, project, check, scatter.

use super::Xpbd;
use crate::Vec3;
use crate::fem::energy::{element_grads, gather};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::solver::error::SolverCounters;
use crate::solver::nan_guard::{BadElement, non_finite_node};
use crate::solver::step::StepInput;
use crate::xpbd::constraint::{
    Formulation, NodeScratch, project_deviatoric_constraint, project_energy_constraint, project_split_constraints,
};

impl Xpbd {
    /// One Gauss–Seidel sweep over every element constraint: in element order, or colour by
    /// colour with the elements of a colour projected in parallel.
    /// Stops at the first element whose corrections come out non-finite (not scattered) and
    /// returns it.
    pub(super) fn project_elements(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), BadElement> {
        let inv_dt2 = 1.0 / (s.h * s.h);
        if s.settings.sweep.is_colour() {
            return self.project_elements_by_colour(s, positions, counters, inv_dt2);
        }
        for (bi, lambdas) in self.lambdas.iter_mut().enumerate() {
            let block = &s.mesh.blocks[bi];
            let n = block.nodes_per_element();
            if s.settings.formulation == Formulation::Energy {
                use crate::xpbd::kernels::{Multipliers, Positions, energy_sweep};
                let data = self.packed.serial[bi].data();
                // SAFETY: one thread; the mesh was validated, so its node indices fit positions,
                // and lambdas holds one multiplier per element.
                let fast = unsafe {
                    energy_sweep(
                        n,
                        s.material,
                        Positions::new(positions),
                        &s.mesh.rest_positions,
                        s.inv_mass,
                        &data,
                        0..block.len(),
                        Multipliers::new(lambdas),
                        inv_dt2,
                    )
                };
                match fast {
                    Some(Ok(projected)) => {
                        counters.element_projections += projected;
                        continue;
                    }
                    Some(Err(bad)) => {
                        return Err(BadElement::projected(
                            bi,
                            bad.element,
                            bad.node,
                            block.element(bad.element),
                            |i| positions[i],
                        ));
                    }
                    None => {}
                }
            }
            let per_element = lambdas.len() / block.len().max(1);
            let mut x = NodeScratch::new(Vec3::zeros(), n);
            let x = x.as_mut_slice();
            for (e, nodes) in block.elements().enumerate() {
                let lambda = &mut lambdas[e * per_element..(e + 1) * per_element];
                let ctx = ProjectionContext::new(s, bi, inv_dt2);
                let read = &*positions;
                if ctx.project(|i| read[i], &s.geometry[bi], e, nodes, lambda, x) {
                    if let Some(node) = non_finite_node(x, nodes) {
                        return Err(BadElement::projected(bi, e, node, nodes, |i| read[i]));
                    }
                    for (xi, &node) in x.iter().zip(nodes) {
                        positions[node as usize] = *xi;
                    }
                    counters.element_projections += 1;
                }
            }
        }
        Ok(())
    }

    /// The colour sweep: same-colour elements touch disjoint nodes and multipliers, so they
    /// are projected concurrently and the result does not depend on the scheduling or the thread
    /// count. Large blocks of the energy formulation are swept slab by slab
    /// ([`crate::xpbd::kernels::Partition`]), their slab count set by the block's size alone.
    fn project_elements_by_colour(
        &mut self,
        s: &StepInput<'_>,
        positions: &mut [Vec3],
        counters: &mut SolverCounters,
        inv_dt2: f64,
    ) -> Result<(), BadElement> {
        use rayon::prelude::*;
        let positions = crate::math::shared::SharedMut::new(positions);
        for (bi, lambdas) in self.lambdas.iter_mut().enumerate() {
            let block = &s.mesh.blocks[bi];
            let n = block.nodes_per_element();
            let per_element = lambdas.len() / block.len().max(1);
            if s.settings.formulation == Formulation::Energy {
                // SAFETY of the aliasing: the specialised sweep writes positions through its own
                // pointer, and nothing else touches them meanwhile.
                let all = unsafe { positions.slice_mut(0, positions.len()) };
                use crate::xpbd::kernels::BlockSweep;
                let slabs = super::block_slab_count(block, &s.geometry[bi], self.partition_min_per_slab);
                if slabs >= 2 && self.partitions[bi].0 != slabs {
                    // a block too thin for its slab count is cut into fewer rather than not at all
                    let partition = crate::xpbd::kernels::Partition::largest(
                        block,
                        &s.geometry[bi],
                        &self.colours[bi],
                        &s.mesh.rest_positions,
                        slabs,
                        self.packed.colour[bi].lanes,
                    );
                    self.partitions[bi] = (slabs, partition);
                }
                let sweep = match &self.partitions[bi] {
                    (count, Some(partition)) if slabs >= 2 && *count == slabs => BlockSweep::Slabs(partition),
                    _ => BlockSweep::Colours(&self.packed.colour[bi]),
                };
                let result = crate::xpbd::kernels::parallel_energy_block(
                    n,
                    s.material,
                    all,
                    &s.mesh.rest_positions,
                    s.inv_mass,
                    sweep,
                    lambdas,
                    inv_dt2,
                    self.simd_batches,
                );
                match result {
                    Some(Ok(projected)) => {
                        counters.element_projections += projected;
                        continue;
                    }
                    Some(Err(bad)) => {
                        let read = |i: usize| unsafe { positions.read(i) };
                        return Err(BadElement::projected(bi, bad.element, bad.node, block.element(bad.element), read));
                    }
                    None => {}
                }
            }
            let lambdas = crate::math::shared::SharedMut::new(lambdas);
            for colour in &self.colours[bi] {
                let projected: Result<usize, BadElement> = colour
                    .par_iter()
                    .with_min_len(crate::xpbd::kernels::GENERIC_MIN_ELEMENTS_PER_TASK)
                    .map(|&e| {
                        let e = e as usize;
                        let nodes = block.element(e);
                        // SAFETY: no two elements of a colour share a node (colouring.rs), and
                        // each element owns its multipliers: concurrent writes are disjoint.
                        let lambda = unsafe { lambdas.slice_mut(e * per_element, per_element) };
                        let ctx = ProjectionContext::new(s, bi, inv_dt2);
                        let mut x = NodeScratch::new(Vec3::zeros(), n);
                        let x = x.as_mut_slice();
                        // SAFETY: reads only this element's nodes, which no other thread writes.
                        let read = |i: usize| unsafe { positions.read(i) };
                        if !ctx.project(read, &s.geometry[bi], e, nodes, lambda, x) {
                            return Ok(0);
                        }
                        if let Some(node) = non_finite_node(x, nodes) {
                            return Err(BadElement::projected(bi, e, node, nodes, read));
                        }
                        for (xi, &node) in x.iter().zip(nodes) {
                            // SAFETY: as above.
                            unsafe { positions.write(node as usize, *xi) };
                        }
                        Ok(1)
                    })
                    .sum();
                counters.element_projections += projected? as u64;
            }
        }
        Ok(())
    }
}

/// What projecting one element needs to read.
struct ProjectionContext<'a> {
    rest: &'a [Vec3],
    inv_mass: &'a [f64],
    material: &'a Material,
    formulation: Formulation,
    /// The block's pressure is one per node patch (P1 mixed): the element keeps its deviatoric
    /// energy alone ([`crate::xpbd::patch`] holds the rest).
    deviatoric_only: bool,
    inv_dt2: f64,
}

impl<'a> ProjectionContext<'a> {
    fn new(s: &StepInput<'a>, block: usize, inv_dt2: f64) -> Self {
        Self {
            rest: &s.mesh.rest_positions,
            inv_mass: s.inv_mass,
            material: s.material,
            formulation: s.settings.formulation,
            deviatoric_only: crate::fem::energy::mixed::patch::is_patch_block(&s.mesh.blocks[block], s.material),
            inv_dt2,
        }
    }

    /// Gathers element `e`, projects its constraints into `x` (updating its multipliers) and
    /// returns true, or false when all its nodes are pinned.
    #[inline]
    fn project(
        &self,
        read: impl Fn(usize) -> Vec3,
        g: &BlockGeometry,
        e: usize,
        nodes: &[u32],
        lambda: &mut [f64],
        x: &mut [Vec3],
    ) -> bool {
        let n = x.len();
        let (mut w, mut rest) = (NodeScratch::new(0.0, n), NodeScratch::new(Vec3::zeros(), n));
        let (w, rest) = (w.as_mut_slice(), rest.as_mut_slice());
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
            Formulation::Mixed if self.deviatoric_only => {
                project_deviatoric_constraint(
                    x,
                    rest,
                    w,
                    element_grads(g, e),
                    g.volumes(e),
                    self.material,
                    self.inv_dt2,
                    &mut lambda[0],
                );
            }
            // the mixed element's energy: the material measures its hydrostatic term per element
            Formulation::Energy | Formulation::Mixed => {
                project_energy_constraint(
                    x,
                    rest,
                    w,
                    element_grads(g, e),
                    g.volumes(e),
                    self.material,
                    self.inv_dt2,
                    &mut lambda[0],
                );
            }
            Formulation::Split => {
                project_split_constraints(
                    x,
                    rest,
                    w,
                    element_grads(g, e),
                    g.volumes(e),
                    self.material,
                    self.inv_dt2,
                    lambda,
                );
            }
        }
        true
    }
}
