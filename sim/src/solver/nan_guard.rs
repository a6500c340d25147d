//! The NaN guard described in the module doc of [`super`]: how the failing element and its origin
//! are named ([`BadElement`]). The check after a substep and the roll-back to the last finite
//! state are the simulation's (`simulation.rs`).

use crate::Vec3;

/// An element the NaN guard names: block, index in the block, one of its non-finite nodes, and
/// what went wrong.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BadElement {
    pub(super) block: usize,
    pub(super) element: usize,
    pub(super) node: u32,
    pub(super) origin: &'static str,
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
pub(super) const ORIGIN_STATE: &str = "a non-finite position or velocity in";

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

/// The first non-finite position.
pub(super) fn first_non_finite_position(x: &[Vec3]) -> Option<usize> {
    x.iter().position(|p| !p.iter().all(|c| c.is_finite()))
}

/// An implicit solver's check of the positions it is handed: the first non-finite one names an
/// element holding it, as bad input ([`ORIGIN_INPUT`]).
pub(super) fn check_input(mesh: &crate::mesh::Mesh, positions: &[Vec3]) -> Result<(), BadElement> {
    match first_non_finite_position(positions) {
        Some(i) => Err(BadElement::at_node(mesh, i, ORIGIN_INPUT)),
        None => Ok(()),
    }
}

/// The first node of an element whose gathered position `x` is not finite.
#[inline]
pub(super) fn non_finite_node(x: &[Vec3], nodes: &[u32]) -> Option<u32> {
    x.iter().zip(nodes).find(|(xi, _)| !xi.iter().all(|c| c.is_finite())).map(|(_, &n)| n)
}
