//! The paper's figure section as a recording entity (issue #39): in the paper's scenes, the rest
//! points `hox paper` samples — the tension's mid-plane, the torsion's mid-length section, the
//! bending's top face (`hox_scenes::paper::FigureKind::samples`) — carried every frame by their
//! elements' shape functions (inside curved elements, not their nodes only), as
//! `world/<config>/section` (a `Mesh3D` coloured by `|u|`, viridis up to the largest seen so far)
//! and `world/<config>/section/outline` (its boundary, `LineStrips3D`).

use crate::display::f32s;
use hox_scenes::Instance;
use hox_scenes::paper::{FigureKind, ring};
use hox_scenes::present::colour::viridis;
use hox_sim::Vec3;
use hox_sim::measure::probe::Probe;
use rerun::RecordingStream;

/// The sample grid of one configuration, located once.
pub struct Section {
    probes: Vec<Probe>,
    rest: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    ring: Vec<usize>,
    /// The largest `|u|` on the section so far, metres (the colour scale's top).
    u_max: f64,
}

impl Section {
    /// The section of `instance` when its scene is one of the paper's and every sample point
    /// lies in the mesh; None otherwise.
    pub fn of(instance: &Instance) -> Option<Section> {
        let kind = FigureKind::of_scene(instance.scene.name())?;
        let params = instance.scene.params();
        let (lo, hi) = (Vec3::from(params.box_min_m), Vec3::from(params.box_max_m));
        let (rest, nu, nv) = kind.samples(lo, hi, true);
        let mesh = instance.sim.mesh();
        let probes = rest.iter().map(|&x| Probe::locate(mesh, "section", x).ok()).collect::<Option<Vec<_>>>()?;
        let mut triangles = Vec::with_capacity(2 * (nu - 1) * (nv - 1));
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                let [a, b, c, d] =
                    [j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i].map(|k| k as u32);
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        Some(Section { probes, rest, triangles, ring: ring(nu, nv), u_max: 0.0 })
    }

    /// Logs the section's current state under `root` (`world/<config>`).
    pub fn log(
        &mut self,
        rec: &RecordingStream,
        logged: &mut super::retire::Logged,
        root: &str,
        instance: &Instance,
    ) -> Result<(), rerun::RecordingStreamError> {
        let deformed: Vec<Vec3> = self.probes.iter().map(|p| p.position(&instance.sim.positions)).collect();
        let u: Vec<f64> = deformed.iter().zip(&self.rest).map(|(x, r)| (x - r).norm()).collect();
        self.u_max = u.iter().copied().fold(self.u_max, f64::max);
        let top = self.u_max.max(f64::MIN_POSITIVE);
        let colours: Vec<rerun::Color> = u
            .iter()
            .map(|v| {
                let [r, g, b] = viridis(v / top);
                rerun::Color::from_rgb(r, g, b)
            })
            .collect();
        let positions: Vec<[f32; 3]> = deformed.iter().map(f32s).collect();
        logged.at(
            rec,
            format!("{root}/section"),
            &rerun::Mesh3D::new(positions.clone())
                .with_triangle_indices(self.triangles.iter().map(|t| rerun::TriangleIndices::from(*t)))
                .with_vertex_colors(colours),
        )?;
        let mut outline: Vec<[f32; 3]> = self.ring.iter().map(|&k| positions[k]).collect();
        outline.extend(outline.first().copied());
        logged.at(
            rec,
            format!("{root}/section/outline"),
            &rerun::LineStrips3D::new([outline])
                .with_colors([rerun::Color::from_rgb(10, 10, 10)])
                .with_radii([rerun::Radius::new_ui_points(1.5)]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The torsion scene's section is the mid-length cross-section, located in its elements and
    /// carried by them: turned with the beam, and logged; a part that is not one of the paper's
    /// scenes has none.
    #[test]
    fn the_torsion_section_turns_with_the_beam_and_other_scenes_have_none() {
        let scene = hox_scenes::by_name("torsion").unwrap();
        let mut instance = Instance::new(scene).unwrap();
        let mut section = Section::of(&instance).expect("torsion is a paper scene");
        assert!(section.rest.iter().all(|p| (p.x - 0.5).abs() < 1e-12), "the section x = 0.5 m");
        assert_eq!(section.triangles.len(), 2 * 8 * 8);
        for _ in 0..30 {
            instance.sim.step_frame().unwrap();
        }
        let corner = section.ring[0];
        let moved = section.probes[corner].position(&instance.sim.positions) - section.rest[corner];
        assert!(moved.norm() > 0.01, "the section's corner turned: {moved}");
        let rec = rerun::RecordingStreamBuilder::new("hox-section-test").buffered().unwrap();
        section.log(&rec, &mut super::super::retire::Logged::default(), "world/test", &instance).unwrap();
        assert!(section.u_max >= moved.norm());
        let tube = Instance::new(hox_scenes::by_name("tube").unwrap()).unwrap();
        assert!(Section::of(&tube).is_none());
    }
}
