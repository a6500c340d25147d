//! The static reference solver: equilibrium of the FE model, independent of XPBD.
//!
//! Newton's method on the total potential `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i` (body
//! acceleration `a`, the same lumped masses as XPBD) with Dirichlet nodes (clamped, or driven to
//! prescribed positions), on the same elements, quadrature and materials as XPBD:
//! - element Hessians `Σ_q V_q (∇_X N_i)ᵀ ∂P/∂F (∇_X N_j)` with `∂P/∂F` projected to positive
//!   semi-definite per quadrature point, assembled into a sparse matrix on the free degrees of
//!   freedom (lower triangle);
//! - a sparse Cholesky factorisation (`faer`, AMD ordering; the symbolic analysis is done once);
//! - a backtracking line search on `Π`;
//! - load stepping: body force and prescribed positions are applied in increments
//!   `s ∈ (0, 1]`, halved when Newton fails to converge within an increment;
//! - convergence when the free residual `|∇Π|` is at most `tolerance` times the force scale
//!   (body force `Σ m_i |a|`, or the reaction forces at the Dirichlet nodes if larger).

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
}

/// Progress of a solve: `(load fraction reached, Newton iteration, relative residual)`.
pub type Progress<'p> = &'p mut dyn FnMut(f64, usize, f64);

/// Solves `problem`. `progress` is called after every Newton iteration.
pub fn solve(problem: &StaticProblem<'_>, progress: Progress<'_>) -> Result<StaticSolution, StaticError> {
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
    let mut pattern = SparsePattern::new(mesh, |i| prescribed_node[i])?;
    let free_dofs = pattern.free_dofs;
    let mut x = mesh.rest_positions.clone();
    let mut total_iterations = 0;
    let mut done = 0.0;
    let mut increment = 1.0 / problem.load_steps.max(1) as f64;
    let mut last_residual = 0.0;
    while done < 1.0 {
        let target = (done + increment).min(1.0);
        let mut trial = x.clone();
        apply_dirichlet(problem, target, &mut trial);
        match newton(problem, &geo, &masses, &mut pattern, target, &mut trial, &mut total_iterations, progress) {
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
    })
}

fn apply_dirichlet(problem: &StaticProblem<'_>, fraction: f64, x: &mut [Vec3]) {
    for p in &problem.dirichlet {
        for &node in &p.nodes {
            x[node as usize] = p.target(&problem.mesh.rest_positions[node as usize], fraction);
        }
    }
}

/// Newton iterations at one load fraction; returns the relative residual reached.
#[allow(clippy::too_many_arguments)]
fn newton(
    problem: &StaticProblem<'_>,
    geo: &[BlockGeometry],
    masses: &[f64],
    pattern: &mut SparsePattern,
    fraction: f64,
    x: &mut Vec<Vec3>,
    total_iterations: &mut usize,
    progress: Progress<'_>,
) -> Result<f64, StaticError> {
    let mesh = problem.mesh;
    let n = mesh.num_nodes();
    let a = problem.acceleration_m_s2 * fraction;
    let potential = |x: &[Vec3]| -> (f64, Vec<Vec3>) {
        let mut g = vec![Vec3::zeros(); n];
        let mut pot = total_energy_and_gradient(mesh, geo, &problem.material, x, &mut g);
        for i in 0..n {
            pot -= masses[i] * a.dot(&x[i]);
            g[i] -= masses[i] * a;
        }
        (pot, g)
    };
    let body_force: f64 = masses.iter().map(|m| m * a.norm()).sum();
    let dof_of = pattern.dof_of.clone();
    let free_dofs = pattern.free_dofs;
    let split = |g: &[Vec3]| -> (Vec<f64>, f64) {
        let mut r = vec![0.0; free_dofs];
        let mut reactions = 0.0;
        for (d, &k) in dof_of.iter().enumerate() {
            let v = g[d / 3][d % 3];
            if k == usize::MAX {
                reactions += v * v;
            } else {
                r[k] = v;
            }
        }
        (r, reactions.sqrt())
    };
    let (mut pot, mut g) = potential(x);
    let mut residual = f64::INFINITY;
    for _ in 0..50 {
        let (r, reactions) = split(&g);
        let scale = super::residual::load_scale(body_force, reactions);
        residual = norm(&r) / scale;
        progress(fraction, *total_iterations, residual);
        if residual <= problem.tolerance {
            return Ok(residual);
        }
        *total_iterations += 1;
        let par = faer::get_global_parallelism();
        pattern.assemble_and_factor(mesh, geo, &problem.material, x, &[], true, par)?;
        let mut step: Vec<f64> = r.iter().map(|v| -v).collect();
        pattern.solve_in_place(&mut step, par);
        let mut t = 1.0;
        let mut accepted = false;
        while t > 1e-8 {
            let mut xt = x.clone();
            for (d, &k) in dof_of.iter().enumerate() {
                if k != usize::MAX {
                    xt[d / 3][d % 3] += t * step[k];
                }
            }
            let (pt, gt) = potential(&xt);
            // accept a decrease of Π or, at Π's round-off floor, of the residual
            if pt.is_finite() && (pt <= pot || norm(&split(&gt).0) < norm(&r)) {
                *x = xt;
                pot = pt;
                g = gt;
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    Err(StaticError::NotConverged { load_fraction: fraction, residual })
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|c| c * c).sum::<f64>().sqrt()
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
