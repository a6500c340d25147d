//! The reference-element view, a teaching aid: pick an element type and one of its nodes and see
//! that node's shape function `N_i(r)` as a colour field on the reference element, with the
//! element's nodes and the quadrature points the solver samples.
//!
//! Every element maps its reference domain to space by `x(r) = Σ_j N_j(r) x_j`, and the shape
//! functions are built so that `N_i(r_j) = δ_ij` at the nodes `r_j`. Here the element *is* its
//! reference domain (`x_j = r_j`; the shape functions reproduce linear functions, so the map is
//! the identity): a displayed point's position is its reference coordinate `r`, and its colour is
//! `N_i(r)` from the element's own `shape_functions`.
//!
//! The picture is the sim's display surface ([`Surface`]) of a one-element mesh with every face
//! edge cut into [`SEGMENTS`] = 12 pieces: a multiple of 2 and 3, so every edge and face node of
//! P2, P3 and Q2 is a display vertex, where the field reads exactly 1 (its own node) or 0 (any
//! other). The reference element is straight-sided, so its faces are planes and are drawn flat;
//! only the field curves. An interior node (the Q2 centre) cannot be seen from outside — its
//! function vanishes on every face — so the view then shows the three sections through the node
//! (parallel to the coordinate planes); the same sections can be asked for any node.
//!
//! Colours: a diverging map, blue below zero (saturated at −0.25), white at 0, yellow to red up
//! to 1. Quadratic and cubic shape functions dip below zero between nodes; the linear ones (P1,
//! Q1, prism, pyramid) never do. Element edges are drawn in the picture (depth-tested), the edges
//! on the far side dashed over it; nodes are dots labelled with their index (corners black,
//! high-order nodes purple, the selected node large and green, far-side nodes faded). Orange dots
//! are the quadrature points of `∫ f ≈ Σ_q w_q f(r_q)` (drawn through the surface: they are all
//! inside the element).
//!
//! Mouse: drag to orbit, right- or middle-drag to pan, scroll to zoom, click a node to select it,
//! double-click to reset the view. The picture is re-rendered only when what it shows changes.

use super::raster::{Camera, Image, Overlay, TriangleLayer};
use eframe::egui;
use hox_sim::Vec3;
use hox_sim::element::{ElementType, ReferenceElement, ReferenceShape};
use hox_sim::fem::quadrature;
use hox_sim::measure::surface::Surface;
use hox_sim::mesh::{ElementBlock, Mesh};

/// Pieces per face edge of the display surface (a multiple of 2 and 3: see the module docs).
pub const SEGMENTS: usize = 12;
/// Pick radius around a projected node, points.
const PICK_RADIUS_POINTS: f32 = 12.0;
/// The value the blue end of the colour map stands for.
const FIELD_MIN_SHOWN: f64 = -0.25;
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
const CORNER_NODE_COLOUR: egui::Color32 = egui::Color32::from_rgb(20, 20, 24);
const HIGH_ORDER_NODE_COLOUR: egui::Color32 = egui::Color32::from_rgb(120, 60, 200);
const SELECTED_NODE_COLOUR: egui::Color32 = egui::Color32::from_rgb(0, 190, 110);
const QUADRATURE_COLOUR: egui::Color32 = egui::Color32::from_rgb(255, 140, 0);

/// The reference-element view's state: what is shown and the cached picture.
pub struct ReferenceElementView {
    element: ElementType,
    /// The selected node, whose shape function is drawn.
    node: usize,
    camera: Camera,
    show_quadrature: bool,
    /// Quadrature degree of exactness; `None` = the element's default.
    quadrature_degree: Option<usize>,
    /// Show the sections through the selected node instead of the surface.
    sections: bool,
    geometry: Option<ElementGeometry>,
    field: Option<(FieldKey, FieldMesh)>,
    image: Option<Image>,
    picture: Option<Picture>,
    texture: Option<egui::TextureHandle>,
}

impl Default for ReferenceElementView {
    fn default() -> Self {
        let element =
            ElementType::from_name("p2").or_else(|| ElementType::all().next()).expect("hox registers element types");
        ReferenceElementView {
            element,
            node: 0,
            camera: framing_camera(element.shape()),
            show_quadrature: true,
            quadrature_degree: None,
            sections: false,
            geometry: None,
            field: None,
            image: None,
            picture: None,
            texture: None,
        }
    }
}

/// The camera that frames the reference domain of `shape` (the sphere about its vertices' mean
/// through its farthest vertex), from a direction that shows two or three of its faces at a fair
/// angle (the slanted face of the tetrahedron and the prism too).
fn framing_camera(shape: ReferenceShape) -> Camera {
    let vertices = shape.vertices();
    let centre = Vec3::from(polygon_centroid(vertices));
    let radius = vertices.iter().map(|v| (Vec3::from(*v) - centre).norm()).fold(0.0, f64::max) as f32;
    let mut camera = Camera::framing([-1.0; 3], [1.0; 3]);
    // (yaw, pitch), radians
    (camera.yaw, camera.pitch) = match shape {
        ReferenceShape::Tetrahedron => (-0.64, 0.6),
        ReferenceShape::Prism => (-0.5, 0.5),
        ReferenceShape::Hexahedron => (-0.9, 0.45),
        ReferenceShape::Pyramid => (-0.6, 0.4),
    };
    camera.target = [centre.x as f32, centre.y as f32, centre.z as f32];
    camera.distance = 1.05 * radius.max(1e-3) / (0.5 * camera.fov_y).sin();
    camera
}

/// The one-element mesh of an element type and its display surface.
struct ElementGeometry {
    element: ElementType,
    surface: Surface,
    /// The reference coordinate `r` of every surface vertex (= its position: the map is the
    /// identity on the reference element).
    vertex_reference: Vec<[f64; 3]>,
    /// The surface vertex at each node (`None` for a node inside the element).
    node_vertex: Vec<Option<usize>>,
}

impl ElementGeometry {
    fn new(element: ElementType) -> ElementGeometry {
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

fn same_point(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < 1e-9)
}

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
struct FieldKey {
    element: &'static str,
    node: usize,
    sections: bool,
}

/// Flat triangles of reference points with the field at each, plus the lines drawn over them.
#[derive(Default)]
struct FieldMesh {
    /// Reference coordinates (= positions).
    points: Vec<[f64; 3]>,
    /// The unit normal of the plane each point was emitted on.
    normals: Vec<[f32; 3]>,
    values: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    lines: Vec<([f32; 3], [f32; 3], [u8; 4])>,
    /// Smallest and largest value shown.
    min: f64,
    max: f64,
}

impl FieldMesh {
    /// The field of `node` on the surface of `geometry`, or on the sections through the node.
    fn new(geometry: &ElementGeometry, node: usize, sections: bool) -> FieldMesh {
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
fn render_field(field: &FieldMesh, camera: &Camera, image: &mut Image) {
    let layer = field.layer(camera);
    let overlay = Overlay { lines: field.lines.clone(), points: Vec::new() };
    image.render(camera, &[&layer], &overlay);
}

/// The section of the reference domain of `shape` by the plane `r[axis] = value`: a convex
/// polygon with its vertices in order, or `None` when the plane only touches the domain.
fn section_polygon(shape: ReferenceShape, axis: usize, value: f64) -> Option<Vec<[f64; 3]>> {
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

fn polygon_centroid(points: &[[f64; 3]]) -> [f64; 3] {
    let n = points.len().max(1) as f64;
    std::array::from_fn(|k| points.iter().map(|p| p[k]).sum::<f64>() / n)
}

/// Area of a planar polygon lying in a plane normal to `axis` (shoelace formula).
fn polygon_area(points: &[[f64; 3]], axis: usize) -> f64 {
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
fn seen_from(shape: ReferenceShape, r: &[f64; 3], eye: [f32; 3]) -> bool {
    let vertices = shape.vertices();
    let r = Vec3::from(*r);
    let eye = Vec3::from(eye.map(|c| c as f64));
    shape.faces().iter().any(|face| {
        let [a, b, c] = [face[0], face[1], face[2]].map(|i| Vec3::from(vertices[i]));
        let n = (b - a).cross(&(c - a));
        (r - a).dot(&n).abs() < 1e-9 * n.norm() && (eye - r).dot(&n) > 0.0
    })
}

/// Where a node was drawn: pixel position in the picture and whether it is in view.
#[derive(Clone, Copy, Debug, PartialEq)]
struct NodeMark {
    px: [f32; 2],
    visible: bool,
}

/// The index of the mark nearest to `px` within `radius_px`, visible marks first.
fn nearest_node(marks: &[Option<NodeMark>], px: [f32; 2], radius_px: f32) -> Option<usize> {
    let distance = |m: &NodeMark| ((m.px[0] - px[0]).powi(2) + (m.px[1] - px[1]).powi(2)).sqrt();
    let best = |visible: bool| {
        marks
            .iter()
            .enumerate()
            .filter_map(|(i, m)| m.filter(|m| m.visible == visible).map(|m| (i, distance(&m))))
            .filter(|&(_, d)| d <= radius_px)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    best(true).or_else(|| best(false))
}

/// Everything the picture depends on: it is re-rendered when this changes.
#[derive(Clone, Debug, PartialEq)]
struct RenderKey {
    field: FieldKey,
    camera: Camera,
    quadrature_degree: Option<usize>,
    size_px: [usize; 2],
}

/// The rendered picture's marks, in pixels of the picture.
struct Picture {
    key: RenderKey,
    nodes: Vec<Option<NodeMark>>,
    quadrature_px: Vec<[f32; 2]>,
    /// Edge segments on the far side of the element, drawn faint and dashed through it.
    hidden_edges_px: Vec<Vec<[f32; 2]>>,
    /// Number of quadrature points and degree, or why there is no rule.
    quadrature: Result<(usize, usize), String>,
}

/// The kind of node `node` of `element`: corner, edge, face or interior.
fn node_kind(element: &dyn ReferenceElement, node: usize) -> &'static str {
    if node < element.num_vertices() {
        return "corner node";
    }
    match element.faces().iter().filter(|f| f.nodes.contains(&node)).count() {
        0 => "interior node",
        1 => "face node",
        _ => "edge node",
    }
}

/// The polynomial space of `element`'s shape functions, in words.
fn function_kind(element: &dyn ReferenceElement) -> String {
    match element.name() {
        "p1" => "linear".into(),
        "p2" => "quadratic".into(),
        "p3" => "cubic".into(),
        "q1" => "trilinear".into(),
        "q2" => "triquadratic".into(),
        "prism" => "linear-times-linear".into(),
        "pyramid" => "rational".into(),
        _ => match element.order() {
            1 => "linear".into(),
            2 => "quadratic".into(),
            3 => "cubic".into(),
            k => format!("degree-{k}"),
        },
    }
}

/// The one-line explanation under the picture.
fn explanation(element: &dyn ReferenceElement, node: usize, field_min: f64, on_surface: bool) -> String {
    let name = element.name().to_uppercase();
    let kind = function_kind(element);
    let mut s = format!("N_{node} of {name} ({}): 1 at node {node}, 0 at every other node; ", node_kind(element, node));
    if field_min < -1e-9 {
        s += &format!(
            "negative values (blue, down to {field_min:.3} here) show where a {kind} shape function dips below zero"
        );
    } else if element.order() == 1 {
        s += &format!("a {kind} shape function, never negative");
    } else {
        s += &format!("a {kind} shape function, not negative anywhere shown");
    }
    if !on_surface {
        s += &format!(
            ". Node {node} is inside the element, so N_{node} vanishes on every face: shown on the sections through it"
        );
    }
    s
}

impl ReferenceElementView {
    /// The whole view: controls, picture, legend and explanation.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.controls_ui(ui);
        self.picture_ui(ui);
        self.legend_ui(ui);
    }

    /// Switches to `element`, keeping the node index and degree in range and reframing.
    fn set_element(&mut self, element: ElementType) {
        self.element = element;
        self.node = self.node.min(element.num_nodes().saturating_sub(1));
        if let Some(d) = self.quadrature_degree {
            self.quadrature_degree = Some(d.min(quadrature::max_degree(element.shape())));
        }
        self.camera = framing_camera(element.shape());
    }

    fn controls_ui(&mut self, ui: &mut egui::Ui) {
        let label = |e: ElementType| format!("{} — {}", e.name().to_uppercase(), e.description());
        ui.horizontal_wrapped(|ui| {
            let mut chosen = self.element;
            egui::ComboBox::from_id_salt("hox-teach-element")
                .selected_text(label(chosen))
                .show_ui(ui, |ui| {
                    for e in ElementType::all() {
                        ui.selectable_value(&mut chosen, e, label(e));
                    }
                })
                .response
                .on_hover_text("The element type whose reference element is shown.");
            if chosen != self.element {
                self.set_element(chosen);
            }
            let last_node = self.element.num_nodes().saturating_sub(1);
            self.node = self.node.min(last_node);
            ui.add(egui::Slider::new(&mut self.node, 0..=last_node).text("node")).on_hover_text(
                "The node whose shape function N_i colours the element (or click a node in the picture).",
            );
            ui.checkbox(&mut self.sections, "sections through the node")
                .on_hover_text("Show the field on the three planes through the node instead of on the surface.");
            ui.checkbox(&mut self.show_quadrature, "quadrature points")
                .on_hover_text("Show the quadrature points where the solver evaluates the element's energy (orange).");
            let shape = self.element.shape();
            let default_degree = self.element.default_quadrature_degree();
            let degree_text = |d: Option<usize>| match d {
                None => format!("degree: default ({default_degree})"),
                Some(k) => format!("degree {k}"),
            };
            ui.add_enabled_ui(self.show_quadrature, |ui| {
                egui::ComboBox::from_id_salt("hox-teach-quadrature-degree")
                    .selected_text(degree_text(self.quadrature_degree))
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut self.quadrature_degree, None, degree_text(None));
                        for k in 1..=quadrature::max_degree(shape) {
                            ui.selectable_value(&mut self.quadrature_degree, Some(k), degree_text(Some(k)));
                        }
                    })
                    .response
                    .on_hover_text(
                        "The polynomial degree the quadrature rule integrates exactly (default: the element's own).",
                    );
            });
            if ui.button("reset view").on_hover_text("Frame the element again from the default direction.").clicked() {
                self.camera = framing_camera(shape);
            }
        });
    }

    fn picture_ui(&mut self, ui: &mut egui::Ui) {
        let element = self.element.reference();

        // --- layout (room left below for the legend and the explanation)
        let available = ui.available_size();
        let width = available.x.max(64.0);
        let height = (0.7 * width).min(available.y - 110.0).max(160.0);
        let (rect, response) = ui.allocate_exact_size(egui::vec2(width, height), egui::Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size_px =
            [((rect.width() * ppp).round() as usize).max(16), ((rect.height() * ppp).round() as usize).max(16)];
        let to_point = |px: [f32; 2]| {
            rect.min + egui::vec2(px[0] / size_px[0] as f32 * rect.width(), px[1] / size_px[1] as f32 * rect.height())
        };
        let to_px = |p: egui::Pos2| {
            [
                (p.x - rect.min.x) / rect.width() * size_px[0] as f32,
                (p.y - rect.min.y) / rect.height() * size_px[1] as f32,
            ]
        };

        // --- input (picking uses the picture on screen)
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera.zoom((scroll * 0.002).exp());
            }
        }
        if response.dragged_by(egui::PointerButton::Primary) {
            let d = response.drag_delta();
            self.camera.orbit(d.x, d.y);
        }
        if response.dragged_by(egui::PointerButton::Secondary) || response.dragged_by(egui::PointerButton::Middle) {
            let d = response.drag_delta();
            self.camera.pan(d.x, d.y, rect.height());
        }
        if response.double_clicked() {
            self.camera = framing_camera(element.shape());
        } else if response.clicked()
            && let (Some(pos), Some(picture)) = (response.interact_pointer_pos(), &self.picture)
            && let Some(picked) = nearest_node(&picture.nodes, to_px(pos), PICK_RADIUS_POINTS * ppp)
        {
            self.node = picked;
        }

        // --- what is shown: the selected node's field on the surface, or on the sections
        if self.geometry.as_ref().is_none_or(|g| g.element != self.element) {
            self.geometry = Some(ElementGeometry::new(self.element));
        }
        let Some(geometry) = self.geometry.as_ref() else { return };
        let node = self.node.min(element.num_nodes().saturating_sub(1));
        let on_surface = geometry.node_vertex.get(node).is_some_and(Option::is_some);
        let field_key = FieldKey { element: element.name(), node, sections: self.sections || !on_surface };
        if self.field.as_ref().is_none_or(|(k, _)| *k != field_key) {
            self.field = Some((field_key.clone(), FieldMesh::new(geometry, node, field_key.sections)));
        }

        // --- render when something changed
        let key =
            RenderKey { field: field_key, camera: self.camera, quadrature_degree: self.quadrature_degree, size_px };
        if self.picture.as_ref().is_none_or(|p| p.key != key) {
            let Some((_, field)) = &self.field else { return };
            let image = self.image.get_or_insert_with(|| Image::new(size_px[0], size_px[1]));
            if [image.width, image.height] != size_px {
                *image = Image::new(size_px[0], size_px[1]);
            }
            render_field(field, &self.camera, image);
            let eye = self.camera.eye();
            let eye = [eye.x, eye.y, eye.z];
            let nodes = element
                .nodes()
                .iter()
                .map(|r| {
                    let visible = key.field.sections || seen_from(element.shape(), r, eye);
                    image.project(r.map(|c| c as f32)).map(|s| NodeMark { px: [s[0], s[1]], visible })
                })
                .collect();
            let degree = self.quadrature_degree.unwrap_or_else(|| element.default_quadrature_degree());
            let (quadrature_px, quadrature) = match quadrature::rule(element.shape(), degree) {
                Ok(rule) => (
                    rule.points
                        .iter()
                        .filter_map(|r| image.project(r.map(|c| c as f32)))
                        .map(|s| [s[0], s[1]])
                        .collect(),
                    Ok((rule.len(), rule.degree)),
                ),
                Err(e) => (Vec::new(), Err(e.to_string())),
            };
            let pixels = image.rgba.iter().map(|c| egui::Color32::from_rgb(c[0], c[1], c[2])).collect();
            let colour_image = egui::ColorImage {
                size: size_px,
                source_size: egui::vec2(size_px[0] as f32, size_px[1] as f32),
                pixels,
            };
            match &mut self.texture {
                Some(t) => t.set(colour_image, egui::TextureOptions::LINEAR),
                None => {
                    self.texture =
                        Some(ui.ctx().load_texture("hox-reference-element", colour_image, egui::TextureOptions::LINEAR))
                }
            }
            let mut hidden_edges_px = Vec::new();
            if !key.field.sections {
                // runs of consecutive hidden segments of each edge polyline, as polylines
                for edge in &geometry.surface.edges {
                    let mut run: Vec<[f32; 2]> = Vec::new();
                    for pair in edge.windows(2) {
                        let [a, b] = [pair[0], pair[1]].map(|v| geometry.vertex_reference[v as usize]);
                        let middle = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
                        let projected = (image.project(a.map(|c| c as f32)), image.project(b.map(|c| c as f32)));
                        match projected {
                            (Some(pa), Some(pb)) if !seen_from(element.shape(), &middle, eye) => {
                                if run.is_empty() {
                                    run.push([pa[0], pa[1]]);
                                }
                                run.push([pb[0], pb[1]]);
                            }
                            _ => {
                                if run.len() > 1 {
                                    hidden_edges_px.push(std::mem::take(&mut run));
                                }
                                run.clear();
                            }
                        }
                    }
                    hidden_edges_px.extend((run.len() > 1).then_some(run));
                }
            }
            self.picture = Some(Picture { key, nodes, quadrature_px, hidden_edges_px, quadrature });
        }

        // --- paint: picture, quadrature points, nodes, labels
        let painter = ui.painter_at(rect);
        if let Some(t) = &self.texture {
            painter.image(
                t.id(),
                rect,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                egui::Color32::WHITE,
            );
        }
        if let Some(picture) = &self.picture {
            let hidden = egui::Stroke::new(1.0, egui::Color32::from_rgba_unmultiplied(150, 150, 165, 110));
            for run in &picture.hidden_edges_px {
                let points: Vec<egui::Pos2> = run.iter().map(|&p| to_point(p)).collect();
                painter.extend(egui::Shape::dashed_line(&points, hidden, 4.0, 3.0));
            }
            if self.show_quadrature {
                for &q in &picture.quadrature_px {
                    painter.circle(
                        to_point(q),
                        3.5,
                        QUADRATURE_COLOUR,
                        egui::Stroke::new(1.0, egui::Color32::from_rgb(60, 30, 0)),
                    );
                }
            }
            let font = egui::FontId::proportional(12.0);
            for (i, mark) in picture.nodes.iter().enumerate() {
                let Some(mark) = mark else { continue };
                let p = to_point(mark.px);
                let alpha = if mark.visible { 255 } else { 70 };
                let fill = if i == self.node {
                    SELECTED_NODE_COLOUR
                } else if i < element.num_vertices() {
                    CORNER_NODE_COLOUR
                } else {
                    HIGH_ORDER_NODE_COLOUR
                };
                let fill = egui::Color32::from_rgba_unmultiplied(fill.r(), fill.g(), fill.b(), alpha);
                let (radius, stroke) = if i == self.node {
                    (7.0, egui::Stroke::new(2.0, egui::Color32::BLACK))
                } else {
                    (4.0, egui::Stroke::new(1.0, egui::Color32::from_white_alpha(alpha)))
                };
                painter.circle(p, radius, fill, stroke);
                let text_pos = p + egui::vec2(radius + 2.0, -radius - 1.0);
                painter.text(
                    text_pos + egui::vec2(1.0, 1.0),
                    egui::Align2::LEFT_BOTTOM,
                    i,
                    font.clone(),
                    egui::Color32::from_black_alpha(alpha),
                );
                painter.text(
                    text_pos,
                    egui::Align2::LEFT_BOTTOM,
                    i,
                    font.clone(),
                    egui::Color32::from_white_alpha(alpha),
                );
            }
        }
        response.on_hover_text("Drag to orbit, right-drag to pan, scroll to zoom, click a node to select it, double-click to reset the view.");
    }

    fn legend_ui(&self, ui: &mut egui::Ui) {
        let Some((key, field)) = &self.field else { return };
        let element = self.element.reference();
        // the colour bar, FIELD_MIN_SHOWN … 1
        let (rect, _) =
            ui.allocate_exact_size(egui::vec2(ui.available_width().clamp(120.0, 360.0), 30.0), egui::Sense::hover());
        let painter = ui.painter_at(rect);
        let bar = egui::Rect::from_min_size(rect.min, egui::vec2(rect.width(), 12.0));
        let slices = 96;
        let value_at = |t: f32| FIELD_MIN_SHOWN + t as f64 * (1.0 - FIELD_MIN_SHOWN);
        for s in 0..slices {
            let (t0, t1) = (s as f32 / slices as f32, (s + 1) as f32 / slices as f32);
            let c = field_colour(value_at(0.5 * (t0 + t1)));
            let slice = egui::Rect::from_x_y_ranges(
                bar.left() + t0 * bar.width()..=bar.left() + t1 * bar.width(),
                bar.y_range(),
            );
            painter.rect_filled(slice, 0.0, egui::Color32::from_rgb(c[0], c[1], c[2]));
        }
        let text_colour = ui.visuals().text_color();
        for tick in [FIELD_MIN_SHOWN, 0.0, 0.5, 1.0] {
            let x = bar.left() + ((tick - FIELD_MIN_SHOWN) / (1.0 - FIELD_MIN_SHOWN)) as f32 * bar.width();
            painter.line_segment(
                [egui::pos2(x, bar.bottom()), egui::pos2(x, bar.bottom() + 3.0)],
                egui::Stroke::new(1.0, text_colour),
            );
            let anchor = if tick == FIELD_MIN_SHOWN {
                egui::Align2::LEFT_TOP
            } else if tick == 1.0 {
                egui::Align2::RIGHT_TOP
            } else {
                egui::Align2::CENTER_TOP
            };
            painter.text(
                egui::pos2(x, bar.bottom() + 3.0),
                anchor,
                format!("{tick}"),
                egui::FontId::proportional(11.0),
                text_colour,
            );
        }
        ui.label(format!(
            "N_{} from {:.3} to {:.3} on what is shown (colours saturate below {FIELD_MIN_SHOWN} and above 1)",
            key.node, field.min, field.max
        ));
        let on_surface = self.geometry.as_ref().and_then(|g| g.node_vertex.get(key.node).copied().flatten()).is_some();
        ui.label(explanation(element, key.node, field.min, on_surface));
        let far_side =
            self.picture.as_ref().and_then(|p| p.nodes.get(key.node).copied().flatten()).is_some_and(|m| !m.visible);
        if far_side {
            ui.weak(format!(
                "Node {} is on the far side: drag the picture to turn the element, or show the sections.",
                key.node
            ));
        }
        if self.show_quadrature
            && let Some(picture) = &self.picture
        {
            match &picture.quadrature {
                Ok((points, degree)) => ui.weak(format!("{points} quadrature points (orange), exact for polynomials of degree {degree}: ∫ f ≈ Σ_q w_q f(r_q)")),
                Err(e) => ui.colored_label(ui.visuals().error_fg_color, e),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_node_on_a_face_is_a_display_vertex() {
        for e in ElementType::all() {
            let g = ElementGeometry::new(e);
            for i in 0..e.num_nodes() {
                let on_a_face = e.faces().iter().any(|f| f.nodes.contains(&i));
                assert_eq!(g.node_vertex[i].is_some(), on_a_face, "{} node {i}", e.name());
            }
        }
    }

    #[test]
    fn the_field_of_node_i_is_one_at_node_i_and_zero_at_every_other_node() {
        for e in ElementType::all() {
            let g = ElementGeometry::new(e);
            for i in 0..e.num_nodes() {
                let field = shape_function_field(e.reference(), &g.vertex_reference, i);
                assert_eq!(field.len(), g.surface.num_vertices());
                for (j, v) in g.node_vertex.iter().enumerate() {
                    let Some(v) = v else { continue };
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((field[*v] - want).abs() < 1e-9, "{} N_{i} at node {j}: {}", e.name(), field[*v]);
                }
                assert!(field.iter().all(|v| v.is_finite()), "{} N_{i}", e.name());
            }
        }
    }

    #[test]
    fn the_field_mesh_carries_the_same_values_at_the_nodes() {
        // the flat sub-triangles the picture is drawn with (P1 subdivided, sections) agree too
        for e in ElementType::all() {
            let g = ElementGeometry::new(e);
            for sections in [false, true] {
                let i = e.num_nodes() - 1;
                let f = FieldMesh::new(&g, i, sections);
                assert!(!f.triangles.is_empty(), "{} sections {sections}", e.name());
                for (p, v) in f.points.iter().zip(&f.values) {
                    if let Some(j) = e.nodes().iter().position(|r| same_point(r, p)) {
                        let want = if i == j { 1.0 } else { 0.0 };
                        assert!((v - want).abs() < 1e-9, "{} N_{i} at node {j}: {v}", e.name());
                    }
                }
                assert!(f.max <= 1.2 && f.min >= -0.5, "{} {} {}", e.name(), f.min, f.max);
            }
        }
    }

    #[test]
    fn sections_through_the_centre_have_the_expected_area() {
        for (shape, axis, value, area) in [
            (ReferenceShape::Hexahedron, 2, 0.0, 4.0),
            (ReferenceShape::Tetrahedron, 2, 0.5, 0.125),
            (ReferenceShape::Pyramid, 2, 0.5, 1.0),
            (ReferenceShape::Prism, 2, 0.0, 0.5),
            (ReferenceShape::Prism, 0, 0.5, 1.0),
        ] {
            let p = section_polygon(shape, axis, value).expect("a section");
            assert!((polygon_area(&p, axis) - area).abs() < 1e-12, "{shape:?} {axis} {value}: {p:?}");
        }
        assert!(section_polygon(ReferenceShape::Tetrahedron, 0, 1.0).is_none(), "a vertex only");
        assert!(section_polygon(ReferenceShape::Hexahedron, 1, 2.0).is_none(), "outside");
    }

    #[test]
    fn the_colour_map_is_white_at_zero_red_at_one_and_blue_below_zero() {
        assert_eq!(field_colour(0.0), [247, 247, 247]);
        let one = field_colour(1.0);
        assert!(one[0] > 150 && one[1] < 50 && one[2] < 60, "{one:?}");
        let below = field_colour(-0.2);
        assert!(below[2] > below[0] + 80, "{below:?}");
        assert_eq!(field_colour(-3.0), field_colour(FIELD_MIN_SHOWN));
        assert_eq!(field_colour(7.0), field_colour(1.0));
        assert_eq!(field_colour(f64::NAN), [128, 128, 128]);
    }

    #[test]
    fn explanation_names_the_node_and_says_whether_it_dips_below_zero() {
        let p2 = ElementType::from_name("p2").unwrap();
        let s = explanation(p2.reference(), 5, -0.125, true);
        assert!(s.starts_with("N_5 of P2 (edge node): 1 at node 5, 0 at every other node"), "{s}");
        assert!(s.contains("quadratic shape function dips below zero"), "{s}");
        let q1 = ElementType::from_name("q1").unwrap();
        assert!(explanation(q1.reference(), 0, 0.0, true).contains("never negative"));
        let q2 = ElementType::from_name("q2").unwrap();
        let s = explanation(q2.reference(), 26, -0.0, false);
        assert!(s.contains("interior node") && s.contains("inside the element"), "{s}");
        assert_eq!(node_kind(q2.reference(), 20), "face node");
    }

    #[test]
    fn picking_takes_the_nearest_visible_node_within_the_radius() {
        let marks = [
            Some(NodeMark { px: [10.0, 10.0], visible: true }),
            Some(NodeMark { px: [14.0, 10.0], visible: false }),
            None,
            Some(NodeMark { px: [40.0, 40.0], visible: true }),
        ];
        assert_eq!(nearest_node(&marks, [13.0, 10.0], 12.0), Some(0), "visible first");
        assert_eq!(nearest_node(&marks, [38.0, 41.0], 12.0), Some(3));
        assert_eq!(nearest_node(&marks, [100.0, 100.0], 12.0), None);
        let hidden_only = [None, Some(NodeMark { px: [0.0, 0.0], visible: false })];
        assert_eq!(nearest_node(&hidden_only, [3.0, 4.0], 12.0), Some(1));
    }

    #[test]
    fn the_near_corner_of_the_default_view_is_seen_and_the_far_one_is_not() {
        let camera = framing_camera(ReferenceShape::Hexahedron);
        let eye = camera.eye();
        let eye = [eye.x, eye.y, eye.z];
        // the default camera looks from +x, −y, +z
        assert!(seen_from(ReferenceShape::Hexahedron, &[1.0, -1.0, 1.0], eye));
        assert!(!seen_from(ReferenceShape::Hexahedron, &[-1.0, 1.0, -1.0], eye));
    }

    #[test]
    fn rendering_draws_the_colour_field_over_the_background() {
        let background = Image::new(1, 1).rgba[0];
        for name in ["p1", "p2", "q2", "pyramid"] {
            let e = ElementType::from_name(name).unwrap();
            let g = ElementGeometry::new(e);
            let field = FieldMesh::new(&g, 0, false);
            let mut image = Image::new(160, 120);
            render_field(&field, &framing_camera(e.shape()), &mut image);
            let drawn = image.rgba.iter().filter(|c| **c != background).count();
            assert!(drawn > image.rgba.len() / 20, "{name}: {drawn} px drawn");
            let reddish = image.rgba.iter().filter(|c| c[0] > 120 && c[0] as i32 > c[2] as i32 + 60).count();
            assert!(reddish > 0, "{name}: the field rises to 1 somewhere in view");
            if name == "p2" {
                let bluish = image.rgba.iter().filter(|c| c[2] as i32 > c[0] as i32 + 40).count();
                assert!(bluish > 20, "P2 corner function dips below zero in view ({bluish} px)");
            }
        }
    }
}
