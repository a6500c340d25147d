//! The NaN guard described in the module doc of [`super`]: the check of every position and
//! velocity after a substep ([`Simulation::first_non_finite`]), the roll-back to the last finite
//! state ([`Simulation::fail`]), and how the failing element and its origin are named
//! ([`BadElement`]).

use super::{SimError, Simulation};
use crate::Vec3;

impl Simulation {
    /// The first node whose position or velocity is not finite, with an element holding it.
    pub(super) fn first_non_finite(&self) -> Option<BadElement> {
        let node = self
            .positions
            .iter()
            .zip(&self.velocities)
            .position(|(x, v)| !(x.iter().chain(v.iter()).all(|c| c.is_finite())))?;
        Some(BadElement::at_node(&self.mesh, node, ORIGIN_STATE))
    }

    /// Builds the NaN guard's error, puts the state back to the last finite positions (the
    /// start of this substep, else the rest shape) at rest, and stops the simulation until reset.
    pub(super) fn fail(&mut self, bad: BadElement) -> SimError {
        let method = self.solver.method();
        let err = SimError::NonFinite {
            solver: method.name(),
            block: bad.block,
            element: bad.element,
            element_type: self
                .mesh
                .blocks
                .get(bad.block)
                .map(|b| b.element_type.to_string())
                .unwrap_or_else(|| "none".into()),
            node: bad.node as usize,
            origin: bad.origin,
            frame: self.frames + 1,
            substep_in_frame: self.substeps_in_frame,
            substeps_per_frame: self.substeps_per_frame,
            substep: self.counters.substeps,
            time_secs: self.time_secs,
        };
        let last = if self.prev_positions.iter().all(|x| x.iter().all(|c| c.is_finite())) {
            &self.prev_positions
        } else {
            &self.mesh.rest_positions
        };
        self.positions.clone_from(last);
        self.velocities.iter_mut().for_each(|v| *v = Vec3::zeros());
        self.failure = Some(err.clone());
        err
    }
}

/// An element the NaN guard names: block, index in the block, one of its non-finite nodes, and
/// what went wrong.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BadElement {
    block: usize,
    element: usize,
    node: u32,
    origin: &'static str,
}

/// The guard's wording when an element's projection turned finite positions into non-finite ones.
const ORIGIN_PROJECTION: &str = "the projection of";
/// … when the element was handed a non-finite position (by an effect or the caller).
pub(super) const ORIGIN_INPUT: &str = "a non-finite position handed to";
/// … when vertex block descent's update of a node came out non-finite.
pub(super) const ORIGIN_VBD: &str = "the vertex block update of a node of";
/// … when Newton's step came out non-finite.
pub(super) const ORIGIN_NEWTON: &str = "the Newton step at a node of";
/// … when the check after the substep finds a non-finite position or velocity.
const ORIGIN_STATE: &str = "a non-finite position or velocity in";

impl BadElement {
    /// Element `e` of block `block` produced non-finite corrections at `node`; `read` gives the
    /// (unchanged) positions it was handed, to tell its own failure from bad input.
    pub(super) fn projected(
        block: usize,
        element: usize,
        node: u32,
        nodes: &[u32],
        read: impl Fn(usize) -> Vec3,
    ) -> Self {
        let input_finite = nodes.iter().all(|&n| read(n as usize).iter().all(|c| c.is_finite()));
        Self { block, element, node, origin: if input_finite { ORIGIN_PROJECTION } else { ORIGIN_INPUT } }
    }
}

impl BadElement {
    /// `node` went non-finite (`origin` says how); names the first element holding it.
    pub(super) fn at_node(mesh: &crate::mesh::Mesh, node: usize, origin: &'static str) -> Self {
        let (block, element) = mesh
            .blocks
            .iter()
            .enumerate()
            .find_map(|(bi, b)| b.elements().position(|el| el.contains(&(node as u32))).map(|e| (bi, e)))
            .unwrap_or((0, 0));
        Self { block, element, node: node as u32, origin }
    }
}

/// What the NaN guard calls a solver's step: XPBD takes substeps, the implicit solvers steps.
pub(super) fn step_word(solver: &str) -> &'static str {
    if solver == super::Method::Xpbd.name() { "substep" } else { "step" }
}

/// What the NaN guard suggests after a blow-up under `solver`.
pub(super) fn remedy(solver: &str) -> &'static str {
    if solver == super::Method::Xpbd.name() {
        "more substeps, a softer material or stable Neo-Hookean"
    } else {
        "more steps per frame, a softer material or stable Neo-Hookean"
    }
}

/// The first non-finite position.
pub(super) fn first_non_finite_position(x: &[Vec3]) -> Option<usize> {
    x.iter().position(|p| !p.iter().all(|c| c.is_finite()))
}

/// The first node of an element whose gathered position `x` is not finite.
#[inline]
pub(super) fn non_finite_node(x: &[Vec3], nodes: &[u32]) -> Option<u32> {
    x.iter().zip(nodes).find(|(xi, _)| !xi.iter().all(|c| c.is_finite())).map(|(_, &n)| n)
}
