//! Rerun logging of running simulations, shared by `hox record` and the app.
//!
//! Entity layout (one recording may hold several configurations side by side):
//! - `world/<config>`: a static `Transform3D` offsetting the configuration in space;
//! - `world/<config>/surface`: the deformed boundary surface (`Mesh3D`), curved faces tessellated
//!   ([`hox_sim::measure::surface`]), coloured by displacement magnitude on a fixed range (viridis);
//! - `world/<config>/edges`: element edges (`LineStrips3D`, curved for high-order elements);
//! - `world/<config>/rest_edges`: the rest shape's edges, static, as a ghost;
//! - `world/<config>/probes`, `world/<config>/quadrature_points` (on request): `Points3D`;
//! - `world/<config>/legend`: the colour bar beside the body with tick labels, and
//!   `legend/<config>`: the same legend as text;
//! - `plots/<quantity>/<config>`: `Scalars` — every probe displacement component (m), kinetic and
//!   elastic energy (J), milliseconds per frame and the smallest det F over all quadrature points.
//!
//! Timelines: `frame` (sequence) and `sim_time` (seconds). Topology, labels, the legend and the
//! rest shape are logged once as static data; a frame logs only what moves.

use crate::colour::ColourRange;
use crate::display::{SurfaceFrame, f32s};
use hox_scenes::Instance;
use hox_sim::Vec3;
use hox_sim::measure::surface::{PointMap, Surface};
use rerun::RecordingStream;

/// What to log besides the always-present surface, edges, probes and time series.
#[derive(Clone, Debug, PartialEq)]
pub struct LogSettings {
    /// Pieces per edge of curved or quadrilateral faces.
    pub segments: usize,
    /// The displacement colour range ([`crate::display::colour_range`]): configurations
    /// recorded side by side share the first one's, as the viewport shows them.
    pub colours: ColourRange,
    /// Also log the quadrature points.
    pub quadrature_points: bool,
}

impl LogSettings {
    /// The display parameters of a configuration (`[display]` of the parameter table), drawn on
    /// the shared colour range `colours`.
    pub fn new(params: &hox_scenes::Params, colours: ColourRange) -> LogSettings {
        LogSettings { segments: params.tessellation, colours, quadrature_points: params.quadrature_points }
    }
}

/// Logs one simulation (one configuration) frame after frame.
pub struct SimLogger {
    name: String,
    surface: Surface,
    quadrature: Option<PointMap>,
    colours: ColourRange,
    /// What is drawn this frame (the viewport's display frame).
    frame: SurfaceFrame,
    /// Quadrature points this frame, reused.
    points: Vec<Vec3>,
}

/// A name usable as one entity path part: lowercase letters, digits and `_`.
pub fn entity_name(label: &str) -> String {
    let s: String =
        label.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' }).collect();
    let s = s.trim_matches('_').to_string();
    if s.is_empty() { "sim".to_string() } else { s }
}

/// A short label for an instance, e.g. `p2 160` (element type and count).
/// What the recording states about a configuration: every parameter of the table
/// ([`hox_scenes::params`]) by its scene-file key, with its unit.
pub fn configuration_markdown(instance: &Instance) -> String {
    let scene = &instance.scene;
    let mut text = format!("Configuration of scene `{}`:\n", scene.name());
    for p in hox_scenes::params::PARAMS.iter().filter(|p| scene.is_box() || !p.box_only) {
        let unit = if p.unit.is_empty() { String::new() } else { format!(" {}", p.unit) };
        text += &format!("- `{}` = {}{unit}\n", p.file_path(), (p.get)(scene.params()));
    }
    text
}

pub fn config_label(instance: &Instance) -> String {
    let mesh = instance.sim.mesh();
    let types: Vec<&str> = mesh.blocks.iter().map(|b| b.element_type.name()).collect();
    let label = format!("{} {}", types.join("+"), mesh.num_elements());
    // XPBD, the paper's solver, is unnamed (the labels of earlier recordings stay as they were)
    match instance.sim.method() {
        hox_sim::solver::Method::Xpbd => label,
        other => format!("{label} {other}"),
    }
}

impl SimLogger {
    /// Logs the static data of `instance` under `world/<name>` offset by `offset_m`.
    pub fn new(
        rec: &RecordingStream,
        name: &str,
        instance: &Instance,
        offset_m: Vec3,
        settings: &LogSettings,
    ) -> Result<SimLogger, rerun::RecordingStreamError> {
        let name = entity_name(name);
        let mesh = instance.sim.mesh();
        let surface = Surface::new(mesh, settings.segments);
        let quadrature = settings
            .quadrature_points
            .then(|| hox_sim::measure::surface::quadrature_points(mesh, instance.sim.geometry()));
        let (lo, hi) = mesh.bounding_box();
        let colours = settings.colours;
        let root = format!("world/{name}");
        rec.log_static(root.as_str(), &rerun::Transform3D::from_translation(f32s(&offset_m)))?;
        rec.log_static(
            format!("{root}/surface"),
            &rerun::Mesh3D::update_fields()
                .with_triangle_indices(surface.triangles.iter().map(|t| rerun::TriangleIndices::from(*t))),
        )?;
        // the rest shape's edges, a faint ghost
        let mut rest = Vec::new();
        surface.vertices.eval_into(&mesh.rest_positions, &mut rest);
        let strips: Vec<Vec<[f32; 3]>> =
            surface.edges.iter().map(|e| e.iter().map(|&i| f32s(&rest[i as usize])).collect()).collect();
        rec.log_static(
            format!("{root}/rest_edges"),
            &rerun::LineStrips3D::new(strips)
                .with_colors([rerun::Color::from_unmultiplied_rgba(160, 160, 160, 90)])
                .with_radii([rerun::Radius::new_ui_points(0.5)]),
        )?;
        let probe_names: Vec<String> = instance.probes.iter().map(|p| p.name.clone()).collect();
        rec.log_static(
            format!("{root}/probes"),
            &rerun::Points3D::update_fields()
                .with_labels(probe_names.iter().map(String::as_str))
                .with_colors([rerun::Color::from_rgb(230, 60, 40)])
                .with_radii([rerun::Radius::new_ui_points(6.0)]),
        )?;
        rec.log_static(
            format!("{root}/edges"),
            &rerun::LineStrips3D::update_fields()
                .with_colors([rerun::Color::from_rgb(20, 20, 20)])
                .with_radii([rerun::Radius::new_ui_points(0.75)]),
        )?;
        if quadrature.is_some() {
            rec.log_static(
                format!("{root}/quadrature_points"),
                &rerun::Points3D::update_fields()
                    .with_colors([rerun::Color::from_rgb(255, 140, 0)])
                    .with_radii([rerun::Radius::new_ui_points(2.5)]),
            )?;
        }
        Self::log_legend(rec, &name, &root, &colours, lo, hi, &configuration_markdown(instance))?;
        Ok(SimLogger { name, surface, quadrature, colours, frame: SurfaceFrame::default(), points: Vec::new() })
    }

    /// A vertical colour bar beside the body (its lower end at the body's rest bottom, height the
    /// body's height) with labelled ticks, plus the legend as text.
    fn log_legend(
        rec: &RecordingStream,
        name: &str,
        root: &str,
        colours: &ColourRange,
        lo: Vec3,
        hi: Vec3,
        configuration: &str,
    ) -> Result<(), rerun::RecordingStreamError> {
        let extent = hi - lo;
        let height = extent.z.max(0.25 * extent.max());
        let width = 0.08 * height;
        let x0 = hi.x + 0.15 * extent.max();
        let y = 0.5 * (lo.y + hi.y);
        let steps = 32;
        let mut positions = Vec::new();
        let mut vertex_colours = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..=steps {
            let f = i as f64 / steps as f64;
            let z = lo.z + f * height;
            let c = colours.colour(f * colours.max_m);
            for x in [x0, x0 + width] {
                positions.push([x as f32, y as f32, z as f32]);
                vertex_colours.push(rerun::Color::from_rgb(c[0], c[1], c[2]));
            }
            if i < steps {
                let k = 2 * i as u32;
                triangles.push([k, k + 1, k + 3]);
                triangles.push([k, k + 3, k + 2]);
                // both sides visible
                triangles.push([k, k + 3, k + 1]);
                triangles.push([k, k + 2, k + 3]);
            }
        }
        rec.log_static(
            format!("{root}/legend/bar"),
            &rerun::Mesh3D::new(positions).with_vertex_colors(vertex_colours).with_triangle_indices(triangles),
        )?;
        let ticks = colours.ticks_m();
        let tick_positions: Vec<[f32; 3]> = ticks
            .iter()
            .map(|t| [(x0 + 1.5 * width) as f32, y as f32, (lo.z + t / colours.max_m * height) as f32])
            .collect();
        let labels: Vec<String> = ticks.iter().map(|t| format!("{} m", format_metres(*t))).collect();
        rec.log_static(
            format!("{root}/legend/ticks"),
            &rerun::Points3D::new(tick_positions)
                .with_labels(labels)
                .with_radii([rerun::Radius::new_ui_points(2.0)])
                .with_colors([rerun::Color::from_rgb(220, 220, 220)]),
        )?;
        rec.log_static(
            format!("legend/{name}"),
            &rerun::TextDocument::from_markdown(format!(
                "**{name}**: surface colour = displacement magnitude |u| in metres, viridis, fixed range 0 m (dark purple) to {} m (yellow); larger values are clamped.\n\n{}",
                format_metres(colours.max_m),
                configuration
            )),
        )
    }

    /// Logs the current state of `instance` at its frame and time. `ms_per_frame` is the wall
    /// time of the last step.
    pub fn log_frame(
        &mut self,
        rec: &RecordingStream,
        instance: &Instance,
        ms_per_frame: f64,
    ) -> Result<(), rerun::RecordingStreamError> {
        let sim = &instance.sim;
        let mesh = sim.mesh();
        rec.set_time_sequence("frame", sim.frames() as i64);
        rec.set_duration_secs("sim_time", sim.time_secs());
        let root = format!("world/{}", self.name);
        self.frame.update(&self.surface, sim, &self.colours);
        let frame = &self.frame;
        rec.log(
            format!("{root}/surface"),
            &rerun::Mesh3D::update_fields()
                .with_vertex_positions(frame.positions_m.iter().map(f32s))
                .with_vertex_normals(frame.normals.iter().map(f32s))
                .with_vertex_colors(frame.colours.iter().map(|c| rerun::Color::from_rgb(c[0], c[1], c[2]))),
        )?;
        let x = &frame.positions_m;
        rec.log(
            format!("{root}/edges"),
            &rerun::LineStrips3D::update_fields().with_strips(
                self.surface.edges.iter().map(|e| e.iter().map(|&i| f32s(&x[i as usize])).collect::<Vec<_>>()),
            ),
        )?;
        let probe_positions: Vec<[f32; 3]> =
            instance.probes.iter().map(|p| f32s(&p.position(&sim.positions))).collect();
        rec.log(format!("{root}/probes"), &rerun::Points3D::update_fields().with_positions(probe_positions))?;
        if let Some(q) = &self.quadrature {
            q.eval_into(&sim.positions, &mut self.points);
            rec.log(
                format!("{root}/quadrature_points"),
                &rerun::Points3D::update_fields().with_positions(self.points.iter().map(f32s)),
            )?;
        }
        for (name, u) in instance.probe_displacements() {
            for (axis, value) in ["u_x_m", "u_y_m", "u_z_m"].iter().zip(u) {
                rec.log(
                    format!("plots/probe_{}_{axis}/{}", entity_name(&name), self.name),
                    &rerun::Scalars::single(value),
                )?;
            }
        }
        let min_det_f =
            hox_sim::measure::min_det_f(mesh, sim.geometry(), &sim.positions).map_or(f64::INFINITY, |m| m.det_f);
        for (quantity, value) in [
            ("kinetic_energy_j", sim.kinetic_energy_j()),
            ("elastic_energy_j", sim.elastic_energy_j()),
            ("ms_per_frame", ms_per_frame),
            ("min_det_f", min_det_f),
        ] {
            rec.log(format!("plots/{quantity}/{}", self.name), &rerun::Scalars::single(value))?;
        }
        Ok(())
    }

    pub fn name(&self) -> &str {
        &self.name
    }
}

/// `0.125`, `0.3`, `1.5e-4`: a compact metre value for labels.
pub fn format_metres(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e4 {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_labels() {
        assert_eq!(entity_name("P2 160"), "p2_160");
        assert_eq!(entity_name("  "), "sim");
        assert_eq!(format_metres(0.0), "0");
        assert_eq!(format_metres(0.125), "0.125");
        assert_eq!(format_metres(0.4), "0.4");
        assert_eq!(format_metres(1.5e-4), "1.50e-4");
    }
}
