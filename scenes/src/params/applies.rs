//! When a parameter applies to a configuration (the app greys it out where not): a solver's own
//! parameters apply when the configuration's solver reads them (its entry's
//! [`hox_sim::solver::MethodInfo::parameters`], [`solver_reads`]), others by the entry's
//! predicate, such as the element's shape.

use hox_sim::element::ReferenceShape;
use hox_sim::solver::{METHODS, Method};

use super::Params;

/// Whether the element type is a tetrahedron (P1, P2, P3): the tet split and refinement apply.
pub fn is_tetrahedral(p: &Params) -> bool {
    p.element.shape() == ReferenceShape::Tetrahedron
}

/// Whether the table entry of scene-file key `file_key` applies under `method`: false only for a
/// parameter some solver declares as its own and `method` does not read.
pub fn solver_reads(method: Method, file_key: &str) -> bool {
    method.reads_parameter(file_key) || !METHODS.iter().any(|m| m.parameters.contains(&file_key))
}
