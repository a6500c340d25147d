//! The current view exported as the paper's figure (issue #39): the configurations on screen —
//! A, and B in compare mode — as they are now, sampled inside their elements and drawn in
//! `hox paper`'s style (`hox_scenes::paper::draw_figure`) against the reference the screen
//! measures them by (issue #57: the figure once drew its own coarse Q2 solution and said
//! 16.33 % where the screen said 17.19 %). A reference that holds only its probes (a committed
//! one) gets its displacement field first, solved in the background like the error field's
//! ([`PendingFigure`]); only where the app has no reference at all is the static solution on
//! the figure's coarse Q2 grid solved on the spot (under a second) and named so.

use super::model::Model;
use super::readout::ReferenceState;
use super::session::Session;
use hox_scenes::paper::{FigureKind, Panel, draw_figure, panel_of, reference_panel, sample};
use hox_scenes::reference::{Reference, ReferenceField};
use hox_sim::Vec3;
use std::path::{Path, PathBuf};

/// A figure export waiting for its reference's displacement field.
pub struct PendingFigure {
    folder: PathBuf,
    reference: ReferenceState,
}

/// What *Export figure* did: wrote the files, or waits for the reference's field.
pub enum Export {
    Written(Vec<PathBuf>),
    Pending(PendingFigure),
}

/// Starts the export of the configurations on screen to `folder`: at once when the screen's
/// reference has its field (or there is none), else once the field is solved.
pub fn start_export(model: &Model, folder: &Path) -> Result<Export, String> {
    figure_kind(model)?;
    let first = model.active_session();
    match first.reference.reference() {
        Some(r) if r.field.is_none() && first.instance.scene.is_box() => {
            let reference = ReferenceState::for_scene(&first.instance.scene, true);
            let mut pending = PendingFigure { folder: folder.to_path_buf(), reference };
            match pending.poll(model) {
                Some(done) => done.map(Export::Written),
                None => Ok(Export::Pending(pending)),
            }
        }
        r => export_figure(model, folder, r).map(Export::Written),
    }
}

impl PendingFigure {
    /// The files written once the field has come (or the message why not); None while waiting.
    pub fn poll(&mut self, model: &Model) -> Option<Result<Vec<PathBuf>, String>> {
        self.reference.poll();
        match &self.reference {
            ReferenceState::Ready { reference, .. } => Some(export_figure(model, &self.folder, Some(reference))),
            ReferenceState::Failed { message, .. } => Some(Err(format!("figure: the reference's field: {message}"))),
            ReferenceState::Unavailable(why) => Some(Err(format!("figure: no reference: {why}"))),
            ReferenceState::Computing { .. } => None,
        }
    }

    /// What it waits for, for the status line: "figure: computing reference field … (40 %)".
    pub fn status(&self) -> String {
        format!("figure waits for its reference: {}", self.reference.short_status().unwrap_or_default())
    }
}

fn figure_kind(model: &Model) -> Result<FigureKind, String> {
    let name = model.active_session().base.name().to_string();
    FigureKind::of_scene(&name).ok_or_else(|| {
        format!("the figure export draws the paper's scenes (tension, torsion, bending); this is {name}")
    })
}

/// Writes the figure of the configurations on screen to `folder` (`fig2-torsion.svg` and `.png`,
/// …) against `reference` and returns the files written; the message says what went wrong (not
/// a paper scene, an unwritable folder).
fn export_figure(model: &Model, folder: &Path, reference: Option<&Reference>) -> Result<Vec<PathBuf>, String> {
    let first = model.active_session();
    let kind = figure_kind(model)?;
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
    panels.push(reference_of(first, reference, kind, &points)?);
    let figure = draw_figure(kind, panels, &points, nu, nv);
    write_figure(&figure, &svg_path, &png_path)
}

/// The figure as SVG and PNG files.
#[cfg(not(target_arch = "wasm32"))]
fn write_figure(figure: &hox_scenes::paper::Figure, svg_path: &Path, png_path: &Path) -> Result<Vec<PathBuf>, String> {
    let png = crate::output::svg_to_png(&figure.svg).map_err(|e| format!("{e:#}"))?;
    std::fs::write(svg_path, &figure.svg).map_err(|e| format!("cannot write {}: {e}", svg_path.display()))?;
    std::fs::write(png_path, png).map_err(|e| format!("cannot write {}: {e}", png_path.display()))?;
    Ok(vec![svg_path.to_path_buf(), png_path.to_path_buf()])
}

/// In a page: no folder to write to.
#[cfg(target_arch = "wasm32")]
fn write_figure(figure: &hox_scenes::paper::Figure, _svg: &Path, _png: &Path) -> Result<Vec<PathBuf>, String> {
    Err(format!("{} figure drawn; saving it needs the desktop app (a page has no folder to write to)", figure.name))
}

/// The reference panel: `reference`'s field when it has one, else solved.
fn reference_of(
    s: &Session,
    reference: Option<&Reference>,
    kind: FigureKind,
    points: &[Vec3],
) -> Result<Panel, String> {
    let field = reference.and_then(|r| r.field.as_ref());
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
            // the screen's name of it, to the mesh ("static (committed), Q2 24×12×12")
            label: format!("reference: {}", reference.map(short_label).unwrap_or_default()),
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

/// The reference's label ([`Reference::label`]) up to its mesh: what fits under a panel.
pub fn short_label(reference: &Reference) -> String {
    let label = reference.label();
    label.split(", ν =").next().unwrap_or(&label).to_string()
}
