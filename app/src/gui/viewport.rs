//! The 3D viewport: the deformed surfaces of the running sessions (side by side in compare
//! mode), coloured by displacement magnitude with a legend in metres, element edges, nodes,
//! quadrature points, clamped and driven nodes, the rest shape as a ghost; orbit (drag), pan
//! (right or middle drag, or shift-drag), zoom (scroll), reset (double-click); dragging a node
//! pulls it with an attachment that exists only while the mouse button is held.
//!
//! Every displayed point is a material point `r` of an element, drawn at `x(r) = Σ N_i(r) x_i`
//! ([`hox_sim::measure::surface`]), so curved high-order faces and edges bend as the elements do.

use super::gl_view::{GlScene, GlState, paint_callback};
use super::raster::{BACKGROUND, Camera, Image, Overlay, TriangleLayer, shade};
use super::session::{Drag, Session};
use crate::colour::ColourRange;
use crate::display::SurfaceFrame;
pub use crate::display::f32s;
use eframe::egui;
use hox_sim::Vec3;
use std::sync::Arc;
use std::time::Instant;

/// What the viewport shows.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ViewOptions {
    pub edges: bool,
    pub nodes: bool,
    pub boundary_conditions: bool,
    pub ghost: bool,
    pub probes: bool,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self { edges: true, nodes: false, boundary_conditions: true, ghost: true, probes: true }
    }
}

pub const CORNER_NODE: [u8; 4] = [250, 250, 250, 255];
pub const HIGH_ORDER_NODE: [u8; 4] = [40, 220, 240, 255];
const QUADRATURE_POINT: [u8; 4] = [255, 150, 20, 255];
const CLAMPED: [u8; 4] = [70, 120, 255, 255];
const DRIVEN: [u8; 4] = [230, 70, 230, 255];
const PROBE: [u8; 4] = [240, 50, 40, 255];
const EDGE: [u8; 4] = [15, 15, 20, 200];
const GHOST: [u8; 4] = [200, 200, 210, 70];

pub struct Viewport {
    pub camera: Camera,
    image: Image,
    texture: Option<egui::TextureHandle>,
    layers: Vec<TriangleLayer>,
    /// The display frame of each session (shared with the recording, [`crate::display`]).
    frames: Vec<SurfaceFrame>,
    /// Wall time of the last render (rasterise + upload), milliseconds.
    pub render_ms: f64,
    /// Node picked for dragging: session index and node.
    dragging: Option<(usize, u32, f32)>,
    fitted: bool,
    /// The OpenGL view's objects, shared with its paint callbacks.
    gl_state: GlState,
    /// Where the view was last drawn, in points.
    last_rect: egui::Rect,
}

impl Viewport {
    pub fn new(camera: Option<Camera>) -> Viewport {
        Viewport {
            fitted: camera.is_some(),
            camera: camera.unwrap_or(Camera::framing([0.0; 3], [1.0; 3])),
            image: Image::new(1, 1),
            texture: None,
            layers: Vec::new(),
            frames: Vec::new(),
            render_ms: 0.0,
            dragging: None,
            gl_state: GlState::default(),
            last_rect: egui::Rect::NOTHING,
        }
    }

    /// Frames the sessions' bodies again.
    pub fn reset_camera(&mut self, sessions: &[Session], offsets: &[Vec3]) {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for (s, o) in sessions.iter().zip(offsets) {
            let (a, b) = s.instance.sim.mesh().bounding_box();
            lo = lo.inf(&(a + o));
            hi = hi.sup(&(b + o));
        }
        if lo.x.is_finite() {
            self.camera = Camera::framing(f32s(&lo), f32s(&hi));
        }
        self.fitted = true;
    }

    /// The colour range of the first session (shared by all, so colours compare).
    pub fn colour_range(sessions: &[Session]) -> ColourRange {
        let first = sessions.first();
        crate::display::colour_range(first.map(|s| s.instance.sim.mesh()), first.map_or(0.0, |s| s.config.colour_max_m))
    }

    /// Shows the view; `gl` says whether the frame has an OpenGL context to draw it with (else,
    /// or if the GL view failed to build, the CPU rasteriser draws it).
    pub fn ui(&mut self, ui: &mut egui::Ui, sessions: &mut [Session], offsets: &[Vec3], opts: &ViewOptions, gl: bool) {
        let use_gl = gl && self.gl_error().is_none();
        if !self.fitted {
            self.reset_camera(sessions, offsets);
        }
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size().max(egui::vec2(64.0, 64.0)), egui::Sense::click_and_drag());
        self.last_rect = rect;
        let ppp = ui.ctx().pixels_per_point();
        let scale = (1600.0 / (rect.width() * ppp)).min(1000.0 / (rect.height() * ppp)).min(1.0);
        let (w, h) =
            (((rect.width() * ppp * scale) as usize).max(16), ((rect.height() * ppp * scale) as usize).max(16));
        if self.image.width != w || self.image.height != h {
            self.image = Image::new(w, h);
        }
        let to_px = |p: egui::Pos2| -> [f32; 2] {
            [(p.x - rect.min.x) / rect.width() * w as f32, (p.y - rect.min.y) / rect.height() * h as f32]
        };

        // --- input
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera.zoom((scroll * 0.002).exp());
            }
        }
        if response.double_clicked() {
            self.reset_camera(sessions, offsets);
        }
        let shift = ui.input(|i| i.modifiers.shift);
        if response.drag_started_by(egui::PointerButton::Primary)
            && !shift
            && let Some(pos) = response.interact_pointer_pos()
        {
            if use_gl {
                // picking needs the depth buffer on the CPU: draw the last frame's surfaces once
                let layer_refs: Vec<&TriangleLayer> = self.layers.iter().collect();
                self.image.render(&self.camera, &layer_refs, &Overlay::default());
            }
            self.dragging = self.pick_node(sessions, offsets, to_px(pos));
        }
        if response.dragged_by(egui::PointerButton::Primary) {
            let delta = response.drag_delta();
            match (self.dragging, response.interact_pointer_pos()) {
                (Some((k, node, depth)), Some(pos)) => {
                    let px = to_px(pos);
                    if let Some(world) = self.image.unproject(px[0], px[1], depth) {
                        let target = Vec3::new(world[0] as f64, world[1] as f64, world[2] as f64) - offsets[k];
                        sessions[k].drag = Some(Drag { node, target_m: target });
                    }
                }
                _ if shift => self.camera.pan(delta.x, delta.y, rect.height()),
                _ => self.camera.orbit(delta.x, delta.y),
            }
        }
        if response.dragged_by(egui::PointerButton::Secondary) || response.dragged_by(egui::PointerButton::Middle) {
            let delta = response.drag_delta();
            self.camera.pan(delta.x, delta.y, rect.height());
        }
        if (response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()))
            && let Some((k, _, _)) = self.dragging.take()
        {
            sessions[k].drag = None;
        }

        // --- scene
        let started = Instant::now();
        let colours = Self::colour_range(sessions);
        self.layers.resize_with(sessions.len(), TriangleLayer::default);
        self.frames.resize_with(sessions.len(), SurfaceFrame::default);
        let mut overlay = Overlay::default();
        let mut x = Vec::new();
        for (((s, layer), frame), o) in sessions.iter().zip(&mut self.layers).zip(&mut self.frames).zip(offsets) {
            let sim = &s.instance.sim;
            frame.update(&s.surface, sim, &colours);
            layer.positions = frame.positions_m.iter().map(|p| f32s(&(p + o))).collect();
            layer.normals = frame.normals.iter().map(f32s).collect();
            layer.colours.clone_from(&frame.colours);
            layer.triangles.clone_from(&s.surface.triangles);
            if opts.edges {
                for e in &s.surface.edges {
                    for pair in e.windows(2) {
                        overlay.lines.push((
                            layer.positions[pair[0] as usize],
                            layer.positions[pair[1] as usize],
                            EDGE,
                        ));
                    }
                }
            }
            if opts.ghost {
                let rest = &s.rest_vertices;
                for e in &s.surface.edges {
                    for pair in e.windows(2) {
                        overlay.lines.push((
                            f32s(&(rest[pair[0] as usize] + o)),
                            f32s(&(rest[pair[1] as usize] + o)),
                            GHOST,
                        ));
                    }
                }
            }
            if opts.nodes {
                for (i, p) in sim.positions.iter().enumerate() {
                    let (half, c) = if s.corner_nodes[i] { (3.0, CORNER_NODE) } else { (2.5, HIGH_ORDER_NODE) };
                    overlay.points.push((f32s(&(p + o)), half, c));
                }
            }
            if opts.boundary_conditions {
                for &n in &s.clamped {
                    overlay.points.push((f32s(&(sim.positions[n as usize] + o)), 2.0, CLAMPED));
                }
                for &n in &s.driven {
                    overlay.points.push((f32s(&(sim.positions[n as usize] + o)), 2.0, DRIVEN));
                }
            }
            if s.config.quadrature_points {
                let q = s.quadrature_points();
                q.eval_into(&sim.positions, &mut x);
                overlay.points.extend(x.iter().map(|p| (f32s(&(p + o)), 2.0, QUADRATURE_POINT)));
            }
            if opts.probes {
                for p in &s.instance.probes {
                    overlay.points.push((f32s(&(p.position(&sim.positions) + o)), 4.0, PROBE));
                }
            }
            if let Some(d) = s.drag {
                overlay.lines.push((
                    f32s(&(sim.positions[d.node as usize] + o)),
                    f32s(&(d.target_m + o)),
                    [255, 255, 0, 255],
                ));
                overlay.points.push((f32s(&(d.target_m + o)), 4.0, [255, 255, 0, 255]));
            }
        }
        let painter = ui.painter_at(rect);
        if use_gl {
            self.image.set_camera(&self.camera);
            let eye = self.camera.eye();
            let mut scene =
                GlScene { view_projection: self.image.view_projection(), background: BACKGROUND, ..Default::default() };
            for layer in &self.layers {
                let shaded: Vec<[u8; 3]> = layer
                    .positions
                    .iter()
                    .zip(&layer.normals)
                    .zip(&layer.colours)
                    .map(|((&p, &n), &c)| shade(p, n, c, eye).map(|v| v.clamp(0.0, 255.0) as u8))
                    .collect();
                scene.add_triangles(&layer.positions, &shaded, &layer.triangles);
            }
            for &(a, b, colour) in &overlay.lines {
                scene.add_line(a, b, colour);
            }
            for &(p, half, colour) in &overlay.points {
                scene.add_point(p, half, colour);
            }
            painter.add(paint_callback(rect, self.gl_state.clone(), Arc::new(scene)));
            self.render_ms = started.elapsed().as_secs_f64() * 1e3;
        } else {
            self.cpu_view(&painter, rect, w, h, scale, &overlay);
            self.render_ms = started.elapsed().as_secs_f64() * 1e3;
        }
        // labels above each body in compare mode
        if sessions.len() > 1 {
            for (s, o) in sessions.iter().zip(offsets) {
                let (lo, hi) = s.instance.sim.mesh().bounding_box();
                let top = Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z) + o;
                if let Some(p) = self.screen_position(top) {
                    let mut text = s.label();
                    text += &format!("\n{}", s.readout().text());
                    painter.text(
                        p - egui::vec2(0.0, 14.0),
                        egui::Align2::CENTER_BOTTOM,
                        text,
                        egui::FontId::proportional(14.0),
                        egui::Color32::WHITE,
                    );
                }
            }
        }
        legend_ui(&painter, rect, &colours);
    }

    /// Draws the view with the CPU rasteriser and shows it as a texture.
    fn cpu_view(
        &mut self,
        painter: &egui::Painter,
        rect: egui::Rect,
        w: usize,
        h: usize,
        scale: f32,
        overlay: &Overlay,
    ) {
        let layer_refs: Vec<&TriangleLayer> = self.layers.iter().collect();
        self.image.render(&self.camera, &layer_refs, overlay);
        let pixels: Vec<egui::Color32> =
            self.image.rgba.iter().map(|c| egui::Color32::from_rgb(c[0], c[1], c[2])).collect();
        // one texel per screen pixel unless the view is capped: nearest sampling is exact there and
        // cheaper than bilinear in a software renderer
        let sampling = if scale < 1.0 { egui::TextureOptions::LINEAR } else { egui::TextureOptions::NEAREST };
        let image = egui::ColorImage { size: [w, h], source_size: egui::vec2(w as f32, h as f32), pixels };
        match &mut self.texture {
            Some(t) => t.set(image, sampling),
            None => self.texture = Some(painter.ctx().load_texture("hox-viewport", image, sampling)),
        }
        if let Some(t) = &self.texture {
            painter.image(
                t.id(),
                rect,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                egui::Color32::WHITE,
            );
        }
    }

    /// Where the world point `p` was drawn in the last frame, in points (None if behind the
    /// camera or not drawn yet).
    pub fn screen_position(&self, p: Vec3) -> Option<egui::Pos2> {
        let s = self.image.project(f32s(&p))?;
        let r = self.last_rect;
        Some(egui::pos2(
            r.min.x + s[0] / self.image.width as f32 * r.width(),
            r.min.y + s[1] / self.image.height as f32 * r.height(),
        ))
    }

    /// Why the OpenGL view could not be made (the CPU rasteriser is used instead), if it failed.
    pub fn gl_error(&self) -> Option<String> {
        match self.gl_state.lock().ok()?.as_ref()? {
            Err(e) => Some(e.clone()),
            Ok(_) => None,
        }
    }

    /// The visible mesh node nearest to pixel `px` (within 12 px): session, node, its NDC depth.
    fn pick_node(&self, sessions: &[Session], offsets: &[Vec3], px: [f32; 2]) -> Option<(usize, u32, f32)> {
        let radius_px = 12.0 * self.image.width as f32 / 1000.0_f32.max(self.image.width as f32) + 8.0;
        let mut best: Option<(f32, (usize, u32, f32))> = None;
        for (k, (s, o)) in sessions.iter().zip(offsets).enumerate() {
            let sim = &s.instance.sim;
            for (v, kind) in s.surface.node_kind.iter().enumerate() {
                if kind.is_none() {
                    continue;
                }
                let Some(node) = s.surface.vertices.single_node(v) else { continue };
                if sim.inv_mass()[node as usize] == 0.0 {
                    continue; // clamped or driven: not draggable
                }
                let Some(p) = self.image.project(f32s(&(sim.positions[node as usize] + o))) else { continue };
                let d2 = (p[0] - px[0]).powi(2) + (p[1] - px[1]).powi(2);
                if d2 > radius_px * radius_px || !self.image.visible(p) {
                    continue;
                }
                if best.is_none_or(|b| d2 < b.0) {
                    best = Some((d2, (k, node, p[2])));
                }
            }
        }
        best.map(|b| b.1)
    }
}

/// The colour bar (metres) in the viewport's top-right corner.
fn legend_ui(painter: &egui::Painter, rect: egui::Rect, colours: &ColourRange) {
    let bar = egui::Rect::from_min_size(rect.right_top() + egui::vec2(-70.0, 30.0), egui::vec2(16.0, 160.0));
    let steps = 40;
    for i in 0..steps {
        let f0 = i as f32 / steps as f32;
        let f1 = (i + 1) as f32 / steps as f32;
        let c = colours.colour(colours.max_m * (f0 as f64 + 0.5 / steps as f64));
        let r = egui::Rect::from_min_max(
            egui::pos2(bar.min.x, bar.max.y - f1 * bar.height()),
            egui::pos2(bar.max.x, bar.max.y - f0 * bar.height()),
        );
        painter.rect_filled(r, 0.0, egui::Color32::from_rgb(c[0], c[1], c[2]));
    }
    for t in colours.ticks_m() {
        let y = bar.max.y - (t / colours.max_m) as f32 * bar.height();
        painter.text(
            egui::pos2(bar.max.x + 4.0, y),
            egui::Align2::LEFT_CENTER,
            crate::recording::format_metres(t),
            egui::FontId::monospace(11.0),
            egui::Color32::WHITE,
        );
    }
    painter.text(
        bar.center_top() - egui::vec2(0.0, 6.0),
        egui::Align2::CENTER_BOTTOM,
        "|u| (m)",
        egui::FontId::proportional(12.0),
        egui::Color32::WHITE,
    );
}
