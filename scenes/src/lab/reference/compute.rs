//! Solving a reference: six static levels of the scene's box (Q2, or P2 with one pressure per
//! element near incompressibility: [`Levels`]), coarse to fine, with a
//! provisional estimate as soon as three are solved (issue #35: a class that changes ν gets a
//! number with its error bar within seconds, refined in the background), and the static
//! solution of a mesh file's own mesh.
//!
//! **Levels** ([`grids`]): a quarter, three eighths, a half, five eighths, three quarters and
//! all of the finest grid's cells per direction ([`super::levels`]; bending: 8×2×2, 12×3×3,
//! 16×4×4, 20×5×5, 24×6×6, 32×8×8). The eighths only serve the provisional estimates: three
//! levels give one within seconds, four a tight one soon after. P2 mixed levels keep the even
//! grids only ([`Levels::grids`]; bending: 8×2×2, 16×4×4, 24×6×6, 32×8×8; at ν = 0.49 on the
//! project's 2-core machine the estimate after three comes in about 3 s, the final in about
//! 10 s). Each level is built from the physics alone ([`level_scene`]): Q2 or P2 mixed, the
//! grid, no refinement, the element's own quadrature — whatever mesh, split, refinement or
//! element the configuration uses.
//!
//! **Provisional estimates** ([`provisional`]), after every level from the third. From three
//! levels `(h₁, u₁), (h₂, u₂), (h₃, u₃)`: the observed order `p` and Richardson's limit
//! `u₃ + (u₃ − u₂) h₃ᵖ/(h₂ᵖ − h₃ᵖ)` (module docs of [`super`]); its stated uncertainty is
//! Roache's grid convergence index of the finest level, `GCI = F_s |limit − u₃|` with the
//! safety factor `F_s = 1.25` of a three-level study (Roache 1994, 1998): the whole correction
//! and a quarter more, since coarse levels may not yet be in the asymptotic range. Without
//! monotone convergence the finest level is the estimate and three times the larger of the last
//! two differences its uncertainty (Roache's `F_s = 3` where no order is observed). From four levels or more, as the final reference: the finest
//! extrapolated with the order of the last three, its uncertainty the distance to the
//! extrapolation from the levels one and three steps coarser (with their order).
//!
//! **Final** (all five): the finest level extrapolated with the order of the three finest
//! levels (½, ¾, 1), its uncertainty the distance to the extrapolation by the halving levels
//! (¼, ½, 1): two independent estimates of the limit (unchanged from issue #20).

use super::field::ReferenceField;
use super::{Origin, Probes, Reference, Refining, distance, extrapolate, levels, mesh_error, observed_order};
use crate::error::SceneError;
use crate::params::SceneOverrides;
use crate::scene::Scene;
use hox_sim::Vec3;
use hox_sim::element::ElementType;
use hox_sim::material::VolumeMeasure;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::stability::NEAR_INCOMPRESSIBLE_POISSON_RATIO;
use hox_sim::xpbd::constraint::Formulation;

/// Progress of a computation: (what is being done, overall fraction 0–1).
pub type Progress<'p> = &'p mut dyn FnMut(&str, f64);

/// Receives each provisional reference while finer levels are solved ([`compute_with`]).
pub type OnEstimate<'p> = &'p mut dyn FnMut(&Reference);

/// Static tolerance and load steps of a computed reference: a residual of 1e-9 of the load is
/// far below the mesh error (the committed ones went to 1e-10, which the twist scene's large
/// rotation cannot always reach).
pub const TOLERANCE: f64 = 1e-9;
pub const LOAD_STEPS: usize = 10;

/// Roache's safety factor of a grid convergence index from three levels.
pub const SAFETY_FACTOR: f64 = 1.25;

/// Roache's safety factor where no order of convergence can be observed.
pub const UNCONVERGED_SAFETY_FACTOR: f64 = 3.0;

/// How many levels a computed reference solves.
pub const LEVELS: usize = 6;

/// What a reference's levels are solved with: Q2, or near incompressibility (ν ≥
/// [`NEAR_INCOMPRESSIBLE_POISSON_RATIO`], `λ ≥ 9μ`) with a model the mixed formulation runs
/// (stvk, nh) P2 with one pressure per element (`--formulation mixed`), since Q2 with its full
/// rule locks there itself (issue #62). Measured on the bending beam: P2 mixed 16×4×4, 24×6×6 and
/// 32×8×8 agree within 0.04 % at ν = 0.45, 0.499 and 0.4999 (Q2's levels within 0.5 % at 0.499),
/// and in the linear regime (E = 3 GPa) P2 mixed 32×8×8 is within 0.2 % of scikit-fem's
/// Taylor–Hood limit (`scripts/taylor_hood.py`, `python/tests/test_taylor_hood.py`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Levels {
    Q2,
    P2Mixed,
}

impl Levels {
    /// The levels a scene's reference is solved with.
    pub fn of(scene: &Scene) -> Levels {
        let mixed_runs = scene.material().with_volume_measure(VolumeMeasure::Element).is_ok();
        if scene.params().poisson_ratio >= NEAR_INCOMPRESSIBLE_POISSON_RATIO && mixed_runs {
            Levels::P2Mixed
        } else {
            Levels::Q2
        }
    }

    /// The grids of this kind's levels on a box ([`grids`]), coarse to fine. P2 mixed keeps only
    /// the grids with an even count of cells in every direction (bending: 8×2×2, 16×4×4, 24×6×6,
    /// 32×8×8) when at least three have: the five-tetrahedron split of an odd count is not
    /// mirror-symmetric, and it showed (bending at ν = 0.49: 20×5×5's tip moved 3e-5 m sideways
    /// and 5e-5 m off the even levels' trend; the estimate after it was off the final by 0.034 %
    /// for a stated 0.003 %). Q2 has no split and keeps every level.
    pub fn grids(self, box_min_m: [f64; 3], box_max_m: [f64; 3], finest_cells: usize) -> Vec<[usize; 3]> {
        let all = grids(box_min_m, box_max_m, finest_cells);
        let even: Vec<[usize; 3]> = all.iter().copied().filter(|g| g.iter().all(|n| n % 2 == 0)).collect();
        match self {
            Levels::P2Mixed if even.len() >= 3 => even,
            _ => all,
        }
    }

    /// "Q2" or "P2 mixed".
    pub fn element_name(self) -> &'static str {
        match self {
            Levels::Q2 => "Q2",
            Levels::P2Mixed => "P2 mixed",
        }
    }

    /// The name of the level on `grid`: "Q2 32×8×8", "P2 mixed 32×8×8".
    pub fn name(self, g: [usize; 3]) -> String {
        format!("{} {}×{}×{}", self.element_name(), g[0], g[1], g[2])
    }
}

/// The scene of one reference level: the physics of `scene` on a box mesh of `grid` cells of
/// its [`Levels`] (Q2, or P2 mixed on the five-tetrahedron split), with the element's own
/// quadrature and no refinement, whatever the configuration's mesh (issue #35: a refined P1
/// passed its refinement on to the Q2 levels, which refused it).
pub fn level_scene(scene: &Scene, grid: [usize; 3]) -> Result<Scene, SceneError> {
    let (element, formulation) = match Levels::of(scene) {
        Levels::Q2 => ("q2", Formulation::Energy),
        Levels::P2Mixed => ("p2", Formulation::Mixed),
    };
    let o = SceneOverrides {
        element: ElementType::from_name(element),
        grid: Some(grid),
        split: Some(TetSplit::Five),
        refine: Some(0),
        quadrature_degree: Some(None),
        formulation: Some(formulation),
        ..Default::default()
    };
    scene.with_overrides(&o)
}

/// The six grids of a computed reference on a box (module docs), coarse to fine; a level
/// that would repeat its coarser neighbour (a small box) is left out.
pub fn grids(box_min_m: [f64; 3], box_max_m: [f64; 3], finest_cells: usize) -> Vec<[usize; 3]> {
    let [quarter, half, fine] = levels(box_min_m, box_max_m, finest_cells);
    let eighths = |k: usize| fine.map(|n| ((k * n + 4) / 8).max(1));
    let mut out: Vec<[usize; 3]> = Vec::new();
    for g in [quarter, eighths(3), half, eighths(5), fine.map(|n| 3 * n / 4), fine] {
        if out.last() != Some(&g) {
            out.push(g);
        }
    }
    out
}

/// Representative cell size of a grid on the scene's box: the largest cell extent, metres.
pub(super) fn cell_size(scene: &Scene, grid: [usize; 3]) -> f64 {
    let p = scene.params();
    (0..3).map(|d| (p.box_max_m[d] - p.box_min_m[d]) / grid[d] as f64).fold(0.0, f64::max)
}

/// The provisional reference from the levels solved so far, `(cell size, probes)` coarse to
/// fine (module docs); None before three.
pub fn provisional(
    solved: &[(f64, Probes)],
    finest: [usize; 3],
    levels: usize,
    poisson_ratio: f64,
    kind: Levels,
) -> Option<Reference> {
    let grid_name = |g| kind.name(g);
    let [.., b, c, d] = solved else { return None };
    let order = |x: &(f64, Probes), y: &(f64, Probes)| observed_order(&[x.clone(), y.clone(), d.clone()]);
    let extrapolated = format!("{} extrapolated", grid_name(finest));
    // four levels or more: the order from the levels one and three steps coarser too
    let wide = solved.len().checked_sub(4).and_then(|k| order(&solved[k], b));
    let (probes, error_m, estimate, mesh) = match (order(b, c), wide) {
        // two extrapolations of the finest, as the final reference
        (Some(p_last), Some(p_wide)) => {
            let (by_last, by_wide) = (extrapolate(c, d, p_last), extrapolate(b, d, p_wide));
            let error_m = distance(&by_last, &by_wide);
            (
                by_last,
                error_m,
                format!("Richardson from the last four levels, order {p_last:.2}; {p_wide:.2} wider"),
                extrapolated,
            )
        }
        (Some(p), None) => {
            let limit = extrapolate(c, d, p);
            let error_m = SAFETY_FACTOR * distance(&limit, &d.1);
            (
                limit,
                error_m,
                format!("Richardson from the last three levels, order {p:.2}; ± GCI, F_s = {SAFETY_FACTOR}"),
                extrapolated,
            )
        }
        (None, _) => (
            d.1.clone(),
            UNCONVERGED_SAFETY_FACTOR * distance(&b.1, &c.1).max(distance(&c.1, &d.1)),
            format!(
                "{UNCONVERGED_SAFETY_FACTOR} × the larger of the last two level differences; not yet converging monotonically"
            ),
            grid_name(finest),
        ),
    };
    Some(Reference {
        origin: Origin::Computed,
        probes,
        mesh,
        estimated_error_m: Some(error_m),
        estimate,
        poisson_ratio,
        field: None,
        refining: Some(Refining { levels_done: solved.len(), levels }),
    })
}

/// Computes the reference of a box scene's physics on [`LEVELS`] Q2 levels ([`grids`] with
/// `finest_cells`), calling `on_estimate` with each provisional reference on the way.
pub fn compute_with(
    scene: &Scene,
    finest_cells: usize,
    progress: Progress<'_>,
    on_estimate: OnEstimate<'_>,
) -> Result<Reference, SceneError> {
    let p = scene.params();
    let kind = Levels::of(scene);
    let grids = kind.grids(p.box_min_m, p.box_max_m, finest_cells);
    let cells: Vec<f64> = grids.iter().map(|g| (g[0] * g[1] * g[2]) as f64).collect();
    let total: f64 = cells.iter().sum();
    let mut done = 0.0;
    let mut solved = Vec::new();
    let mut finest_field = None;
    let n = grids.len();
    for (k, grid) in grids.iter().enumerate() {
        let level = level_scene(scene, *grid)?;
        let mesh = level.build_mesh()?;
        let what = format!("computing reference, level {} of {n} (static {})", k + 1, kind.name(*grid));
        let solution = crate::instance::solve_static(&level, &mesh, TOLERANCE, LOAD_STEPS, &mut |fraction, _, _| {
            progress(&what, (done + fraction * cells[k]) / total)
        })?;
        done += cells[k];
        solved.push((cell_size(scene, *grid), probes_at(&level, &mesh, &solution.positions)?));
        if k + 1 == n {
            finest_field = ReferenceField::lattice(&mesh, &solution.positions, p.box_min_m, p.box_max_m, *grid);
        } else if let Some(r) = provisional(&solved, *grid, n, p.poisson_ratio, kind) {
            on_estimate(&r);
        }
    }
    Ok(finish(&solved, &grids, p.poisson_ratio, finest_field, kind))
}

/// The final reference from every level (module docs).
fn finish(
    solved: &[(f64, Probes)],
    grids: &[[usize; 3]],
    poisson_ratio: f64,
    field: Option<ReferenceField>,
    kind: Levels,
) -> Reference {
    let grid_name = |g| kind.name(g);
    let n = solved.len();
    let fine = grids[n - 1];
    // the halving levels: a half and a quarter as many cells per direction as the finest
    let at = |g: [usize; 3]| grids.iter().position(|x| *x == g);
    let (quarter, half) = (at(fine.map(|c| c / 4)), at(fine.map(|c| c / 2)));
    let triplet = |i: usize, j: usize, k: usize| [solved[i].clone(), solved[j].clone(), solved[k].clone()];
    let orders = match (quarter, half) {
        (Some(q), Some(h)) if n >= 3 && h + 1 < n - 1 => {
            observed_order(&triplet(q, h, n - 1)).zip(observed_order(&triplet(h, n - 2, n - 1))).map(|o| (o, h))
        }
        _ => None,
    };
    match orders {
        Some(((p_halving, p_finest), h)) => {
            let by_halving = extrapolate(&solved[h], &solved[n - 1], p_halving);
            let by_finest = extrapolate(&solved[n - 2], &solved[n - 1], p_finest);
            Reference {
                origin: Origin::Computed,
                estimated_error_m: Some(distance(&by_halving, &by_finest)),
                probes: by_finest,
                mesh: format!("{} extrapolated", grid_name(fine)),
                estimate: format!("Richardson from four levels, order {p_finest:.2}; {p_halving:.2} by halving"),
                poisson_ratio,
                field,
                refining: None,
            }
        }
        None => {
            let (error_m, estimate) = mesh_error(&solved[n.saturating_sub(3)..]);
            Reference {
                origin: Origin::Computed,
                probes: solved[n - 1].1.clone(),
                mesh: grid_name(fine),
                estimated_error_m: Some(error_m),
                estimate,
                poisson_ratio,
                field,
                refining: None,
            }
        }
    }
}

/// The displacement of every probe of `scene` at `positions` on `mesh`.
pub(super) fn probes_at(scene: &Scene, mesh: &hox_sim::mesh::Mesh, positions: &[Vec3]) -> Result<Probes, SceneError> {
    scene
        .file
        .probes
        .iter()
        .map(|q| {
            let probe = hox_sim::measure::probe::Probe::locate(mesh, &q.name, Vec3::from(q.point_m))
                .map_err(|e| SceneError::Probe { source_name: scene.source.clone(), message: e.to_string() })?;
            let u = probe.displacement(positions, &mesh.rest_positions);
            Ok((q.name.clone(), [u.x, u.y, u.z]))
        })
        .collect()
}

/// The static solution of the scene's own mesh (a mesh file's scene).
pub fn own_mesh(scene: &Scene, progress: Progress<'_>) -> Result<Reference, SceneError> {
    // a part meshed per element type: its highest order's file (P3), whichever is on screen
    let highest = highest_order(scene)?;
    let solved = highest.as_ref().unwrap_or(scene);
    let mesh = solved.build_mesh()?;
    let what = if highest.is_some() {
        format!("computing reference: static solution of the {} part", solved.params().element.name().to_uppercase())
    } else {
        "computing reference: static solution of this mesh".to_string()
    };
    let solution = crate::instance::solve_static(solved, &mesh, TOLERANCE, LOAD_STEPS, &mut |fraction, _, _| {
        progress(&what, fraction)
    })?;
    let probes = probes_at(solved, &mesh, &solution.positions)?;
    let described = format!("{} ({} elements)", solved.mesh.element_names(), mesh.num_elements());
    Ok(match highest {
        Some(h) => Reference {
            origin: Origin::HighestOrder,
            probes,
            mesh: format!("{described}, {} nodes", mesh.num_nodes()),
            estimated_error_m: None,
            estimate: format!(
                "the {} part's own mesh error is not estimated; lower orders' errors include their mesh's",
                h.params().element.name().to_uppercase()
            ),
            poisson_ratio: scene.params().poisson_ratio,
            // its nodes are not the lower orders' nodes: no field to colour their error by
            field: None,
            refining: None,
        },
        None => Reference {
            origin: Origin::OwnMesh,
            probes,
            mesh: described,
            estimated_error_m: None,
            estimate: "measures the solver's error only, not the mesh's".into(),
            poisson_ratio: scene.params().poisson_ratio,
            field: Some(ReferenceField::Nodes {
                displacements_m: solution
                    .positions
                    .iter()
                    .zip(&mesh.rest_positions)
                    .map(|(x, r)| (x - r).into())
                    .collect(),
            }),
            refining: None,
        },
    })
}

/// For a part meshed per element type (`[mesh] files`), the scene on its highest-order file
/// (the highest polynomial order; P3 of P1, P2, P3); None for any other scene.
pub fn highest_order(scene: &Scene) -> Result<Option<Scene>, SceneError> {
    if scene.mesh_kind() != crate::params::MeshKind::Files {
        return Ok(None);
    }
    let Some(element) = scene
        .file
        .mesh_files
        .keys()
        .filter_map(|n| hox_sim::element::ElementType::from_name(n))
        .max_by_key(|e| e.order())
    else {
        return Ok(None);
    };
    if element == scene.params().element {
        return Ok(Some(scene.clone()));
    }
    scene.with_overrides(&crate::params::SceneOverrides { element: Some(element), ..Default::default() }).map(Some)
}
