//! When a parameter applies to a configuration (the app greys it out where not): the solver's
//! predicates and the element's shape.

use hox_sim::element::ElementType;
use hox_sim::solver::Method;

use super::Params;

/// Whether the solver is the paper's XPBD (substeps, iterations, formulation and guard apply).
pub fn is_xpbd(p: &Params) -> bool {
    Method::from_name(&p.method).is_none_or(|m| m == Method::Xpbd)
}
/// Whether the solver is implicit (VBD or Newton: steps per frame apply).
pub fn is_implicit(p: &Params) -> bool {
    !is_xpbd(p)
}
pub fn is_vbd(p: &Params) -> bool {
    Method::from_name(&p.method) == Some(Method::Vbd)
}
pub(super) fn is_newton(p: &Params) -> bool {
    Method::from_name(&p.method) == Some(Method::Newton)
}

/// Whether the element type is a tetrahedron (P1, P2, P3): the tet split and refinement apply.
pub fn is_tetrahedral(p: &Params) -> bool {
    ElementType::from_name(&p.element).is_some_and(|e| e.shape() == hox_sim::element::ReferenceShape::Tetrahedron)
}
