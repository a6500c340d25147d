//! The 3D viewport: the deformed surfaces of the running sessions (side by side in compare
//! mode), coloured by a field (|u|, von Mises stress, strain, det F, energy density, error;
//! [`crate::display`]) on one range with a legend in the field's unit that shows saturation,
//! element edges, nodes, quadrature points, clamped and driven nodes and the edges of their
//! faces, the rest shape as a ghost; camera presets ([`ViewPreset`]); orbit (drag), pan
//! (right or middle drag, or shift-drag), zoom (scroll), reset (double-click); dragging a node
//! pulls it with an attachment that exists only while the mouse button is held.
//!
//! Every displayed point is a material point `r` of an element, drawn at `x(r) = Σ N_i(r) x_i`
//! ([`hox_sim::measure::surface`]), so curved high-order faces and edges bend as the elements do.

use super::gl_view::{GlScene, GlState, paint_callback};
use super::presets::{ViewOptions, ViewPreset};
use super::raster::{BACKGROUND, Camera, Image, Overlay, TriangleLayer, shade};
use super::session::{Drag, Session};
use super::session_view::SessionView;
use crate::display::SurfaceFrame;
pub use crate::display::f32s;
use eframe::egui;
use hox_scenes::present::colour::{ColourRange, FieldScale};
use hox_sim::Vec3;
use hox_sim::measure::field::Field;
use std::sync::Arc;
use web_time::Instant;

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
    /// How each session is drawn ([`SessionView`]), following it.
    views: Vec<SessionView>,
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
    /// The colour scale all sessions share (automatic ranges grow with what was seen).
    scale: Option<FieldScale>,
    /// Each session's frame count when last drawn: a smaller one is a new run (the automatic
    /// range starts again).
    last_frames: Vec<u64>,
    /// The camera preset last chosen (a double-click frames the bodies from it again).
    pub preset: ViewPreset,
    /// The camera was framed before the view had a size (at start): framed again on the first
    /// frame drawn, for the view's real proportions.
    framed_blind: bool,
    /// The view's proportions the camera was framed for, and whether the user has moved the
    /// camera since: an unmoved camera is framed again when the view changes shape (a panel
    /// opening, another window size; issue #35: bodies clipped at the view's edges).
    framed_aspect: f32,
    user_moved: bool,
    /// Where the last frame drew the legend, the bodies' labels and the bodies (their current
    /// extent), in points: the UI tests check that none overlaps another or leaves the view.
    pub drawn: Drawn,
    /// Labels name the bodies only (presenter mode: its caption carries the numbers).
    pub short_labels: bool,
    /// In a lesson, each body's label shows the step's measurement as the panel does (issue #57:
    /// the labels' error against the reference and the panel's against the mesh's equilibrium
    /// both said "error"); set by the window each frame.
    pub lesson_labels: Option<Vec<String>>,
}

/// Rectangles drawn in the view at the last frame ([`Viewport::drawn`]).
#[derive(Clone, Debug, Default)]
#[cfg_attr(not(test), allow(dead_code))]
pub struct Drawn {
    pub view: Option<egui::Rect>,
    pub legend: Option<egui::Rect>,
    pub labels: Vec<egui::Rect>,
    pub bodies: Vec<egui::Rect>,
}

/// The legend's column at the view's right (its panel and margins), points.
const LEGEND_COLUMN: f32 = 172.0;
/// Room above the bodies for their labels in compare mode (three lines), points.
const LABEL_ROOM: f32 = 64.0;

impl Viewport {
    pub fn new(camera: Option<Camera>) -> Viewport {
        Viewport {
            fitted: camera.is_some(),
            camera: camera.unwrap_or(Camera::framing([0.0; 3], [1.0; 3])),
            image: Image::new(1, 1),
            texture: None,
            layers: Vec::new(),
            views: Vec::new(),
            frames: Vec::new(),
            render_ms: 0.0,
            dragging: None,
            gl_state: GlState::default(),
            last_rect: egui::Rect::NOTHING,
            scale: None,
            last_frames: Vec::new(),
            preset: ViewPreset::default(),
            framed_blind: false,
            framed_aspect: 0.0,
            user_moved: false,
            drawn: Drawn::default(),
            short_labels: false,
            lesson_labels: None,
        }
    }

    /// Where the view was drawn last, points.
    #[cfg(test)]
    pub fn rect(&self) -> egui::Rect {
        self.last_rect
    }

    /// Frames the sessions' bodies again from the preset's direction.
    pub fn reset_camera(&mut self, sessions: &[Session], offsets: &[Vec3]) {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for (s, o) in sessions.iter().zip(offsets) {
            let (a, b) = s.instance.sim.mesh().bounding_box();
            lo = lo.inf(&(a + o));
            hi = hi.sup(&(b + o));
        }
        if lo.x.is_finite() {
            let (yaw, pitch) = self.preset.yaw_pitch();
            let r = self.last_rect;
            if r.is_positive() {
                // the bodies in the part of the view the legend (right) and the labels (top)
                // leave free
                let label_room = if sessions.len() > 1 { LABEL_ROOM } else { 0.0 };
                let free = egui::vec2(
                    (r.width() - LEGEND_COLUMN).max(0.4 * r.width()),
                    (r.height() - label_room).max(0.6 * r.height()),
                );
                self.camera = Camera::framing_from(f32s(&lo), f32s(&hi), yaw, pitch, free.x / free.y);
                self.camera.distance *= r.height() / free.y;
                self.camera.pan(-(r.width() - free.x) / 2.0, (r.height() - free.y) / 2.0, r.height());
                self.framed_aspect = r.width() / r.height();
            } else {
                self.camera = Camera::framing_from(f32s(&lo), f32s(&hi), yaw, pitch, super::raster::DEFAULT_ASPECT);
            }
            self.framed_blind = !r.is_positive();
        }
        self.user_moved = false;
        self.fitted = true;
    }

    /// The colour range drawn last (shared by every session, so colours compare); the UI
    /// tests read it.
    #[cfg(test)]
    pub fn colour_range(&self) -> Option<ColourRange> {
        self.scale.as_ref().map(FieldScale::range)
    }

    /// Takes this frame's field values of every session into the shared scale: the first
    /// session's field and range settings for all, started again when a run restarts or they
    /// change.
    fn update_fields(&mut self, sessions: &[Session]) -> ColourRange {
        let Some(first) = sessions.first() else { return ColourRange::metres(1.0) };
        let field = crate::display::fields(&first.config)[0];
        let want = crate::display::field_scale(Some(first.instance.sim.mesh()), &first.config, field);
        let frames: Vec<u64> = sessions.iter().map(|s| s.instance.sim.frames()).collect();
        let restarted = frames.len() != self.last_frames.len()
            || frames.iter().zip(&self.last_frames).any(|(now, before)| now < before);
        self.last_frames = frames;
        let scale = match &mut self.scale {
            Some(s) if s.field == want.field && s.fixed_max == want.fixed_max && s.floor == want.floor => s,
            slot => slot.insert(want),
        };
        if restarted {
            scale.reset();
        }
        self.frames.resize_with(sessions.len(), SurfaceFrame::default);
        for ((s, v), frame) in sessions.iter().zip(&mut self.views).zip(&mut self.frames) {
            v.field_source.field = field;
            frame.update(&v.surface, &s.instance.sim);
            frame.update_field(&v.surface, &s.instance.sim, &mut v.field_source);
            scale.observe(&frame.values);
        }
        let range = scale.range();
        for frame in &mut self.frames {
            frame.paint(&range);
        }
        range
    }

    /// The views follow `sessions` (one each, rebuilt for a new mesh, caught up otherwise).
    pub fn follow(&mut self, sessions: &[Session]) {
        self.views.truncate(sessions.len());
        for (k, s) in sessions.iter().enumerate() {
            match self.views.get_mut(k) {
                Some(v) => v.follow(s),
                None => self.views.push(SessionView::new(s)),
            }
        }
    }

    /// The view of session `k`, as drawn last.
    #[cfg(test)]
    pub fn view(&self, k: usize) -> Option<&SessionView> {
        self.views.get(k)
    }

    /// Shows the view; `gl` says whether the frame has an OpenGL context to draw it with (else,
    /// or if the GL view failed to build, the CPU rasteriser draws it). Returns a change of the
    /// mouse drag: the session and its new drag (None: released).
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        sessions: &[Session],
        offsets: &[Vec3],
        opts: &ViewOptions,
        gl: bool,
    ) -> Option<(usize, Option<Drag>)> {
        self.follow(sessions);
        let mut drag_change = None;
        let use_gl = gl && self.gl_error().is_none();
        if !self.fitted {
            self.reset_camera(sessions, offsets);
        }
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size().max(egui::vec2(64.0, 64.0)), egui::Sense::click_and_drag());
        self.last_rect = rect;
        let reshaped = (rect.width() / rect.height() / self.framed_aspect.max(1e-3) - 1.0).abs() > 0.03;
        if self.framed_blind || (!self.user_moved && reshaped) {
            self.reset_camera(sessions, offsets);
        }
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
                self.user_moved = true;
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
                        drag_change = Some((k, Some(Drag { node, target_m: target })));
                    }
                }
                _ if shift => {
                    self.camera.pan(delta.x, delta.y, rect.height());
                    self.user_moved = true;
                }
                _ => {
                    self.camera.orbit(delta.x, delta.y);
                    self.user_moved = true;
                }
            }
        }
        if response.dragged_by(egui::PointerButton::Secondary) || response.dragged_by(egui::PointerButton::Middle) {
            let delta = response.drag_delta();
            self.camera.pan(delta.x, delta.y, rect.height());
            self.user_moved = true;
        }
        if (response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()))
            && let Some((k, _, _)) = self.dragging.take()
        {
            drag_change = Some((k, None));
        }

        // --- scene
        let started = Instant::now();
        let colours = self.update_fields(sessions);
        self.layers.resize_with(sessions.len(), TriangleLayer::default);
        let mut overlay = Overlay::default();
        let mut x = Vec::new();
        for ((((s, v), layer), frame), o) in
            sessions.iter().zip(&self.views).zip(&mut self.layers).zip(&self.frames).zip(offsets)
        {
            let sim = &s.instance.sim;
            layer.positions = frame.positions_m.iter().map(|p| f32s(&(p + o))).collect();
            layer.normals = frame.normals.iter().map(f32s).collect();
            layer.colours.clone_from(&frame.colours);
            layer.triangles.clone_from(&v.surface.triangles);
            if opts.edges {
                for e in &v.surface.edges {
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
                let rest = &v.rest_vertices;
                for e in &v.surface.edges {
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
                    let (half, c) = if v.corner_nodes[i] { (3.0, CORNER_NODE) } else { (2.5, HIGH_ORDER_NODE) };
                    overlay.points.push((f32s(&(p + o)), half, c));
                }
            }
            if opts.boundary_conditions {
                for (edges, colour) in [(&v.clamped_edges, CLAMPED), (&v.driven_edges, DRIVEN)] {
                    for &k in edges {
                        for pair in v.surface.edges[k].windows(2) {
                            overlay.lines.push((
                                layer.positions[pair[0] as usize],
                                layer.positions[pair[1] as usize],
                                colour,
                            ));
                        }
                    }
                }
                for &n in &v.clamped {
                    overlay.points.push((f32s(&(sim.positions[n as usize] + o)), 2.0, CLAMPED));
                }
                for &n in &v.driven {
                    overlay.points.push((f32s(&(sim.positions[n as usize] + o)), 2.0, DRIVEN));
                }
            }
            if s.config.quadrature_points {
                let q = v.quadrature_points(s);
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
        // where each body is now, and its label in compare mode: above it, or below it where
        // that would cover the legend, another label or leave the view (issue #35)
        let legend = legend_rect(rect);
        let mut drawn = Drawn { view: Some(rect), legend: Some(legend), ..Default::default() };
        for (s, o) in sessions.iter().zip(offsets) {
            drawn.bodies.push(self.screen_extent(&s.instance.sim.positions, o).unwrap_or(egui::Rect::NOTHING));
        }
        // a body that grows out of the view (the stability lesson's unguarded beam blowing up,
        // issue #57) is followed: the camera backs off, a step a frame, unless the user moved it
        if !self.user_moved
            && drawn.bodies.iter().any(|b| b.is_positive() && !rect.contains_rect(*b))
            && self.camera.distance.is_finite()
            && self.camera.distance < 1e4
        {
            self.camera.distance *= 1.25;
            ui.ctx().request_repaint();
        }
        if sessions.len() > 1 {
            let names = super::session::labels(sessions);
            for (k, s) in sessions.iter().enumerate() {
                let body = drawn.bodies[k];
                if !body.is_positive() {
                    continue;
                }
                let text = match (&self.lesson_labels, self.short_labels) {
                    (_, true) => format!("{}: {}", ["A", "B"][k.min(1)], names[k]),
                    (Some(labels), false) if k < labels.len() => body_label(k, &names[k], &labels[k]),
                    _ => body_label(k, &names[k], &s.readout_label()),
                };
                // wrapped to the room beside the legend (issue #57: at 1280×720 with a lesson's
                // panel the view is narrow, and a long label sat on the legend)
                let room = (rect.width() - (rect.right() - legend.left()) - 12.0).max(140.0);
                let galley = painter.layout(text, egui::FontId::proportional(14.0), egui::Color32::WHITE, room);
                let size = galley.size();
                let place = |top_left: egui::Pos2| {
                    let x = top_left.x.clamp(rect.min.x + 4.0, (rect.max.x - size.x - 4.0).max(rect.min.x + 4.0));
                    egui::Rect::from_min_size(egui::pos2(x, top_left.y), size)
                };
                let above = place(egui::pos2(body.center().x - size.x / 2.0, body.min.y - 6.0 - size.y));
                let below = place(egui::pos2(body.center().x - size.x / 2.0, body.max.y + 6.0));
                let free = |r: &egui::Rect| {
                    rect.contains_rect(*r)
                        && !r.intersects(legend)
                        && drawn.labels.iter().chain(&drawn.bodies).all(|l| !l.intersects(*r))
                };
                // neither: stacked in the view's top-left corner, under the labels already there
                let stacked = egui::Rect::from_min_size(
                    egui::pos2(
                        rect.min.x + 4.0,
                        drawn.labels.iter().map(|l| l.max.y + 4.0).fold(rect.min.y + 4.0, f32::max),
                    ),
                    size,
                );
                // or in the bottom-left corner, above the labels already there
                let low = drawn.labels.iter().map(|l| l.min.y - 4.0).fold(rect.max.y - 4.0, f32::min);
                let bottom = egui::Rect::from_min_size(egui::pos2(rect.min.x + 4.0, low - size.y), size);
                // beside the body before any corner (issue #57: in presenter mode a label sat in a
                // corner far from its body)
                let beside_y = body.center().y - size.y / 2.0;
                let left = egui::Rect::from_min_size(egui::pos2(body.min.x - 8.0 - size.x, beside_y), size);
                let right = egui::Rect::from_min_size(egui::pos2(body.max.x + 8.0, beside_y), size);
                let at = [above, below, left, right, stacked, bottom].into_iter().find(free).unwrap_or(stacked);
                painter.galley(at.min, galley, egui::Color32::WHITE);
                drawn.labels.push(at);
            }
        }
        self.drawn = drawn;
        let values: Vec<f64> = self.frames.iter().flat_map(|f| f.values.iter().copied()).collect();
        let note = sessions.first().zip(self.views.first()).and_then(|(s, v)| {
            (colours.field == Field::Error && !v.field_source.has_reference())
                .then(|| format!("no reference field: {}", s.reference.status()))
        });
        let held = (
            opts.boundary_conditions && self.views.iter().any(|v| !v.clamped_edges.is_empty()),
            opts.boundary_conditions && self.views.iter().any(|v| !v.driven_edges.is_empty()),
        );
        legend_ui(&painter, rect, &colours, &values, note.as_deref(), held);
        drag_change
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
    /// The screen rectangle of `positions` moved by `offset` (the corners of their box), points.
    fn screen_extent(&self, positions: &[Vec3], offset: &Vec3) -> Option<egui::Rect> {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let corners = (0..8).map(|k| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) + offset
        });
        let points: Vec<egui::Pos2> = corners.map(|c| self.screen_position(c)).collect::<Option<_>>()?;
        Some(egui::Rect::from_points(&points))
    }

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
        for (k, ((s, view), o)) in sessions.iter().zip(&self.views).zip(offsets).enumerate() {
            let sim = &s.instance.sim;
            for (v, kind) in view.surface.node_kind.iter().enumerate() {
                if kind.is_none() {
                    continue;
                }
                let Some(node) = view.surface.vertices.single_node(v) else { continue };
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

/// Where the legend is drawn in a view `rect`: its top-right corner.
fn legend_rect(rect: egui::Rect) -> egui::Rect {
    let shorter = 130.0 - legend_bar_height(rect);
    egui::Rect::from_min_size(rect.right_top() + egui::vec2(-166.0, 6.0), egui::vec2(160.0, 236.0 - shorter))
}

/// The colour bar's height: 130 points, less in a low view (presenter mode at 1280×720), so the
/// legend stays inside it.
fn legend_bar_height(rect: egui::Rect) -> f32 {
    (rect.height() - 118.0).clamp(40.0, 130.0)
}

/// The legend in the viewport's top-right corner, on a dark panel: the field and its unit,
/// whether the range is automatic or fixed, the colour bar with ticks in the unit, the share of
/// the surface beyond a fixed range (drawn in the saturation colours), why a field has no value
/// (`note`), and what the coloured face edges mean (`held`: clamped, driven).
fn legend_ui(
    painter: &egui::Painter,
    rect: egui::Rect,
    colours: &ColourRange,
    values: &[f64],
    note: Option<&str>,
    held: (bool, bool),
) {
    let font = egui::FontId::proportional(12.0);
    let mono = egui::FontId::monospace(11.0);
    let white = egui::Color32::WHITE;
    let (over, under) = colours.saturation(values);
    let panel = legend_rect(rect);
    painter.rect_filled(panel, 4.0, egui::Color32::from_rgba_unmultiplied(0, 0, 0, 150));
    painter.text(
        panel.left_top() + egui::vec2(6.0, 4.0),
        egui::Align2::LEFT_TOP,
        colours.field.title(),
        font.clone(),
        white,
    );
    let unit = colours.field.unit();
    let mode = format!(
        "{}{}",
        if unit.is_empty() { String::new() } else { format!("{unit}, ") },
        if colours.automatic { "automatic range" } else { "fixed range" }
    );
    painter.text(panel.left_top() + egui::vec2(6.0, 20.0), egui::Align2::LEFT_TOP, mode, mono.clone(), white);
    let bar =
        egui::Rect::from_min_size(panel.left_top() + egui::vec2(10.0, 52.0), egui::vec2(16.0, legend_bar_height(rect)));
    let swatch = |y: f32, c: [u8; 3], text: String| {
        let r = egui::Rect::from_min_size(egui::pos2(bar.min.x, y), egui::vec2(bar.width(), 10.0));
        painter.rect_filled(r, 0.0, egui::Color32::from_rgb(c[0], c[1], c[2]));
        painter.text(egui::pos2(bar.max.x + 4.0, y + 5.0), egui::Align2::LEFT_CENTER, text, mono.clone(), white);
    };
    if !colours.automatic {
        swatch(bar.min.y - 14.0, hox_scenes::present::colour::OVER, format!("above: {:.0} %", 100.0 * over));
    }
    let steps = 40;
    for i in 0..steps {
        let f0 = i as f32 / steps as f32;
        let f1 = (i + 1) as f32 / steps as f32;
        let c = hox_scenes::present::colour::viridis((f0 as f64 + 0.5 / steps as f64).clamp(0.0, 1.0));
        let r = egui::Rect::from_min_max(
            egui::pos2(bar.min.x, bar.max.y - f1 * bar.height()),
            egui::pos2(bar.max.x, bar.max.y - f0 * bar.height()),
        );
        painter.rect_filled(r, 0.0, egui::Color32::from_rgb(c[0], c[1], c[2]));
    }
    for t in colours.ticks() {
        let y = bar.max.y - colours.fraction(t) as f32 * bar.height();
        painter.text(egui::pos2(bar.max.x + 4.0, y), egui::Align2::LEFT_CENTER, colours.format(t), mono.clone(), white);
    }
    let mut y = bar.max.y + 6.0;
    if !colours.automatic && colours.field.two_sided() {
        swatch(y, hox_scenes::present::colour::UNDER, format!("below: {:.0} %", 100.0 * under));
        y += 14.0;
    }
    let mut line = |text: &str, colour: Option<[u8; 4]>| {
        if let Some(c) = colour {
            let a = egui::pos2(bar.min.x, y + 6.0);
            painter.line_segment(
                [a, a + egui::vec2(16.0, 0.0)],
                egui::Stroke::new(3.0, egui::Color32::from_rgb(c[0], c[1], c[2])),
            );
        }
        painter.text(egui::pos2(bar.max.x + 4.0, y + 6.0), egui::Align2::LEFT_CENTER, text, mono.clone(), white);
        y += 14.0;
    };
    if held.0 {
        line("clamped face", Some(CLAMPED));
    }
    if held.1 {
        line("driven face", Some(DRIVEN));
    }
    if let Some(n) = note {
        line(n, None);
    }
}

/// The label above configuration `k` in compare mode: its letter (the status line's and the
/// controls' A and B, issue #35), its mesh, and its readout below.
pub(super) fn body_label(k: usize, label: &str, readout: &str) -> String {
    let letter = ["A", "B"].get(k).map_or(String::new(), |l| format!("{l}: "));
    format!("{letter}{label}\n{readout}")
}
