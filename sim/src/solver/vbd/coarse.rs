//! Two-level (coarse-grid) correction for vertex block descent.
//!
//! A Gauss–Seidel sweep over the nodes removes error that varies from node to node in a few
//! sweeps, but error that is smooth over the body — a beam's slow bending — only by about
//! `λ/D` per sweep (`λ` the mode's stiffness, `D` a node's own): on Gmsh's P2 beam about 0.5 %
//! per sweep, so a step's ten sweeps leave the slow modes nearly where the initial guess put
//! them. The correction solves the step's incremental potential `G` (see [`super::vbd`]) on a
//! coarse space of smooth displacements, the Galerkin coarse-grid correction of multigrid
//! (Briggs, Henson, McCormick, "A Multigrid Tutorial", 2nd ed., SIAM 2000, ch. 10):
//!
//! `δ = −(Uᵀ H U)⁻¹ Uᵀ ∇G(x)`, `x ← x + U δ`,
//!
//! - `U` the prolongation: fine node `i` takes `Σ_J φ_J(X_i) δ_J`, `φ_J` the trilinear hat
//!   functions of a regular grid of cells over the rest shape's bounding box (about
//!   [`super::VbdSettings::coarse_cells`] cells, near-cubic), zero rows for held and driven nodes;
//!   any mesh of any element type gets one, as it only reads the nodes' rest positions;
//! - `H` the projected Hessian of `G` (`M/h²`, the elements' Hessians with `∂P/∂F` projected to
//!   positive semi-definite per quadrature point as Newton's, the springs' `k I`), made at the
//!   current positions every [`REFRESH_STEPS`] steps (sooner when the line search finds it off)
//!   and kept factored (dense Cholesky) in between; a drag spring that appears or goes between
//!   two makings is in `∇G` at once and in the matrix at the next;
//! - the step length `α` by a secant on the directional derivative,
//!   `α = −s₀/(s₁ − s₀)`, `s_t = ∇G(x + t U δ) · U δ` (exact on a quadratic `G`; `α = 1` where
//!   the curvature along `U δ` is not positive), at most 2;
//! - `∇G(x) = M (x − y)/h² + ∇U(x) + Σ_k k_k (x_{n_k} − t_k)` on the free nodes.
//!
//! The coarse matrix is `Uᵀ H U` assembled element by element, never the fine `H`.

use crate::Vec3;
use crate::effect::NodeSpring;
use crate::fem::energy::for_each_element;
use crate::fem::geometry::deformation_gradient;
use crate::material::tangent::{contract_left, contract_right};
use crate::mesh::Mesh;
use crate::solver::potential::Potential;
use crate::solver::settings::SolverSettings;
use crate::solver::step::StepInput;
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// Cells per axis for a box of extents `ext_m`: near-cubic cells, at least one across every
/// direction however thin (a plate's bending needs the in-plane motion to vary across its
/// thickness), and no more than `cells_wanted` in all: a direction thinner than a cell gets one,
/// the cell size is set by the others, and the direction with the most cells gives one up until
/// the count fits.
fn grid_cells(ext_m: &Vec3, cells_wanted: usize) -> [usize; 3] {
    let mut thin = [false; 3];
    let mut cells = [1usize; 3];
    loop {
        let wide: Vec<usize> = (0..3).filter(|&a| !thin[a] && ext_m[a] > 0.0).collect();
        if wide.is_empty() {
            break;
        }
        let volume: f64 = wide.iter().map(|&a| ext_m[a]).product();
        let cell_size_m = (volume / cells_wanted as f64).powf(1.0 / wide.len() as f64);
        match wide.iter().find(|&&a| ext_m[a] < cell_size_m) {
            Some(&a) => thin[a] = true,
            None => {
                for &a in &wide {
                    cells[a] = ((ext_m[a] / cell_size_m).round() as usize).max(1);
                }
                break;
            }
        }
    }
    while cells.iter().product::<usize>() > cells_wanted {
        let Some(a) = (0..3).filter(|&a| cells[a] > 1).max_by_key(|&a| cells[a]) else { break };
        cells[a] -= 1;
    }
    cells
}

/// A fine node's coarse nodes (the 8 corners of its cell) and their trilinear weights.
type Corners = [(u32, f64); 8];

pub(crate) struct CoarseSpace {
    target_cells: u32,
    /// The grid: its lowest corner, cell size and nodes per axis (the coarse nodes' positions,
    /// which only the tests need: the weights already hold them).
    #[cfg_attr(not(test), allow(dead_code))]
    origin: Vec3,
    #[cfg_attr(not(test), allow(dead_code))]
    cell_m: Vec3,
    #[cfg_attr(not(test), allow(dead_code))]
    dims: [usize; 3],
    corners: Vec<Corners>,
    num_coarse: usize,
    factor: Option<Cholesky<f64, Dyn>>,
    /// Steps since the coarse matrix was made.
    age: u32,
    /// The model version and step it was made for.
    made_for: (u64, f64),
    grad: Vec<Vec3>,
    step: Vec<Vec3>,
    trial: Vec<Vec3>,
}

/// Steps a coarse matrix is kept before it is made again at the current positions.
pub(crate) const REFRESH_STEPS: u32 = 10;
/// Relative weight added to the coarse matrix's diagonal.
const REGULARISATION: f64 = 1e-9;
/// Fine nodes per coarse cell at least: a grid as fine as the mesh corrects nothing the sweeps
/// do not.
const NODES_PER_CELL: usize = 8;
/// Largest multiple of the coarse step the line search takes.
const MAX_STEP: f64 = 2.0;
/// A line-search step further than this from 1 marks the coarse matrix stale.
const STALE_STEP: f64 = 0.5;

/// The coarse grid's cell count the settings ask for; None when the correction is off.
pub(crate) fn coarse_cells(settings: &SolverSettings) -> Option<u32> {
    Some(settings.vbd.coarse_cells).filter(|&c| c > 0)
}

impl CoarseSpace {
    /// The coarse space `settings` ask for on `mesh`; None when off.
    pub fn for_settings(mesh: &Mesh, settings: &SolverSettings) -> Option<Self> {
        coarse_cells(settings).map(|c| Self::new(mesh, c))
    }

    pub fn target_cells(&self) -> u32 {
        self.target_cells
    }

    /// A grid of about `target_cells` near-cubic cells over the rest shape's bounding box.
    pub fn new(mesh: &Mesh, target_cells: u32) -> Self {
        let (lo, hi) = mesh
            .rest_positions
            .iter()
            .fold((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        let ext = hi - lo;
        let cells_wanted = (target_cells as usize).min(mesh.num_nodes() / NODES_PER_CELL).max(1);
        let cells = grid_cells(&ext, cells_wanted);
        let dims = cells.map(|c| c + 1);
        let corners = mesh
            .rest_positions
            .iter()
            .map(|p| {
                let mut cell = [0usize; 3];
                let mut t = [0.0; 3];
                for a in 0..3 {
                    let u = if ext[a] == 0.0 { 0.0 } else { (p[a] - lo[a]) / ext[a] * cells[a] as f64 };
                    let c = (u.floor() as isize).clamp(0, cells[a] as isize - 1) as usize;
                    cell[a] = c;
                    t[a] = (u - c as f64).clamp(0.0, 1.0);
                }
                std::array::from_fn(|k| {
                    let off = [k & 1, (k >> 1) & 1, (k >> 2) & 1];
                    let mut w = 1.0;
                    for a in 0..3 {
                        w *= if off[a] == 1 { t[a] } else { 1.0 - t[a] };
                    }
                    let (i, j, l) = (cell[0] + off[0], cell[1] + off[1], cell[2] + off[2]);
                    ((i + dims[0] * (j + dims[1] * l)) as u32, w)
                })
            })
            .collect();
        let cell_m = Vec3::from_fn(|a, _| ext[a] / cells[a] as f64);
        Self {
            target_cells,
            origin: lo,
            cell_m,
            dims,
            corners,
            num_coarse: dims.iter().product(),
            factor: None,
            age: 0,
            made_for: (u64::MAX, 0.0),
            grad: Vec::new(),
            step: Vec::new(),
            trial: Vec::new(),
        }
    }

    /// Makes `Uᵀ H U` at `x` and factors it; `None` factor when it is not positive definite.
    fn make(&mut self, s: &StepInput<'_>, x: &[Vec3], springs: &[NodeSpring]) {
        let n = 3 * self.num_coarse;
        let mut a = DMatrix::<f64>::zeros(n, n);
        let inv_h2_per_s2 = 1.0 / (s.inertia_h * s.inertia_h);
        let free = |i: usize| s.inv_mass[i] > 0.0;
        let add_node_diag = |a: &mut DMatrix<f64>, i: usize, k: f64| {
            for &(cj, wj) in &self.corners[i] {
                for &(ck, wk) in &self.corners[i] {
                    let v = k * wj * wk;
                    for c in 0..3 {
                        a[(3 * cj as usize + c, 3 * ck as usize + c)] += v;
                    }
                }
            }
        };
        for i in 0..x.len() {
            if free(i) {
                add_node_diag(&mut a, i, s.masses_kg[i] * inv_h2_per_s2);
            }
        }
        for sp in springs {
            if free(sp.node as usize) {
                add_node_diag(&mut a, sp.node as usize, sp.stiffness_n_per_m);
            }
        }
        if s.material.volume_measure == crate::material::VolumeMeasure::Point {
            self.add_point_stiffness(&mut a, s, x);
        } else {
            self.add_term_stiffness(&mut a, s, x);
        }
        // coarse nodes no free node reaches: identity rows (their δ is then zero); and a relative
        // 1e-9 on the diagonal, as where the grid resolves more than the mesh `U z = 0` for some
        // `z`: the factor then exists, and such a `z` in `δ` moves no node
        for d in 0..n {
            a[(d, d)] = if a[(d, d)] == 0.0 { 1.0 } else { a[(d, d)] * (1.0 + REGULARISATION) };
        }
        self.factor = Cholesky::new(a);
    }

    /// `Uᵀ K U` of the elastic stiffness, point by point (the point law's projected tangent).
    fn add_point_stiffness(&self, a: &mut DMatrix<f64>, s: &StepInput<'_>, x: &[Vec3]) {
        let free = |i: usize| s.inv_mass[i] > 0.0;
        // per element: its free nodes' coarse nodes `J` (local list) and, per point, the coarse
        // gradients `G_J = Σ_a φ_J(X_a) ∇_X N_a(r_q)`, so that `δF_q = Σ_J δ_J ⊗ G_J` and the
        // element adds `V_q Σ_{c,d} ∂P_{rc}/∂F_{kd} (G_J)_c (G_K)_d` to block `(J, K)`
        let corners = &self.corners;
        let (mut local, mut slots, mut weights) =
            (Vec::<u32>::new(), Vec::<(usize, usize, f64)>::new(), Vec::<f64>::new());
        let (mut gq, mut t) = (Vec::<Vec3>::new(), Vec::<[f64; 27]>::new());
        for_each_element(s.mesh, s.geometry, x, |el| {
            let n = el.nodes.len();
            // the element's coarse nodes `local`, each free node's weights on them by local index
            local.clear();
            slots.clear();
            for (a, &i) in el.nodes.iter().enumerate() {
                if free(i as usize) {
                    for &(c, wc) in &corners[i as usize] {
                        if wc != 0.0 {
                            let j = local.iter().position(|&l| l == c).unwrap_or_else(|| {
                                local.push(c);
                                local.len() - 1
                            });
                            slots.push((a, j, wc));
                        }
                    }
                }
            }
            let m = local.len();
            if m == 0 {
                return;
            }
            // weights[a · m + j] = φ_{local[j]}(X_a) on free nodes
            weights.clear();
            weights.resize(n * m, 0.0);
            for &(a, j, wc) in &slots {
                weights[a * m + j] += wc;
            }
            let grads = el.grads();
            gq.resize(m, Vec3::zeros());
            t.resize(m, [0.0; 27]);
            for (q, &v) in el.volumes().iter().enumerate() {
                let g = &grads[q * n..(q + 1) * n];
                for (j, gj) in gq.iter_mut().enumerate() {
                    *gj = g.iter().enumerate().map(|(a, ga)| ga * weights[a * m + j]).sum();
                }
                let f = deformation_gradient(el.x, el.rest, g);
                let c = s.material.dpdf_projected(&f);
                // C(G_J, G_K) in two stages ([`contract_right`], then [`contract_left`])
                for (tk, gk) in t.iter_mut().zip(gq.iter()) {
                    *tk = contract_right(&c, gk);
                }
                for (j, gj) in gq.iter().enumerate() {
                    let row = 3 * local[j] as usize;
                    for (kk, tk) in t.iter().enumerate() {
                        let col = 3 * local[kk] as usize;
                        let b = contract_left(tk, gj);
                        for r in 0..3 {
                            for k in 0..3 {
                                a[(row + r, col + k)] += v * b[(r, k)];
                            }
                        }
                    }
                }
            }
        });
    }

    /// `Uᵀ K U` of the elastic stiffness term by term where the formulation's Hessian is not the
    /// point law's (the mixed formulation: each element's Hessian with its pressure, P1's node
    /// patches' dense terms, [`crate::fem::energy::mixed::patch::hessian_terms`]; projected): the
    /// locked pointwise tangent made the coarse correction all but useless at ν = 0.4999.
    fn add_term_stiffness(&self, a: &mut DMatrix<f64>, s: &StepInput<'_>, x: &[Vec3]) {
        let corners = &self.corners;
        let free = |i: usize| s.inv_mass[i] > 0.0;
        let add = |nodes: &[u32], h: &DMatrix<f64>| {
            for (li, &i) in nodes.iter().enumerate().filter(|(_, i)| free(**i as usize)) {
                for (lj, &j) in nodes.iter().enumerate().filter(|(_, j)| free(**j as usize)) {
                    for &(ci, wi) in &corners[i as usize] {
                        for &(cj, wj) in &corners[j as usize] {
                            let w = wi * wj;
                            if w == 0.0 {
                                continue;
                            }
                            let (row, col) = (3 * ci as usize, 3 * cj as usize);
                            for r in 0..3 {
                                for k in 0..3 {
                                    a[(row + r, col + k)] += w * h[(3 * li + r, 3 * lj + k)];
                                }
                            }
                        }
                    }
                }
            }
        };
        crate::solver::sparse::for_each_hessian_term(s.mesh, s.geometry, s.material, x, true, add);
    }

    /// Starts a step: the coarse matrix is remade when it is [`REFRESH_STEPS`] old, when the
    /// last correction's line search found it far off, or when the model or the step changed.
    pub fn begin_step(&mut self, s: &StepInput<'_>, x: &[Vec3], springs: &[NodeSpring]) {
        let made_for = (s.model_version, s.inertia_h);
        if self.made_for != made_for || self.factor.is_none() || self.age >= REFRESH_STEPS {
            self.make(s, x, springs);
            self.made_for = made_for;
            self.age = 0;
        }
        self.age += 1;
    }

    /// `Uᵀ g`: a per-node field restricted to the coarse nodes (held nodes' rows of `U` are zero).
    fn restrict(&self, g: &[Vec3], inv_mass: &[f64]) -> DVector<f64> {
        let mut r = DVector::<f64>::zeros(3 * self.num_coarse);
        for (i, gi) in g.iter().enumerate() {
            if inv_mass[i] == 0.0 {
                continue;
            }
            for &(c, wc) in &self.corners[i] {
                for k in 0..3 {
                    r[3 * c as usize + k] += wc * gi[k];
                }
            }
        }
        r
    }

    /// One coarse correction of the free nodes of `x` towards the minimiser of `G`, scaled by
    /// the secant line search; returns whether it moved them.
    pub fn correct(&mut self, s: &StepInput<'_>, x: &mut [Vec3], y: &[Vec3], springs: &[NodeSpring]) -> bool {
        let Some(factor) = &self.factor else { return false };
        potential_gradient(s, x, y, springs, &mut self.grad);
        let r = -self.restrict(&self.grad, s.inv_mass);
        let delta = factor.solve(&r);
        self.step.clear();
        self.step.resize(x.len(), Vec3::zeros());
        for (i, d) in self.step.iter_mut().enumerate() {
            if s.inv_mass[i] == 0.0 {
                continue;
            }
            for &(c, wc) in &self.corners[i] {
                let c = 3 * c as usize;
                *d += Vec3::new(delta[c], delta[c + 1], delta[c + 2]) * wc;
            }
        }
        let slope0 = dot(&self.grad, &self.step);
        if !(slope0 < 0.0) {
            // no unbalanced force the coarse space sees (or a non-finite one)
            return false;
        }
        self.trial.clear();
        self.trial.extend(x.iter().zip(&self.step).map(|(xi, d)| xi + d));
        potential_gradient(s, &self.trial, y, springs, &mut self.grad);
        let slope1 = dot(&self.grad, &self.step);
        if !slope1.is_finite() {
            self.age = REFRESH_STEPS;
            return false;
        }
        let curvature = slope1 - slope0;
        let alpha = if curvature > 0.0 { (-slope0 / curvature).min(MAX_STEP) } else { 1.0 };
        if (alpha - 1.0).abs() > STALE_STEP {
            self.age = REFRESH_STEPS;
        }
        for (xi, d) in x.iter_mut().zip(&self.step) {
            *xi += d * alpha;
        }
        true
    }
}

/// `∇G(x)` into `out`: Newton's [`Potential`] (zero on held nodes).
fn potential_gradient(s: &StepInput<'_>, x: &[Vec3], y: &[Vec3], springs: &[NodeSpring], out: &mut Vec<Vec3>) {
    out.resize(x.len(), Vec3::zeros());
    Potential { input: s, y, springs, w: 1.0 / (s.inertia_h * s.inertia_h) }.eval(x, out);
}

/// `Σ_i a_i · b_i` over the nodes `b` moves (held nodes have `b_i = 0`).
fn dot(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a.dot(b)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::{Clamp, Effect, Gravity};
    use crate::element::ElementType;
    use crate::material::{Material, MaterialModel};
    use crate::solver::tests::{G, beam, clamped_at_x0};
    use crate::solver::{Simulation, SolverSettings};

    impl CoarseSpace {
        fn node_position(&self, j: usize) -> Vec3 {
            let idx = [j % self.dims[0], (j / self.dims[0]) % self.dims[1], j / (self.dims[0] * self.dims[1])];
            self.origin + Vec3::from_fn(|a, _| idx[a] as f64 * self.cell_m[a])
        }

        /// `Uᵀ ∇G(x)` on the coarse nodes.
        fn coarse_gradient(&mut self, s: &StepInput<'_>, x: &[Vec3], y: &[Vec3]) -> f64 {
            potential_gradient(s, x, y, &[], &mut self.grad);
            self.restrict(&self.grad, s.inv_mass).norm()
        }
    }

    /// Near-cubic cells, one across a thin direction, never more than asked for in all.
    #[test]
    fn the_grid_has_near_cubic_cells_and_at_most_the_cells_asked_for() {
        assert_eq!(grid_cells(&Vec3::new(2.0, 0.5, 0.5), 32), [8, 2, 2]);
        assert_eq!(grid_cells(&Vec3::new(1.0, 1.0, 1.0), 27), [3, 3, 3]);
        // a plate: one cell across its thickness, the rest square
        let plate = grid_cells(&Vec3::new(1.0, 1.0, 1e-3), 32);
        assert_eq!(plate[2], 1);
        assert!(plate[0].abs_diff(plate[1]) <= 1 && plate.iter().product::<usize>() <= 32, "{plate:?}");
        // a rod, a point, a count below what rounding gives
        assert_eq!(grid_cells(&Vec3::new(1.0, 1e-9, 1e-9), 32), [32, 1, 1]);
        assert_eq!(grid_cells(&Vec3::zeros(), 32), [1, 1, 1]);
        for wanted in 1..=300 {
            for ext in [Vec3::new(2.0, 0.5, 0.5), Vec3::new(1.0, 1.0, 1e-3), Vec3::new(0.3, 5.0, 1.0)] {
                let cells = grid_cells(&ext, wanted);
                assert!(cells.iter().product::<usize>() <= wanted, "{ext:?} {wanted}: {cells:?}");
            }
        }
    }

    /// Trilinear interpolation is a partition of unity and reproduces affine fields, so the
    /// coarse space holds the rigid translations and every uniform strain, on a beam and on a
    /// flat body (one cell across its thickness).
    #[test]
    fn the_prolongation_is_a_partition_of_unity_that_reproduces_affine_fields() {
        let flat = {
            let mut m = beam(ElementType::from_name("q1").unwrap(), [4, 2, 1]);
            m.rest_positions.iter_mut().for_each(|p| p.z *= 1e-6);
            m
        };
        for (mesh, cells) in [(beam(ElementType::from_name("p2").unwrap(), [4, 1, 1]), 32), (flat, 16)] {
            let c = CoarseSpace::new(&mesh, cells);
            assert!(c.num_coarse > 8, "a grid of {:?} nodes", c.dims);
            let affine = |p: &Vec3| Vec3::new(0.3 + 2.0 * p.x - p.y, -1.0 + 0.5 * p.z, p.x + p.y + p.z);
            for (i, p) in mesh.rest_positions.iter().enumerate() {
                let w: f64 = c.corners[i].iter().map(|&(_, w)| w).sum();
                assert!((w - 1.0).abs() < 1e-12, "node {i}: weights sum to {w}");
                assert!(c.corners[i].iter().all(|&(_, w)| (0.0..=1.0).contains(&w)));
                let at: Vec3 = c.corners[i].iter().map(|&(j, w)| affine(&c.node_position(j as usize)) * w).sum();
                assert!((at - affine(p)).norm() < 1e-9, "node {i}: {at} against {}", affine(p));
            }
        }
    }

    /// On a potential close to quadratic (small displacements), one correction with a matrix
    /// made at the current positions is the Galerkin projection: the coarse gradient `Uᵀ∇G`
    /// all but vanishes and `G` falls; the line search takes about the whole step.
    #[test]
    fn a_fresh_correction_removes_the_coarse_gradient_on_a_nearly_quadratic_potential() {
        for et in ["p1", "p2", "q2"] {
            let mesh = beam(ElementType::from_name(et).unwrap(), [4, 1, 1]);
            let clamped = clamped_at_x0(&mesh);
            let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
            let settings = SolverSettings::default();
            let effects: Vec<Box<dyn Effect>> =
                vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped.clone() })];
            let sim = Simulation::new(mesh, material, settings, effects).unwrap();
            let mut inv_mass = sim.inv_mass().to_vec();
            clamped.iter().for_each(|&i| inv_mass[i as usize] = 0.0);
            let s = StepInput {
                mesh: sim.mesh(),
                geometry: sim.geometry(),
                material: sim.material(),
                masses_kg: sim.masses_kg(),
                inv_mass: &inv_mass,
                prev_positions: &sim.mesh().rest_positions,
                body_acceleration: Vec3::zeros(),
                h: 1.0 / 60.0,
                inertia_h: 1.0 / 60.0,
                guess: None,
                settings: &settings,
                model_version: 1,
            };
            // the inertial target: a small bend plus a node-to-node ripple; x starts at rest
            let y: Vec<Vec3> = sim
                .mesh()
                .rest_positions
                .iter()
                .enumerate()
                .map(|(i, p)| p + Vec3::new(0.0, 0.0, 1e-6 * p.x * p.x + 1e-8 * (i % 3) as f64 * p.x))
                .collect();
            let mut x = sim.mesh().rest_positions.clone();
            let mut c = CoarseSpace::new(sim.mesh(), 16);
            c.begin_step(&s, &x, &[]);
            let energy = |x: &[Vec3]| {
                let w = 0.5 / (s.inertia_h * s.inertia_h);
                crate::fem::energy::total_energy(s.mesh, s.geometry, s.material, x)
                    + x.iter().zip(&y).zip(s.masses_kg).map(|((a, b), m)| w * m * (a - b).norm_squared()).sum::<f64>()
            };
            let (before, g_before) = (energy(&x), c.coarse_gradient(&s, &x, &y));
            assert!(c.factor.is_some(), "{et}: the coarse matrix is not positive definite");
            assert!(c.correct(&s, &mut x, &y, &[]), "{et}: no correction");
            let (after, g_after) = (energy(&x), c.coarse_gradient(&s, &x, &y));
            assert!(after < before, "{et}: G rose from {before:.6e} to {after:.6e}");
            assert!(g_after < 1e-6 * g_before, "{et}: coarse gradient {g_before:.3e} -> {g_after:.3e}");
            assert!(
                clamped.iter().all(|&i| x[i as usize] == sim.mesh().rest_positions[i as usize]),
                "held nodes moved"
            );
        }
    }
}
