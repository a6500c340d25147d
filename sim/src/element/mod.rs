//! Reference elements: nodes, shape functions `N_i(r)`, their gradients `∂N_i/∂r`, and faces.
//!
//! Every element type lives in one file behind the [`ReferenceElement`] trait and is listed once
//! in [`REGISTRY`]. Node numbering follows Gmsh ("Node ordering" in the Gmsh reference manual),
//! so meshes imported from `.msh` files need no reordering: vertices first, then edge nodes
//! (edge by edge, in the edge's direction), then face nodes, then interior nodes.
//!
//! Polynomial elements are built by the Lagrange construction ([`lagrange`]): given the nodes
//! `r_j` and a monomial basis `m_k` of the element's space (P_k for tetrahedra, Q_k for
//! hexahedra, P1(triangle) ⊗ P1(segment) for the prism) the shape functions are
//! `N_i(r) = Σ_k C_ki m_k(r)` with `C = V⁻¹`, `V_jk = m_k(r_j)`, which makes `N_i(r_j) = δ_ij`
//! true by construction. This replaces the formulas printed in the paper's supplementary
//! material, which carry typos (see `shared/paper/ERRATA.md`). The pyramid's shape functions are
//! rational; they are written out in [`pyramid`].
//!
//! Reference domains (Gmsh's): tetrahedron with vertices (0,0,0), (1,0,0), (0,1,0), (0,0,1);
//! hexahedron [-1,1]³; prism = triangle (0,0), (1,0), (0,1) × [-1,1]; pyramid with base
//! [-1,1]² at z = 0 and apex (0,0,1).

pub mod lagrange;
pub mod p1;
pub mod p2;
pub mod p3;
pub mod prism;
pub mod pyramid;
pub mod q1;
pub mod q2;

/// **The registry**: every element type hox knows, in this order (menus, `hox elements`, tests).
///
/// Adding an element type is its file `sim/src/element/NAME.rs` (a `static` implementing
/// [`ReferenceElement`]: name, nodes, shape functions, quadrature degrees, Gmsh type, VTK cell
/// type and node order), its `pub mod NAME;` line above, and one entry here, `&NAME::STATIC,`.
/// Everything else reads the registry: name lookup and the scene-file, command-line and app
/// choices, Gmsh import (by [`ReferenceElement::gmsh_type`]), VTK export (by
/// [`ReferenceElement::vtk_cell_type`]), box meshing (by shape: a higher-order element raises
/// the registered order-1 element of its shape, [`ElementType::linear`]), the display surface
/// and the kernels (a node count without a specialised sweep takes the generic kernel). The
/// element tests (`tests.rs` here) and `tests/tests/registries.rs` run every entry through all
/// of these. (A new reference *shape* is more than an entry: a [`ReferenceShape`] variant, its
/// quadrature rules and its box-cutting recipe.)
pub static REGISTRY: &[&dyn ReferenceElement] =
    &[&p1::P1, &p2::P2, &p3::P3, &q1::Q1, &q2::Q2, &prism::PRISM, &pyramid::PYRAMID];

/// The geometric shape of a reference element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReferenceShape {
    Tetrahedron,
    Hexahedron,
    Prism,
    Pyramid,
}

impl ReferenceShape {
    /// Corner vertices of the reference domain, in Gmsh order.
    pub const fn vertices(self) -> &'static [[f64; 3]] {
        match self {
            Self::Tetrahedron => &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            Self::Hexahedron => &[
                [-1., -1., -1.],
                [1., -1., -1.],
                [1., 1., -1.],
                [-1., 1., -1.],
                [-1., -1., 1.],
                [1., -1., 1.],
                [1., 1., 1.],
                [-1., 1., 1.],
            ],
            Self::Prism => &[[0., 0., -1.], [1., 0., -1.], [0., 1., -1.], [0., 0., 1.], [1., 0., 1.], [0., 1., 1.]],
            Self::Pyramid => &[[-1., -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.], [0., 0., 1.]],
        }
    }

    /// The faces as lists of corner vertices, counter-clockwise seen from outside (so the
    /// right-hand normal points out of the element).
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            Self::Tetrahedron => &[&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[3, 1, 2]],
            Self::Hexahedron => {
                &[&[0, 3, 2, 1], &[0, 1, 5, 4], &[0, 4, 7, 3], &[1, 2, 6, 5], &[2, 3, 7, 6], &[4, 5, 6, 7]]
            }
            Self::Prism => &[&[0, 2, 1], &[3, 4, 5], &[0, 1, 4, 3], &[0, 3, 5, 2], &[1, 2, 5, 4]],
            Self::Pyramid => &[&[0, 3, 2, 1], &[0, 1, 4], &[1, 2, 4], &[2, 3, 4], &[3, 0, 4]],
        }
    }

    /// The edges as pairs of corner vertices (Gmsh's edge order for each shape).
    pub fn edges(self) -> &'static [[usize; 2]] {
        match self {
            Self::Tetrahedron => &[[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]],
            Self::Hexahedron => {
                &[[0, 1], [0, 3], [0, 4], [1, 2], [1, 5], [2, 3], [2, 6], [3, 7], [4, 5], [4, 7], [5, 6], [6, 7]]
            }
            Self::Prism => &[[0, 1], [0, 2], [0, 3], [1, 2], [1, 4], [2, 5], [3, 4], [3, 5], [4, 5]],
            Self::Pyramid => &[[0, 1], [0, 3], [0, 4], [1, 2], [1, 4], [2, 3], [2, 4], [3, 4]],
        }
    }

    /// Volume of the reference domain.
    pub fn volume(self) -> f64 {
        match self {
            Self::Tetrahedron => 1.0 / 6.0,
            Self::Hexahedron => 8.0,
            Self::Prism => 1.0,
            Self::Pyramid => 4.0 / 3.0,
        }
    }

    /// The reference centroid (a point well inside the element).
    pub fn centroid(self) -> [f64; 3] {
        match self {
            Self::Tetrahedron => [0.25; 3],
            Self::Hexahedron => [0.0; 3],
            Self::Prism => [1.0 / 3.0, 1.0 / 3.0, 0.0],
            Self::Pyramid => [0.0, 0.0, 0.25],
        }
    }

    /// Whether `r` lies in the reference domain, up to `tol`.
    pub fn contains(self, r: &[f64; 3], tol: f64) -> bool {
        let [x, y, z] = *r;
        match self {
            Self::Tetrahedron => x >= -tol && y >= -tol && z >= -tol && x + y + z <= 1.0 + tol,
            Self::Hexahedron => r.iter().all(|c| c.abs() <= 1.0 + tol),
            Self::Prism => x >= -tol && y >= -tol && x + y <= 1.0 + tol && z.abs() <= 1.0 + tol,
            Self::Pyramid => z >= -tol && z <= 1.0 + tol && x.abs() <= 1.0 - z + tol && y.abs() <= 1.0 - z + tol,
        }
    }
}

/// Shape of a face of a reference element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FaceShape {
    Triangle,
    Quadrilateral,
}

/// A face of a reference element with its high-order nodes.
///
/// `nodes` are element-local node indices in the face's own Gmsh order as a 2D element of the
/// same order (3-, 6-, 10-, 15-node … triangle; 4-, 9-, 16-node … quadrangle): corners
/// counter-clockwise seen from outside, then edge nodes edge by edge (edges `(0,1), (1,2), …`),
/// then the interior nodes, ordered in turn as a triangle of order − 3 (quadrangle of
/// order − 2) inside the face.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Face {
    pub shape: FaceShape,
    pub order: usize,
    pub nodes: Vec<usize>,
}

impl Face {
    /// The corner nodes (element-local indices) of the face.
    pub fn corners(&self) -> &[usize] {
        match self.shape {
            FaceShape::Triangle => &self.nodes[..3],
            FaceShape::Quadrilateral => &self.nodes[..4],
        }
    }
}

/// A reference element: the one interface through which the solver sees every element type.
pub trait ReferenceElement: Send + Sync + 'static {
    /// Short name used on the command line and in scene files (`p1`, `p2`, …).
    fn name(&self) -> &'static str;
    /// A human description, e.g. "quadratic tetrahedron (10 nodes)".
    fn description(&self) -> &'static str;
    fn shape(&self) -> ReferenceShape;
    /// Polynomial order along an edge (1 for P1, Q1, prism, pyramid).
    fn order(&self) -> usize;
    /// Reference coordinates of the nodes, in Gmsh order.
    fn nodes(&self) -> &[[f64; 3]];
    /// Shape function values `N_i(r)`; `out.len()` must equal the node count.
    fn shape_functions(&self, r: &[f64; 3], out: &mut [f64]);
    /// Reference gradients `∂N_i/∂r(r)`; `out.len()` must equal the node count.
    fn shape_gradients(&self, r: &[f64; 3], out: &mut [[f64; 3]]);
    /// Faces with their high-order nodes, for surface extraction.
    fn faces(&self) -> &[Face];
    /// Default quadrature degree of exactness for the elastic energy (documented per element).
    fn default_quadrature_degree(&self) -> usize;
    /// Degree needed to integrate `N_i N_j` exactly on an affine element (mass matrices).
    fn mass_quadrature_degree(&self) -> usize;
    /// Gmsh element type number (`.msh` files).
    fn gmsh_type(&self) -> u32;
    /// VTK cell type number (`.vtu` files), e.g. 24 for `VTK_QUADRATIC_TETRA`.
    fn vtk_cell_type(&self) -> u8;
    /// The Gmsh → VTK node permutation: VTK's node `i` is the element's (Gmsh-ordered) node
    /// `vtk_node_order()[i]`; a permutation of `0..num_nodes()`.
    fn vtk_node_order(&self) -> &'static [usize];

    fn num_nodes(&self) -> usize {
        self.nodes().len()
    }
    /// Number of corner (vertex) nodes; Gmsh numbers them first.
    fn num_vertices(&self) -> usize {
        self.shape().vertices().len()
    }
}

/// A copyable handle on a registered element type, compared by name.
#[derive(Clone, Copy)]
pub struct ElementType(&'static dyn ReferenceElement);

impl ElementType {
    /// All registered element types, in registry order.
    pub fn all() -> impl Iterator<Item = ElementType> {
        REGISTRY.iter().map(|e| ElementType(*e))
    }

    /// Looks an element type up by its short name (case-insensitive).
    pub fn from_name(name: &str) -> Option<ElementType> {
        Self::all().find(|e| e.name().eq_ignore_ascii_case(name))
    }

    /// Looks an element type up by its Gmsh element type number.
    pub fn from_gmsh_type(gmsh_type: u32) -> Option<ElementType> {
        Self::all().find(|e| e.gmsh_type() == gmsh_type)
    }

    /// Looks an element type up by its VTK cell type number.
    pub fn from_vtk_cell_type(cell_type: u8) -> Option<ElementType> {
        Self::all().find(|e| e.vtk_cell_type() == cell_type)
    }

    /// The registered linear (order-1) element of `shape` (P1 for tetrahedra, Q1 for
    /// hexahedra, …): what box meshes are cut into before their order is raised.
    pub fn linear(shape: ReferenceShape) -> Option<ElementType> {
        Self::all().find(|e| e.shape() == shape && e.order() == 1)
    }

    /// The comma-separated list of names, for error messages and help texts.
    pub fn names() -> String {
        Self::all().map(|e| e.name()).collect::<Vec<_>>().join(", ")
    }

    pub fn reference(self) -> &'static dyn ReferenceElement {
        self.0
    }
}

impl std::ops::Deref for ElementType {
    type Target = dyn ReferenceElement;
    fn deref(&self) -> &Self::Target {
        self.0
    }
}

crate::math::by_name!(ElementType);

impl std::str::FromStr for ElementType {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| format!("unknown element type '{s}' (expected one of: {})", Self::names()))
    }
}

/// Builds the faces of an element from its shape's outward corner lists, by locating each
/// face node (corners, edge nodes, interior nodes in the face's Gmsh order, [`face_points`])
/// among the element's reference nodes. Used by every element file, for any order; a face node
/// that cannot be found is a bug in the element's node table and panics (the element tests
/// exercise every registered element).
pub(crate) fn build_faces(shape: ReferenceShape, order: usize, nodes: &[[f64; 3]]) -> Vec<Face> {
    let verts = shape.vertices();
    let find = |p: [f64; 3]| -> usize {
        nodes
            .iter()
            .position(|q| (0..3).all(|d| (q[d] - p[d]).abs() < 1e-12))
            .unwrap_or_else(|| panic!("no node of the {shape:?} at {p:?}"))
    };
    shape
        .faces()
        .iter()
        .map(|corners| {
            let c: Vec<[f64; 3]> = corners.iter().map(|&v| verts[v]).collect();
            let n = c.len();
            // (s, t) of the face's Gmsh nodes, mapped onto the reference face: affinely from
            // corners 0, 1, 2 on a triangle, bilinearly on a quadrilateral (whose reference
            // faces are parallelograms, so the map is affine there too)
            let at = |[s, t]: [f64; 2]| -> [f64; 3] {
                std::array::from_fn(|d| match n {
                    3 => c[0][d] + s * (c[1][d] - c[0][d]) + t * (c[2][d] - c[0][d]),
                    _ => {
                        (1.0 - s) * (1.0 - t) * c[0][d]
                            + s * (1.0 - t) * c[1][d]
                            + s * t * c[2][d]
                            + (1.0 - s) * t * c[3][d]
                    }
                })
            };
            let unit: &[[f64; 2]] =
                if n == 3 { &[[0., 0.], [1., 0.], [0., 1.]] } else { &[[0., 0.], [1., 0.], [1., 1.], [0., 1.]] };
            Face {
                shape: if n == 3 { FaceShape::Triangle } else { FaceShape::Quadrilateral },
                order,
                nodes: face_points(unit, order).into_iter().map(|p| find(at(p))).collect(),
            }
        })
        .collect()
}

/// The nodes of a Lagrange triangle (3 corners) or quadrangle (4 corners, counter-clockwise)
/// of `order` in Gmsh's order, in the plane of `corners`: the corners, then `order − 1` nodes
/// along each edge `(0,1), (1,2), …` from its first corner, then the interior nodes, which
/// Gmsh orders as a triangle of order − 3 (quadrangle of order − 2) whose corners are the
/// interior nodes nearest the outer corners; order 0 is the single centre point.
fn face_points(corners: &[[f64; 2]], order: usize) -> Vec<[f64; 2]> {
    let n = corners.len();
    let lerp = |a: [f64; 2], b: [f64; 2], t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    if order == 0 {
        let centre = corners.iter().fold([0.0; 2], |acc, c| [acc[0] + c[0], acc[1] + c[1]]);
        return vec![centre.map(|x| x / n as f64)];
    }
    let mut pts = corners.to_vec();
    for e in 0..n {
        for j in 1..order {
            pts.push(lerp(corners[e], corners[(e + 1) % n], j as f64 / order as f64));
        }
    }
    let inner_order = if n == 3 { order.checked_sub(3) } else { order.checked_sub(2) };
    if let Some(inner_order) = inner_order {
        // corner i of the inner element: one step from corner i along each of its two edges
        let h = 1.0 / order as f64;
        let inner: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let (c, next, prev) = (corners[i], corners[(i + 1) % n], corners[(i + n - 1) % n]);
                [c[0] + h * (next[0] - c[0]) + h * (prev[0] - c[0]), c[1] + h * (next[1] - c[1]) + h * (prev[1] - c[1])]
            })
            .collect();
        pts.extend(face_points(&inner, inner_order));
    }
    pts
}

#[cfg(test)]
pub(crate) mod tests;
