//! The Lagrange construction of nodal shape functions.
//!
//! For nodes `r_j` (j = 0..n) and a monomial basis `m_k(r) = x^a y^b z^c` (k = 0..n) of the
//! element's polynomial space, the nodal basis is `N_i(r) = Σ_k C_ki m_k(r)` where
//! `C = V⁻¹` and `V_jk = m_k(r_j)` is the Vandermonde matrix. Then `N_i(r_j) = δ_ij`, and the
//! `N_i` span exactly the same space as the monomials, so the element reproduces that space.
//! The inverse is computed once per element type (at first use) with a full-pivot LU.

use nalgebra::DMatrix;

/// Exponents `[a, b, c]` of the monomial `x^a y^b z^c`.
pub type Exponents = [u32; 3];

/// Monomials of total degree ≤ k (the space P_k of tetrahedra).
pub fn total_degree_exponents(k: u32) -> Vec<Exponents> {
    let mut e = Vec::new();
    for d in 0..=k {
        for a in (0..=d).rev() {
            for b in (0..=d - a).rev() {
                e.push([a, b, d - a - b]);
            }
        }
    }
    e
}

/// Monomials of degree ≤ k in each variable (the space Q_k of hexahedra).
pub fn tensor_exponents(k: u32) -> Vec<Exponents> {
    let mut e = Vec::new();
    for c in 0..=k {
        for b in 0..=k {
            for a in 0..=k {
                e.push([a, b, c]);
            }
        }
    }
    e
}

/// A nodal basis obtained by inverting the Vandermonde matrix.
#[derive(Clone, Debug)]
pub struct LagrangeBasis {
    exponents: Vec<Exponents>,
    /// `coefficients[(k, i)]`: coefficient of monomial k in shape function i.
    coefficients: DMatrix<f64>,
    max_power: usize,
}

impl LagrangeBasis {
    /// Builds the basis. Panics if the Vandermonde matrix is singular, which means the node set
    /// is not unisolvent for the monomials: a bug in an element's tables, not a user error.
    pub fn new(nodes: &[[f64; 3]], exponents: Vec<Exponents>) -> Self {
        let n = nodes.len();
        assert_eq!(n, exponents.len(), "as many monomials as nodes are needed");
        let max_power = exponents.iter().flatten().copied().max().unwrap_or(0) as usize;
        let vandermonde = DMatrix::from_fn(n, n, |j, k| monomial(&exponents[k], &nodes[j]));
        let coefficients = vandermonde
            .full_piv_lu()
            .try_inverse()
            .expect("the element's nodes are not unisolvent for its polynomial space");
        Self { exponents, coefficients, max_power }
    }

    pub fn len(&self) -> usize {
        self.exponents.len()
    }

    pub fn is_empty(&self) -> bool {
        self.exponents.is_empty()
    }

    /// `out[i] = N_i(r)`.
    pub fn values(&self, r: &[f64; 3], out: &mut [f64]) {
        let pows = Powers::new(r, self.max_power);
        out.fill(0.0);
        for (k, e) in self.exponents.iter().enumerate() {
            let m = pows.get(0, e[0]) * pows.get(1, e[1]) * pows.get(2, e[2]);
            for (i, o) in out.iter_mut().enumerate() {
                *o += self.coefficients[(k, i)] * m;
            }
        }
    }

    /// `out[i] = ∂N_i/∂r(r)`.
    pub fn gradients(&self, r: &[f64; 3], out: &mut [[f64; 3]]) {
        let pows = Powers::new(r, self.max_power);
        let p = |d: usize, e: u32| pows.get(d, e);
        // d/dx x^a = a x^(a-1)
        let dp = |d: usize, e: u32| if e == 0 { 0.0 } else { e as f64 * pows.get(d, e - 1) };
        out.fill([0.0; 3]);
        for (k, e) in self.exponents.iter().enumerate() {
            let g = [
                dp(0, e[0]) * p(1, e[1]) * p(2, e[2]),
                p(0, e[0]) * dp(1, e[1]) * p(2, e[2]),
                p(0, e[0]) * p(1, e[1]) * dp(2, e[2]),
            ];
            for (i, o) in out.iter_mut().enumerate() {
                let c = self.coefficients[(k, i)];
                o[0] += c * g[0];
                o[1] += c * g[1];
                o[2] += c * g[2];
            }
        }
    }
}

/// `x^a y^b z^c` at `r`.
pub fn monomial(e: &Exponents, r: &[f64; 3]) -> f64 {
    r[0].powi(e[0] as i32) * r[1].powi(e[1] as i32) * r[2].powi(e[2] as i32)
}

/// The powers `r_d^k` of a point: tabulated by repeated products up to `k = 7` (every
/// built-in element's basis is of degree 3 at most), `powi` beyond (an element of higher order).
struct Powers {
    table: [[f64; 8]; 3],
    r: [f64; 3],
}

impl Powers {
    fn new(r: &[f64; 3], max_power: usize) -> Self {
        let mut table = [[1.0; 8]; 3];
        for d in 0..3 {
            for k in 1..=max_power.min(7) {
                table[d][k] = table[d][k - 1] * r[d];
            }
        }
        Self { table, r: *r }
    }

    #[inline]
    fn get(&self, d: usize, k: u32) -> f64 {
        match self.table[d].get(k as usize) {
            Some(&v) => v,
            None => self.r[d].powi(k as i32),
        }
    }
}

/// A polynomial element defined by its node table and monomial space: the shared
/// implementation behind P1, P2, P3, Q1, Q2 and the prism. Each element file declares one
/// `static` of this type with its data.
pub struct LagrangeElement {
    pub name: &'static str,
    pub description: &'static str,
    pub shape: super::ReferenceShape,
    pub order: usize,
    pub nodes: &'static [[f64; 3]],
    pub exponents: fn() -> Vec<Exponents>,
    pub default_quadrature_degree: usize,
    pub mass_quadrature_degree: usize,
    pub gmsh_type: u32,
    /// VTK cell type and Gmsh → VTK node permutation ([`super::ReferenceElement::vtk_node_order`]).
    pub vtk_cell_type: u8,
    pub vtk_node_order: &'static [usize],
    pub basis: std::sync::OnceLock<LagrangeBasis>,
    pub faces: std::sync::OnceLock<Vec<super::Face>>,
}

impl LagrangeElement {
    fn basis(&self) -> &LagrangeBasis {
        self.basis.get_or_init(|| LagrangeBasis::new(self.nodes, (self.exponents)()))
    }
}

impl super::ReferenceElement for LagrangeElement {
    fn name(&self) -> &'static str {
        self.name
    }
    fn description(&self) -> &'static str {
        self.description
    }
    fn shape(&self) -> super::ReferenceShape {
        self.shape
    }
    fn order(&self) -> usize {
        self.order
    }
    fn nodes(&self) -> &[[f64; 3]] {
        self.nodes
    }
    fn shape_functions(&self, r: &[f64; 3], out: &mut [f64]) {
        self.basis().values(r, out)
    }
    fn shape_gradients(&self, r: &[f64; 3], out: &mut [[f64; 3]]) {
        self.basis().gradients(r, out)
    }
    fn faces(&self) -> &[super::Face] {
        self.faces.get_or_init(|| super::build_faces(self.shape, self.order, self.nodes))
    }
    fn default_quadrature_degree(&self) -> usize {
        self.default_quadrature_degree
    }
    fn mass_quadrature_degree(&self) -> usize {
        self.mass_quadrature_degree
    }
    fn gmsh_type(&self) -> u32 {
        self.gmsh_type
    }
    fn vtk_cell_type(&self) -> u8 {
        self.vtk_cell_type
    }
    fn vtk_node_order(&self) -> &'static [usize] {
        self.vtk_node_order
    }
}
