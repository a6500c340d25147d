//! The sparse stiffness shared by the static solver and Newton's implicit Euler: the pattern of
//! `K = D + Σ_e Σ_q V_q Gᵀ ∂P/∂F|_projected G` on the free degrees of freedom (lower triangle,
//! `D` a diagonal such as `M/h²`, zero for statics), its assembly from the element Hessians
//! (computed in parallel, summed in a fixed order) and its sparse Cholesky factorisation
//! (`faer`, AMD ordering, the symbolic analysis done once per pattern and the numeric one kept
//! for reuse).

use crate::Vec3;
use crate::fem::energy::{element_grads, element_hessian};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, Par, Side};
use nalgebra::DMatrix;

/// What went wrong with the sparse stiffness.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum SparseError {
    /// The pattern or the symbolic analysis could not be built.
    Pattern(String),
    /// The stiffness is not positive definite on the free degrees of freedom.
    NotPositiveDefinite,
}

/// The free-DOF stiffness pattern (lower triangle, with every diagonal entry), its value order,
/// its symbolic Cholesky factorisation and the last numeric factor.
pub(crate) struct SparsePattern {
    pub free_dofs: usize,
    /// Global DOF `3 i + a` → free DOF, `usize::MAX` for a held one.
    pub dof_of: Vec<usize>,
    symbolic: SymbolicSparseColMat<usize>,
    argsort: faer::sparse::Argsort<usize>,
    cholesky: SymbolicCholesky<usize>,
    factor: Vec<f64>,
    factored: bool,
}

impl SparsePattern {
    /// The pattern of `mesh` with the DOFs of nodes where `held(i)` left out.
    pub fn new(mesh: &Mesh, held: impl Fn(usize) -> bool) -> Result<Self, SparseError> {
        let n = mesh.num_nodes();
        let mut dof_of = vec![usize::MAX; 3 * n];
        let mut free_dofs = 0;
        for (d, slot) in dof_of.iter_mut().enumerate() {
            if !held(d / 3) {
                *slot = free_dofs;
                free_dofs += 1;
            }
        }
        let mut pairs = Vec::new();
        for block in &mesh.blocks {
            for nodes in block.elements() {
                for_each_element_entry(&dof_of, nodes, |row, col, _, _| pairs.push(Pair::new(row, col)));
            }
        }
        pairs.extend((0..free_dofs).map(|d| Pair::new(d, d)));
        let pattern = |e: &dyn std::fmt::Debug| SparseError::Pattern(format!("{e:?}"));
        let (symbolic, argsort) =
            SymbolicSparseColMat::try_new_from_indices(free_dofs, free_dofs, &pairs).map_err(|e| pattern(&e))?;
        let cholesky = factorize_symbolic_cholesky(
            symbolic.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| pattern(&e))?;
        let factor = vec![0.0; cholesky.len_val()];
        Ok(Self { free_dofs, dof_of, symbolic, argsort, cholesky, factor, factored: false })
    }

    /// Assembles `K` at `x` plus `diagonal` (one value per free DOF, or empty for none) and
    /// factors it with parallelism `par`. With `projected`, `∂P/∂F` is projected to positive
    /// semi-definite at each quadrature point (always factorisable where the body is held or
    /// the diagonal positive); without, `K` is the exact Hessian (Newton's quadratic
    /// convergence), which may not be positive definite.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble_and_factor(
        &mut self,
        mesh: &Mesh,
        geo: &[BlockGeometry],
        material: &Material,
        x: &[Vec3],
        diagonal: &[f64],
        projected: bool,
        par: Par,
    ) -> Result<(), SparseError> {
        self.factored = false;
        let dof_of = &self.dof_of;
        let mut values = Vec::with_capacity(self.symbolic.compute_nnz());
        let per_element = map_element_hessians(mesh, geo, material, x, projected, |nodes, he| {
            let mut v = Vec::new();
            for_each_element_entry(dof_of, nodes, |_, _, i, j| v.push(he[(i, j)]));
            v
        });
        per_element.iter().for_each(|v| values.extend_from_slice(v));
        if diagonal.is_empty() {
            values.extend(std::iter::repeat_n(0.0, self.free_dofs));
        } else {
            values.extend_from_slice(diagonal);
        }
        let k = SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, &values)
            .map_err(|e| SparseError::Pattern(format!("{e:?}")))?;
        let scratch = self.cholesky.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buffer = MemBuffer::try_new(scratch).map_err(|e| SparseError::Pattern(format!("{e:?}")))?;
        self.cholesky
            .factorize_numeric_llt(
                &mut self.factor,
                k.as_ref(),
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|_| SparseError::NotPositiveDefinite)?;
        self.factored = self.factor.iter().all(|v| v.is_finite());
        if self.factored { Ok(()) } else { Err(SparseError::NotPositiveDefinite) }
    }

    /// Whether a numeric factor is held.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Solves `K s = r` in place with the last factor (which must exist).
    pub fn solve_in_place(&self, r: &mut [f64], par: Par) {
        debug_assert!(self.factored);
        let mut rhs = faer::MatMut::from_column_major_slice_mut(r, self.free_dofs, 1);
        let scratch = self.cholesky.solve_in_place_scratch::<f64>(1, par);
        let mut buffer = MemBuffer::new(scratch);
        LltRef::new(&self.cholesky, &self.factor).solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            par,
            MemStack::new(&mut buffer),
        );
    }
}

/// Visits every lower-triangle entry of one element's Hessian that couples two free DOFs, in a
/// fixed order: `(global row, global col, local row, local col)`.
fn for_each_element_entry(dof_of: &[usize], nodes: &[u32], mut visit: impl FnMut(usize, usize, usize, usize)) {
    for (li, &ni) in nodes.iter().enumerate() {
        for a in 0..3 {
            let row = dof_of[3 * ni as usize + a];
            if row == usize::MAX {
                continue;
            }
            for (lj, &nj) in nodes.iter().enumerate() {
                for c in 0..3 {
                    let col = dof_of[3 * nj as usize + c];
                    if col == usize::MAX || row < col {
                        continue;
                    }
                    visit(row, col, 3 * li + a, 3 * lj + c);
                }
            }
        }
    }
}

/// Every element's Hessian at `x` (`projected`: PSD-projected per quadrature point), computed in
/// parallel and handed to `f` with the element's nodes; the results in mesh order, block by block,
/// so sums over them take a fixed order (the sparse assembly here, Newton-CG's element Hessians).
pub(crate) fn map_element_hessians<T: Send>(
    mesh: &Mesh,
    geo: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    projected: bool,
    f: impl Fn(&[u32], DMatrix<f64>) -> T + Sync,
) -> Vec<T> {
    use rayon::prelude::*;
    let mut out = Vec::with_capacity(mesh.num_elements());
    for (b, g) in mesh.blocks.iter().zip(geo) {
        let per_element: Vec<T> = (0..b.len())
            .into_par_iter()
            .with_min_len(16)
            .map(|e| {
                let nodes = b.element(e);
                f(nodes, element_hessian_at(mesh, g, e, nodes, material, x, projected))
            })
            .collect();
        out.extend(per_element);
    }
    out
}

/// The Hessian of element `e` (nodes `nodes`) at positions `x` (`projected`: PSD-projected per
/// quadrature point).
pub(crate) fn element_hessian_at(
    mesh: &Mesh,
    g: &BlockGeometry,
    e: usize,
    nodes: &[u32],
    material: &Material,
    x: &[Vec3],
    projected: bool,
) -> DMatrix<f64> {
    let xl: Vec<Vec3> = nodes.iter().map(|&i| x[i as usize]).collect();
    let rest: Vec<Vec3> = nodes.iter().map(|&i| mesh.rest_positions[i as usize]).collect();
    element_hessian(&xl, &rest, element_grads(g, e), g.volumes(e), material, projected)
}

/// The dense Hessian of the total elastic energy at `x` (projected per quadrature point), for
/// small problems such as modal analysis in tests.
pub fn assemble_dense(mesh: &Mesh, geo: &[BlockGeometry], material: &Material, x: &[Vec3]) -> DMatrix<f64> {
    let n = mesh.num_nodes();
    let mut k = DMatrix::zeros(3 * n, 3 * n);
    for (b, gb) in mesh.blocks.iter().zip(geo) {
        for (e, nodes) in b.elements().enumerate() {
            let he = element_hessian_at(mesh, gb, e, nodes, material, x, true);
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
