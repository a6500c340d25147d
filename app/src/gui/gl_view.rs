//! The 3D view drawn by OpenGL inside egui's frame (an `egui_glow` paint callback): the same
//! shaded triangles, depth-tested lines and round points as the CPU rasteriser
//! ([`super::raster`]), handed to the driver instead of drawn pixel by pixel.
//!
//! Why: on a machine without a GPU the driver is Mesa's llvmpipe, which rasterises on the CPU
//! with JIT-compiled shaders in its own threads. Drawing the view there costs less than drawing
//! it ourselves and then uploading and texturing a full-view image every frame (measured in
//! docs/APP.md). The CPU rasteriser stays for contexts without OpenGL (the headless UI tests)
//! and for picking, which needs a depth buffer on the CPU.
//!
//! Conventions match [`super::raster`]: the camera's OpenGL-style view-projection (NDC depth in
//! −1…1, depth test "less or equal"), colours shaded per vertex on the CPU (Lambert with a head
//! light, [`super::raster::shade`]), lines and points depth-tested without writing depth, points
//! pulled 10⁻³ towards the camera in NDC and surfaces pushed back by a polygon offset so lines on
//! a face stay visible.

use eframe::egui;
use eframe::egui_glow;
use eframe::glow::{self, HasContext};
use std::sync::{Arc, Mutex};

/// One vertex of every primitive: triangles and lines use `corner = 0, size_px = 0`; a point is
/// a quad of four vertices at the same position with corners (±1, ±1), expanded on screen by
/// `size_px + 0.5` pixels and cut to a disc in the fragment shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GlVertex {
    pub position: [f32; 3],
    pub colour: [u8; 4],
    pub corner: [f32; 2],
    pub size_px: f32,
}

/// Everything one frame of the view draws.
#[derive(Clone, Debug, Default)]
pub struct GlScene {
    pub view_projection: [f32; 16],
    pub background: [u8; 4],
    pub vertices: Vec<GlVertex>,
    pub triangles: Vec<u32>,
    pub lines: Vec<u32>,
    pub points: Vec<u32>,
}

impl GlScene {
    /// Adds shaded triangles: `positions` and `colours` per vertex, `triangles` indexing them.
    pub fn add_triangles(&mut self, positions: &[[f32; 3]], colours: &[[u8; 3]], triangles: &[[u32; 3]]) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(positions.iter().zip(colours).map(|(&position, c)| GlVertex {
            position,
            colour: [c[0], c[1], c[2], 255],
            ..Default::default()
        }));
        self.triangles.extend(triangles.iter().flat_map(|t| t.map(|i| base + i)));
    }

    pub fn add_line(&mut self, a: [f32; 3], b: [f32; 3], colour: [u8; 4]) {
        let base = self.vertices.len() as u32;
        self.vertices.push(GlVertex { position: a, colour, ..Default::default() });
        self.vertices.push(GlVertex { position: b, colour, ..Default::default() });
        self.lines.extend([base, base + 1]);
    }

    /// A disc of radius `half_px` pixels, drawn over surfaces at the same depth.
    pub fn add_point(&mut self, p: [f32; 3], half_px: f32, colour: [u8; 4]) {
        let base = self.vertices.len() as u32;
        for corner in [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]] {
            self.vertices.push(GlVertex { position: p, colour, corner, size_px: half_px });
        }
        self.points.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
}

/// The GL objects, made on first use inside the paint callback (where the context is current).
pub struct GlView {
    plain: Program,
    discs: Program,
    vertex_array: glow::VertexArray,
    vertex_buffer: glow::Buffer,
    index_buffer: glow::Buffer,
    indices: Vec<u32>,
}

/// Shared between the viewport and its paint callbacks: not yet made, made, or why it failed
/// (then the viewport falls back to the CPU rasteriser).
pub type GlState = Arc<Mutex<Option<Result<GlView, String>>>>;

/// The paint callback drawing `scene` into the callback's rectangle.
pub fn paint_callback(rect: egui::Rect, state: GlState, scene: Arc<GlScene>) -> egui::PaintCallback {
    egui::PaintCallback {
        rect,
        callback: Arc::new(egui_glow::CallbackFn::new(move |info, painter| {
            let gl = painter.gl();
            let Ok(mut guard) = state.lock() else { return };
            if guard.is_none() {
                *guard = Some(unsafe { GlView::new(gl) });
            }
            if let Some(Ok(view)) = guard.as_mut() {
                let vp = info.viewport_in_pixels();
                unsafe { view.paint(gl, &scene, [vp.width_px as f32, vp.height_px as f32]) };
            }
        })),
    }
}

/// The vertex shader and two fragment shaders: plain (surfaces, lines) and disc-cutting
/// (points). They are separate programs because a shader that may `discard` makes the driver
/// run the depth test after shading for every fragment it draws.
fn shader_sources(version: egui_glow::ShaderVersion) -> (String, String, String) {
    let header = version.version_declaration();
    let precision = if version.is_embedded() { "precision mediump float;\n" } else { "" };
    let new = version.is_new_shader_interface();
    let (attribute, vary_out, vary_in) = if new { ("in", "out", "in") } else { ("attribute", "varying", "varying") };
    let vertex = format!(
        "{header}{precision}
{attribute} vec3 a_position;
{attribute} vec4 a_colour;
{attribute} vec2 a_corner;
{attribute} float a_size_px;
uniform mat4 u_view_projection;
uniform vec2 u_viewport_px;
{vary_out} vec4 v_colour;
{vary_out} vec2 v_corner;
void main() {{
    vec4 p = u_view_projection * vec4(a_position, 1.0);
    if (a_size_px > 0.0) {{
        p.xy += a_corner * (a_size_px + 0.5) * 2.0 / u_viewport_px * p.w;
        p.z -= 1e-3 * p.w;
    }}
    gl_Position = p;
    v_colour = a_colour;
    v_corner = a_corner;
}}
"
    );
    let (out_decl, out_name) = if new { ("out vec4 f_colour;", "f_colour") } else { ("", "gl_FragColor") };
    let fragment = |cut: &str| {
        format!(
            "{header}{precision}
{vary_in} vec4 v_colour;
{vary_in} vec2 v_corner;
{out_decl}
void main() {{
    {cut}
    {out_name} = v_colour;
}}
"
        )
    };
    (vertex, fragment(""), fragment("if (dot(v_corner, v_corner) > 1.0) discard;"))
}

/// A linked program with the uniforms the view sets.
struct Program {
    program: glow::Program,
    u_view_projection: Option<glow::UniformLocation>,
    u_viewport_px: Option<glow::UniformLocation>,
}

impl Program {
    /// # Safety
    /// `gl` must be the current context.
    unsafe fn new(gl: &glow::Context, vertex_src: &str, fragment_src: &str) -> Result<Program, String> {
        unsafe {
            let program = gl.create_program()?;
            let mut shaders = Vec::new();
            for (kind, src) in [(glow::VERTEX_SHADER, vertex_src), (glow::FRAGMENT_SHADER, fragment_src)] {
                let shader = gl.create_shader(kind)?;
                gl.shader_source(shader, src);
                gl.compile_shader(shader);
                if !gl.get_shader_compile_status(shader) {
                    return Err(format!("3D view shader: {}", gl.get_shader_info_log(shader)));
                }
                gl.attach_shader(program, shader);
                shaders.push(shader);
            }
            // both programs share one vertex layout: fix the attribute locations
            for (location, name) in ATTRIBUTES.iter().enumerate() {
                gl.bind_attrib_location(program, location as u32, name.0);
            }
            gl.link_program(program);
            if !gl.get_program_link_status(program) {
                return Err(format!("3D view program: {}", gl.get_program_info_log(program)));
            }
            for s in shaders {
                gl.detach_shader(program, s);
                gl.delete_shader(s);
            }
            Ok(Program {
                u_view_projection: gl.get_uniform_location(program, "u_view_projection"),
                u_viewport_px: gl.get_uniform_location(program, "u_viewport_px"),
                program,
            })
        }
    }

    /// # Safety
    /// `gl` must be the current context.
    unsafe fn use_with(&self, gl: &glow::Context, view_projection: &[f32; 16], viewport_px: [f32; 2]) {
        unsafe {
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(self.u_view_projection.as_ref(), false, view_projection);
            gl.uniform_2_f32(self.u_viewport_px.as_ref(), viewport_px[0].max(1.0), viewport_px[1].max(1.0));
        }
    }
}

/// Vertex attributes: name, components, type, normalised, byte offset in [`GlVertex`].
const ATTRIBUTES: [(&str, i32, u32, bool, i32); 4] = [
    ("a_position", 3, glow::FLOAT, false, 0),
    ("a_colour", 4, glow::UNSIGNED_BYTE, true, 12),
    ("a_corner", 2, glow::FLOAT, false, 16),
    ("a_size_px", 1, glow::FLOAT, false, 24),
];

impl GlView {
    /// Compiles the shaders and makes the buffers.
    ///
    /// # Safety
    /// `gl` must be the current context.
    unsafe fn new(gl: &glow::Context) -> Result<GlView, String> {
        unsafe {
            let (vertex_src, plain_src, discs_src) = shader_sources(egui_glow::ShaderVersion::get(gl));
            let plain = Program::new(gl, &vertex_src, &plain_src)?;
            let discs = Program::new(gl, &vertex_src, &discs_src)?;
            let vertex_array = gl.create_vertex_array()?;
            let vertex_buffer = gl.create_buffer()?;
            let index_buffer = gl.create_buffer()?;
            gl.bind_vertex_array(Some(vertex_array));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vertex_buffer));
            let stride = size_of::<GlVertex>() as i32;
            for (location, (_, size, kind, normalised, offset)) in ATTRIBUTES.into_iter().enumerate() {
                let location = location as u32;
                gl.enable_vertex_attrib_array(location);
                gl.vertex_attrib_pointer_f32(location, size, kind, normalised, stride, offset);
            }
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            Ok(GlView { plain, discs, vertex_array, vertex_buffer, index_buffer, indices: Vec::new() })
        }
    }

    /// Clears the callback's rectangle (egui's scissor limits the clear to it) and draws.
    ///
    /// # Safety
    /// `gl` must be the current context, inside an `egui_glow` paint callback (which restores
    /// egui's state afterwards).
    unsafe fn paint(&mut self, gl: &glow::Context, scene: &GlScene, viewport_px: [f32; 2]) {
        self.indices.clear();
        self.indices.extend_from_slice(&scene.triangles);
        self.indices.extend_from_slice(&scene.lines);
        self.indices.extend_from_slice(&scene.points);
        let bg = scene.background.map(|c| c as f32 / 255.0);
        unsafe {
            gl.clear_color(bg[0], bg[1], bg[2], bg[3]);
            gl.depth_mask(true);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LEQUAL);
            self.plain.use_with(gl, &scene.view_projection, viewport_px);
            gl.bind_vertex_array(Some(self.vertex_array));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.vertex_buffer));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytemuck::cast_slice(&scene.vertices), glow::STREAM_DRAW);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.index_buffer));
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, bytemuck::cast_slice(&self.indices), glow::STREAM_DRAW);
            // opaque surfaces, pushed back a little so edges drawn on them pass the depth test
            gl.disable(glow::BLEND);
            gl.enable(glow::POLYGON_OFFSET_FILL);
            gl.polygon_offset(1.0, 1.0);
            gl.draw_elements(glow::TRIANGLES, scene.triangles.len() as i32, glow::UNSIGNED_INT, 0);
            gl.disable(glow::POLYGON_OFFSET_FILL);
            // lines and points: blended, depth-tested, not writing depth; destination alpha kept
            gl.enable(glow::BLEND);
            gl.blend_func_separate(glow::SRC_ALPHA, glow::ONE_MINUS_SRC_ALPHA, glow::ZERO, glow::ONE);
            gl.depth_mask(false);
            let offset = 4 * scene.triangles.len() as i32;
            gl.draw_elements(glow::LINES, scene.lines.len() as i32, glow::UNSIGNED_INT, offset);
            let offset = offset + 4 * scene.lines.len() as i32;
            self.discs.use_with(gl, &scene.view_projection, viewport_px);
            gl.draw_elements(glow::TRIANGLES, scene.points.len() as i32, glow::UNSIGNED_INT, offset);
            gl.depth_mask(true);
            gl.disable(glow::DEPTH_TEST);
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_quads_of_two_triangles_and_indices_follow_the_vertices() {
        let mut s = GlScene::default();
        s.add_triangles(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[1, 2, 3]; 3], &[[0, 1, 2]]);
        s.add_line([0.0; 3], [1.0; 3], [9; 4]);
        s.add_point([2.0; 3], 3.0, [7; 4]);
        assert_eq!(s.triangles, vec![0, 1, 2]);
        assert_eq!(s.lines, vec![3, 4]);
        assert_eq!(s.points, vec![5, 6, 7, 5, 7, 8]);
        assert_eq!(s.vertices.len(), 9);
        assert!(s.vertices[5..].iter().all(|v| v.size_px == 3.0 && v.position == [2.0; 3]));
        assert_eq!(s.vertices[0].colour, [1, 2, 3, 255]);
        assert_eq!(size_of::<GlVertex>(), 28, "the attribute offsets assume this layout");
    }

    #[test]
    fn shaders_use_the_interface_of_the_context_version() {
        let (v, f, d) = shader_sources(egui_glow::ShaderVersion::Gl140);
        assert!(v.starts_with("#version 140") && v.contains("in vec3 a_position") && f.contains("out vec4 f_colour"));
        assert!(!f.contains("discard") && d.contains("discard"), "only the point program cuts fragments");
        let (v, f, _) = shader_sources(egui_glow::ShaderVersion::Gl120);
        assert!(v.contains("attribute vec3 a_position") && f.contains("gl_FragColor") && !f.contains("out vec4"));
        let (_, f, _) = shader_sources(egui_glow::ShaderVersion::Es300);
        assert!(f.contains("precision mediump float;"));
        for (name, ..) in ATTRIBUTES {
            assert!(v.contains(name), "{name}");
        }
    }
}
