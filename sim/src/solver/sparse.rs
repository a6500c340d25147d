//! The sparse stiffness shared by the static solver and Newton's implicit Euler: the pattern of
//! `K = D + Σ_e Σ_q V_q Gᵀ ∂P/∂F|_projected G` on the free degrees of freedom (lower triangle,
//! `D` a diagonal such as `M/h²`, zero for statics), its assembly from the element Hessians
//! (computed in parallel, summed in a fixed order) and its sparse Cholesky factorisation
//! (`faer`'s supernodal `L Lᵀ`, the symbolic analysis done once per pattern and the numeric one
//! kept for reuse).
//!
//! Made for 100k degrees of freedom (issue #37, docs/journal/performance.md session 22): the pattern
//! comes from the node graph (AMD on it, a ninth of the scalar graph: the same fill, since AMD
//! merges a node's three indistinguishable degrees of freedom anyway), `K` is assembled straight
//! into its compressed columns in elimination order (no triplets, no sort, no permuted copy inside
//! the factorisation), with `u32` indices; the element Hessians come from the two-stage,
//! one-triangle kernel of `fem::energy`. On the 33,748-node P3 tube: 100,128 unknowns, a
//! 52-million-entry factor (418 MB of the 577 MB the whole `hox static` takes at its peak).
//! Nested dissection by coordinate bisection was tried for the ordering and filled 2–50 % more
//! than AMD on every mesh of the project (session 22).

use crate::Vec3;
use crate::fem::energy::mixed::patch;
use crate::fem::energy::{element_grads, element_hessian};
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
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

/// The free-DOF stiffness pattern (lower triangle, with every diagonal entry), its node graph,
/// its symbolic Cholesky factorisation and the last numeric factor.
///
/// A node is held or free as a whole, so the free degrees of freedom come in triples (free node
/// `k` owns `3k`, `3k + 1`, `3k + 2`) and the pattern is built from the node graph: column
/// `3j + b` holds rows `3j + b … 3j + 2`, then the three rows of every neighbour `i > j` in
/// increasing order, so an entry's place follows from the neighbour's place in node `j`'s list
/// (no sort of the element entries, no index per entry). The fill-reducing ordering is AMD on
/// the node graph (a ninth of the scalar graph's entries), each node's three degrees of freedom
/// kept together, which the supernodal factorisation then finds as dense blocks.
pub(crate) struct SparsePattern {
    pub free_dofs: usize,
    /// Global DOF `3 i + a` → free DOF, `usize::MAX` for a held one.
    pub dof_of: Vec<usize>,
    /// Global node → its place in the elimination order (`u32::MAX` for a held node), and free
    /// DOF `3k + a` (natural order) → `3 place[k] + a`: `K` is stored and factored in that
    /// order, so the factorisation needs no permuted copy of it.
    place_of_node: Vec<u32>,
    place_of_free: Vec<u32>,
    /// Per place `j`, its neighbours `i ≥ j` (itself first), sorted:
    /// `node_rows[node_col_ptr[j]..node_col_ptr[j + 1]]`.
    node_col_ptr: Vec<usize>,
    node_rows: Vec<u32>,
    symbolic: SymbolicSparseColMat<u32>,
    /// `K`'s values in the order of [`Self::symbolic`].
    values: Vec<f64>,
    cholesky: SymbolicCholesky<u32>,
    factor: Vec<f64>,
    /// The factor in single precision, when the last factorisation asked for it (empty until).
    factor_single: Vec<f32>,
    /// Whether the held factor is [`Self::factor_single`].
    single: bool,
    /// Whether a time step's factor may be single precision (`NewtonPolicy::Interactive`).
    pub single_precision: bool,
    factored: bool,
    /// What the pattern's work has cost so far.
    pub cost: SparseCost,
}

/// Where a sparse stiffness spent its time, cumulative over its life (`hox static --json`'s
/// `cost`, docs/PERFORMANCE.md): the pattern and its symbolic analysis (the fill-reducing
/// ordering included), the element Hessians with their assembly, the numeric factorisations and
/// the triangular solves; with the sizes that set them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SparseCost {
    /// The pattern, its fill-reducing ordering and the symbolic factorisation (once).
    pub pattern_secs: f64,
    /// The element Hessians and their assembly into `K` (every factorisation).
    pub hessian_secs: f64,
    /// The numeric Cholesky factorisations.
    pub factor_secs: f64,
    /// The triangular solves with the factor.
    pub solve_secs: f64,
    /// Numeric factorisations made.
    pub factorisations: usize,
    /// Stored entries of `K`'s lower triangle.
    pub matrix_nonzeros: usize,
    /// Stored entries of the Cholesky factor `L`.
    pub factor_nonzeros: usize,
}

/// Elements whose Hessians are computed in parallel before they are added to `K` in mesh order
/// (bounds the memory they take: 64 P3 Hessians are 1.8 MB).
const ASSEMBLY_CHUNK: usize = 64;

impl SparsePattern {
    /// The pattern of `mesh` under `material` with the DOFs of nodes where `held(i)` left out
    /// (widened to every node patch's pairs where the formulation measures the volume per patch:
    /// [`crate::fem::energy::mixed::patch`]).
    pub fn new(mesh: &Mesh, material: &Material, held: impl Fn(usize) -> bool) -> Result<Self, SparseError> {
        let started = web_time::Instant::now();
        let pattern = |e: &dyn std::fmt::Debug| SparseError::Pattern(format!("{e:?}"));
        let n = mesh.num_nodes();
        let mut free_of = vec![u32::MAX; n];
        let mut free_nodes = 0usize;
        for (i, slot) in free_of.iter_mut().enumerate() {
            if !held(i) {
                *slot = free_nodes as u32;
                free_nodes += 1;
            }
        }
        let dof_of: Vec<usize> = (0..3 * n)
            .map(|d| if free_of[d / 3] == u32::MAX { usize::MAX } else { 3 * free_of[d / 3] as usize + d % 3 })
            .collect();
        let free_dofs = 3 * free_nodes;
        // the node graph (natural order), its AMD ordering, then the graph in that order
        let natural = node_graph(mesh, material, &free_of, free_nodes);
        let (mut perm, mut place_of_free) = (vec![0u32; free_nodes], vec![0u32; free_nodes]);
        {
            let graph = SymbolicSparseColMat::new_checked(free_nodes, free_nodes, natural.0, None, natural.1);
            let scratch = amd::order_scratch::<u32>(free_nodes, graph.compute_nnz());
            let mut buffer = MemBuffer::try_new(scratch).map_err(|e| pattern(&e))?;
            amd::order(
                &mut perm,
                &mut place_of_free,
                graph.as_ref(),
                amd::Control::default(),
                MemStack::new(&mut buffer),
            )
            .map_err(|e| pattern(&e))?;
        }
        let place_of_node: Vec<u32> =
            free_of.iter().map(|&k| if k == u32::MAX { u32::MAX } else { place_of_free[k as usize] }).collect();
        let (node_col_ptr, node_rows) = node_graph(mesh, material, &place_of_node, free_nodes);
        let node_col_ptr: Vec<usize> = node_col_ptr.iter().map(|&v| v as usize).collect();
        // the scalar pattern, column by column
        let mut col_ptr = Vec::with_capacity(free_dofs + 1);
        col_ptr.push(0u32);
        let mut row_idx: Vec<u32> = Vec::new();
        for j in 0..free_nodes {
            let rows = &node_rows[node_col_ptr[j]..node_col_ptr[j + 1]];
            for b in 0..3 {
                row_idx.extend((b..3).map(|a| (3 * j + a) as u32));
                row_idx.extend(rows[1..].iter().flat_map(|&i| (0..3).map(move |a| 3 * i + a)));
                col_ptr.push(u32::try_from(row_idx.len()).map_err(|e| pattern(&e))?);
            }
        }
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(free_dofs, free_dofs, col_ptr, None, row_idx);
        // (faer's symbolic analysis without an ordering reads the upper triangle whatever side it
        // is told, so it is given the transpose; the numeric one then takes the lower as it is)
        let upper = transposed(free_dofs, symbolic.col_ptr(), symbolic.row_idx());
        let cholesky = factorize_symbolic_cholesky(
            upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| pattern(&e))?;
        drop(upper);
        release_freed_memory();
        let factor = vec![0.0; cholesky.len_val()];
        let cost = SparseCost {
            pattern_secs: started.elapsed().as_secs_f64(),
            matrix_nonzeros: nnz,
            factor_nonzeros: cholesky.len_val(),
            ..SparseCost::default()
        };
        Ok(Self {
            free_dofs,
            dof_of,
            place_of_node,
            place_of_free,
            node_col_ptr,
            node_rows,
            symbolic,
            values: vec![0.0; nnz],
            cholesky,
            factor,
            factor_single: Vec::new(),
            single: false,
            single_precision: false,
            factored: false,
            cost,
        })
    }

    /// The internal (eliminated-order) index of natural free DOF `d`.
    fn place(&self, d: usize) -> usize {
        3 * self.place_of_free[d / 3] as usize + d % 3
    }

    /// Adds one element's Hessian `he` (nodes `nodes`) to [`Self::values`].
    fn add_element(&mut self, nodes: &[u32], he: &DMatrix<f64>) {
        let col_ptr = self.symbolic.col_ptr();
        for (lj, &nj) in nodes.iter().enumerate() {
            let j = self.place_of_node[nj as usize];
            if j == u32::MAX {
                continue;
            }
            let rows = &self.node_rows[self.node_col_ptr[j as usize]..self.node_col_ptr[j as usize + 1]];
            for (li, &ni) in nodes.iter().enumerate() {
                let i = self.place_of_node[ni as usize];
                if i == u32::MAX || i < j {
                    continue;
                }
                let place = rows.binary_search(&i).expect("the pattern holds every element's node pairs");
                for b in 0..3 {
                    let col = 3 * j as usize + b;
                    let column = &mut self.values[col_ptr[col] as usize..col_ptr[col + 1] as usize];
                    // column 3j + b: its own node's rows 3j + b … 3j + 2 first, then three rows per
                    // neighbour
                    if place == 0 {
                        for a in b..3 {
                            column[a - b] += he[(3 * li + a, 3 * lj + b)];
                        }
                    } else {
                        let from = (3 - b) + 3 * (place - 1);
                        for a in 0..3 {
                            column[from + a] += he[(3 * li + a, 3 * lj + b)];
                        }
                    }
                }
            }
        }
    }

    /// Assembles `K` at `x` plus `diagonal` (one value per free DOF, or empty for none) and
    /// factors it with parallelism `par`. With `projected`, `∂P/∂F` is projected to positive
    /// semi-definite at each quadrature point (always factorisable where the body is held or
    /// the diagonal positive); without, `K` is the exact Hessian (Newton's quadratic
    /// convergence), which may not be positive definite. With `single`, `K` is rounded to `f32`
    /// and factored in single precision: half the memory traffic of every later solve (which is
    /// memory-bound: on the P2 tube's 3.8 M-entry factor a double solve moves 61 MB), for a
    /// caller that corrects the solve's error itself (Newton's iteration does, as iterative
    /// refinement would). The element Hessians are computed in parallel, [`ASSEMBLY_CHUNK`] at a
    /// time, and added in mesh order (the same sums on any number of threads).
    #[allow(clippy::too_many_arguments)]
    pub fn assemble_and_factor(
        &mut self,
        mesh: &Mesh,
        geo: &[BlockGeometry],
        material: &Material,
        x: &[Vec3],
        diagonal: &[f64],
        projected: bool,
        single: bool,
        par: Par,
    ) -> Result<(), SparseError> {
        use rayon::prelude::*;
        self.factored = false;
        let started = web_time::Instant::now();
        self.values.iter_mut().for_each(|v| *v = 0.0);
        if patch::has_patches(mesh, material) {
            patch::hessian_terms(mesh, geo, material, x, projected, |nodes, h| self.add_element(nodes, h));
        }
        for (b, g) in mesh.blocks.iter().zip(geo) {
            if patch::is_patch_block(b, material) {
                continue;
            }
            for chunk_start in (0..b.len()).step_by(ASSEMBLY_CHUNK) {
                let chunk = chunk_start..(chunk_start + ASSEMBLY_CHUNK).min(b.len());
                let hessians: Vec<DMatrix<f64>> = chunk
                    .clone()
                    .into_par_iter()
                    .with_min_len(16)
                    .map(|e| element_hessian_at(mesh, g, e, b.element(e), material, x, projected))
                    .collect();
                for (e, he) in chunk.zip(&hessians) {
                    self.add_element(b.element(e), he);
                }
            }
        }
        if !diagonal.is_empty() {
            // each column's first entry is its diagonal
            for (d, value) in diagonal.iter().enumerate() {
                let first = self.symbolic.col_ptr()[self.place(d)] as usize;
                self.values[first] += value;
            }
        }
        let k = SparseColMatRef::new(self.symbolic.as_ref(), &self.values);
        let assembled = web_time::Instant::now();
        self.cost.hessian_secs += (assembled - started).as_secs_f64();
        self.cost.factorisations += 1;
        self.single = single;
        let outcome = if single {
            let values: Vec<f32> = self.values.iter().map(|&v| v as f32).collect();
            self.factor_single.resize(self.cholesky.len_val(), 0.0);
            factor_numeric(
                &self.cholesky,
                &mut self.factor_single,
                SparseColMatRef::new(self.symbolic.as_ref(), &values),
                par,
            )
        } else {
            factor_numeric(&self.cholesky, &mut self.factor, k, par)
        };
        self.cost.factor_secs += assembled.elapsed().as_secs_f64();
        outcome?;
        self.factored = if single {
            self.factor_single.iter().all(|v| v.is_finite())
        } else {
            self.factor.iter().all(|v| v.is_finite())
        };
        if self.factored { Ok(()) } else { Err(SparseError::NotPositiveDefinite) }
    }

    /// Drops the numeric factor (the matrix's values changed); the pattern and its symbolic
    /// analysis are kept.
    pub fn forget_factor(&mut self) {
        self.factored = false;
    }

    /// Whether a numeric factor is held.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Solves `K s = r` in place with the last factor (which must exist).
    pub fn solve_in_place(&self, r: &mut [f64], par: Par) {
        debug_assert!(self.factored);
        let mut placed = vec![0.0; self.free_dofs];
        for (d, v) in r.iter().enumerate() {
            placed[self.place(d)] = *v;
        }
        if self.single {
            let mut placed_single: Vec<f32> = placed.iter().map(|&v| v as f32).collect();
            solve_with(&self.cholesky, &self.factor_single, &mut placed_single, par);
            placed.iter_mut().zip(&placed_single).for_each(|(v, &w)| *v = f64::from(w));
        } else {
            solve_with(&self.cholesky, &self.factor, &mut placed, par);
        }
        for (d, v) in r.iter_mut().enumerate() {
            *v = placed[self.place(d)];
        }
    }
}

/// Factors `k` into `factor` (the numeric `L Lᵀ` on `cholesky`'s symbolic analysis), in `T`'s
/// precision.
fn factor_numeric<T: faer::traits::ComplexField>(
    cholesky: &SymbolicCholesky<u32>,
    factor: &mut [T],
    k: SparseColMatRef<'_, u32, T>,
    par: Par,
) -> Result<(), SparseError> {
    let scratch = cholesky.factorize_numeric_llt_scratch::<T>(par, Default::default());
    let mut buffer = MemBuffer::try_new(scratch).map_err(|e| SparseError::Pattern(format!("{e:?}")))?;
    cholesky
        .factorize_numeric_llt(
            factor,
            k,
            Side::Lower,
            Default::default(),
            par,
            MemStack::new(&mut buffer),
            Default::default(),
        )
        .map(|_| ())
        .map_err(|_| SparseError::NotPositiveDefinite)
}

/// Solves `L Lᵀ s = r` in place (`r` in elimination order), in `T`'s precision.
fn solve_with<T: faer::traits::ComplexField>(cholesky: &SymbolicCholesky<u32>, factor: &[T], r: &mut [T], par: Par) {
    let n = r.len();
    let mut rhs = faer::MatMut::from_column_major_slice_mut(r, n, 1);
    let scratch = cholesky.solve_in_place_scratch::<T>(1, par);
    let mut buffer = MemBuffer::new(scratch);
    LltRef::new(cholesky, factor).solve_in_place_with_conj(Conj::No, rhs.as_mut(), par, MemStack::new(&mut buffer));
}

/// Hands the memory freed so far back to the system. glibc raises its threshold for mapping
/// large blocks each time one is freed, so the pattern's scratch (the node graph, the transposed
/// pattern: tens of MB at 100k unknowns) would stay resident under the factor made next; on
/// other platforms nothing is done.
fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `malloc_trim` only returns free pages of the allocator's heap to the system.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// The pattern of the transpose of the `n × n` pattern `(col_ptr, row_idx)`, rows sorted.
fn transposed(n: usize, col_ptr: &[u32], row_idx: &[u32]) -> SymbolicSparseColMat<u32> {
    let mut ptr = vec![0u32; n + 1];
    for &r in row_idx {
        ptr[r as usize + 1] += 1;
    }
    for k in 0..n {
        ptr[k + 1] += ptr[k];
    }
    let mut next: Vec<u32> = ptr[..n].to_vec();
    let mut rows = vec![0u32; row_idx.len()];
    for c in 0..n {
        for &r in &row_idx[col_ptr[c] as usize..col_ptr[c + 1] as usize] {
            rows[next[r as usize] as usize] = c as u32;
            next[r as usize] += 1;
        }
    }
    SymbolicSparseColMat::new_checked(n, n, ptr, None, rows)
}

/// The lower triangle of the free nodes' graph, the diagonal included, in the numbering
/// `index[node]` (`u32::MAX` for a held node): `(col_ptr, rows)`, each column's rows sorted, its
/// own node first; with every node patch's pairs where `material` measures the volume per patch.
fn node_graph(mesh: &Mesh, material: &Material, index: &[u32], free_nodes: usize) -> (Vec<u32>, Vec<u32>) {
    let mut pairs: Vec<(u32, u32)> = (0..free_nodes as u32).map(|k| (k, k)).collect();
    for block in &mesh.blocks {
        for nodes in block.elements() {
            for &a in nodes {
                for &b in nodes {
                    let (i, j) = (index[a as usize], index[b as usize]);
                    if i != u32::MAX && j != u32::MAX && i > j {
                        pairs.push((j, i));
                    }
                }
            }
        }
    }
    if patch::has_patches(mesh, material) {
        patch::pattern_pairs(mesh, material, index, &mut pairs);
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut col_ptr = vec![0u32; free_nodes + 1];
    for &(j, _) in &pairs {
        col_ptr[j as usize + 1] += 1;
    }
    for k in 0..free_nodes {
        col_ptr[k + 1] += col_ptr[k];
    }
    (col_ptr, pairs.into_iter().map(|(_, i)| i).collect())
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
    let mut add = |nodes: &[u32], he: &DMatrix<f64>| {
        for (li, &i) in nodes.iter().enumerate() {
            for (lj, &j) in nodes.iter().enumerate() {
                for a in 0..3 {
                    for c in 0..3 {
                        k[(3 * i as usize + a, 3 * j as usize + c)] += he[(3 * li + a, 3 * lj + c)];
                    }
                }
            }
        }
    };
    for_each_hessian_term(mesh, geo, material, x, true, &mut add);
    k
}

/// Every term of the elastic Hessian at `x` with its nodes (`projected`: PSD-projected per
/// quadrature point): P1's node patches' terms under the mixed formulation first
/// ([`patch::hessian_terms`]), then every other block's element Hessians, in mesh order.
pub(crate) fn for_each_hessian_term(
    mesh: &Mesh,
    geo: &[BlockGeometry],
    material: &Material,
    x: &[Vec3],
    projected: bool,
    mut add: impl FnMut(&[u32], &DMatrix<f64>),
) {
    if patch::has_patches(mesh, material) {
        patch::hessian_terms(mesh, geo, material, x, projected, &mut add);
    }
    for (b, gb) in mesh.blocks.iter().zip(geo) {
        if patch::is_patch_block(b, material) {
            continue;
        }
        for (e, nodes) in b.elements().enumerate() {
            add(nodes, &element_hessian_at(mesh, gb, e, nodes, material, x, projected));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ElementType;
    use crate::fem::geometry::precompute;
    use crate::material::{MaterialModel, VolumeMeasure};
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    /// `K` assembled into its columns in elimination order, factored and solved, is the dense
    /// Hessian (plus the diagonal) on the free degrees of freedom: `K s = r` agrees with the dense
    /// solve, for every element type, with some nodes held (their rows and columns left out).
    /// The mixed formulation's too: per element, and on P1 per node patch (the pattern widened to
    /// the patch pairs, without which the assembly would panic).
    #[test]
    fn the_sparse_solve_is_the_dense_solve_on_the_free_dofs() {
        let measures = [VolumeMeasure::Point, VolumeMeasure::Element];
        for (et, measure) in ElementType::all().flat_map(|et| measures.map(|m| (et, m))) {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 0.4, 0.3), cells: [3, 2, 1] },
                element_type: et,
                split: TetSplit::Five,
                refine: 0,
            }
            .build()
            .unwrap();
            let geo = precompute(&mesh, None).unwrap();
            let material = Material::new(MaterialModel::StVenantKirchhoff, 1e5, 0.3, 1000.0)
                .unwrap()
                .with_volume_measure(measure)
                .unwrap();
            let et = format!("{et} {measure:?}");
            let x: Vec<Vec3> = mesh
                .rest_positions
                .iter()
                .map(|p| p + Vec3::new(0.05 * (3.0 * p.y).sin(), 0.02 * p.x * p.x, -0.04 * p.x * p.z))
                .collect();
            let held = |i: usize| mesh.rest_positions[i].x < 1e-9;
            let mut pattern = SparsePattern::new(&mesh, &material, held).unwrap();
            let n = pattern.free_dofs;
            let diagonal: Vec<f64> = (0..n).map(|d| 10.0 + d as f64).collect();
            pattern.assemble_and_factor(&mesh, &geo, &material, &x, &diagonal, true, false, Par::Seq).unwrap();
            let dense = assemble_dense(&mesh, &geo, &material, &x);
            let mut k = DMatrix::zeros(n, n);
            for (gi, &fi) in pattern.dof_of.iter().enumerate() {
                for (gj, &fj) in pattern.dof_of.iter().enumerate() {
                    if fi != usize::MAX && fj != usize::MAX {
                        k[(fi, fj)] = dense[(gi, gj)];
                    }
                }
            }
            for (d, v) in diagonal.iter().enumerate() {
                k[(d, d)] += v;
            }
            let r: Vec<f64> = (0..n).map(|d| ((7 * d) % 13) as f64 - 6.0).collect();
            let expected =
                k.clone().cholesky().expect("positive definite").solve(&nalgebra::DVector::from_column_slice(&r));
            let mut s = r.clone();
            pattern.solve_in_place(&mut s, Par::Seq);
            let error = (nalgebra::DVector::from_column_slice(&s) - &expected).amax();
            assert!(error <= 1e-9 * expected.amax(), "{et}: {error:e} of {:e}", expected.amax());
            assert_eq!(pattern.cost.factorisations, 1);
            assert!(pattern.cost.factor_nonzeros >= pattern.cost.matrix_nonzeros);
            // the single-precision factor of the same K: the same solve to f32's rounding times
            // K's condition, and a double factor made after it is exact again
            pattern.assemble_and_factor(&mesh, &geo, &material, &x, &diagonal, true, true, Par::Seq).unwrap();
            let mut s = r.clone();
            pattern.solve_in_place(&mut s, Par::Seq);
            let error = (nalgebra::DVector::from_column_slice(&s) - &expected).amax();
            let eigen = k.clone().symmetric_eigenvalues();
            let condition = eigen.max() / eigen.min();
            let bar = 1e-6 * condition * expected.amax();
            assert!(error <= bar, "{et}, single: {error:e} of {:e} (condition {condition:.1e})", expected.amax());
            assert!(error > 0.0, "{et}: the single-precision solve should round");
            pattern.assemble_and_factor(&mesh, &geo, &material, &x, &diagonal, true, false, Par::Seq).unwrap();
            let mut s = r.clone();
            pattern.solve_in_place(&mut s, Par::Seq);
            let error = (nalgebra::DVector::from_column_slice(&s) - &expected).amax();
            assert!(error <= 1e-9 * expected.amax(), "{et}, double again: {error:e}");
        }
    }
}
