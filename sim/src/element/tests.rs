//! Property tests run for every registered element type.

use super::lagrange::{Exponents, monomial, tensor_exponents, total_degree_exponents};
use super::*;
use proptest::prelude::*;

/// Maps four numbers in [0,1] to a point of the reference shape (away from the pyramid apex).
pub(crate) fn point_in(shape: ReferenceShape, u: [f64; 4]) -> [f64; 3] {
    match shape {
        ReferenceShape::Tetrahedron => {
            let s: f64 = u.iter().sum::<f64>() + 1e-9;
            [u[1] / s, u[2] / s, u[3] / s]
        }
        ReferenceShape::Hexahedron => [2. * u[0] - 1., 2. * u[1] - 1., 2. * u[2] - 1.],
        ReferenceShape::Prism => {
            let s = u[0] + u[1] + u[2] + 1e-9;
            [u[1] / s, u[2] / s, 2. * u[3] - 1.]
        }
        ReferenceShape::Pyramid => {
            let z = 0.95 * u[2];
            [(2. * u[0] - 1.) * (1. - z), (2. * u[1] - 1.) * (1. - z), z]
        }
    }
}

/// Monomials each element must reproduce exactly.
fn reproduced_space(e: ElementType) -> Vec<Exponents> {
    match e.shape() {
        ReferenceShape::Tetrahedron => total_degree_exponents(e.order() as u32),
        ReferenceShape::Hexahedron => tensor_exponents(e.order() as u32),
        ReferenceShape::Prism => vec![[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]],
        ReferenceShape::Pyramid => total_degree_exponents(1),
    }
}

/// A quartic tetrahedron P4 (35 nodes, order-4 faces of 15 nodes) that is **not** registered:
/// what adding an element type brings, so that tests can run every generic path (meshing,
/// faces, the generic kernels, the surface, VTK) on an element of order 4 with more nodes than
/// any built-in one. A [`LagrangeElement`](super::lagrange::LagrangeElement) of the lattice
/// points `i/4`: the vertices, then three nodes per edge in Gmsh's edge order, then the face and
/// interior points in lexicographic order (not Gmsh's: it is never read from a file). Its VTK
/// node order is the identity (not checked against VTK's Lagrange tetrahedron).
pub(crate) fn unregistered_p4() -> ElementType {
    use super::lagrange::LagrangeElement;
    use std::sync::OnceLock;
    static P4: OnceLock<&'static LagrangeElement> = OnceLock::new();
    let p4: &'static LagrangeElement = P4.get_or_init(|| {
        let k = 4;
        let verts = ReferenceShape::Tetrahedron.vertices();
        let mut nodes: Vec<[f64; 3]> = verts.to_vec();
        for [a, b] in ReferenceShape::Tetrahedron.edges() {
            for j in 1..k {
                let t = j as f64 / k as f64;
                nodes.push(std::array::from_fn(|d| verts[*a][d] + t * (verts[*b][d] - verts[*a][d])));
            }
        }
        for a in 0..=k {
            for b in 0..=k - a {
                for c in 0..=k - a - b {
                    let r = [a, b, c].map(|i| i as f64 / k as f64);
                    if !nodes.iter().any(|q| (0..3).all(|d| (q[d] - r[d]).abs() < 1e-12)) {
                        nodes.push(r);
                    }
                }
            }
        }
        let identity: Vec<usize> = (0..nodes.len()).collect();
        Box::leak(Box::new(LagrangeElement {
            name: "p4",
            description: "quartic tetrahedron (35 nodes), unregistered, for tests",
            shape: ReferenceShape::Tetrahedron,
            order: 4,
            nodes: Box::leak(nodes.into_boxed_slice()),
            exponents: || total_degree_exponents(4),
            // ∇N_i · ∇N_j is of degree 6; N_i N_j of degree 8
            default_quadrature_degree: 6,
            mass_quadrature_degree: 8,
            gmsh_type: 30,
            vtk_cell_type: 71,
            vtk_node_order: Box::leak(identity.into_boxed_slice()),
            basis: OnceLock::new(),
            faces: OnceLock::new(),
        }))
    });
    ElementType(p4)
}

/// The registered element types and the unregistered P4.
fn registered_and_p4() -> impl Iterator<Item = ElementType> {
    ElementType::all().chain(std::iter::once(unregistered_p4()))
}

#[test]
fn the_unregistered_p4_has_35_nodes_and_15_node_faces_and_is_not_registered() {
    let p4 = unregistered_p4();
    assert_eq!(p4.num_nodes(), 35);
    assert!(p4.faces().iter().all(|f| f.nodes.len() == 15 && f.order == 4));
    assert!(ElementType::from_name("p4").is_none() && ElementType::from_gmsh_type(30).is_none());
}

fn unit4() -> impl Strategy<Value = [f64; 4]> {
    [0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64]
}

fn eval(e: ElementType, r: &[f64; 3]) -> (Vec<f64>, Vec<[f64; 3]>) {
    let mut n = vec![0.0; e.num_nodes()];
    let mut g = vec![[0.0; 3]; e.num_nodes()];
    e.shape_functions(r, &mut n);
    e.shape_gradients(r, &mut g);
    (n, g)
}

#[test]
fn registry_starts_with_the_seven_built_in_types_with_gmsh_node_counts_and_unique_names_and_codes() {
    let counts: Vec<(String, usize, u32)> =
        ElementType::all().map(|e| (e.name().to_string(), e.num_nodes(), e.gmsh_type())).collect();
    assert_eq!(
        counts[..7],
        [
            ("p1".into(), 4, 4),
            ("p2".into(), 10, 11),
            ("p3".into(), 20, 29),
            ("q1".into(), 8, 5),
            ("q2".into(), 27, 12),
            ("prism".into(), 6, 6),
            ("pyramid".into(), 5, 7),
        ]
    );
    // names, Gmsh types and VTK cell types each find one element
    for e in ElementType::all() {
        assert_eq!(ElementType::from_name(&e.name().to_uppercase()), Some(e));
        assert_eq!(ElementType::from_gmsh_type(e.gmsh_type()), Some(e), "{e}: Gmsh type {}", e.gmsh_type());
        assert_eq!(ElementType::from_vtk_cell_type(e.vtk_cell_type()), Some(e), "{e}: VTK type {}", e.vtk_cell_type());
        let linear = ElementType::linear(e.shape()).unwrap_or_else(|| panic!("{e}: no linear {:?}", e.shape()));
        assert_eq!((linear.shape(), linear.order()), (e.shape(), 1), "{e}");
    }
    assert_eq!(ElementType::from_name("P2").unwrap().name(), "p2");
    let unknown = "p9".parse::<ElementType>().unwrap_err();
    assert!(
        unknown.contains(&ElementType::names()) && unknown.contains("p1, p2, p3, q1, q2, prism, pyramid"),
        "{unknown}"
    );
    assert_eq!(ElementType::from_gmsh_type(29).unwrap().name(), "p3");
}

#[test]
fn kronecker_property_at_the_nodes() {
    for e in registered_and_p4() {
        for (j, r) in e.nodes().iter().enumerate() {
            let (n, _) = eval(e, r);
            for (i, v) in n.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-12, "{e}: N_{i}(node {j}) = {v}");
            }
        }
    }
}

#[test]
fn vertices_come_first_and_nodes_lie_in_the_reference_domain() {
    for e in registered_and_p4() {
        let verts = e.shape().vertices();
        assert_eq!(&e.nodes()[..verts.len()], verts, "{e}");
        assert!(e.nodes().iter().all(|r| e.shape().contains(r, 1e-14)), "{e}");
        // no duplicate nodes
        for (i, a) in e.nodes().iter().enumerate() {
            for b in &e.nodes()[i + 1..] {
                assert!(a != b, "{e}: duplicate node {a:?}");
            }
        }
    }
}

#[test]
fn high_order_nodes_sit_on_their_gmsh_edges() {
    // Gmsh: edge nodes follow the vertices, edge by edge in the shape's edge order, each edge
    // traversed from its first to its second vertex.
    for e in registered_and_p4().filter(|e| e.order() > 1) {
        let verts = e.shape().vertices();
        let k = e.order();
        let mut idx = verts.len();
        for [a, b] in e.shape().edges() {
            for j in 1..k {
                let t = j as f64 / k as f64;
                let want: Vec<f64> = (0..3).map(|d| verts[*a][d] + t * (verts[*b][d] - verts[*a][d])).collect();
                let got = e.nodes()[idx];
                assert!((0..3).all(|d| (got[d] - want[d]).abs() < 1e-14), "{e}: node {idx} {got:?} vs {want:?}");
                idx += 1;
            }
        }
    }
}

#[test]
fn faces_are_outward_planar_and_have_the_high_order_node_count() {
    for e in registered_and_p4() {
        let centroid = e.shape().centroid();
        let nodes = e.nodes();
        let mut covered = vec![false; e.num_nodes()];
        for f in e.faces() {
            let k = f.order;
            let want = match f.shape {
                FaceShape::Triangle => (k + 1) * (k + 2) / 2,
                FaceShape::Quadrilateral => (k + 1) * (k + 1),
            };
            assert_eq!(f.nodes.len(), want, "{e}");
            let c = f.corners();
            let p = |i: usize| nalgebra::Vector3::from(nodes[c[i]]);
            let normal = (p(1) - p(0)).cross(&(p(2) - p(0)));
            let inward = nalgebra::Vector3::from(centroid) - p(0);
            assert!(normal.dot(&inward) < 0.0, "{e}: face {:?} points inwards", f.nodes);
            for &n in &f.nodes {
                let d = (nalgebra::Vector3::from(nodes[n]) - p(0)).dot(&normal);
                assert!(d.abs() < 1e-12, "{e}: node {n} off the face plane");
                covered[n] = true;
            }
        }
        // every node but interior ones lies on some face
        let interior = nodes.iter().filter(|r| e.shape().contains(r, -1e-9)).count();
        assert_eq!(covered.iter().filter(|c| !**c).count(), interior, "{e}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn partition_of_unity_and_gradients_sum_to_zero(u in unit4()) {
        for e in registered_and_p4() {
            let r = point_in(e.shape(), u);
            let (n, g) = eval(e, &r);
            let sum: f64 = n.iter().sum();
            prop_assert!((sum - 1.0).abs() < 1e-12, "{}: ΣN = {}", e, sum);
            for d in 0..3 {
                let s: f64 = g.iter().map(|gi| gi[d]).sum();
                prop_assert!(s.abs() < 1e-11, "{}: Σ∂N/∂r_{} = {}", e, d, s);
            }
        }
    }

    #[test]
    fn polynomials_of_the_element_space_are_reproduced_exactly(u in unit4()) {
        for e in registered_and_p4() {
            let r = point_in(e.shape(), u);
            let (n, g) = eval(e, &r);
            for m in reproduced_space(e) {
                let interp: f64 = e.nodes().iter().zip(&n).map(|(x, ni)| monomial(&m, x) * ni).sum();
                prop_assert!((interp - monomial(&m, &r)).abs() < 1e-11, "{}: {:?}", e, m);
                // and its gradient
                for d in 0..3 {
                    let gi: f64 = e.nodes().iter().zip(&g).map(|(x, gi)| monomial(&m, x) * gi[d]).sum();
                    let mut dm = m;
                    let exact = if m[d] == 0 { 0.0 } else {
                        dm[d] -= 1;
                        m[d] as f64 * monomial(&dm, &r)
                    };
                    prop_assert!((gi - exact).abs() < 1e-10, "{}: ∂{:?}/∂r_{}", e, m, d);
                }
            }
        }
    }

    #[test]
    fn gradients_match_finite_differences(u in unit4()) {
        let h = 1e-6;
        for e in registered_and_p4() {
            let r = point_in(e.shape(), u);
            let (_, g) = eval(e, &r);
            for d in 0..3 {
                let (mut rp, mut rm) = (r, r);
                rp[d] += h;
                rm[d] -= h;
                let (np, _) = eval(e, &rp);
                let (nm, _) = eval(e, &rm);
                for i in 0..e.num_nodes() {
                    let fd = (np[i] - nm[i]) / (2.0 * h);
                    prop_assert!((fd - g[i][d]).abs() < 1e-7 * (1.0 + fd.abs()), "{}: ∂N_{}/∂r_{}: {} vs {}", e, i, d, g[i][d], fd);
                }
            }
        }
    }
}

/// The Lagrange construction has no order limit: a degree-9 tetrahedron basis (220 lattice
/// nodes, monomial powers beyond the tabulated 7) is nodal and sums to one.
#[test]
fn the_lagrange_construction_works_beyond_the_tabulated_powers() {
    use super::lagrange::LagrangeBasis;
    let k = 9;
    let mut nodes = Vec::new();
    for a in 0..=k {
        for b in 0..=k - a {
            for c in 0..=k - a - b {
                nodes.push([a, b, c].map(|i| i as f64 / k as f64));
            }
        }
    }
    let basis = LagrangeBasis::new(&nodes, total_degree_exponents(k as u32));
    let mut n = vec![0.0; nodes.len()];
    for (j, r) in nodes.iter().enumerate().step_by(7) {
        basis.values(r, &mut n);
        for (i, v) in n.iter().enumerate() {
            assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-6, "N_{i}(node {j}) = {v}");
        }
    }
    basis.values(&[0.1, 0.2, 0.3], &mut n);
    assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-6);
}
