//! Static equilibrium of the FE model, independent of XPBD: Newton's method on the total
//! potential `Π(x) = Σ_e U_e(x) − Σ_i m_i a·x_i` (body acceleration `a`, lumped masses) with
//! Dirichlet nodes held at given positions, analytic element Hessians from dP/dF projected to
//! positive semi-definite per quadrature point, and a backtracking line search on Π.
//! Stops at a relative residual `|∇Π|_free ≤ tolerance · Σ_i m_i |a|` (or `· |∇U(x₀)|` without
//! body force).
//!
//! This version assembles a **dense** stiffness matrix and factors it with Cholesky: it is the
//! reference for small meshes (a few thousand degrees of freedom) in tests and measurements.

use crate::Vec3;
use crate::energy::{element_grads, element_hessian, total_energy_and_gradient};
use crate::geometry::{GeometryError, precompute};
use crate::mass::lumped_masses_kg;
use crate::material::Material;
use crate::mesh::Mesh;
use nalgebra::{DMatrix, DVector};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StaticError {
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    #[error("the stiffness matrix is not positive definite on the free nodes (is the body held at all?)")]
    Singular,
    #[error("Newton's method did not converge in {iterations} iterations (relative residual {residual:.3e})")]
    NotConverged { iterations: usize, residual: f64 },
}

/// A converged static solution.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    pub positions: Vec<Vec3>,
    pub newton_iterations: usize,
    pub relative_residual: f64,
}

/// Solves for the equilibrium of `mesh` under body acceleration `acceleration_m_s2`, with the
/// nodes of `dirichlet` held at the given positions.
pub fn solve_dense(
    mesh: &Mesh,
    material: &Material,
    quadrature_degree: Option<usize>,
    acceleration_m_s2: Vec3,
    dirichlet: &[(u32, Vec3)],
    tolerance: f64,
) -> Result<StaticSolution, StaticError> {
    let geo = precompute(mesh, quadrature_degree)?;
    let masses = lumped_masses_kg(mesh, material.density_kg_m3)?;
    let n = mesh.num_nodes();
    let mut x = mesh.rest_positions.clone();
    let mut free = vec![true; n];
    for &(node, p) in dirichlet {
        free[node as usize] = false;
        x[node as usize] = p;
    }
    let dof: Vec<usize> = (0..3 * n).filter(|d| free[d / 3]).collect();
    let potential = |x: &[Vec3]| -> (f64, Vec<Vec3>) {
        let mut g = vec![Vec3::zeros(); n];
        let mut pot = total_energy_and_gradient(mesh, &geo, material, x, &mut g);
        for i in 0..n {
            pot -= masses[i] * acceleration_m_s2.dot(&x[i]);
            g[i] -= masses[i] * acceleration_m_s2;
        }
        (pot, g)
    };
    let free_residual = |g: &[Vec3]| DVector::from_iterator(dof.len(), dof.iter().map(|&d| g[d / 3][d % 3]));
    let body_force: f64 = masses.iter().map(|m| m * acceleration_m_s2.norm()).sum();
    let scale = if body_force > 0.0 { body_force } else { free_residual(&potential(&x).1).norm().max(f64::MIN_POSITIVE) };
    let mut residual = f64::INFINITY;
    for it in 0..200 {
        let (pot, g) = potential(&x);
        let r = free_residual(&g);
        residual = r.norm() / scale;
        if residual <= tolerance {
            return Ok(StaticSolution { positions: x, newton_iterations: it, relative_residual: residual });
        }
        let k = assemble_dense(mesh, &geo, material, &x);
        let kf = DMatrix::from_fn(dof.len(), dof.len(), |i, j| k[(dof[i], dof[j])]);
        let step = kf.cholesky().ok_or(StaticError::Singular)?.solve(&(-&r));
        let mut t = 1.0;
        loop {
            let mut xt = x.clone();
            for (s, &d) in step.iter().zip(&dof) {
                xt[d / 3][d % 3] += t * s;
            }
            let (pt, gt) = potential(&xt);
            // accept a decrease of Π, or (near the round-off floor of Π) of the residual
            if pt <= pot || free_residual(&gt).norm() < r.norm() || t < 1e-6 {
                x = xt;
                break;
            }
            t *= 0.5;
        }
    }
    Err(StaticError::NotConverged { iterations: 200, residual })
}

/// The dense Hessian of the total elastic energy at `x` (projected per quadrature point).
pub fn assemble_dense(mesh: &Mesh, geo: &[crate::geometry::BlockGeometry], material: &Material, x: &[Vec3]) -> DMatrix<f64> {
    let n = mesh.num_nodes();
    let mut k = DMatrix::zeros(3 * n, 3 * n);
    for (b, gb) in mesh.blocks.iter().zip(geo) {
        for (e, nodes) in b.elements().enumerate() {
            let xl: Vec<Vec3> = nodes.iter().map(|&i| x[i as usize]).collect();
            let rest: Vec<Vec3> = nodes.iter().map(|&i| mesh.rest_positions[i as usize]).collect();
            let he = element_hessian(&xl, &rest, element_grads(gb, e), gb.volumes(e), material, true);
            for (li, &i) in nodes.iter().enumerate() {
                for (lj, &j) in nodes.iter().enumerate() {
                    for a in 0..3 {
                        for c in 0..3 {
                            k[(3 * i as usize + a, 3 * j as usize + c)] += he[(3 * li + a, 3 * lj + c)];
                        }
                    }
                }
            }
        }
    }
    k
}
