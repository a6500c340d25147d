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
//!
//! Here the view's state, controls, picture and legend; the field and its colour map in
//! `field.rs`; the element's mesh, sections and polygon helpers in `geometry.rs`; the explanation
//! under the picture in `explain.rs`.
//!
//! [`Surface`]: hox_sim::measure::surface::Surface

mod explain;
mod field;
mod geometry;

use super::raster::{Camera, Image};
use eframe::egui;
use explain::explanation;
use field::{FIELD_MIN_SHOWN, FieldKey, FieldMesh, field_colour, render_field};
use geometry::{ElementGeometry, polygon_centroid, seen_from};
use hox_sim::Vec3;
use hox_sim::element::{ElementType, ReferenceShape};
use hox_sim::fem::quadrature;

/// Pieces per face edge of the display surface (a multiple of 2 and 3: see the module docs).
pub const SEGMENTS: usize = 12;
/// Pick radius around a projected node, points.
const PICK_RADIUS_POINTS: f32 = 12.0;
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

impl ReferenceElementView {
    /// The whole view: controls, picture, legend and explanation.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.controls_ui(ui);
        self.picture_ui(ui);
        self.legend_ui(ui);
    }

    /// Switches to `element`, keeping the node index and degree in range and reframing.
    pub fn set_element(&mut self, element: ElementType) {
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
mod tests;
