//! Probes: material points of the body, followed through the deformation.
//!
//! A probe is located once in the rest mesh by inverting the isoparametric map of an element,
//! `X(r) = Σ_i N_i(r) X_i = p`, by Newton's method from the reference centroid:
//!
//! `r ← r − J(X, r)⁻¹ (X(r) − p)`, with `J(X, r) = Σ_i X_i ⊗ ∂N_i/∂r(r)`,
//!
//! damped by backtracking (the step is halved until `|X(r) − p|` decreases) and restarted from
//! points between the centroid and each reference vertex when it fails, so that curved
//! high-order elements work too. The point belongs to the element when `r` lies in the reference
//! domain (within 1e-9) and `|X(r) − p| ≤ 1e-10 ×` the element's size. The probe then keeps the
//! element's nodes and the weights `N_i(r)`, and moves with the body as `x(p) = Σ_i N_i(r) x_i`,
//! its displacement being `u(p) = Σ_i N_i(r) (x_i − X_i)`: it works on every element type, not
//! only where a node sits, and reproduces affine deformations exactly.
//!
//! Candidate elements are those whose node bounding box, padded, contains the point (linear
//! elements lie in the convex hull of their nodes; curved elements may bulge a little past
//! theirs). Points on faces, edges or vertices shared by several elements belong to the first
//! element found (block order, then element order). A point that no element contains is
//! projected on the nearest element (projected Newton iterations in reference coordinates): it
//! counts as inside, with `r` clamped to the reference domain, when it lies within 1e-9 × the
//! body's size of that element — so probes placed on the surface survive round-off — and is
//! [`ProbeError::Outside`] otherwise.

use crate::Vec3;
use crate::element::{ElementType, ReferenceShape};
use crate::fem::geometry::jacobian;
use crate::mesh::Mesh;
use nalgebra::Matrix3;

/// A located material point.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    pub name: String,
    /// Rest position asked for, metres.
    pub point_m: Vec3,
    /// Mesh block index.
    pub block: usize,
    /// Element index in the block.
    pub element: usize,
    /// Reference coordinates `r` with `X(r) = point`.
    pub reference: [f64; 3],
    /// The element's nodes.
    pub nodes: Vec<u32>,
    /// `N_i(r)`, one per node.
    pub weights: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProbeError {
    #[error(
        "probe '{name}' at {point_m:?} m lies outside the body (nearest element {nearest_element} is {distance_m:.3e} m away)"
    )]
    Outside { name: String, point_m: [f64; 3], nearest_element: usize, distance_m: f64 },
    #[error("probe '{name}' has a non-finite coordinate {point_m:?}")]
    NonFinite { name: String, point_m: [f64; 3] },
}

/// Tolerance on reference coordinates for "r lies in the reference domain".
const REFERENCE_TOLERANCE: f64 = 1e-9;
/// Accepted residual `|X(r) − p|`, relative to the element's size.
const RESIDUAL_TOLERANCE: f64 = 1e-10;
/// Distance outside the boundary that still counts as inside, relative to the body's size.
const SURFACE_TOLERANCE: f64 = 1e-9;
/// Bounding-box padding relative to the element's size: linear elements (convex combinations
/// of their nodes) and curved high-order elements (which may bulge past their nodes).
const LINEAR_PADDING: f64 = 1e-6;
const CURVED_PADDING: f64 = 0.1;
/// Newton iterations per start, and the reference-coordinate bound past which Newton has left.
const MAX_NEWTON_ITERATIONS: usize = 60;
const MAX_REFERENCE_COORDINATE: f64 = 10.0;
/// Halvings of a Newton step before giving up on decreasing the residual.
const MAX_HALVINGS: usize = 12;

impl Probe {
    /// Locates `point_m` in `mesh`: candidate elements by bounding box (padded by a small relative
    /// tolerance), then Newton's method on `X(r) = Σ N_i(r) X_i = point` from the reference
    /// centroid (with restarts and damping for robustness on curved elements), accepted when `r`
    /// lies in the reference shape within 1e-9 ([`ReferenceShape::contains`]) and
    /// `|X(r) − point| ≤ 1e-10 ×` element size. Points on shared faces/edges/vertices belong to
    /// the first element found. Points within 1e-9 × body size outside the boundary count as
    /// inside (clamped to the nearest element's reference domain), so probes placed exactly on
    /// the surface always work despite round-off.
    pub fn locate(mesh: &Mesh, name: &str, point_m: Vec3) -> Result<Probe, ProbeError> {
        let point = [point_m.x, point_m.y, point_m.z];
        if !point.iter().all(|c| c.is_finite()) {
            return Err(ProbeError::NonFinite { name: name.to_string(), point_m: point });
        }
        let probe = |block: usize, element: usize, reference: [f64; 3]| {
            let et = mesh.blocks[block].element_type;
            let mut weights = vec![0.0; et.num_nodes()];
            et.shape_functions(&reference, &mut weights);
            Probe {
                name: name.to_string(),
                point_m,
                block,
                element,
                reference,
                nodes: mesh.blocks[block].element(element).to_vec(),
                weights,
            }
        };

        // Pass 1: elements whose padded bounding box holds the point, in order.
        let mut boxes = Vec::with_capacity(mesh.num_elements());
        for (b, block) in mesh.blocks.iter().enumerate() {
            let et = block.element_type;
            let padding = if et.order() > 1 { CURVED_PADDING } else { LINEAR_PADDING };
            let mut map = ElementMap::new(et, &mesh.rest_positions);
            for (e, nodes) in block.elements().enumerate() {
                let (lo, hi) = node_box(&mesh.rest_positions, nodes);
                let size_m = (hi - lo).norm();
                let pad_m = padding * size_m;
                let outside_m = (lo - point_m).sup(&(point_m - hi)).sup(&Vec3::zeros()).norm();
                boxes.push((b, e, (outside_m - pad_m).max(0.0)));
                if outside_m > pad_m {
                    continue;
                }
                map.load(nodes);
                if let Some(r) = map.inverse(&point_m, size_m) {
                    return Ok(probe(b, e, r));
                }
            }
        }

        // Pass 2: the nearest element, by increasing lower bound on the distance.
        boxes.sort_by(|a, b| a.2.total_cmp(&b.2));
        let (lo, hi) = mesh.bounding_box();
        let body_size_m = if mesh.num_nodes() > 0 { (hi - lo).norm() } else { 0.0 };
        let mut nearest: Option<(usize, usize, [f64; 3], f64)> = None;
        let mut maps: Vec<ElementMap> =
            mesh.blocks.iter().map(|b| ElementMap::new(b.element_type, &mesh.rest_positions)).collect();
        for &(b, e, lower_bound_m) in &boxes {
            if nearest.is_some_and(|n| lower_bound_m > n.3) {
                break;
            }
            let map = &mut maps[b];
            map.load(mesh.blocks[b].element(e));
            let (r, distance_m) = map.nearest(&point_m);
            if nearest.is_none_or(|n| distance_m < n.3) {
                nearest = Some((b, e, r, distance_m));
            }
        }
        match nearest {
            Some((b, e, r, distance_m)) if distance_m <= SURFACE_TOLERANCE * body_size_m => Ok(probe(b, e, r)),
            _ => Err(ProbeError::Outside {
                name: name.to_string(),
                point_m: point,
                nearest_element: nearest.map_or(0, |n| n.1),
                distance_m: nearest.map_or(f64::INFINITY, |n| n.3),
            }),
        }
    }

    /// Current position `Σ N_i x_i`.
    pub fn position(&self, positions: &[Vec3]) -> Vec3 {
        self.nodes.iter().zip(&self.weights).map(|(&n, &w)| w * positions[n as usize]).sum()
    }

    /// Displacement `Σ N_i (x_i − X_i)`.
    pub fn displacement(&self, positions: &[Vec3], rest_positions: &[Vec3]) -> Vec3 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(&n, &w)| w * (positions[n as usize] - rest_positions[n as usize]))
            .sum()
    }
}

/// Axis-aligned bounding box of an element's nodes.
fn node_box(positions: &[Vec3], nodes: &[u32]) -> (Vec3, Vec3) {
    let first = positions[nodes[0] as usize];
    nodes.iter().fold((first, first), |(lo, hi), &n| (lo.inf(&positions[n as usize]), hi.sup(&positions[n as usize])))
}

/// The isoparametric map `X(r) = Σ N_i(r) X_i` of one element of `positions`, with its work
/// buffers.
struct ElementMap<'a> {
    et: ElementType,
    positions: &'a [Vec3],
    nodes: &'a [u32],
    values: Vec<f64>,
    gradients: Vec<[f64; 3]>,
}

impl<'a> ElementMap<'a> {
    fn new(et: ElementType, positions: &'a [Vec3]) -> Self {
        let nn = et.num_nodes();
        Self { et, positions, nodes: &[], values: vec![0.0; nn], gradients: vec![[0.0; 3]; nn] }
    }

    /// `X(r)` and `J(X, r) = Σ X_i ⊗ ∂N_i/∂r` ([`jacobian`]).
    fn eval(&mut self, r: &[f64; 3]) -> (Vec3, Matrix3<f64>) {
        self.et.shape_functions(r, &mut self.values);
        self.et.shape_gradients(r, &mut self.gradients);
        let mut x = Vec3::zeros();
        for (&node, &n) in self.nodes.iter().zip(&self.values) {
            x += n * self.positions[node as usize];
        }
        (x, jacobian(self.positions, self.nodes, &self.gradients))
    }

    /// Makes this the map of the element with nodes `nodes`.
    fn load(&mut self, nodes: &'a [u32]) {
        self.nodes = nodes;
    }

    fn shape(&self) -> ReferenceShape {
        self.et.shape()
    }

    /// Starting points: the centroid, then halfway from the centroid to each vertex.
    fn starts(&self) -> impl Iterator<Item = [f64; 3]> {
        let c = self.shape().centroid();
        std::iter::once(c).chain(self.shape().vertices().iter().map(move |v| [0, 1, 2].map(|d| 0.5 * (c[d] + v[d]))))
    }

    /// `r` in the reference domain with `X(r) = p` (within the tolerances), if any.
    fn inverse(&mut self, p: &Vec3, size_m: f64) -> Option<[f64; 3]> {
        let accept_m = RESIDUAL_TOLERANCE * size_m;
        let shape = self.shape();
        let starts: Vec<[f64; 3]> = self.starts().collect();
        starts.into_iter().find_map(|r0| {
            let (r, residual_m) = self.newton(p, r0, None)?;
            (residual_m <= accept_m && shape.contains(&r, REFERENCE_TOLERANCE)).then_some(r)
        })
    }

    /// The point of the element nearest to `p` (approximately: projected Newton iterations in
    /// reference coordinates), as `(r, |X(r) − p|)` with `r` in the reference domain.
    fn nearest(&mut self, p: &Vec3) -> ([f64; 3], f64) {
        let shape = self.shape();
        let starts: Vec<[f64; 3]> = self.starts().collect();
        let mut best = (shape.centroid(), f64::INFINITY);
        for r0 in starts {
            if let Some((r, d)) = self.newton(p, r0, Some(shape))
                && d < best.1
            {
                best = (r, d);
            }
            if best.1 == 0.0 {
                break;
            }
        }
        if !best.1.is_finite() {
            let c = shape.centroid();
            best = (c, (self.eval(&c).0 - p).norm());
        }
        best
    }

    /// Damped Newton iterations `r ← r − t J⁻¹ (X(r) − p)` from `r0`, each step projected on the
    /// reference domain of `project` if given. Returns the last iterate and its residual
    /// `|X(r) − p|`, or None when Newton leaves (singular Jacobian, non-finite or far iterates).
    fn newton(&mut self, p: &Vec3, r0: [f64; 3], project: Option<ReferenceShape>) -> Option<([f64; 3], f64)> {
        let mut r = r0;
        let (mut x, mut j) = self.eval(&r);
        let mut residual_m = (x - p).norm();
        for _ in 0..MAX_NEWTON_ITERATIONS {
            if residual_m == 0.0 {
                break;
            }
            let step = j.lu().solve(&(x - p))?;
            let mut t = 1.0;
            let mut improved = false;
            for _ in 0..=MAX_HALVINGS {
                let mut trial = [0, 1, 2].map(|d| r[d] - t * step[d]);
                if let Some(shape) = project {
                    trial = project_on(shape, trial);
                }
                if !trial.iter().all(|c| c.is_finite() && c.abs() <= MAX_REFERENCE_COORDINATE) {
                    return None;
                }
                let (xt, jt) = self.eval(&trial);
                let trial_m = (xt - p).norm();
                if trial_m < residual_m {
                    (r, x, j, residual_m) = (trial, xt, jt, trial_m);
                    improved = true;
                    break;
                }
                t *= 0.5;
            }
            if !improved {
                break; // round-off reached, or (projected) stagnation
            }
        }
        Some((r, residual_m))
    }
}

/// The half-spaces `a · r ≤ b` whose intersection is the reference domain.
fn half_spaces(shape: ReferenceShape) -> &'static [([f64; 3], f64)] {
    match shape {
        ReferenceShape::Tetrahedron => {
            &[([-1., 0., 0.], 0.), ([0., -1., 0.], 0.), ([0., 0., -1.], 0.), ([1., 1., 1.], 1.)]
        }
        ReferenceShape::Hexahedron => &[
            ([-1., 0., 0.], 1.),
            ([1., 0., 0.], 1.),
            ([0., -1., 0.], 1.),
            ([0., 1., 0.], 1.),
            ([0., 0., -1.], 1.),
            ([0., 0., 1.], 1.),
        ],
        ReferenceShape::Prism => {
            &[([-1., 0., 0.], 0.), ([0., -1., 0.], 0.), ([1., 1., 0.], 1.), ([0., 0., -1.], 1.), ([0., 0., 1.], 1.)]
        }
        ReferenceShape::Pyramid => {
            &[([0., 0., -1.], 0.), ([1., 0., 1.], 1.), ([-1., 0., 1.], 1.), ([0., 1., 1.], 1.), ([0., -1., 1.], 1.)]
        }
    }
}

/// Euclidean projection of `r` on the reference domain (Dykstra's alternating projections on
/// its half-spaces), up to round-off.
fn project_on(shape: ReferenceShape, r: [f64; 3]) -> [f64; 3] {
    if shape.contains(&r, 0.0) {
        return r;
    }
    let planes = half_spaces(shape);
    let mut x = Vec3::from(r);
    let mut corrections = [Vec3::zeros(); 6];
    for _ in 0..500 {
        let before = x;
        for ((a, b), c) in planes.iter().zip(&mut corrections) {
            let a = Vec3::from(*a);
            let y = x + *c;
            let excess = a.dot(&y) - b;
            let projected = if excess > 0.0 { y - a * (excess / a.norm_squared()) } else { y };
            *c = y - projected;
            x = projected;
        }
        if (x - before).amax() <= 1e-15 {
            break;
        }
    }
    [x.x, x.y, x.z]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::geometry::tests::curved_element;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    use proptest::prelude::*;
    use std::sync::OnceLock;

    const MIN_M: [f64; 3] = [0.1, -0.2, 0.0];
    const MAX_M: [f64; 3] = [1.1, 0.3, 0.6];

    /// A small structured box of every element type.
    fn boxes() -> &'static [(ElementType, Mesh)] {
        static MESHES: OnceLock<Vec<(ElementType, Mesh)>> = OnceLock::new();
        MESHES.get_or_init(|| {
            ElementType::all()
                .map(|et| {
                    let spec = BoxMeshSpec {
                        grid: BoxGrid { min_m: Vec3::from(MIN_M), max_m: Vec3::from(MAX_M), cells: [3, 2, 2] },
                        element_type: et,
                        split: TetSplit::Five,
                        refine: 0,
                    };
                    (et, spec.build().unwrap())
                })
                .collect()
        })
    }

    fn beam(element: &str, split: TetSplit) -> Mesh {
        BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [8, 2, 2] },
            element_type: ElementType::from_name(element).unwrap(),
            split,
            refine: 0,
        }
        .build()
        .unwrap()
    }

    fn box_point(t: [f64; 3]) -> Vec3 {
        Vec3::from([0, 1, 2].map(|d| MIN_M[d] + t[d] * (MAX_M[d] - MIN_M[d])))
    }

    /// Checks the invariants of a located probe.
    fn check_probe(mesh: &Mesh, probe: &Probe) {
        let block = &mesh.blocks[probe.block];
        assert_eq!(probe.nodes, block.element(probe.element));
        assert_eq!(probe.weights.len(), probe.nodes.len());
        assert!(block.element_type.shape().contains(&probe.reference, REFERENCE_TOLERANCE), "{probe:?}");
        let sum: f64 = probe.weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-10, "weights sum to {sum}");
    }

    #[test]
    fn a_probe_on_a_node_has_weight_one_there_and_follows_the_node() {
        for (et, mesh) in boxes() {
            let x: Vec<Vec3> = mesh
                .rest_positions
                .iter()
                .enumerate()
                .map(|(i, p)| p + Vec3::new((i as f64).sin(), (0.3 * i as f64).cos(), 0.01 * i as f64))
                .collect();
            for (node, p) in mesh.rest_positions.iter().enumerate() {
                let probe = Probe::locate(mesh, "node", *p).unwrap_or_else(|e| panic!("{et}: {e}"));
                check_probe(mesh, &probe);
                for (&n, &w) in probe.nodes.iter().zip(&probe.weights) {
                    let expected = if n as usize == node { 1.0 } else { 0.0 };
                    assert!((w - expected).abs() < 1e-9, "{et} node {node}: weight {w} on node {n}");
                }
                assert!(probe.nodes.contains(&(node as u32)), "{et} node {node}: {probe:?}");
                let u = probe.displacement(&x, &mesh.rest_positions);
                assert!((u - (x[node] - p)).norm() < 1e-9, "{et} node {node}: {u}");
                assert!((probe.position(&x) - x[node]).norm() < 1e-9, "{et} node {node}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Random interior points are located and reproduce their rest position.
        #[test]
        fn interior_points_reproduce_their_rest_position(t in proptest::array::uniform3(0.001..0.999f64)) {
            let p = box_point(t);
            for (et, mesh) in boxes() {
                let probe = Probe::locate(mesh, "inside", p).unwrap_or_else(|e| panic!("{et}: {e}"));
                check_probe(mesh, &probe);
                let back = probe.position(&mesh.rest_positions);
                prop_assert!((back - p).norm() < 1e-9, "{}: {} vs {}", et, back, p);
                prop_assert!(probe.displacement(&mesh.rest_positions, &mesh.rest_positions).norm() < 1e-12);
            }
        }

        /// Under x = A X + b the probe moves exactly to A p + b, on every element type.
        #[test]
        fn affine_deformations_move_probes_exactly(
            t in proptest::array::uniform3(0.0..=1.0f64),
            a in proptest::array::uniform9(-1.0..1.0f64),
            b in proptest::array::uniform3(-1.0..1.0f64),
        ) {
            let a = Matrix3::identity() + Matrix3::from_column_slice(&a) * 0.5;
            let b = Vec3::from(b);
            let p = box_point(t);
            for (et, mesh) in boxes() {
                let probe = Probe::locate(mesh, "affine", p).unwrap_or_else(|e| panic!("{et}: {e}"));
                let x: Vec<Vec3> = mesh.rest_positions.iter().map(|q| a * q + b).collect();
                let expected = a * p + b;
                let moved = probe.position(&x);
                prop_assert!((moved - expected).norm() < 1e-9, "{}: {} vs {}", et, moved, expected);
                let u = probe.displacement(&x, &mesh.rest_positions);
                prop_assert!((u - (expected - p)).norm() < 1e-9, "{}: displacement {}", et, u);
            }
        }

        /// On curved high-order elements, X(r0) is located back to r0.
        #[test]
        fn curved_elements_invert_their_map(u in proptest::array::uniform4(0.0..1.0f64), bend in 0.0..0.15f64) {
            for et in ElementType::all().filter(|e| e.order() > 1) {
                let mesh = curved_element(et, bend);
                let r0 = crate::element::tests::point_in(et.shape(), u);
                let mut map = ElementMap::new(et, &mesh.rest_positions);
                map.load(mesh.blocks[0].element(0));
                let p = map.eval(&r0).0;
                let probe = Probe::locate(&mesh, "curved", p).unwrap_or_else(|e| panic!("{et}: {e}"));
                let dr = [0, 1, 2].map(|d| (probe.reference[d] - r0[d]).abs()).into_iter().fold(0.0, f64::max);
                prop_assert!(dr < 1e-9, "{}: r = {:?} vs r0 = {:?}", et, probe.reference, r0);
                prop_assert!((probe.position(&mesh.rest_positions) - p).norm() < 1e-9);
            }
        }
    }

    #[test]
    fn chosen_points_of_curved_p2_and_q2_elements_are_located_back() {
        let cases: [(&str, [f64; 3]); 6] = [
            ("p2", [0.2, 0.3, 0.15]),
            ("p2", [0.05, 0.05, 0.85]),
            ("p2", [0.25, 0.25, 0.25]),
            ("q2", [0.3, -0.5, 0.6]),
            ("q2", [0.95, -0.9, 0.9]),
            ("q2", [-0.99, 0.0, 0.5]),
        ];
        for (name, r0) in cases {
            let et = ElementType::from_name(name).unwrap();
            let mesh = curved_element(et, 0.15);
            let mut map = ElementMap::new(et, &mesh.rest_positions);
            map.load(mesh.blocks[0].element(0));
            let (p, _) = map.eval(&r0);
            let (straight, _) = {
                let flat_mesh = curved_element(et, 0.0);
                let mut flat = ElementMap::new(et, &flat_mesh.rest_positions);
                flat.load(mesh.blocks[0].element(0));
                flat.eval(&r0)
            };
            assert!((p - straight).norm() > 1e-3, "{name}: the element is not curved at {r0:?}");
            let probe = Probe::locate(&mesh, "curved", p).unwrap();
            for d in 0..3 {
                assert!((probe.reference[d] - r0[d]).abs() < 1e-9, "{name}: {:?} vs {r0:?}", probe.reference);
            }
        }
    }

    #[test]
    fn points_outside_the_body_are_errors_naming_the_probe() {
        for name in ["p1", "p2", "q1", "prism", "pyramid"] {
            let mesh = beam(name, TetSplit::Five);
            let err = Probe::locate(&mesh, "tip-far", Vec3::new(3.0, 0.25, 0.25)).unwrap_err();
            match &err {
                ProbeError::Outside { name: n, distance_m, .. } => {
                    assert_eq!(n, "tip-far");
                    assert!((distance_m - 1.0).abs() < 1e-6, "{name}: distance {distance_m}");
                }
                other => panic!("{name}: {other:?}"),
            }
            let message = err.to_string();
            assert!(message.contains("'tip-far'") && message.contains("outside"), "{message}");
            // The body's size is |(2, 0.5, 0.5)| ≈ 2.12 m, so the surface tolerance is ≈ 2.1e-9 m.
            // Just outside, but farther than the surface tolerance:
            let err = Probe::locate(&mesh, "near", Vec3::new(2.0 + 3e-9, 0.25, 0.25)).unwrap_err();
            assert!(matches!(err, ProbeError::Outside { .. }), "{name}: {err:?}");
            // within it (and ≥ 6e-9 outside in reference coordinates): inside, clamped onto the face.
            let probe = Probe::locate(&mesh, "skin", Vec3::new(2.0 + 1.5e-9, 0.25, 0.25)).unwrap();
            check_probe(&mesh, &probe);
            assert!((probe.position(&mesh.rest_positions) - Vec3::new(2.0, 0.25, 0.25)).norm() < 1e-12);
        }
        let mesh = &boxes()[0].1;
        for bad in [Vec3::new(f64::NAN, 0.0, 0.0), Vec3::new(0.5, f64::INFINITY, 0.0)] {
            let err = Probe::locate(mesh, "nan", bad).unwrap_err();
            assert!(matches!(err, ProbeError::NonFinite { .. }), "{err:?}");
            assert!(err.to_string().contains("'nan'"), "{err}");
        }
    }

    /// The paper's bending probe lies on the end face of the beam, on an element edge.
    #[test]
    fn the_paper_bending_probe_is_located_on_the_p2_beam() {
        let p = Vec3::new(2.0, 0.25, 0.25);
        for split in [TetSplit::Five, TetSplit::Six] {
            let mesh = beam("p2", split);
            let probe = Probe::locate(&mesh, "bending", p).unwrap();
            check_probe(&mesh, &probe);
            assert!((probe.position(&mesh.rest_positions) - p).norm() < 1e-12);
            // A bending-like smooth deformation: the probe follows the interpolated field.
            let x: Vec<Vec3> = mesh.rest_positions.iter().map(|q| q + Vec3::new(0.0, 0.0, -0.1 * q.x * q.x)).collect();
            let u = probe.displacement(&x, &mesh.rest_positions);
            assert!((u - Vec3::new(0.0, 0.0, -0.4)).norm() < 1e-9, "{u}"); // P2 reproduces x²
        }
    }

    #[test]
    fn projection_on_reference_domains_lands_inside_and_fixes_inside_points() {
        for et in ElementType::all() {
            let shape = et.shape();
            let c = shape.centroid();
            assert_eq!(project_on(shape, c), c);
            for v in shape.vertices() {
                let far = [0, 1, 2].map(|d| c[d] + 3.0 * (v[d] - c[d]));
                let r = project_on(shape, far);
                assert!(shape.contains(&r, 1e-14), "{shape:?}: {r:?}");
                for d in 0..3 {
                    assert!((r[d] - v[d]).abs() < 1e-9, "{shape:?}: {far:?} -> {r:?}, vertex {v:?}");
                }
            }
        }
    }
}
