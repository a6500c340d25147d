//! When a parameter applies to a configuration (the app greys it out where not): the solver's
//! predicates and the element's shape.

use hox_sim::element::ReferenceShape;
use hox_sim::solver::Method;

use super::Params;

/// Whether the solver is the paper's XPBD (substeps, iterations, formulation and guard apply).
pub fn is_xpbd(p: &Params) -> bool {
    p.method == Method::Xpbd
}
/// Whether the solver is implicit (VBD or Newton: steps per frame apply).
pub fn is_implicit(p: &Params) -> bool {
    !is_xpbd(p)
}
pub fn is_vbd(p: &Params) -> bool {
    p.method == Method::Vbd
}
pub(super) fn is_newton(p: &Params) -> bool {
    p.method == Method::Newton
}

/// Whether the element type is a tetrahedron (P1, P2, P3): the tet split and refinement apply.
pub fn is_tetrahedral(p: &Params) -> bool {
    p.element.shape() == ReferenceShape::Tetrahedron
}
