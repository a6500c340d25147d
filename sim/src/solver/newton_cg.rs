//! Newton-CG: the implicit step's incremental potential (`potential.rs`, under any of the
//! integrators) minimised by the one Newton (`newton_core.rs`: its line search, convergence test
//! and refresh policy), each iteration's `K Δ = −∇E` solved by preconditioned conjugate gradients
//! instead of a sparse Cholesky factorisation — an inexact (truncated) Newton method (Dembo,
//! Eisenstat & Steihaug 1982, "Inexact Newton methods", SIAM J. Numer. Anal. 19(2); Nocedal &
//! Wright, *Numerical Optimization*, 2nd ed., §7.1).
//!
//! - **`K`** `= M/h̄² + Σ_k k_k I + Σ_e Σ_q V_q Gᵀ ∂P/∂F|₊ G`, the material tangent projected to
//!   positive semi-definite per quadrature point, so `K` is positive definite on the free degrees
//!   of freedom wherever a step has mass: what conjugate gradients need. It is kept as the element
//!   Hessians, computed in parallel at the iterate the Newton asks for (every iteration whose
//!   residual fell less than 4×: with an inexact solve, most of them), and applied element by
//!   element; it is never assembled for the product. Where P1's pressure is one per node patch
//!   (the mixed formulation), the node patches' dense terms (nodal strain and pressure) join the element terms.
//! - **Preconditioner**: the sparse Cholesky factor of `K` at an earlier iterate (`sparse.rs`,
//!   projected), kept across iterations and steps and remade only when a solve needed more than
//!   [`SLOW_CG_ITERATIONS`] iterations; where it cannot be made, block Jacobi (each free node's
//!   3×3 diagonal block of `K`, inverted). With block Jacobi alone, the slender beams need
//!   hundreds of iterations per solve (the Gmsh P2 beam settled in 29 s against Newton's 1.7 s);
//!   with the kept factor, a handful (5.2–7.1 s), and at most a third of Newton's factorisations
//!   (`newton_cg_follows_newton_step_by_step`: one in 40 frames of a P2 cantilever).
//! - **Forcing term**: conjugate gradients stop when `‖K Δ + ∇E‖ ≤ η ‖∇E‖` with
//!   `η = min(1/2, √r)`, `r` the Newton iteration's relative residual (Eisenstat & Walker 1996's
//!   choice of order 3/2: loose far from the solution, superlinear near it), or after
//!   [`MAX_CG_ITERATIONS`]; a direction that is not one of descent cannot come out (every CG
//!   iterate of a positive definite system descends), and the Newton's line search takes the rest.
//! - **Bits**: the element Hessians are computed in parallel and every sum is taken in a fixed
//!   order, so results do not depend on the thread count.
//!
//! The solver is `Newton::<ConjugateGradients>` (`newton.rs`, `registry.rs`): everything but the
//! linear solve is Newton's. What it costs against Newton (release, one thread, Intel Xeon): on
//! the bending beam P2 8×2×2 8.2 ms per frame against 1.5 (4.5 iterations per frame, every one
//! computing the element Hessians, which Newton's reused factor spares it), on the Gmsh P2 beam
//! 5.2–7.1 s to settle against 1.7 s, to the same equilibrium and the same motion (the study's
//! rows): docs/journal/performance.md, session 19.

use super::error::SolverCounters;
use super::newton_core::{HessianModel, LinearSolver};
use super::sparse::{SparseError, SparsePattern, map_element_hessians};
use crate::Vec3;
use crate::fem::energy::mixed::patch;
use crate::material::Material;
use crate::mesh::Mesh;
use nalgebra::Matrix3;

/// Conjugate-gradient iterations per linear solve at most.
pub(crate) const MAX_CG_ITERATIONS: usize = 1000;

/// Conjugate-gradient iterations of a solve above which the next update remakes the kept factor.
pub(crate) const SLOW_CG_ITERATIONS: usize = 20;

/// The forcing term's ceiling `η_max`.
const MAX_FORCING: f64 = 0.5;

/// `K` as element Hessians, its block-Jacobi preconditioner and the conjugate-gradient buffers.
pub(crate) struct ConjugateGradients {
    dof_of: Vec<usize>,
    free_dofs: usize,
    /// Every element's nodes, concatenated block by block; element `k`'s are
    /// `nodes[node_start[k]..node_start[k + 1]]`.
    nodes: Vec<u32>,
    node_start: Vec<usize>,
    /// Every element's `3n × 3n` Hessian (column-major), concatenated in the same order.
    hessians: Vec<f64>,
    /// `D`, the diagonal beyond the elastic part (one value per free degree of freedom).
    diagonal: Vec<f64>,
    /// Per node, the inverse of its 3×3 diagonal block of `K` (identity on held nodes).
    block_inverse: Vec<Matrix3<f64>>,
    ready: bool,
    /// The kept preconditioner: the sparse Cholesky factor of `K` (projected) at an earlier
    /// iterate, remade only when conjugate gradients needed more than [`SLOW_CG_ITERATIONS`].
    factor: Option<SparsePattern>,
    /// Whether [`Self::factor`] holds a factor to precondition with (else block Jacobi).
    use_factor: bool,
    /// Conjugate-gradient iterations of the last solve.
    last_iterations: usize,
    residual: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    x: Vec<f64>,
    local: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl ConjugateGradients {
    /// `out = K v` on free degrees of freedom, element by element in a fixed order.
    fn apply(&mut self, v: &[f64], out: &mut [f64]) {
        for ((o, d), x) in out.iter_mut().zip(&self.diagonal).zip(v) {
            *o = d * x;
        }
        let mut h_at = 0;
        for k in 0..self.node_start.len() - 1 {
            let nodes = &self.nodes[self.node_start[k]..self.node_start[k + 1]];
            let m = 3 * nodes.len();
            self.local.clear();
            self.local.extend(nodes.iter().flat_map(|&i| (0..3).map(move |a| 3 * i as usize + a)).map(|dof| {
                let f = self.dof_of[dof];
                if f == usize::MAX { 0.0 } else { v[f] }
            }));
            let h = &self.hessians[h_at..h_at + m * m];
            h_at += m * m;
            for (row, &node) in nodes.iter().enumerate().flat_map(|(li, n)| (0..3).map(move |a| (3 * li + a, n))) {
                let f = self.dof_of[3 * node as usize + row % 3];
                if f == usize::MAX {
                    continue;
                }
                // K is symmetric: row `row` is column `row` of the column-major block
                out[f] += dot(&h[row * m..row * m + m], &self.local);
            }
        }
    }

    /// `K`'s terms where P1's pressure and nodal strain are one per node patch (the mixed
    /// formulation, [`patch`]): every patch element's term and every node patch's dense term
    /// ([`patch::hessian_terms`], projected), then every other block's element Hessians; the
    /// term list (`nodes`, `node_start`) is remade to match.
    fn patch_hessians(&mut self, model: &HessianModel<'_>, x: &[Vec3]) {
        let (mesh, geometry, material) = (model.mesh, model.geometry, model.material);
        let (mut nodes, mut node_start, mut hessians) = (Vec::new(), vec![0], Vec::new());
        let mut add = |term: &[u32], h: &nalgebra::DMatrix<f64>| {
            nodes.extend_from_slice(term);
            node_start.push(nodes.len());
            hessians.extend_from_slice(h.as_slice());
        };
        crate::solver::sparse::for_each_hessian_term(mesh, geometry, material, x, true, &mut add);
        (self.nodes, self.node_start, self.hessians) = (nodes, node_start, hessians);
    }

    /// `z = P r`: the kept factor's solve, else block Jacobi.
    fn precondition(&self, r: &[f64], z: &mut [f64]) {
        if self.use_factor
            && let Some(factor) = &self.factor
        {
            z.copy_from_slice(r);
            factor.solve_in_place(z, faer::Par::Seq);
            return;
        }
        for (node, inv) in self.block_inverse.iter().enumerate() {
            let f = self.dof_of[3 * node];
            if f == usize::MAX {
                continue;
            }
            let v = inv * Vec3::new(r[f], r[f + 1], r[f + 2]);
            z[f..f + 3].copy_from_slice(v.as_slice());
        }
    }
}

impl LinearSolver for ConjugateGradients {
    fn for_mesh(mesh: &Mesh, material: &Material, held: &dyn Fn(usize) -> bool) -> Result<Self, SparseError> {
        let n = mesh.num_nodes();
        let mut dof_of = vec![usize::MAX; 3 * n];
        let mut free_dofs = 0;
        for node in (0..n).filter(|&i| !held(i)) {
            for a in 0..3 {
                dof_of[3 * node + a] = free_dofs;
                free_dofs += 1;
            }
        }
        let mut nodes = Vec::new();
        let mut node_start = vec![0];
        for block in &mesh.blocks {
            for element in block.elements() {
                nodes.extend_from_slice(element);
                node_start.push(nodes.len());
            }
        }
        Ok(Self {
            dof_of,
            free_dofs,
            nodes,
            node_start,
            hessians: Vec::new(),
            diagonal: Vec::new(),
            block_inverse: vec![Matrix3::identity(); n],
            ready: false,
            factor: SparsePattern::new(mesh, material, held).ok(),
            use_factor: false,
            last_iterations: usize::MAX,
            residual: Vec::new(),
            z: Vec::new(),
            p: Vec::new(),
            q: Vec::new(),
            x: Vec::new(),
            local: Vec::new(),
        })
    }
    fn dof_of(&self) -> &[usize] {
        &self.dof_of
    }
    fn free_dofs(&self) -> usize {
        self.free_dofs
    }
    fn is_ready(&self) -> bool {
        self.ready
    }
    fn forget_model(&mut self) {
        self.ready = false;
    }

    fn update(
        &mut self,
        model: &HessianModel<'_>,
        x: &[Vec3],
        counters: &mut SolverCounters,
    ) -> Result<(), SparseError> {
        self.ready = false;
        self.hessians.clear();
        if patch::has_patches(model.mesh, model.material) {
            self.patch_hessians(model, x);
        } else {
            let per_element = map_element_hessians(model.mesh, model.geometry, model.material, x, true, |_, h| h);
            per_element.iter().for_each(|h| self.hessians.extend_from_slice(h.as_slice()));
        }
        if !self.hessians.iter().all(|v| v.is_finite()) {
            return Err(SparseError::NotPositiveDefinite);
        }
        self.diagonal.clear();
        if model.diagonal.is_empty() {
            self.diagonal.resize(self.free_dofs, 0.0);
        } else {
            self.diagonal.extend_from_slice(model.diagonal);
        }
        // each free node's diagonal block: D plus its block of every element holding it
        let mut blocks = vec![Matrix3::<f64>::zeros(); self.block_inverse.len()];
        let mut h_at = 0;
        for k in 0..self.node_start.len() - 1 {
            let nodes = &self.nodes[self.node_start[k]..self.node_start[k + 1]];
            let m = 3 * nodes.len();
            let h = &self.hessians[h_at..h_at + m * m];
            h_at += m * m;
            for (li, &node) in nodes.iter().enumerate() {
                for a in 0..3 {
                    for c in 0..3 {
                        blocks[node as usize][(a, c)] += h[(3 * li + c) * m + 3 * li + a];
                    }
                }
            }
        }
        for (node, (block, inverse)) in blocks.iter_mut().zip(self.block_inverse.iter_mut()).enumerate() {
            let f = self.dof_of[3 * node];
            if f == usize::MAX {
                *inverse = Matrix3::identity();
                continue;
            }
            for a in 0..3 {
                block[(a, a)] += self.diagonal[f + a];
            }
            *inverse = block.try_inverse().filter(|i| i.iter().all(|v| v.is_finite())).unwrap_or_else(|| {
                Matrix3::from_diagonal(&block.diagonal().map(|d| if d > 0.0 { 1.0 / d } else { 1.0 }))
            });
        }
        // the kept factor, remade where conjugate gradients slowed down (or there is none yet)
        if self.last_iterations > SLOW_CG_ITERATIONS
            && let Some(factor) = &mut self.factor
        {
            let made = factor.assemble_and_factor(
                model.mesh,
                model.geometry,
                model.material,
                x,
                model.diagonal,
                true,
                false,
                faer::Par::Seq,
            );
            counters.factorizations += 1;
            self.use_factor = made.is_ok();
            self.last_iterations = 0;
        }
        self.ready = true;
        Ok(())
    }

    fn solve(&mut self, r: &mut [f64], relative_residual: f64, counters: &mut SolverCounters) {
        let n = self.free_dofs;
        let eta = MAX_FORCING.min(relative_residual.max(0.0).sqrt());
        let b_norm = dot(r, r).sqrt();
        let mut residual = std::mem::take(&mut self.residual);
        let (mut z, mut p, mut q, mut x) = (
            std::mem::take(&mut self.z),
            std::mem::take(&mut self.p),
            std::mem::take(&mut self.q),
            std::mem::take(&mut self.x),
        );
        for v in [&mut z, &mut p, &mut q, &mut x] {
            v.clear();
            v.resize(n, 0.0);
        }
        residual.clear();
        residual.extend_from_slice(r);
        if b_norm > 0.0 {
            self.precondition(&residual, &mut z);
            p.copy_from_slice(&z);
            let mut rz = dot(&residual, &z);
            for iteration in 0..MAX_CG_ITERATIONS {
                self.last_iterations = iteration + 1;
                self.apply(&p, &mut q);
                let pq = dot(&p, &q);
                if !(pq > 0.0 && pq.is_finite()) {
                    // no positive curvature along p (round-off at the solution): keep what was
                    // found, or the preconditioned gradient, a descent direction, at the start
                    if iteration == 0 {
                        x.copy_from_slice(&z);
                    }
                    break;
                }
                counters.linear_iterations += 1;
                let alpha = rz / pq;
                for ((xi, ri), (pi, qi)) in x.iter_mut().zip(residual.iter_mut()).zip(p.iter().zip(&q)) {
                    *xi += alpha * pi;
                    *ri -= alpha * qi;
                }
                if dot(&residual, &residual).sqrt() <= eta * b_norm {
                    break;
                }
                self.precondition(&residual, &mut z);
                let rz_next = dot(&residual, &z);
                let beta = rz_next / rz;
                rz = rz_next;
                for (pi, zi) in p.iter_mut().zip(&z) {
                    *pi = zi + beta * *pi;
                }
            }
        }
        r.copy_from_slice(&x);
        (self.residual, self.z, self.p, self.q, self.x) = (residual, z, p, q, x);
    }

    fn work_summary(counters: &SolverCounters) -> String {
        format!("{} CG iterations, {} factorisations", counters.linear_iterations, counters.factorizations)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::fem::geometry::precompute;
    use crate::material::{Material, MaterialModel};
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    use crate::solver::sparse::assemble_dense;

    fn beam(element: &str) -> Mesh {
        BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 0.2, 0.2), cells: [4, 1, 1] },
            element_type: ElementType::from_name(element).unwrap(),
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap()
    }

    /// The element-by-element `K v` equals the assembled Hessian's, and conjugate gradients
    /// solve `K s = r` to the forcing term asked, on a bent beam (held at x = 0).
    #[test]
    fn conjugate_gradients_solve_the_element_by_element_stiffness_to_the_forcing_term() {
        for element in ["p1", "p2", "q2"] {
            let mesh = beam(element);
            let geometry = precompute(&mesh, None).unwrap();
            let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e6, 0.45, 1000.0).unwrap();
            let held = |i: usize| mesh.rest_positions[i].x < 1e-9;
            let x: Vec<Vec3> =
                mesh.rest_positions.iter().map(|p| p + Vec3::new(0.0, 0.1 * p.x * p.x, 0.05 * p.x * p.y)).collect();
            let mut cg = ConjugateGradients::for_mesh(&mesh, &material, &held).unwrap();
            let diagonal = vec![50.0; cg.free_dofs()];
            let model = HessianModel { mesh: &mesh, geometry: &geometry, material: &material, diagonal: &diagonal };
            cg.update(&model, &x, &mut SolverCounters::default()).unwrap();
            // the assembled K restricted to the free degrees of freedom
            let dense = assemble_dense(&mesh, &geometry, &material, &x);
            let free: Vec<usize> = (0..3 * mesh.num_nodes()).filter(|&d| cg.dof_of()[d] != usize::MAX).collect();
            let k = nalgebra::DMatrix::from_fn(free.len(), free.len(), |i, j| {
                dense[(free[i], free[j])] + if i == j { diagonal[i] } else { 0.0 }
            });
            let v: Vec<f64> = (0..free.len()).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
            let mut kv = vec![0.0; free.len()];
            cg.apply(&v, &mut kv);
            let expected = &k * nalgebra::DVector::from_column_slice(&v);
            let scale = expected.amax();
            for (a, b) in kv.iter().zip(expected.iter()) {
                assert!((a - b).abs() <= 1e-10 * scale, "{element}: K v {a} against {b}");
            }
            // with the kept factor (made at this K: one iteration), and with block Jacobi alone
            for (use_factor, relative_residual) in [(true, 1e-8), (false, 1e-2), (false, 1e-8)] {
                cg.use_factor = use_factor;
                let mut s = v.clone();
                let mut counters = SolverCounters::default();
                cg.solve(&mut s, relative_residual, &mut counters);
                let ks = &k * nalgebra::DVector::from_column_slice(&s);
                let b = nalgebra::DVector::from_column_slice(&v);
                let achieved = (ks - &b).norm() / b.norm();
                let asked = relative_residual.sqrt().min(MAX_FORCING);
                assert!(
                    achieved <= asked,
                    "{element}, factor {use_factor}: CG reached {achieved:.2e}, asked {asked:.2e}"
                );
                assert!(counters.linear_iterations > 0);
            }
        }
    }

    /// Newton-CG takes the steps Newton takes: the same incremental potential to the same
    /// tolerance, on a P2 cantilever swinging under gravity, under each integrator.
    #[test]
    fn newton_cg_follows_newton_step_by_step() {
        use crate::effect::{Clamp, Effect, Gravity};
        use crate::solver::{Integrator, Method, Simulation, SolverSettings};
        let mesh = beam("p2");
        let clamped: Vec<u32> =
            (0..mesh.num_nodes() as u32).filter(|&i| mesh.rest_positions[i as usize].x < 1e-9).collect();
        let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
        for integrator in Integrator::ALL {
            let run = |method| {
                let effects: Vec<Box<dyn Effect>> = vec![
                    Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
                    Box::new(Clamp { nodes: clamped.clone() }),
                ];
                let settings = SolverSettings { method, integrator, ..SolverSettings::default() };
                let mut sim = Simulation::new(mesh.clone(), material, settings, effects).unwrap();
                let mut tip = Vec::new();
                for _ in 0..40 {
                    sim.step_frame().unwrap();
                    tip.push(sim.positions.iter().map(|p| p.z).fold(f64::INFINITY, f64::min));
                }
                (tip, sim.counters())
            };
            let (newton, direct) = run(Method::Newton);
            let (cg, counters) = run(Method::NewtonCg);
            let swing = newton.iter().fold(0.0f64, |m, z| m.max(z.abs()));
            for (frame, (a, b)) in newton.iter().zip(&cg).enumerate() {
                assert!((a - b).abs() <= 1e-4 * swing, "{integrator}, frame {frame}: newton {a}, newton-cg {b}");
            }
            // the kept factor is remade far more rarely than Newton refreshes its own
            assert!(counters.linear_iterations > 0, "{counters:?}");
            assert!(
                counters.factorizations >= 1 && 3 * counters.factorizations <= direct.factorizations,
                "{integrator}: newton-cg {} factorisations, newton {}",
                counters.factorizations,
                direct.factorizations
            );
            assert_eq!(counters.unconverged_steps, 0, "{integrator}");
        }
    }
}
