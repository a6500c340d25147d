//! The current view exported as the paper's figure (issue #39): the configurations on screen —
//! A, and B in compare mode — as they are now, sampled inside their elements and drawn in
//! `hox paper`'s style (`hox_scenes::paper::draw_figure`) against the reference of their physics:
//! the reference field the app already holds (the error field's), else the static solution on
//! the figure's coarse Q2 grid, solved on the spot (under a second).

use super::model::Model;
use super::session::Session;
use hox_scenes::paper::{FigureKind, Panel, draw_figure, panel_of, reference_panel, sample};
use hox_scenes::reference::ReferenceField;
use hox_sim::Vec3;
use std::path::{Path, PathBuf};

/// Writes the figure of the configurations on screen to `folder` (`fig2-torsion.svg` and `.png`,
/// …) and returns the files written; the message says what went wrong (not a paper scene, an
/// unwritable folder).
pub fn export_figure(model: &Model, folder: &Path) -> Result<Vec<PathBuf>, String> {
    let first = model.active_session();
    let name = first.base.name().to_string();
    let kind = FigureKind::of_scene(&name).ok_or_else(|| {
        format!("the figure export draws the paper's scenes (tension, torsion, bending); this is {name}")
    })?;
    std::fs::create_dir_all(folder).map_err(|e| format!("cannot create the folder {}: {e}", folder.display()))?;
    let stem = folder.join(kind.file_name());
    let (svg_path, png_path) = (stem.with_extension("svg"), stem.with_extension("png"));
    for path in [&svg_path, &png_path] {
        crate::output::check_writable(path).map_err(|e| format!("{e:#}"))?;
    }
    let params = first.instance.scene.params();
    let (lo, hi) = (Vec3::from(params.box_min_m), Vec3::from(params.box_max_m));
    let (points, nu, nv) = kind.samples(lo, hi, false);
    let shown: Vec<usize> = if model.compare() { (0..model.sessions().len()).collect() } else { vec![model.active()] };
    let mut panels: Vec<Panel> = Vec::new();
    for &k in &shown {
        let s = &model.sessions()[k];
        let label =
            if shown.len() > 1 { format!("{}: {}", ["A", "B", "C", "D"][k.min(3)], s.label()) } else { s.label() };
        let settled = s.rest.settled() || s.rest.at_rest();
        let mesh = s.instance.sim.mesh();
        panels.push(
            panel_of(label, mesh, &s.instance.sim.positions, &points, Some((s.ms_per_frame, settled)))
                .map_err(|e| e.to_string())?,
        );
    }
    panels.push(reference_of(first, kind, &points)?);
    let figure = draw_figure(kind, panels, &points, nu, nv);
    let png = crate::output::svg_to_png(&figure.svg).map_err(|e| format!("{e:#}"))?;
    std::fs::write(&svg_path, &figure.svg).map_err(|e| format!("cannot write {}: {e}", svg_path.display()))?;
    std::fs::write(&png_path, png).map_err(|e| format!("cannot write {}: {e}", png_path.display()))?;
    Ok(vec![svg_path, png_path])
}

/// The reference panel: the session's reference field when it has one, else solved.
fn reference_of(s: &Session, kind: FigureKind, points: &[Vec3]) -> Result<Panel, String> {
    let field = s.reference.reference().and_then(|r| r.field.as_ref());
    let mesh = s.instance.sim.mesh();
    let deformed: Option<Vec<Vec3>> = match field {
        Some(f @ ReferenceField::Lattice { .. }) => Some(points.iter().map(|p| p + f.lattice_at(p)).collect()),
        Some(ReferenceField::Nodes { displacements_m }) if displacements_m.len() == mesh.num_nodes() => {
            let positions: Vec<Vec3> =
                mesh.rest_positions.iter().zip(displacements_m).map(|(x, u)| x + Vec3::from(*u)).collect();
            Some(sample(mesh, &positions, points).map_err(|e| e.to_string())?)
        }
        _ => None,
    };
    match deformed {
        Some(deformed) => Ok(Panel {
            label: "reference (the app's)".into(),
            nodes: 0,
            elements: 0,
            ms_per_frame: None,
            settled: true,
            deformed,
            measure: None,
        }),
        None => reference_panel(&s.instance.scene, kind, points, true).map_err(|e| e.to_string()),
    }
}
