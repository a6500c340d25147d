use super::*;
use crate::element::ElementType;
use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

fn box_mesh(element: &str, cells: [usize; 3]) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 1.0, 0.5), cells },
        element_type: ElementType::from_name(element).unwrap(),
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap()
}

fn vertex_positions(s: &Surface, nodes: &[Vec3]) -> Vec<Vec3> {
    let mut out = Vec::new();
    s.vertices.eval_into(nodes, &mut out);
    out
}

/// Volume enclosed by the triangles (divergence theorem); exact for a closed, outward surface.
fn enclosed_volume(s: &Surface, v: &[Vec3]) -> f64 {
    s.triangles.iter().map(|t| v[t[0] as usize].dot(&v[t[1] as usize].cross(&v[t[2] as usize])) / 6.0).sum()
}

#[test]
fn surface_is_closed_outward_and_encloses_the_box_for_every_element_type() {
    for e in ElementType::all() {
        for segments in [1, 3] {
            let mesh = box_mesh(e.name(), [2, 1, 1]);
            let s = Surface::new(&mesh, segments);
            let v = vertex_positions(&s, &mesh.rest_positions);
            let volume = enclosed_volume(&s, &v);
            assert!((volume - 1.0).abs() < 1e-12, "{} segments {segments}: enclosed volume {volume}", e.name());
            // watertight and consistently oriented: every directed edge once, its reverse once
            let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
            for t in &s.triangles {
                for k in 0..3 {
                    *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &directed {
                assert_eq!(n, 1, "{}: edge {a}-{b} used {n} times in one direction", e.name());
                assert_eq!(directed.get(&(b, a)), Some(&1), "{}: edge {a}-{b} has no opposite", e.name());
            }
        }
    }
}

#[test]
fn curved_faces_follow_the_element_map_exactly() {
    // a quadratic bend u_z = 0.1 X_x², which P2, P3 and Q2 elements reproduce exactly
    let bend = |x: &Vec3| Vec3::new(x.x, x.y, x.z + 0.1 * x.x * x.x);
    for (name, exact) in [("p2", true), ("p3", true), ("q2", true), ("q1", false)] {
        let mesh = box_mesh(name, [2, 1, 1]);
        let s = Surface::new(&mesh, 4);
        let deformed: Vec<Vec3> = mesh.rest_positions.iter().map(bend).collect();
        let rest = vertex_positions(&s, &mesh.rest_positions);
        let now = vertex_positions(&s, &deformed);
        let worst = rest.iter().zip(&now).map(|(x, y)| (bend(x) - y).norm()).fold(0.0, f64::max);
        if exact {
            assert!(worst < 1e-12, "{name}: display surface off the exact bend by {worst}");
        } else {
            assert!(worst > 1e-4, "{name}: a linear element cannot follow a quadratic bend ({worst})");
        }
    }
}

#[test]
fn edges_and_node_kinds_of_one_cube() {
    let q1 = box_mesh("q1", [1, 1, 1]);
    let s = Surface::new(&q1, 3);
    assert_eq!(s.edges.len(), 12);
    assert!(s.edges.iter().all(|e| e.len() == 4));
    assert_eq!(s.node_kind.iter().filter(|k| **k == Some(NodeKind::Corner)).count(), 8);
    let q2 = box_mesh("q2", [1, 1, 1]);
    let s = Surface::new(&q2, 2);
    assert_eq!(s.node_kind.iter().filter(|k| **k == Some(NodeKind::Corner)).count(), 8);
    assert_eq!(s.node_kind.iter().filter(|k| **k == Some(NodeKind::HighOrder)).count(), 12 + 6);
    // linear triangles stay single triangles whatever the setting
    let p1 = box_mesh("p1", [1, 1, 1]);
    let s = Surface::new(&p1, 5);
    assert_eq!(s.triangles.len(), 12);
    assert!(s.edges.iter().all(|e| e.len() == 2));
}

#[test]
fn quadrature_points_lie_in_the_body() {
    for e in ElementType::all() {
        let mesh = box_mesh(e.name(), [2, 1, 1]);
        let geometry = crate::fem::geometry::precompute(&mesh, None).unwrap();
        let q = quadrature_points(&mesh, &geometry);
        let expected: usize = geometry.iter().map(|g| g.num_elements() * g.points_per_element).sum();
        assert_eq!(q.len(), expected);
        let mut x = Vec::new();
        q.eval_into(&mesh.rest_positions, &mut x);
        let inside = |p: &Vec3| p.x >= 0.0 && p.x <= 2.0 && p.y >= 0.0 && p.y <= 1.0 && p.z >= 0.0 && p.z <= 0.5;
        assert!(x.iter().all(inside), "{}", e.name());
    }
}
