//! The display frame: what the viewport ([`crate::gui::viewport`]) and a Rerun recording
//! ([`crate::recording`]) draw of the running configurations, computed in one place so the two
//! show the same thing.
//!
//! - **Layout**: configurations side by side along y, one body width of the first configuration
//!   plus a gap apart ([`side_by_side_offsets`]).
//! - **Colour**: a field ([`Field`]: |u|, von Mises stress, strain, det F, energy density, error
//!   against the reference) evaluated at every display vertex as a material point of its
//!   elements ([`hox_sim::measure::field`]), mapped to viridis on one range shared by every
//!   configuration ([`field_scale`]), so colours compare: the user's fixed top, or automatic —
//!   growing with the largest value seen. Values beyond a fixed range take the saturation
//!   colours ([`hox_scenes::present::colour::OVER`]).
//! - **Surface frame** ([`SurfaceFrame`]): the boundary surface's vertices `x(r) = Σ N_i(r) x_i`
//!   (curved faces follow the elements' maps, [`hox_sim::measure::surface`]), their normals,
//!   field values and colours, in the body's own coordinates; the viewport adds the offset, the
//!   recording logs it once as the configuration's transform.
//! - **Held faces** ([`held_nodes`], [`Surface::edges_between`]): the nodes clamps hold and
//!   drives move, whose face edges are drawn in their own colours.

use hox_scenes::Instance;
use hox_scenes::present::colour::{ColourRange, FieldScale};
use hox_scenes::reference::ReferenceField;
use hox_sim::Vec3;
use hox_sim::measure::field::{Field, SurfaceGradients};
use hox_sim::measure::surface::Surface;
use hox_sim::mesh::Mesh;
use hox_sim::solver::Simulation;

/// The axis configurations are laid apart along, so that none hides another from the camera:
/// across the line of sight ([`crate::gui::presets::ViewPreset::layout_axis`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutAxis {
    X,
    Y,
}

/// World offsets of `count` configurations side by side along `axis`, spaced by the first
/// configuration's mesh (`first`): its extent along the axis plus a gap of a quarter of its
/// largest extent.
pub fn side_by_side_offsets(first: &Mesh, count: usize, axis: LayoutAxis) -> Vec<Vec3> {
    let (lo, hi) = first.bounding_box();
    let e = hi - lo;
    let d = match axis {
        LayoutAxis::X => 0,
        LayoutAxis::Y => 1,
    };
    let spacing_m = e[d] + 0.25 * e.max();
    (0..count)
        .map(|k| {
            let mut o = Vec3::zeros();
            o[d] = k as f64 * spacing_m;
            o
        })
        .collect()
}

/// The fields a configuration's `[display] field` lists (the first is the one drawn).
pub fn fields(params: &hox_scenes::Params) -> Vec<Field> {
    if params.field.is_empty() { vec![Field::Displacement] } else { params.field.clone() }
}

/// The colour scale of `field` every configuration shares, from the first one's display
/// parameters (`params`) and mesh (`first`): fixed at `colour_max_m` for the metre fields (|u|,
/// error) and at `colour_max` for the first other field listed when these are positive,
/// automatic otherwise ([`FieldScale`]).
pub fn field_scale(first: Option<&Mesh>, params: &hox_scenes::Params, field: Field) -> FieldScale {
    let extent_m = first.map_or(1.0, |m| {
        let (lo, hi) = m.bounding_box();
        (hi - lo).max()
    });
    let fixed = if field.unit() == "m" {
        params.colour_max_m
    } else if fields(params).into_iter().find(|f| f.unit() != "m") == Some(field) {
        params.colour_max
    } else {
        0.0
    };
    FieldScale::new(field, fixed, extent_m)
}

/// The nodes held by clamps and moved by prescribed motion (drives), each sorted.
pub fn held_nodes(instance: &Instance) -> (Vec<u32>, Vec<u32>) {
    use hox_scenes::scene::EffectSpec;
    let scene = &instance.scene;
    let mesh = instance.sim.mesh();
    let (mut clamped, mut driven) = (Vec::new(), Vec::new());
    for (k, e) in scene.file.effects.iter().enumerate() {
        let (EffectSpec::Clamp { nodes } | EffectSpec::Prescribed { nodes, .. }) = e else { continue };
        let set = scene.selected_nodes(mesh, k, nodes).unwrap_or_default();
        if matches!(e, EffectSpec::Clamp { .. }) { clamped.extend(set) } else { driven.extend(set) }
    }
    clamped.sort_unstable();
    driven.sort_unstable();
    (clamped, driven)
}

/// Node flags of `nodes` among `num_nodes`.
pub fn node_flags(nodes: &[u32], num_nodes: usize) -> Vec<bool> {
    let mut flags = vec![false; num_nodes];
    for &n in nodes {
        if let Some(f) = flags.get_mut(n as usize) {
            *f = true;
        }
    }
    flags
}

/// What a configuration's surface is coloured by and what that needs, built once per surface:
/// the material gradients at the display points (for the fields of `F`) and the reference
/// displacement there (for the error field).
#[derive(Clone, Debug)]
pub struct FieldSource {
    pub field: Field,
    gradients: Option<SurfaceGradients>,
    reference_m: Option<Vec<Vec3>>,
}

impl FieldSource {
    pub fn new(field: Field) -> FieldSource {
        FieldSource { field, gradients: None, reference_m: None }
    }

    /// Takes the reference field (None: none known), evaluated at `surface`'s vertices of `mesh`.
    pub fn set_reference(&mut self, surface: &Surface, mesh: &Mesh, field: Option<&ReferenceField>) {
        self.reference_m = field.and_then(|f| {
            let mut rest = Vec::new();
            surface.vertices.eval_into(&mesh.rest_positions, &mut rest);
            f.at_points(&rest, &surface.vertices, mesh.num_nodes())
        });
    }

    /// Whether the error field has a reference to measure against.
    pub fn has_reference(&self) -> bool {
        self.reference_m.is_some()
    }

    /// Forgets what was built for a surface (a new mesh or tessellation).
    pub fn surface_changed(&mut self) {
        self.gradients = None;
        self.reference_m = None;
    }

    /// The field at every vertex of `frame` (updated for `sim` on `surface`), into `out`; the
    /// error field without a reference is NaN everywhere.
    pub fn values_into(&mut self, surface: &Surface, sim: &Simulation, frame: &SurfaceFrame, out: &mut Vec<f64>) {
        out.clear();
        match self.field {
            Field::Displacement => out.extend(frame.displacements_m.iter().map(|u| u.norm())),
            Field::Error => match &self.reference_m {
                Some(r) => out.extend(frame.displacements_m.iter().zip(r).map(|(u, r)| (u - r).norm())),
                None => out.resize(frame.displacements_m.len(), f64::NAN),
            },
            field => {
                let mesh = sim.mesh();
                let gradients = self.gradients.get_or_insert_with(|| SurfaceGradients::new(mesh, surface));
                gradients.values_into(field, sim.material(), &sim.positions, &mesh.rest_positions, out);
            }
        }
    }
}

/// One configuration's surface as drawn this frame; buffers are reused from frame to frame.
#[derive(Clone, Debug, Default)]
pub struct SurfaceFrame {
    /// Display vertices, metres, in the body's coordinates (no offset).
    pub positions_m: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// The drawn field's value at every vertex ([`SurfaceFrame::update_field`]).
    pub values: Vec<f64>,
    /// Vertex colours: the values on the shared colour range ([`SurfaceFrame::paint`]).
    pub colours: Vec<[u8; 3]>,
    /// Vertex displacements, metres.
    pub displacements_m: Vec<Vec3>,
}

impl SurfaceFrame {
    /// The vertices and normals of `sim` drawn on `surface`.
    pub fn update(&mut self, surface: &Surface, sim: &Simulation) {
        let mesh = sim.mesh();
        surface.vertices.eval_into(&sim.positions, &mut self.positions_m);
        surface.vertices.displacements_into(&sim.positions, &mesh.rest_positions, &mut self.displacements_m);
        surface.vertex_normals(&self.positions_m, &mut self.normals);
    }

    /// The values of `source`'s field this frame (after [`SurfaceFrame::update`]).
    pub fn update_field(&mut self, surface: &Surface, sim: &Simulation, source: &mut FieldSource) {
        let mut values = std::mem::take(&mut self.values);
        source.values_into(surface, sim, self, &mut values);
        self.values = values;
    }

    /// Colours the values on `range`.
    pub fn paint(&mut self, range: &ColourRange) {
        self.colours.clear();
        self.colours.extend(self.values.iter().map(|&v| range.colour(v)));
    }
}

/// Single precision for drawing and logging.
pub fn f32s(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// `0.125`, `0.3`, `1.5e-4`: a compact metre value for labels.
pub fn format_metres(v: f64) -> String {
    hox_scenes::present::colour::format_value(v, "")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The viewport and the recording share one layout and one colour scale: the paper's beam
    /// ([0,2]×[0,0.5]×[0,0.5] m) is spaced 0.5 + 0.5 = 1 m along y, 2 + 0.5 = 2.5 m along x; the displacement
    /// range is automatic unless `colour_max_m` fixes it.
    #[test]
    fn layout_and_colour_scale_of_the_paper_beam() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let instance = hox_scenes::Instance::new(scene).unwrap();
        let mesh = instance.sim.mesh();
        assert_eq!(side_by_side_offsets(mesh, 2, LayoutAxis::Y), [Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0)]);
        assert_eq!(side_by_side_offsets(mesh, 2, LayoutAxis::X), [Vec3::zeros(), Vec3::new(2.5, 0.0, 0.0)]);
        let mut p = instance.scene.params().clone();
        assert!(field_scale(Some(mesh), &p, Field::Displacement).range().automatic);
        p.colour_max_m = 0.1;
        p.colour_max = 2e5;
        p.field = vec![Field::Strain, Field::VonMises];
        assert_eq!(field_scale(Some(mesh), &p, Field::Displacement).range().max, 0.1);
        assert_eq!(fields(&p), [Field::Strain, Field::VonMises]);
        // the fixed top belongs to the first non-metre field listed; the others stay automatic
        assert_eq!(field_scale(Some(mesh), &p, Field::Strain).range().max, 2e5);
        assert!(field_scale(Some(mesh), &p, Field::VonMises).range().automatic);
    }

    /// A body at rest is drawn at its rest surface with no displacement or stress; moved rigidly
    /// by `d`, every vertex moves by `d`, its |u| is |d| and it has still no stress.
    #[test]
    fn the_surface_frame_follows_the_nodes_and_a_rigid_motion_has_no_stress() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let mut instance = hox_scenes::Instance::new(scene).unwrap();
        let surface = Surface::new(instance.sim.mesh(), 3);
        let mut frame = SurfaceFrame::default();
        let mut u = FieldSource::new(Field::Displacement);
        let mut vm = FieldSource::new(Field::VonMises);
        frame.update(&surface, &instance.sim);
        frame.update_field(&surface, &instance.sim, &mut u);
        let rest = frame.positions_m.clone();
        assert!(!rest.is_empty() && frame.normals.len() == rest.len() && frame.values.len() == rest.len());
        assert!(frame.values.iter().all(|&v| v == 0.0));
        assert!(frame.normals.iter().all(|n| (n.norm() - 1.0).abs() < 1e-9));
        let d = Vec3::new(0.0, 0.0, -0.2);
        for x in &mut instance.sim.positions {
            *x += d;
        }
        frame.update(&surface, &instance.sim);
        frame.update_field(&surface, &instance.sim, &mut u);
        assert!(frame.positions_m.iter().zip(&rest).all(|(x, r)| (x - r - d).norm() < 1e-12));
        assert!(frame.values.iter().all(|&v| (v - 0.2).abs() < 1e-12));
        let range = ColourRange::metres(0.4);
        frame.paint(&range);
        assert!(frame.colours.iter().all(|&c| c == range.colour(0.2)));
        frame.update_field(&surface, &instance.sim, &mut vm);
        assert!(frame.values.iter().all(|&v| v.abs() < 1e-6), "a rigid translation is stress-free");
        // without a reference, the error field has no value
        let mut err = FieldSource::new(Field::Error);
        frame.update_field(&surface, &instance.sim, &mut err);
        assert!(!err.has_reference() && frame.values.iter().all(|v| v.is_nan()));
    }
}
