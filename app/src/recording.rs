//! Rerun logging of running simulations, shared by `hox record` and the app, with the layout a
//! recording opens in (its blueprint).
//!
//! Entity layout (one recording may hold several configurations side by side):
//! - `world/<config>`: a static `Transform3D` offsetting the configuration in space;
//! - `world/<config>/surface/<field>`: the deformed boundary surface (`Mesh3D`), curved faces
//!   tessellated ([`hox_sim::measure::surface`]), coloured by one field ([`crate::display`]) on
//!   a range every configuration shares — one mesh per recorded field;
//! - `world/<config>/edges`: element edges (`LineStrips3D`, curved for high-order elements);
//!   `world/<config>/clamped`, `world/<config>/driven`: the edges of clamped and driven faces;
//! - `world/<config>/rest_edges`: the rest shape's edges, static, as a ghost;
//! - `world/<config>/probes`, `world/<config>/quadrature_points` (on request): `Points3D`;
//! - `world/<config>/section`, `…/section/outline`: in the paper's scenes, the section `hox
//!   paper` draws (`recording/section.rs`);
//! - `legend/<field>/bar`, `legend/<field>/ticks`: each field's colour bar (an image) with its
//!   tick labels in the field's unit (relabelled as an automatic range grows; a fixed range's
//!   top and bottom labels say how much of the surface is saturated); `legend/text`: the
//!   legend and every configuration's parameters as one text;
//! - `plots/<quantity>/<config>`: `Scalars` — every probe displacement component (m), kinetic and
//!   elastic energy (J), milliseconds per frame and the smallest det F over all quadrature points;
//!   `plots/probe_<probe>_u_<axis>_m/reference_static`: the reference's value, where one is known.
//!
//! The blueprint ([`Recorder::blueprint`]): the first field's 3D view large on the left (a
//! further field's view below it), the legend text and colour bars beside it, and one
//! time-series chart per quantity with every configuration overlaid on the right, the probes'
//! u_z first with their reference.
//!
//! Timelines: `frame` (sequence) and `sim_time` (seconds). Topology, labels and the rest shape
//! are logged once as static data; a frame logs only what moves.

use crate::display::{FieldSource, SurfaceFrame, f32s};
use hox_scenes::Instance;
use hox_scenes::present::colour::{ColourRange, FieldScale};
use hox_scenes::reference::Reference;
use hox_sim::Vec3;
use hox_sim::measure::field::Field;
use hox_sim::measure::surface::{PointMap, Surface};
use rerun::RecordingStream;
use rerun::blueprint as bp;

pub mod eye;
mod legend;
mod retire;
mod section;

/// The bounding box of `instances`' rest shapes placed at `offsets`, metres (what a
/// recording's 3D views open on: [`eye::send`]).
pub fn bounds_of<'a>(placed: impl IntoIterator<Item = (&'a Instance, Vec3)>) -> Option<(Vec3, Vec3)> {
    let mut out: Option<(Vec3, Vec3)> = None;
    for (instance, offset) in placed {
        for p in &instance.sim.mesh().rest_positions {
            let q = p + offset;
            out = Some(match out {
                Some((lo, hi)) => (lo.inf(&q), hi.sup(&q)),
                None => (q, q),
            });
        }
    }
    out
}

/// What to log besides the always-present surface, edges, probes and time series.
#[derive(Clone, Debug, PartialEq)]
pub struct LogSettings {
    /// Pieces per edge of curved or quadrilateral faces.
    pub segments: usize,
    /// Also log the quadrature points.
    pub quadrature_points: bool,
    /// Log the fixed data (topology, rest shape, labels) as static — for a whole recording —
    /// or at the current time, for one segment of a longer one (a lesson's step, whose
    /// entities are cleared when it ends).
    pub static_data: bool,
    /// Send the recording's blueprint (a lesson sends its own).
    pub blueprint: bool,
    /// Added to every frame's `frame` and `sim_time` (a lesson's step starts where the last
    /// one ended).
    pub time_offset: (i64, f64),
    /// The blueprint shows a lesson's step text (`lesson/step`) above the legend (the app's
    /// stream while a lesson is open).
    pub lesson_text: bool,
    /// A live stream: the viewer follows its newest frame (issue #57: a page opened late
    /// replayed from t = 0 and ran 48 s behind the app).
    pub follow_latest: bool,
}

impl LogSettings {
    /// The display parameters of a configuration (`[display]` of the parameter table).
    pub fn new(params: &hox_scenes::Params) -> LogSettings {
        LogSettings {
            segments: params.tessellation,
            quadrature_points: params.quadrature_points,
            static_data: true,
            blueprint: true,
            time_offset: (0, 0.0),
            lesson_text: false,
            follow_latest: false,
        }
    }
}

/// Logs fixed data as static, or at the current time ([`LogSettings::static_data`]).
struct Fixed<'a> {
    rec: &'a RecordingStream,
    statics: bool,
    logged: &'a mut retire::Logged,
}

impl Fixed<'_> {
    fn log<A: ?Sized + rerun::AsComponents>(
        &mut self,
        path: impl Into<rerun::EntityPath>,
        archetype: &A,
    ) -> Result<(), rerun::RecordingStreamError> {
        self.logged.log(self.rec, path, self.statics, archetype)
    }
}

/// One configuration to record: its entity name, instance, place and reference (if known).
pub struct Configuration<'a> {
    pub name: String,
    pub instance: &'a Instance,
    pub offset_m: Vec3,
    pub reference: Option<&'a Reference>,
}

/// Logs one configuration frame after frame.
struct SimLogger {
    name: String,
    label: String,
    surface: Surface,
    quadrature: Option<PointMap>,
    /// What is drawn this frame (the viewport's display frame).
    frame: SurfaceFrame,
    /// One source per recorded field, with this frame's values.
    sources: Vec<(FieldSource, Vec<f64>)>,
    /// Quadrature points this frame, reused.
    points: Vec<Vec3>,
    clamped_edges: Vec<usize>,
    driven_edges: Vec<usize>,
    /// The reference's probe displacements, metres.
    reference: Option<hox_scenes::reference::Probes>,
    /// The paper's figure section, in the paper's scenes (`section.rs`).
    section: Option<section::Section>,
}

/// Logs several configurations side by side on shared colour ranges, with the recording's
/// blueprint.
pub struct Recorder {
    loggers: Vec<SimLogger>,
    fields: Vec<Field>,
    /// One colour scale per field, shared by every configuration.
    scales: Vec<FieldScale>,
    probe_names: Vec<String>,
    /// Added to the frame and time of every frame logged.
    time_offset: (i64, f64),
    /// The blueprint's legend column starts with the lesson's step text.
    lesson_text: bool,
    /// The viewer follows the newest frame ([`LogSettings::follow_latest`]).
    follow_latest: bool,
    /// What it logged, to retire when replaced on a stream that goes on ([`Recorder::retire`]).
    logged: retire::Logged,
}

/// A name usable as one entity path part: lowercase letters, digits and `_`.
pub fn entity_name(label: &str) -> String {
    let s: String =
        label.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' }).collect();
    let s = s.trim_matches('_').to_string();
    if s.is_empty() { "sim".to_string() } else { s }
}

/// What the recording states about a configuration: every parameter of the table
/// ([`hox_scenes::params`]) by its scene-file key, with its unit.
pub fn configuration_markdown(instance: &Instance) -> String {
    let scene = &instance.scene;
    let mut text = format!("Configuration of scene `{}`:\n", scene.name());
    for p in hox_scenes::params::PARAMS.iter().filter(|p| p.used_with(scene.mesh_kind())) {
        let unit = if p.unit.is_empty() { String::new() } else { format!(" {}", p.unit) };
        text += &format!("- `{}` = {}{unit}\n", p.file_path(), (p.get)(scene.params()));
    }
    text
}

/// A short label for an instance, e.g. `p2 160` (element type and count; an implicit solver
/// and its integrator follow: `p2 160 newton bdf2`).
pub fn config_label(instance: &Instance) -> String {
    let mesh = instance.sim.mesh();
    let types: Vec<&str> = mesh.blocks.iter().map(|b| b.element_type.name()).collect();
    let label = format!("{} {}", types.join("+"), mesh.num_elements());
    // the default solver (XPBD, the paper's) is unnamed (the labels of earlier recordings stay
    // as they were)
    let method = instance.sim.method();
    if method == hox_sim::solver::Method::default() {
        label
    } else {
        // an implicit solver with its integrator (issue #36): `p2 160 newton bdf2`
        format!("{label} {method} {}", instance.sim.integrator())
    }
}

/// Line colours of the configurations in the charts, in order (Tableau 10).
const SERIES: [[u8; 3]; 6] =
    [[78, 121, 167], [242, 142, 43], [89, 161, 79], [225, 87, 89], [176, 122, 161], [118, 183, 178]];
/// The clamped and driven face edges (as the viewport draws them).
const CLAMPED: [u8; 3] = [70, 120, 255];
const DRIVEN: [u8; 3] = [230, 70, 230];

/// The entity of the chart of probe `probe`'s component `axis` (0–2).
fn probe_plot(probe: &str, axis: usize) -> String {
    format!("plots/probe_{}_{}_m", entity_name(probe), ["u_x", "u_y", "u_z"][axis])
}

impl SimLogger {
    /// Logs the static data of one configuration (`index`-th) under `world/<name>`.
    fn new(
        rec: &RecordingStream,
        index: usize,
        config: &Configuration<'_>,
        settings: &LogSettings,
        fields: &[Field],
        logged: &mut retire::Logged,
    ) -> Result<SimLogger, rerun::RecordingStreamError> {
        let (name, instance) = (entity_name(&config.name), config.instance);
        let mesh = instance.sim.mesh();
        let surface = Surface::new(mesh, settings.segments);
        let quadrature = settings
            .quadrature_points
            .then(|| hox_sim::measure::surface::quadrature_points(mesh, instance.sim.geometry()));
        let root = format!("world/{name}");
        let mut fixed = Fixed { rec, statics: settings.static_data, logged };
        fixed.log(root.as_str(), &rerun::Transform3D::from_translation(f32s(&config.offset_m)))?;
        for field in fields {
            fixed.log(
                format!("{root}/surface/{}", field.name()),
                &rerun::Mesh3D::update_fields()
                    .with_triangle_indices(surface.triangles.iter().map(|t| rerun::TriangleIndices::from(*t))),
            )?;
        }
        // the rest shape's edges, a faint ghost
        let mut rest = Vec::new();
        surface.vertices.eval_into(&mesh.rest_positions, &mut rest);
        let strips: Vec<Vec<[f32; 3]>> =
            surface.edges.iter().map(|e| e.iter().map(|&i| f32s(&rest[i as usize])).collect()).collect();
        fixed.log(
            format!("{root}/rest_edges"),
            &rerun::LineStrips3D::new(strips)
                .with_colors([rerun::Color::from_unmultiplied_rgba(160, 160, 160, 90)])
                .with_radii([rerun::Radius::new_ui_points(0.5)]),
        )?;
        let probe_names: Vec<String> = instance.probes.iter().map(|p| p.name.clone()).collect();
        fixed.log(
            format!("{root}/probes"),
            &rerun::Points3D::update_fields()
                .with_labels(probe_names.iter().map(String::as_str))
                .with_colors([rerun::Color::from_rgb(190, 30, 20)])
                .with_radii([rerun::Radius::new_ui_points(6.0)]),
        )?;
        fixed.log(
            format!("{root}/edges"),
            &rerun::LineStrips3D::update_fields()
                .with_colors([rerun::Color::from_rgb(20, 20, 20)])
                .with_radii([rerun::Radius::new_ui_points(0.75)]),
        )?;
        let (clamped, driven) = crate::display::held_nodes(instance);
        let n = mesh.num_nodes();
        let clamped_edges = surface.edges_between(&crate::display::node_flags(&clamped, n));
        let driven_edges = surface.edges_between(&crate::display::node_flags(&driven, n));
        for (part, edges, c) in [("clamped", &clamped_edges, CLAMPED), ("driven", &driven_edges, DRIVEN)] {
            if !edges.is_empty() {
                fixed.log(
                    format!("{root}/{part}"),
                    &rerun::LineStrips3D::update_fields()
                        .with_colors([rerun::Color::from_rgb(c[0], c[1], c[2])])
                        .with_radii([rerun::Radius::new_ui_points(2.5)]),
                )?;
            }
        }
        if quadrature.is_some() {
            fixed.log(
                format!("{root}/quadrature_points"),
                &rerun::Points3D::update_fields()
                    .with_colors([rerun::Color::from_rgb(255, 140, 0)])
                    .with_radii([rerun::Radius::new_ui_points(2.5)]),
            )?;
        }
        // the charts' line of this configuration: its label and colour in every chart
        let label = config_label(instance);
        let c = SERIES[index % SERIES.len()];
        let mut series: Vec<String> = ["kinetic_energy_j", "elastic_energy_j", "ms_per_frame", "min_det_f"]
            .iter()
            .map(|q| format!("plots/{q}/{name}"))
            .collect();
        for p in &probe_names {
            series.extend((0..3).map(|axis| format!("{}/{name}", probe_plot(p, axis))));
        }
        for path in series {
            fixed.log(
                path,
                &rerun::SeriesLines::new()
                    .with_names([format!("{}: {label}", ["a", "b", "c", "d", "e", "f"][index.min(5)])])
                    .with_colors([rerun::Color::from_rgb(c[0], c[1], c[2])])
                    .with_widths([2.0]),
            )?;
        }
        let reference = config.reference.map(|r| r.probes.clone());
        if reference.is_some() {
            for p in &probe_names {
                for axis in 0..3 {
                    fixed.log(
                        format!("{}/reference_static", probe_plot(p, axis)),
                        &rerun::SeriesLines::new()
                            .with_names(["reference (static)"])
                            .with_colors([rerun::Color::from_rgb(150, 150, 150)])
                            .with_widths([1.0]),
                    )?;
                }
            }
        }
        let mut sources: Vec<(FieldSource, Vec<f64>)> =
            fields.iter().map(|&f| (FieldSource::new(f), Vec::new())).collect();
        for (source, _) in &mut sources {
            source.set_reference(&surface, mesh, config.reference.and_then(|r| r.field.as_ref()));
        }
        Ok(SimLogger {
            name,
            label,
            surface,
            quadrature,
            frame: SurfaceFrame::default(),
            sources,
            points: Vec::new(),
            clamped_edges,
            driven_edges,
            reference,
            section: section::Section::of(instance),
        })
    }

    /// This frame's geometry and field values (before the shared ranges are known).
    fn measure(&mut self, instance: &Instance) {
        self.frame.update(&self.surface, &instance.sim);
        for (source, values) in &mut self.sources {
            source.values_into(&self.surface, &instance.sim, &self.frame, values);
        }
    }

    /// Logs the frame measured last, coloured on `ranges` (one per field). `ms_per_frame` is
    /// the wall time of the last step.
    fn log(
        &mut self,
        rec: &RecordingStream,
        instance: &Instance,
        ranges: &[ColourRange],
        ms_per_frame: f64,
        logged: &mut retire::Logged,
    ) -> Result<(), rerun::RecordingStreamError> {
        let sim = &instance.sim;
        let root = format!("world/{}", self.name);
        if let Some(section) = &mut self.section {
            section.log(rec, logged, &root, instance)?;
        }
        let frame = &self.frame;
        let positions: Vec<[f32; 3]> = frame.positions_m.iter().map(f32s).collect();
        let normals: Vec<[f32; 3]> = frame.normals.iter().map(f32s).collect();
        for ((source, values), range) in self.sources.iter().zip(ranges) {
            logged.at(
                rec,
                format!("{root}/surface/{}", source.field.name()),
                &rerun::Mesh3D::update_fields()
                    .with_vertex_positions(positions.iter().copied())
                    .with_vertex_normals(normals.iter().copied())
                    .with_vertex_colors(values.iter().map(|&v| {
                        let c = range.colour(v);
                        rerun::Color::from_rgb(c[0], c[1], c[2])
                    })),
            )?;
        }
        let strips = |edges: &mut dyn Iterator<Item = &Vec<u32>>| -> Vec<Vec<[f32; 3]>> {
            edges.map(|e| e.iter().map(|&i| positions[i as usize]).collect()).collect()
        };
        logged.at(
            rec,
            format!("{root}/edges"),
            &rerun::LineStrips3D::update_fields().with_strips(strips(&mut self.surface.edges.iter())),
        )?;
        for (part, edges) in [("clamped", &self.clamped_edges), ("driven", &self.driven_edges)] {
            if !edges.is_empty() {
                let mut it = edges.iter().map(|&k| &self.surface.edges[k]);
                logged.at(
                    rec,
                    format!("{root}/{part}"),
                    &rerun::LineStrips3D::update_fields().with_strips(strips(&mut it)),
                )?;
            }
        }
        let probe_positions: Vec<[f32; 3]> =
            instance.probes.iter().map(|p| f32s(&p.position(&sim.positions))).collect();
        logged.at(rec, format!("{root}/probes"), &rerun::Points3D::update_fields().with_positions(probe_positions))?;
        if let Some(q) = &self.quadrature {
            q.eval_into(&sim.positions, &mut self.points);
            logged.at(
                rec,
                format!("{root}/quadrature_points"),
                &rerun::Points3D::update_fields().with_positions(self.points.iter().map(f32s)),
            )?;
        }
        for (name, u) in instance.probe_displacements() {
            for (axis, value) in u.iter().enumerate() {
                logged.at(
                    rec,
                    format!("{}/{}", probe_plot(&name, axis), self.name),
                    &rerun::Scalars::single(*value),
                )?;
                if let Some(r) = self.reference.as_ref().and_then(|r| r.get(&name)) {
                    logged.at(
                        rec,
                        format!("{}/reference_static", probe_plot(&name, axis)),
                        &rerun::Scalars::single(r[axis]),
                    )?;
                }
            }
        }
        let min_det_f =
            hox_sim::measure::min_det_f(sim.mesh(), sim.geometry(), &sim.positions).map_or(f64::INFINITY, |m| m.det_f);
        for (quantity, value) in [
            ("kinetic_energy_j", sim.kinetic_energy_j()),
            ("elastic_energy_j", sim.elastic_energy_j()),
            ("ms_per_frame", ms_per_frame),
            ("min_det_f", min_det_f),
        ] {
            logged.at(rec, format!("plots/{quantity}/{}", self.name), &rerun::Scalars::single(value))?;
        }
        Ok(())
    }
}

impl Recorder {
    /// Logs the static data of `configs` (side by side at their offsets), recording `fields`
    /// (at least one; the first is the large view) on the colour scales of the first
    /// configuration's display parameters, and sends the blueprint.
    pub fn new(
        rec: &RecordingStream,
        configs: &[Configuration<'_>],
        settings: &LogSettings,
        fields: &[Field],
    ) -> Result<Recorder, rerun::RecordingStreamError> {
        let fields: Vec<Field> = if fields.is_empty() { vec![Field::Displacement] } else { fields.to_vec() };
        let first = configs.first().map(|c| c.instance);
        let scales = match first {
            Some(i) => {
                fields.iter().map(|&f| crate::display::field_scale(Some(i.sim.mesh()), i.scene.params(), f)).collect()
            }
            None => Vec::new(),
        };
        // z up, as the scenes are built (gravity along −z)
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        let mut logged = retire::Logged::default();
        let mut loggers = Vec::new();
        for (k, c) in configs.iter().enumerate() {
            loggers.push(SimLogger::new(rec, k, c, settings, &fields, &mut logged)?);
        }
        let probe_names = first.map(|i| i.probes.iter().map(|p| p.name.clone()).collect()).unwrap_or_default();
        let mut recorder = Recorder {
            loggers,
            fields,
            scales,
            probe_names,
            time_offset: settings.time_offset,
            lesson_text: settings.lesson_text,
            follow_latest: settings.follow_latest,
            logged,
        };
        let legend = rerun::TextDocument::from_markdown(recorder.legend_markdown(configs));
        let logged = &mut recorder.logged;
        for field in &recorder.fields {
            logged.log(rec, format!("legend/{}/bar", field.name()), true, &legend::colour_bar_image())?;
        }
        logged.log(rec, "legend/text", settings.static_data, &legend)?;
        if settings.blueprint {
            let bounds = bounds_of(configs.iter().map(|c| (c.instance, c.offset_m)));
            eye::send(rec, recorder.blueprint(), bounds)?;
        }
        Ok(recorder)
    }

    /// Clears every configuration's entities at the current time (the end of a lesson's step).
    pub fn clear(&self, rec: &RecordingStream) -> Result<(), rerun::RecordingStreamError> {
        for l in &self.loggers {
            rec.log(format!("world/{}", l.name), &rerun::Clear::recursive())?;
        }
        Ok(())
    }

    /// Hides at every time what this recorder logged and `replacement` (which has logged its
    /// first frame) does not: bodies, rest shapes, chart lines and legends of configurations
    /// gone from a stream that goes on (`recording/retire.rs`).
    pub fn retire(&self, rec: &RecordingStream, replacement: &Recorder) -> Result<(), rerun::RecordingStreamError> {
        self.logged.retire(rec, &replacement.logged)
    }

    /// The entity names of the configurations, in order.
    pub fn names(&self) -> Vec<&str> {
        self.loggers.iter().map(|l| l.name.as_str()).collect()
    }

    /// Logs the current state of `instances` (in the order given to [`Recorder::new`]) at the
    /// first one's frame and time; `ms_per_frame` is each one's wall time of its last step.
    pub fn log_frame(
        &mut self,
        rec: &RecordingStream,
        instances: &[&Instance],
        ms_per_frame: &[f64],
    ) -> Result<(), rerun::RecordingStreamError> {
        let Some(first) = instances.first() else { return Ok(()) };
        rec.set_time_sequence("frame", self.time_offset.0 + first.sim.frames() as i64);
        rec.set_duration_secs("sim_time", self.time_offset.1 + first.sim.time_secs());
        for (logger, instance) in self.loggers.iter_mut().zip(instances) {
            logger.measure(instance);
            for ((_, values), scale) in logger.sources.iter().zip(&mut self.scales) {
                scale.observe(values);
            }
        }
        let ranges: Vec<ColourRange> = self.scales.iter().map(FieldScale::range).collect();
        for (j, range) in ranges.iter().enumerate() {
            let values: Vec<f64> = self.loggers.iter().flat_map(|l| l.sources[j].1.iter().copied()).collect();
            legend::log_ticks(rec, &mut self.logged, range, &values)?;
        }
        for ((logger, instance), ms) in self.loggers.iter_mut().zip(instances).zip(ms_per_frame) {
            logger.log(rec, instance, &ranges, *ms, &mut self.logged)?;
        }
        Ok(())
    }

    /// The legend as one text: what the colours, lines and marks mean, then every
    /// configuration's parameters.
    fn legend_markdown(&self, configs: &[Configuration<'_>]) -> String {
        let mut text = String::from("## Legend\n\n");
        let mut automatic = false;
        for (field, scale) in self.fields.iter().zip(&self.scales) {
            let range = scale.range();
            automatic |= range.automatic;
            let how = if range.automatic {
                "automatic range".to_string()
            } else {
                format!(
                    "fixed range {} to {}, beyond it pink (above){}",
                    range.format(range.min),
                    range.format(range.max),
                    if field.two_sided() { " and light blue (below)" } else { "" }
                )
            };
            text += &format!("- **{}** view: {} — {how}.\n", field.name(), field.description());
        }
        if automatic {
            text += &format!(
                "- An automatic range grows to hold {:.0} % of each frame's values (a stress peak at a clamped edge would otherwise leave the rest one colour); the few beyond are drawn pink, their share on the colour bar.\n",
                100.0 * hox_scenes::present::colour::AUTOMATIC_PERCENTILE
            );
        }
        text += "- Blue thick edges: clamped faces; magenta: driven faces; red points: probes; grey lines: the rest shape.\n";
        text += "- Charts: one line per configuration, the same colour in every chart; grey: the static reference where one is known.\n\n";
        for (k, (c, logger)) in configs.iter().zip(&self.loggers).enumerate() {
            text += &format!(
                "### {}: {} (`world/{}`)\n\n",
                ["a", "b", "c", "d", "e", "f"][k.min(5)],
                logger.label,
                logger.name
            );
            if let Some(r) = c.reference {
                text += &format!("Reference: {}\n\n", r.label());
            }
            text += &configuration_markdown(c.instance);
            text += "\n";
        }
        text
    }

    /// The layout the recording opens in: the 3D views (first field large) on the left, the
    /// legend and colour bars in a narrow column, the charts on the right.
    pub fn blueprint(&self) -> bp::Blueprint {
        let names: Vec<&str> = self.names();
        let views_3d: Vec<bp::ContainerLike> = self
            .fields
            .iter()
            .map(|field| {
                let mut contents = vec!["+ world/**".to_string()];
                for n in &names {
                    contents.push(format!("- world/{n}/surface/**"));
                    contents.push(format!("+ world/{n}/surface/{}", field.name()));
                }
                bp::Spatial3DView::new(format!("3D: {}", field.title()))
                    .with_origin("world")
                    .with_contents(contents)
                    .into()
            })
            .collect();
        let mut shares_3d = vec![1.0f32; views_3d.len()];
        if let Some(s) = shares_3d.first_mut() {
            *s = 2.0;
        }
        let mut legend: Vec<bp::ContainerLike> = Vec::new();
        if self.lesson_text {
            legend.push(
                bp::TextDocumentView::new("Lesson").with_origin("lesson/step").with_contents(["+ lesson/step"]).into(),
            );
        }
        legend.push(
            bp::TextDocumentView::new("Legend").with_origin("legend/text").with_contents(["+ legend/text"]).into(),
        );
        for (field, scale) in self.fields.iter().zip(&self.scales) {
            legend.push(
                bp::Spatial2DView::new(format!("colours: {}", scale.range().heading()))
                    .with_origin(format!("legend/{}", field.name()))
                    .with_contents([format!("+ legend/{}/**", field.name())])
                    .into(),
            );
        }
        let text_views = if self.lesson_text { vec![1.6, 1.2] } else { vec![1.2] };
        let legend_shares: Vec<f32> = text_views.into_iter().chain(self.fields.iter().map(|_| 1.0)).collect();
        let chart = |title: String, path: String| -> bp::ContainerLike {
            bp::TimeSeriesView::new(title).with_origin(path.as_str()).with_contents([format!("+ {path}/**")]).into()
        };
        let mut charts: Vec<bp::ContainerLike> =
            self.probe_names.iter().map(|p| chart(format!("probe {p}: u_z (m)"), probe_plot(p, 2))).collect();
        let mut probe_rows = vec![2.0f32; charts.len()];
        charts.push(chart("kinetic energy (J)".into(), "plots/kinetic_energy_j".into()));
        charts.push(chart("elastic energy (J)".into(), "plots/elastic_energy_j".into()));
        let mut more: Vec<bp::ContainerLike> = Vec::new();
        for p in &self.probe_names {
            more.push(chart(format!("probe {p}: u_x (m)"), probe_plot(p, 0)));
            more.push(chart(format!("probe {p}: u_y (m)"), probe_plot(p, 1)));
        }
        more.push(chart("ms per frame".into(), "plots/ms_per_frame".into()));
        more.push(chart("smallest det F".into(), "plots/min_det_f".into()));
        charts.push(bp::Tabs::new(more).into());
        probe_rows.extend([1.0, 1.0, 1.5]);
        let root = bp::Horizontal::new([
            bp::Vertical::new(views_3d).with_row_shares(shares_3d).into(),
            bp::Vertical::new(legend).with_row_shares(legend_shares).into(),
            bp::Vertical::new(charts).with_row_shares(probe_rows).into(),
        ])
        .with_column_shares([0.54, 0.18, 0.28]);
        let panel = time_panel();
        let panel =
            if self.follow_latest { panel.with_play_state(bp::components::PlayState::Following) } else { panel };
        blueprint_of(root).with_time_panel(panel)
    }
}

/// The time panel collapsed to its play bar on `sim_time`.
fn time_panel() -> bp::TimePanel {
    bp::TimePanel::new().with_state(bp::components::PanelState::Collapsed).with_timeline("sim_time")
}

/// A blueprint of exactly the views under `root`, the side panels folded away (the views get
/// the window) and the time panel collapsed to its play bar on `sim_time`.
pub fn blueprint_of(root: impl Into<bp::ContainerLike>) -> bp::Blueprint {
    bp::Blueprint::new(root)
        .with_auto_views(false)
        .with_auto_layout(false)
        .with_blueprint_panel(bp::BlueprintPanel::from_state(bp::components::PanelState::Collapsed))
        .with_selection_panel(bp::SelectionPanel::from_state(bp::components::PanelState::Collapsed))
        .with_time_panel(time_panel())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::display::format_metres;

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
