//! How one session is drawn (its view, kept by the viewport apart from the run): the display
//! surface of its mesh (`[display] tessellation` pieces per face edge, [`Surface`]), the rest
//! vertices (the ghost), which nodes are element corners, the clamped and driven nodes and the
//! edges of their faces, the colour field's source (with the reference's displacement field for
//! the error), and the quadrature points.
//!
//! A view follows its session's [`Revisions`]: a new mesh build rebuilds everything, another
//! tessellation the surface, new solver settings the quadrature points, a new reference the
//! error field's data. Nothing here changes the simulation.

use super::session::{Revisions, Session};
use crate::display::FieldSource;
use hox_sim::Vec3;
use hox_sim::measure::surface::{PointMap, Surface};

pub struct SessionView {
    /// What the view was built for.
    revisions: Revisions,
    tessellation: usize,
    pub surface: Surface,
    /// The display vertices at rest (the ghost) and which mesh nodes are element corners.
    pub rest_vertices: Vec<Vec3>,
    pub corner_nodes: Vec<bool>,
    /// Nodes held by clamps and moved by prescribed motions.
    pub clamped: Vec<u32>,
    pub driven: Vec<u32>,
    /// The surface's element edges on clamped and on driven faces ([`Surface::edges_between`]).
    pub clamped_edges: Vec<usize>,
    pub driven_edges: Vec<usize>,
    /// What the surface is coloured by ([`crate::display::FieldSource`]).
    pub field_source: FieldSource,
    quadrature: std::cell::OnceCell<PointMap>,
}

impl SessionView {
    /// The view of `session` as it is now.
    pub fn new(session: &Session) -> SessionView {
        let mesh = session.instance.sim.mesh();
        let field = crate::display::fields(&session.config)[0];
        let (clamped, driven) = crate::display::held_nodes(&session.instance);
        let mut view = SessionView {
            revisions: session.revisions(),
            tessellation: session.config.tessellation,
            surface: Surface::new(mesh, session.config.tessellation),
            rest_vertices: Vec::new(),
            corner_nodes: mesh.vertex_nodes(),
            clamped,
            driven,
            clamped_edges: Vec::new(),
            driven_edges: Vec::new(),
            field_source: FieldSource::new(field),
            quadrature: std::cell::OnceCell::new(),
        };
        view.surface_changed(session);
        view
    }

    /// Catches up with what changed in `session` since the view was built or last followed it.
    pub fn follow(&mut self, session: &Session) {
        let now = session.revisions();
        if now.build != self.revisions.build {
            *self = SessionView::new(session);
            return;
        }
        self.field_source.field = crate::display::fields(&session.config)[0];
        if now.settings != self.revisions.settings {
            self.quadrature = std::cell::OnceCell::new();
        }
        if session.config.tessellation != self.tessellation {
            self.tessellation = session.config.tessellation;
            self.surface = Surface::new(session.instance.sim.mesh(), self.tessellation);
            self.surface_changed(session);
        } else if now.reference != self.revisions.reference
            || (!self.field_source.has_reference() && session.reference.reference().is_some_and(|r| r.field.is_some()))
        {
            self.sync_reference_field(session);
        }
        self.revisions = now;
    }

    /// After the surface was rebuilt: its rest vertices, held edges and field data.
    fn surface_changed(&mut self, session: &Session) {
        let mesh = session.instance.sim.mesh();
        self.surface.vertices.eval_into(&mesh.rest_positions, &mut self.rest_vertices);
        let n = mesh.num_nodes();
        self.clamped_edges = self.surface.edges_between(&crate::display::node_flags(&self.clamped, n));
        self.driven_edges = self.surface.edges_between(&crate::display::node_flags(&self.driven, n));
        self.field_source.surface_changed();
        self.sync_reference_field(session);
    }

    /// Gives the field source the reference's displacement field, when there is one.
    fn sync_reference_field(&mut self, session: &Session) {
        let field = session.reference.reference().and_then(|r| r.field.as_ref());
        self.field_source.set_reference(&self.surface, session.instance.sim.mesh(), field);
    }

    /// Every quadrature point of `session` as a material point (computed on first use).
    pub fn quadrature_points(&self, session: &Session) -> &PointMap {
        self.quadrature.get_or_init(|| {
            hox_sim::measure::surface::quadrature_points(session.instance.sim.mesh(), session.instance.sim.geometry())
        })
    }
}
