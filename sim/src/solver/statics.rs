//! The static reference solver: equilibrium of the FE model, independent of XPBD.
//!
//! Newton's method on the total potential `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i` (body
//! acceleration `a`, the same lumped masses as XPBD) with Dirichlet nodes (clamped, or driven to
//! prescribed positions), on the same elements, quadrature and materials as XPBD:
//! - the one Newton's method of hox ([`super::newton_core`], shared with Newton's implicit
//!   Euler): element Hessians `Σ_q V_q (∇_X N_i)ᵀ ∂P/∂F (∇_X N_j)` (exact where positive
//!   definite, else `∂P/∂F` projected per quadrature point) assembled on the free degrees of
//!   freedom, a sparse Cholesky factorisation on one thread (`faer`, AMD ordering; the symbolic
//!   analysis done once, the numeric factor reused while Newton converges fast), a
//!   backtracking line search on `Π`;
//! - load stepping: body force and prescribed positions are applied in increments
//!   `s ∈ (0, 1]`, halved when Newton fails to converge within an increment;
//! - convergence when the free residual `|∇Π|` is at most `tolerance` times the force scale
//!   (body force `Σ m_i |a|`, or the reaction forces at the Dirichlet nodes if larger), or when
//!   Newton stalls at round-off (a full step moves nothing and no longer reduces the residual:
//!   a stiff material's floor can lie above the tolerance); the residual reached is reported.

use super::error::SolverCounters;
use super::newton_core::{Failure, HessianModel, Objective, Outcome, Scratch, minimise};
use super::settings::{NewtonPolicy, NewtonSettings};
pub use super::sparse::SparseCost;
use super::sparse::{SparseError, SparsePattern};
use crate::Vec3;
use crate::effect::Prescribed;
use crate::fem::energy::total_energy_and_gradient;
use crate::fem::geometry::{BlockGeometry, GeometryError, precompute};
use crate::fem::mass::lumped_masses_kg;
use crate::material::Material;
use crate::mesh::Mesh;

pub use super::sparse::assemble_dense;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StaticError {
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    #[error("the stiffness matrix is not positive definite on the free nodes (is the body held at all?)")]
    Singular,
    #[error("the sparse factorisation failed: {0}")]
    Factorisation(String),
    #[error("Newton's method did not converge (load fraction {load_fraction:.4}, relative residual {residual:.3e})")]
    NotConverged { load_fraction: f64, residual: f64 },
}

/// A static problem: body acceleration and Dirichlet conditions. Clamps are prescribed motions
/// with no translation or rotation; each prescribed motion is evaluated at `ramp_secs = 1` and
/// "time" = load fraction, i.e. fully applied at fraction 1.
pub struct StaticProblem<'a> {
    pub mesh: &'a Mesh,
    pub material: Material,
    pub quadrature_degree: Option<usize>,
    pub acceleration_m_s2: Vec3,
    pub dirichlet: Vec<Prescribed>,
    pub tolerance: f64,
    /// Initial number of load increments.
    pub load_steps: usize,
}

/// A converged static solution.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    pub positions: Vec<Vec3>,
    pub newton_iterations: usize,
    pub relative_residual: f64,
    pub free_dofs: usize,
    /// Where the solve's time went: the sparse stiffness's share ([`SparseCost`]) and the rest
    /// (energies and gradients of the line search, load stepping), wall seconds.
    pub cost: SparseCost,
    pub total_secs: f64,
}

/// Progress of a solve: `(load fraction reached, Newton iteration, relative residual)`.
pub type Progress<'p> = &'p mut dyn FnMut(f64, usize, f64);

/// Solves `problem`. `progress` is called after every Newton iteration.
pub fn solve(problem: &StaticProblem<'_>, progress: Progress<'_>) -> Result<StaticSolution, StaticError> {
    let started = web_time::Instant::now();
    let mesh = problem.mesh;
    let geo = precompute(mesh, problem.quadrature_degree)?;
    let masses = lumped_masses_kg(mesh, problem.material.density_kg_m3)?;
    let n = mesh.num_nodes();
    let mut prescribed_node = vec![false; n];
    for p in &problem.dirichlet {
        for &node in &p.nodes {
            prescribed_node[node as usize] = true;
        }
    }
    let mut pattern = SparsePattern::new(mesh, &problem.material, |i| prescribed_node[i])?;
    let free_dofs = pattern.free_dofs;
    let mut x = mesh.rest_positions.clone();
    let mut total_iterations = 0;
    let mut done = 0.0;
    let mut increment = 1.0 / problem.load_steps.max(1) as f64;
    let mut last_residual = 0.0;
    let mut scratch = Scratch::default();
    while done < 1.0 {
        let target = (done + increment).min(1.0);
        let mut trial = x.clone();
        apply_dirichlet(problem, target, &mut trial);
        match newton(
            problem,
            &geo,
            &masses,
            &prescribed_node,
            &mut pattern,
            target,
            &mut trial,
            &mut total_iterations,
            &mut scratch,
            progress,
        ) {
            Ok(residual) => {
                x = trial;
                done = target;
                last_residual = residual;
                increment = (increment * 1.5).min(1.0);
            }
            Err(StaticError::NotConverged { residual, .. }) if increment > 1e-3 => {
                let _ = residual;
                increment *= 0.5;
            }
            Err(e) => return Err(e),
        }
    }
    Ok(StaticSolution {
        positions: x,
        newton_iterations: total_iterations,
        relative_residual: last_residual,
        free_dofs,
        cost: pattern.cost,
        total_secs: started.elapsed().as_secs_f64(),
    })
}

fn apply_dirichlet(problem: &StaticProblem<'_>, fraction: f64, x: &mut [Vec3]) {
    for p in &problem.dirichlet {
        for &node in &p.nodes {
            x[node as usize] = p.target(&problem.mesh.rest_positions[node as usize], fraction);
        }
    }
}

/// Newton's iterations per load increment ([`StaticProblem::newton_settings`]).
pub const MAX_ITERATIONS_PER_INCREMENT: u32 = 50;

impl StaticProblem<'_> {
    /// The settings of the one Newton ([`super::newton_core`]) for this problem: its tolerance,
    /// [`MAX_ITERATIONS_PER_INCREMENT`], the factor reused while it converges fast.
    pub fn newton_settings(&self) -> NewtonSettings {
        NewtonSettings {
            tolerance: self.tolerance,
            max_iterations: MAX_ITERATIONS_PER_INCREMENT,
            refactor_every_iteration: false,
            policy: NewtonPolicy::Careful,
        }
    }
}

/// `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i` with the body acceleration `a` at one load fraction.
struct TotalPotential<'a> {
    mesh: &'a Mesh,
    geometry: &'a [BlockGeometry],
    material: &'a Material,
    masses_kg: &'a [f64],
    acceleration_m_s2: Vec3,
    held: &'a [bool],
}

impl Objective for TotalPotential<'_> {
    fn eval(&self, x: &[Vec3], grad: &mut [Vec3]) -> (f64, f64) {
        let mut pot = total_energy_and_gradient(self.mesh, self.geometry, self.material, x, grad);
        let mut reactions = 0.0;
        for (i, g) in grad.iter_mut().enumerate() {
            pot -= self.masses_kg[i] * self.acceleration_m_s2.dot(&x[i]);
            *g -= self.acceleration_m_s2 * self.masses_kg[i];
            if self.held[i] {
                reactions += g.norm_squared();
                *g = Vec3::zeros();
            }
        }
        (pot, reactions.sqrt())
    }
}

/// Newton iterations at one load fraction; returns the relative residual reached.
#[allow(clippy::too_many_arguments)]
fn newton(
    problem: &StaticProblem<'_>,
    geo: &[BlockGeometry],
    masses: &[f64],
    held: &[bool],
    pattern: &mut SparsePattern,
    fraction: f64,
    x: &mut [Vec3],
    total_iterations: &mut usize,
    scratch: &mut Scratch,
    progress: Progress<'_>,
) -> Result<f64, StaticError> {
    let a = problem.acceleration_m_s2 * fraction;
    let objective = TotalPotential {
        mesh: problem.mesh,
        geometry: geo,
        material: &problem.material,
        masses_kg: masses,
        acceleration_m_s2: a,
        held,
    };
    let model = HessianModel { mesh: problem.mesh, geometry: geo, material: &problem.material, diagonal: &[] };
    let body_force: f64 = masses.iter().map(|m| m * a.norm()).sum();
    let mut counters = SolverCounters::default();
    let mut iteration = *total_iterations;
    let outcome = minimise(
        &objective,
        &model,
        pattern,
        x,
        &problem.newton_settings(),
        body_force,
        scratch,
        &mut counters,
        &mut |residual| {
            progress(fraction, iteration, residual);
            iteration += 1;
        },
    );
    *total_iterations += counters.solver_iterations as usize;
    match outcome {
        // stalled: a full step moves nothing and no longer reduces the residual, the iterate is
        // the minimiser to round-off (a stiff material's residual floor lies above the
        // tolerance: the stability lesson's E = 1 GPa beam had no reference); its residual is
        // reported with the solution
        Ok(Outcome::Converged { residual } | Outcome::Stalled { residual }) => Ok(residual),
        Ok(Outcome::Unconverged { residual }) => Err(StaticError::NotConverged { load_fraction: fraction, residual }),
        Err(Failure::NonFinite { .. }) => {
            Err(StaticError::NotConverged { load_fraction: fraction, residual: f64::INFINITY })
        }
        Err(Failure::Factorisation(e)) => Err(e.into()),
    }
}

impl From<SparseError> for StaticError {
    fn from(e: SparseError) -> Self {
        match e {
            SparseError::Pattern(what) => StaticError::Factorisation(what),
            SparseError::NotPositiveDefinite => StaticError::Singular,
        }
    }
}

/// Clamps as Dirichlet conditions: the nodes held at their rest positions.
pub fn clamp(nodes: Vec<u32>) -> Prescribed {
    Prescribed { nodes, translation_m: Vec3::zeros(), rotation: None, ramp_secs: 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::material::MaterialModel;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    use nalgebra::Matrix3;

    /// Patch test of the solver: with every boundary node driven by an affine map, the
    /// equilibrium is that homogeneous deformation, for every element type and material.
    #[test]
    fn an_affine_boundary_gives_the_affine_solution_inside() {
        let a = Matrix3::new(1.1, 0.05, 0.0, -0.03, 0.95, 0.02, 0.0, 0.04, 1.05);
        let b = Vec3::new(0.01, -0.02, 0.03);
        for et in ElementType::all() {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 0.5, 0.5), cells: [3, 2, 2] },
                element_type: et,
                split: TetSplit::Five,
                refine: 0,
            }
            .build()
            .unwrap();
            let boundary =
                mesh.nodes_where(|p| (0..3).any(|d| p[d].abs() < 1e-12 || (p[d] - [1.0, 0.5, 0.5][d]).abs() < 1e-12));
            // a "prescribed motion" realising x = A X + b: rotation-free, so use a translation
            // per node through individual prescribed sets
            let dirichlet: Vec<Prescribed> = boundary
                .iter()
                .map(|&n| {
                    let x0 = mesh.rest_positions[n as usize];
                    Prescribed { nodes: vec![n], translation_m: a * x0 + b - x0, rotation: None, ramp_secs: 1.0 }
                })
                .collect();
            for &model in MaterialModel::ALL {
                let problem = StaticProblem {
                    mesh: &mesh,
                    material: Material::new(model, 1e5, 0.3, 1000.0).unwrap(),
                    quadrature_degree: None,
                    acceleration_m_s2: Vec3::zeros(),
                    dirichlet: dirichlet.clone(),
                    tolerance: 1e-10,
                    load_steps: 1,
                };
                let sol = solve(&problem, &mut |_, _, _| {}).unwrap();
                let err = sol
                    .positions
                    .iter()
                    .zip(&mesh.rest_positions)
                    .map(|(x, x0)| (x - (a * x0 + b)).norm())
                    .fold(0.0, f64::max);
                assert!(err < 1e-9, "{et} {model:?}: {err}");
            }
        }
    }

    #[test]
    fn a_body_held_nowhere_is_singular_not_a_nan() {
        let mesh = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 0.5, 0.5), cells: [2, 1, 1] },
            element_type: ElementType::from_name("p1").unwrap(),
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        let problem = StaticProblem {
            mesh: &mesh,
            material: Material::new(MaterialModel::StVenantKirchhoff, 1e5, 0.3, 1000.0).unwrap(),
            quadrature_degree: None,
            acceleration_m_s2: Vec3::new(0.0, 0.0, -9.81),
            dirichlet: Vec::new(),
            tolerance: 1e-10,
            load_steps: 1,
        };
        let err = solve(&problem, &mut |_, _, _| {}).unwrap_err();
        assert_eq!(err, StaticError::Singular);
    }
}
