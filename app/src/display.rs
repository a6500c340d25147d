//! The display frame: what the viewport ([`crate::gui::viewport`]) and a Rerun recording
//! ([`crate::recording`]) draw of the running configurations, computed in one place so the two
//! show the same thing.
//!
//! - **Layout**: configurations side by side along y, one body width of the first configuration
//!   plus a gap apart ([`side_by_side_offsets`]).
//! - **Colour range**: the displacement magnitude `|u| = |x − X|` in metres maps to viridis on a
//!   fixed range `[0, max]` shared by every configuration, so colours compare; `max` is the
//!   user's, or a fifth of the first body's largest extent ([`colour_range`]).
//! - **Surface frame** ([`SurfaceFrame`]): the boundary surface's vertices `x(r) = Σ N_i(r) x_i`
//!   (curved faces follow the elements' maps, [`hox_sim::measure::surface`]), their normals and
//!   colours, in the body's own coordinates; the viewport adds the offset, the recording logs it
//!   once as the configuration's transform.

use crate::colour::ColourRange;
use hox_sim::Vec3;
use hox_sim::measure::surface::Surface;
use hox_sim::mesh::Mesh;
use hox_sim::solver::Simulation;

/// World offsets of `count` configurations side by side along y, spaced by the first
/// configuration's mesh (`first`): its width plus a gap of half its width or a quarter of its
/// largest extent, whichever is larger.
pub fn side_by_side_offsets(first: &Mesh, count: usize) -> Vec<Vec3> {
    let (lo, hi) = first.bounding_box();
    let e = hi - lo;
    let spacing_m = e.y + (0.5 * e.y).max(0.25 * e.max());
    (0..count).map(|k| Vec3::new(0.0, k as f64 * spacing_m, 0.0)).collect()
}

/// The displacement colour range every configuration shares: `[0, colour_max_m]` (the display
/// parameter `colour_max_m` of the first configuration), or, when that is 0 (automatic),
/// `[0, ⅕ × the first body's largest extent]` (`first`: None gives 1 m).
pub fn colour_range(first: Option<&Mesh>, colour_max_m: f64) -> ColourRange {
    if colour_max_m > 0.0 {
        return ColourRange { max_m: colour_max_m };
    }
    let extent_m = first.map_or(1.0, |m| {
        let (lo, hi) = m.bounding_box();
        (hi - lo).max()
    });
    ColourRange { max_m: 0.2 * extent_m }
}

/// One configuration's surface as drawn this frame; buffers are reused from frame to frame.
#[derive(Clone, Debug, Default)]
pub struct SurfaceFrame {
    /// Display vertices, metres, in the body's coordinates (no offset).
    pub positions_m: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Vertex colours: the displacement magnitude on the shared colour range.
    pub colours: Vec<[u8; 3]>,
    displacements_m: Vec<Vec3>,
}

impl SurfaceFrame {
    /// The frame of `sim` drawn on `surface`, coloured on `colours`.
    pub fn update(&mut self, surface: &Surface, sim: &Simulation, colours: &ColourRange) {
        let mesh = sim.mesh();
        surface.vertices.eval_into(&sim.positions, &mut self.positions_m);
        surface.vertices.displacements_into(&sim.positions, &mesh.rest_positions, &mut self.displacements_m);
        surface.vertex_normals(&self.positions_m, &mut self.normals);
        self.colours.clear();
        self.colours.extend(self.displacements_m.iter().map(|u| colours.colour(u.norm())));
    }
}

/// Single precision for drawing and logging.
pub fn f32s(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The viewport and the recording share one layout and one colour range: the spacing of the
    /// paper's beam ([0,2]×[0,0.5]×[0,0.5] m) is 0.5 + max(0.25, 0.5) = 1 m, the range 0.4 m.
    #[test]
    fn layout_and_colour_range_of_the_paper_beam() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let instance = hox_scenes::Instance::new(scene).unwrap();
        let mesh = instance.sim.mesh();
        assert_eq!(side_by_side_offsets(mesh, 2), [Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0)]);
        assert_eq!(colour_range(Some(mesh), 0.0).max_m, 0.4);
        assert_eq!(colour_range(Some(mesh), 0.1).max_m, 0.1);
        assert_eq!(colour_range(None, 0.0).max_m, 0.2);
    }

    /// A body at rest is drawn at its rest surface, in the colour of zero displacement; moved
    /// rigidly by `d`, every vertex moves by `d` and takes the colour of `|d|`.
    #[test]
    fn the_surface_frame_follows_the_nodes_and_colours_by_displacement() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let mut instance = hox_scenes::Instance::new(scene).unwrap();
        let surface = Surface::new(instance.sim.mesh(), 3);
        let colours = ColourRange { max_m: 0.4 };
        let mut frame = SurfaceFrame::default();
        frame.update(&surface, &instance.sim, &colours);
        let rest = frame.positions_m.clone();
        assert!(!rest.is_empty() && frame.normals.len() == rest.len() && frame.colours.len() == rest.len());
        assert!(frame.colours.iter().all(|&c| c == colours.colour(0.0)));
        assert!(frame.normals.iter().all(|n| (n.norm() - 1.0).abs() < 1e-9));
        let d = Vec3::new(0.0, 0.0, -0.2);
        for x in &mut instance.sim.positions {
            *x += d;
        }
        frame.update(&surface, &instance.sim, &colours);
        assert!(frame.positions_m.iter().zip(&rest).all(|(x, r)| (x - r - d).norm() < 1e-12));
        assert!(frame.colours.iter().all(|&c| c == colours.colour(0.2)));
    }
}
