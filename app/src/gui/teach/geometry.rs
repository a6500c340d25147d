//! The reference element as geometry: its one-element mesh and display surface, its sections by
//! coordinate planes, and which of its boundary points face the eye.

use super::SEGMENTS;
use hox_sim::Vec3;
use hox_sim::element::{ElementType, ReferenceShape};
use hox_sim::measure::surface::Surface;
use hox_sim::mesh::{ElementBlock, Mesh};

/// The one-element mesh of an element type and its display surface.
pub(super) struct ElementGeometry {
    pub(super) element: ElementType,
    pub(super) surface: Surface,
    /// The reference coordinate `r` of every surface vertex (= its position: the map is the
    /// identity on the reference element).
    pub(super) vertex_reference: Vec<[f64; 3]>,
    /// The surface vertex at each node (`None` for a node inside the element).
    pub(super) node_vertex: Vec<Option<usize>>,
}

impl ElementGeometry {
    pub(super) fn new(element: ElementType) -> ElementGeometry {
        let reference = element.reference();
        let num_nodes = reference.num_nodes();
        let mesh = Mesh {
            rest_positions: reference.nodes().iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect(),
            blocks: vec![ElementBlock::new(element, (0..num_nodes as u32).collect())],
        };
        let surface = Surface::new(&mesh, SEGMENTS);
        let mut positions = Vec::new();
        surface.vertices.eval_into(&mesh.rest_positions, &mut positions);
        let vertex_reference: Vec<[f64; 3]> = positions.iter().map(|p| [p.x, p.y, p.z]).collect();
        let node_vertex =
            reference.nodes().iter().map(|r| vertex_reference.iter().position(|v| same_point(v, r))).collect();
        ElementGeometry { element, surface, vertex_reference, node_vertex }
    }
}

pub(super) fn same_point(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < 1e-9)
}

/// The section of the reference domain of `shape` by the plane `r[axis] = value`: a convex
/// polygon with its vertices in order, or `None` when the plane only touches the domain.
pub(super) fn section_polygon(shape: ReferenceShape, axis: usize, value: f64) -> Option<Vec<[f64; 3]>> {
    let vertices = shape.vertices();
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut push = |p: [f64; 3]| {
        if !points.iter().any(|q| same_point(q, &p)) {
            points.push(p);
        }
    };
    for &[a, b] in shape.edges() {
        let (pa, pb) = (vertices[a], vertices[b]);
        let (da, db) = (pa[axis] - value, pb[axis] - value);
        if da.abs() < 1e-12 {
            push(pa);
        }
        if db.abs() < 1e-12 {
            push(pb);
        }
        if da * db < 0.0 {
            let t = da / (da - db);
            push(std::array::from_fn(|k| pa[k] + t * (pb[k] - pa[k])));
        }
    }
    if points.len() < 3 {
        return None;
    }
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let c = polygon_centroid(&points);
    points.sort_by(|p, q| (p[v] - c[v]).atan2(p[u] - c[u]).total_cmp(&(q[v] - c[v]).atan2(q[u] - c[u])));
    (polygon_area(&points, axis) > 1e-9).then_some(points)
}

pub(super) fn polygon_centroid(points: &[[f64; 3]]) -> [f64; 3] {
    let n = points.len().max(1) as f64;
    std::array::from_fn(|k| points.iter().map(|p| p[k]).sum::<f64>() / n)
}

/// Area of a planar polygon lying in a plane normal to `axis` (shoelace formula).
pub(super) fn polygon_area(points: &[[f64; 3]], axis: usize) -> f64 {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let twice: f64 = (0..points.len())
        .map(|k| {
            let (p, q) = (points[k], points[(k + 1) % points.len()]);
            p[u] * q[v] - q[u] * p[v]
        })
        .sum();
    0.5 * twice.abs()
}

/// Whether the boundary point `r` of the convex reference domain is seen from `eye`: it lies on a
/// face whose outward normal faces the eye.
pub(super) fn seen_from(shape: ReferenceShape, r: &[f64; 3], eye: [f32; 3]) -> bool {
    let vertices = shape.vertices();
    let r = Vec3::from(*r);
    let eye = Vec3::from(eye.map(|c| c as f64));
    shape.faces().iter().any(|face| {
        let [a, b, c] = [face[0], face[1], face[2]].map(|i| Vec3::from(vertices[i]));
        let n = (b - a).cross(&(c - a));
        (r - a).dot(&n).abs() < 1e-9 * n.norm() && (eye - r).dot(&n) > 0.0
    })
}
