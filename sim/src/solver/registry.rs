//! The one place that names each solver's type: [`make`] builds the solver a [`Method`] asks for.
//! What each solver *is* (name, roles it honours, parameters) is its [`super::method::INFO`]
//! entry.

use super::method::Method;
use super::newton::Newton;
use super::newton_cg::ConjugateGradients;
use super::settings::SolverSettings;
use super::sparse::SparsePattern;
use super::step::StepSolver;
use super::vbd::Vbd;
use super::xpbd::Xpbd;
use crate::fem::geometry::BlockGeometry;
use crate::mesh::Mesh;

/// Makes the solver `settings.method` asks for.
pub(crate) fn make(mesh: &Mesh, geometry: &[BlockGeometry], settings: &SolverSettings) -> Box<dyn StepSolver> {
    match settings.method {
        Method::Xpbd => Box::new(Xpbd::new(mesh, geometry, settings)),
        Method::Vbd => Box::new(Vbd::new(mesh, geometry, settings)),
        Method::Newton => Box::new(Newton::<SparsePattern>::new(mesh)),
        Method::NewtonCg => Box::new(Newton::<ConjugateGradients>::new(mesh)),
    }
}
