//! A node's shape function as a colour field: its values at reference points, the diverging
//! colour map, and the flat triangles (surface or sections) the picture is drawn with.

use super::SEGMENTS;
use super::geometry::{ElementGeometry, polygon_centroid, same_point, section_polygon};
use crate::gui::raster::{Camera, Image, Overlay, TriangleLayer};
use hox_sim::Vec3;
use hox_sim::element::ReferenceElement;

/// The value the blue end of the colour map stands for.
pub(super) const FIELD_MIN_SHOWN: f64 = -0.25;
/// Colour stops of the diverging map: value, RGB (ColorBrewer RdBu / YlOrRd ends).
const FIELD_STOPS: [(f64, [u8; 3]); 6] = [
    (FIELD_MIN_SHOWN, [5, 48, 97]),
    (-0.125, [67, 147, 195]),
    (0.0, [247, 247, 247]),
    (0.35, [254, 224, 139]),
    (0.7, [244, 109, 67]),
    (1.0, [165, 0, 38]),
];
/// Mid grey: seen on the white of a zero field and on the dark background alike.
const EDGE_COLOUR: [u8; 4] = [105, 105, 115, 255];
const SECTION_OUTLINE_COLOUR: [u8; 4] = [150, 150, 160, 255];

/// `N_node(r)` at every reference point `r` of `points`: the shape function of `node` as a field.
///
/// A non-finite value (a rational shape function exactly at a singular point) is replaced by its
/// value at a node there, `δ_ij`, as the display surface's [`hox_sim::measure::surface::PointMap`] does.
pub fn shape_function_field(element: &dyn ReferenceElement, points: &[[f64; 3]], node: usize) -> Vec<f64> {
    let mut n = vec![0.0; element.num_nodes()];
    points
        .iter()
        .map(|r| {
            element.shape_functions(r, &mut n);
            match n.get(node) {
                Some(v) if v.is_finite() => *v,
                _ => match element.nodes().iter().position(|p| same_point(p, r)) {
                    Some(j) if j == node => 1.0,
                    _ => 0.0,
                },
            }
        })
        .collect()
}

/// The colour of shape-function value `value` on the diverging map (blue < 0 ≤ white < red).
pub fn field_colour(value: f64) -> [u8; 3] {
    if value.is_nan() {
        return [128, 128, 128];
    }
    let (first, last) = (FIELD_STOPS[0], FIELD_STOPS[FIELD_STOPS.len() - 1]);
    if value <= first.0 {
        return first.1;
    }
    for w in FIELD_STOPS.windows(2) {
        let ((a, colour_a), (b, colour_b)) = (w[0], w[1]);
        if value <= b {
            let t = (value - a) / (b - a);
            return std::array::from_fn(|k| {
                (colour_a[k] as f64 + t * (colour_b[k] as f64 - colour_a[k] as f64)).round() as u8
            });
        }
    }
    last.1
}

/// What a [`FieldMesh`] shows.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct FieldKey {
    pub(super) element: &'static str,
    pub(super) node: usize,
    pub(super) sections: bool,
}

/// Flat triangles of reference points with the field at each, plus the lines drawn over them.
#[derive(Default)]
pub(super) struct FieldMesh {
    /// Reference coordinates (= positions).
    pub(super) points: Vec<[f64; 3]>,
    /// The unit normal of the plane each point was emitted on.
    normals: Vec<[f32; 3]>,
    pub(super) values: Vec<f64>,
    pub(super) triangles: Vec<[u32; 3]>,
    lines: Vec<([f32; 3], [f32; 3], [u8; 4])>,
    /// Smallest and largest value shown.
    pub(super) min: f64,
    pub(super) max: f64,
}

impl FieldMesh {
    /// The field of `node` on the surface of `geometry`, or on the sections through the node.
    pub(super) fn new(geometry: &ElementGeometry, node: usize, sections: bool) -> FieldMesh {
        let element = geometry.element.reference();
        let shape = element.shape();
        let mut field = FieldMesh::default();
        let f32s = |r: &[f64; 3]| r.map(|c| c as f32);
        if sections {
            let centre = element.nodes().get(node).copied().unwrap_or_else(|| shape.centroid());
            for axis in 0..3 {
                let Some(polygon) = section_polygon(shape, axis, centre[axis]) else { continue };
                let mut normal = [0.0f32; 3];
                normal[axis] = 1.0;
                let c = polygon_centroid(&polygon);
                for k in 0..polygon.len() {
                    let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
                    field.push_triangle([c, a, b], normal, SEGMENTS / 2);
                    field.lines.push((f32s(&a), f32s(&b), SECTION_OUTLINE_COLOUR));
                }
            }
        } else {
            // a surface left coarse (flat P1 faces) is subdivided, so the colour map reads smooth
            let subdivisions = if geometry.surface.triangles.len() <= 2 * element.faces().len() { SEGMENTS } else { 1 };
            for t in &geometry.surface.triangles {
                let [a, b, c] = t.map(|i| geometry.vertex_reference[i as usize]);
                let (ab, ac) = (Vec3::from(b) - Vec3::from(a), Vec3::from(c) - Vec3::from(a));
                let n = ab.cross(&ac).try_normalize(1e-300).unwrap_or_else(Vec3::z);
                field.push_triangle([a, b, c], [n.x as f32, n.y as f32, n.z as f32], subdivisions);
            }
        }
        for edge in &geometry.surface.edges {
            for pair in edge.windows(2) {
                let (a, b) = (geometry.vertex_reference[pair[0] as usize], geometry.vertex_reference[pair[1] as usize]);
                field.lines.push((f32s(&a), f32s(&b), EDGE_COLOUR));
            }
        }
        field.values = shape_function_field(element, &field.points, node);
        // round-off (−1e-16 where the field is 0) is not a dip below zero
        let snap = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v };
        field.min = snap(field.values.iter().copied().fold(f64::INFINITY, f64::min));
        field.max = snap(field.values.iter().copied().fold(f64::NEG_INFINITY, f64::max));
        field
    }

    /// Adds triangle `corners` cut into `k²` flat pieces (its own vertices: flat shading).
    fn push_triangle(&mut self, corners: [[f64; 3]; 3], normal: [f32; 3], k: usize) {
        let k = k.max(1);
        let [a, b, c] = corners;
        let mut index = vec![vec![0u32; k + 1]; k + 1];
        for i in 0..=k {
            for j in 0..=k - i {
                let (s, t) = (i as f64 / k as f64, j as f64 / k as f64);
                index[i][j] = self.points.len() as u32;
                self.points.push(std::array::from_fn(|d| a[d] + s * (b[d] - a[d]) + t * (c[d] - a[d])));
                self.normals.push(normal);
            }
        }
        for i in 0..k {
            for j in 0..k - i {
                self.triangles.push([index[i][j], index[i + 1][j], index[i][j + 1]]);
                if i + j + 1 < k {
                    self.triangles.push([index[i + 1][j], index[i + 1][j + 1], index[i][j + 1]]);
                }
            }
        }
    }

    /// The triangle layer seen by `camera`: field colours, normals tilted toward the viewer so
    /// the shading separates the faces without darkening the colour map much.
    fn layer(&self, camera: &Camera) -> TriangleLayer {
        let eye = camera.eye();
        let view = (Vec3::new(eye.x as f64, eye.y as f64, eye.z as f64) - Vec3::from(camera.target.map(|c| c as f64)))
            .normalize();
        TriangleLayer {
            positions: self.points.iter().map(|r| r.map(|c| c as f32)).collect(),
            normals: self
                .normals
                .iter()
                .map(|n| {
                    let n = Vec3::from(n.map(|c| c as f64));
                    let facing = if n.dot(&view) < 0.0 { -n } else { n };
                    let shading = (facing + 0.6 * view).try_normalize(1e-12).unwrap_or(view);
                    [shading.x as f32, shading.y as f32, shading.z as f32]
                })
                .collect(),
            colours: self.values.iter().map(|&v| field_colour(v)).collect(),
            triangles: self.triangles.clone(),
        }
    }
}

/// Renders `field` seen by `camera` into `image` (its size is the picture's).
pub(super) fn render_field(field: &FieldMesh, camera: &Camera, image: &mut Image) {
    let layer = field.layer(camera);
    let overlay = Overlay { lines: field.lines.clone(), points: Vec::new() };
    image.render(camera, &[&layer], &overlay);
}
