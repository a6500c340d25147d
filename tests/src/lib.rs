//! Cross-crate integration tests live in `tests/tests/`; this library holds what they share:
//! building a [`Simulation`] from a mesh, a material and settings, and the health checks of the
//! robustness suite (`tests/tests/robustness.rs`, `docs/STABILITY.md`):
//!
//! - **finiteness** of every position and velocity;
//! - **total mechanical energy** `H = T + U + V_g`, with kinetic energy `T = ½ Σ m_i |v_i|²`,
//!   elastic energy `U = Σ_e Σ_q V_q ψ(F_q)` and the potential of a uniform body acceleration `g`,
//!   `V_g = −Σ m_i g·(x_i − X_i)` (zero at rest, so a body released at rest starts at `H = 0`);
//! - the smallest **`det F`** over all quadrature points (`≤ 0`: an inverted element), from
//!   [`hox_sim::measure::min_det_f`], and over a dense set of points of every element
//!   ([`min_det_f_sampled`]): a curved high-order element can be inverted between its quadrature
//!   points, where the energy does not see it;
//! - the **distance to the rest shape**, `max_i |x_i − X_i|`, or, for an unconstrained body, the
//!   same after the best rigid alignment (Kabsch: the rotation `R` and translation `t` minimising
//!   `Σ_i |R X_i + t − x_i|²`, from the SVD of the centred cross-covariance).

pub mod docs;
pub mod rooms;

use hox_sim::Vec3;
use hox_sim::effect::{Clamp, Damping, Effect};
use hox_sim::element::ElementType;
use hox_sim::material::{Material, MaterialModel};
use hox_sim::measure::MinDetF;
use hox_sim::mesh::Mesh;
use hox_sim::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
use hox_sim::nalgebra::Matrix3;
use hox_sim::solver::{SimError, Simulation, SolverSettings};
use hox_sim::xpbd::constraint::Formulation;

/// Standard gravity, m/s².
pub const GRAVITY_M_S2: Vec3 = Vec3::new(0.0, 0.0, -9.81);

/// Every registered element type, by name, in the registry's order.
pub fn element_types() -> Vec<&'static str> {
    ElementType::all().map(|e| e.name()).collect()
}

/// An element type by name (test input: panics on a typo).
pub fn element_type(name: &str) -> ElementType {
    ElementType::from_name(name).unwrap_or_else(|| panic!("unknown element type {name}"))
}

/// A structured box `[0, size]` of `cells` hexahedral cells, of `element` (five tetrahedra per
/// cell for the tetrahedral types).
pub fn box_mesh(element: &str, size_m: [f64; 3], cells: [usize; 3]) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::from(size_m), cells },
        element_type: element_type(element),
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap_or_else(|e| panic!("{element} box: {e}"))
}

/// A validated material (test input: panics when invalid).
pub fn material(model: MaterialModel, youngs_modulus_pa: f64, poisson_ratio: f64) -> Material {
    Material::new(model, youngs_modulus_pa, poisson_ratio, 1000.0).unwrap_or_else(|e| panic!("{e}"))
}

/// Solver settings: `substeps` per frame at `frames_per_second`, one iteration, each element
/// type's default quadrature, serial sweep.
pub fn settings(formulation: Formulation, substeps: u32, frames_per_second: f64) -> SolverSettings {
    SolverSettings {
        substeps,
        iterations: 1,
        frames_per_second,
        formulation,
        quadrature_degree: None,
        sweep: hox_sim::solver::Sweep::Element,
        stability_guard: true,
        ..Default::default()
    }
}

/// Nodes whose rest coordinate `axis` equals `at_m` (within 1e-9 × the body's size).
pub fn nodes_on_plane(mesh: &Mesh, axis: usize, at_m: f64) -> Vec<u32> {
    let tol = 1e-9 * size_m(mesh);
    mesh.nodes_where(|p| (p[axis] - at_m).abs() <= tol)
}

/// A clamp of the nodes on the plane x = 0.
pub fn clamp_x0(mesh: &Mesh) -> Box<dyn Effect> {
    Box::new(Clamp { nodes: nodes_on_plane(mesh, 0, 0.0) })
}

/// The body's size: the diagonal of its rest bounding box, metres.
pub fn size_m(mesh: &Mesh) -> f64 {
    let (lo, hi) = mesh.bounding_box();
    (hi - lo).norm()
}

/// The health of a simulation state (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct Health {
    pub finite: bool,
    pub kinetic_j: f64,
    pub elastic_j: f64,
    /// `V_g = −Σ m_i g·(x_i − X_i)`.
    pub gravity_potential_j: f64,
    pub min_det_f: MinDetF,
    /// `max_i |x_i − X_i|`.
    pub max_displacement_m: f64,
}

impl Health {
    /// `H = T + U + V_g`.
    pub fn total_j(&self) -> f64 {
        self.kinetic_j + self.elastic_j + self.gravity_potential_j
    }
}

/// Measures `sim` under body acceleration `gravity_m_s2` (zero when there is none).
pub fn health(sim: &Simulation, gravity_m_s2: Vec3) -> Health {
    let finite = sim.positions.iter().chain(&sim.velocities).all(|v| v.iter().all(|c| c.is_finite()));
    let rest = &sim.mesh().rest_positions;
    let gravity_potential_j = -sim
        .masses_kg()
        .iter()
        .zip(&sim.positions)
        .zip(rest)
        .map(|((m, x), x0)| m * gravity_m_s2.dot(&(x - x0)))
        .sum::<f64>();
    let max_displacement_m = sim.positions.iter().zip(rest).map(|(x, x0)| (x - x0).norm()).fold(0.0, f64::max);
    Health {
        finite,
        kinetic_j: sim.kinetic_energy_j(),
        elastic_j: sim.elastic_energy_j(),
        gravity_potential_j,
        min_det_f: hox_sim::measure::min_det_f(sim.mesh(), sim.geometry(), &sim.positions)
            .expect("a mesh with elements"),
        max_displacement_m,
    }
}

/// What a checked run saw.
#[derive(Clone, Copy, Debug, Default)]
pub struct Trace {
    /// Largest total energy `H` over the frames, J.
    pub max_total_j: f64,
    /// Largest `|V_g|` over the frames (the scale of the work gravity did), J.
    pub max_gravity_work_j: f64,
    /// Largest elastic energy, J.
    pub max_elastic_j: f64,
    /// Smallest `det F` over the frames.
    pub min_det_f: f64,
    /// Largest node displacement over the frames, m.
    pub max_displacement_m: f64,
}

/// Why a checked run failed: the solver's NaN guard, or a check.
#[derive(Debug)]
pub enum RunFailure {
    Solver(SimError),
    Check(String),
}

impl std::fmt::Display for RunFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Solver(e) => write!(f, "solver: {e}"),
            Self::Check(m) => f.write_str(m),
        }
    }
}

impl From<RunFailure> for String {
    fn from(f: RunFailure) -> String {
        f.to_string()
    }
}

/// Runs `frames` frames, checking after each that the state is finite and that the total energy
/// stays at most `energy_bound_j`; returns what it saw.
pub fn run_checked(
    sim: &mut Simulation,
    frames: u64,
    gravity_m_s2: Vec3,
    energy_bound_j: f64,
) -> Result<Trace, RunFailure> {
    let mut trace = Trace { min_det_f: f64::INFINITY, ..Trace::default() };
    for frame in 0..frames {
        sim.step_frame().map_err(RunFailure::Solver)?;
        let h = health(sim, gravity_m_s2);
        if !h.finite {
            return Err(RunFailure::Check(format!("non-finite state after frame {}", frame + 1)));
        }
        trace.max_total_j = trace.max_total_j.max(h.total_j());
        trace.max_gravity_work_j = trace.max_gravity_work_j.max(h.gravity_potential_j.abs());
        trace.max_elastic_j = trace.max_elastic_j.max(h.elastic_j);
        trace.min_det_f = trace.min_det_f.min(h.min_det_f.det_f);
        trace.max_displacement_m = trace.max_displacement_m.max(h.max_displacement_m);
        if !(h.total_j() <= energy_bound_j) {
            return Err(RunFailure::Check(format!(
                "total energy {:.4e} J exceeds the bound {energy_bound_j:.4e} J after frame {} (T = {:.3e}, U = {:.3e}, V_g = {:.3e})",
                h.total_j(),
                frame + 1,
                h.kinetic_j,
                h.elastic_j,
                h.gravity_potential_j
            )));
        }
    }
    Ok(trace)
}

/// The loads gone: removes the effects named in `loads` (gravity, prescribed motion, contact, …),
/// adds velocity damping `rate_per_sec`, runs `frames` frames checked against `energy_bound_j`
/// (no body force any more), and returns the final health.
pub fn release(
    sim: &mut Simulation,
    loads: &[&str],
    damping_per_sec: f64,
    frames: u64,
    energy_bound_j: f64,
) -> Result<Health, RunFailure> {
    for name in loads {
        sim.remove_effects_named(name);
    }
    sim.add_effect(Box::new(Damping { rate_per_sec: damping_per_sec })).map_err(RunFailure::Solver)?;
    run_checked(sim, frames, Vec3::zeros(), energy_bound_j)?;
    Ok(health(sim, Vec3::zeros()))
}

/// `max_i |R X_i + t − x_i|` for the rigid motion `(R, t)` that best maps the rest positions `X`
/// onto `x` in the least-squares sense (Kabsch): the distance to the rest shape of a body free to
/// move, metres.
pub fn distance_to_rest_shape_m(rest: &[Vec3], x: &[Vec3]) -> f64 {
    let n = rest.len() as f64;
    let (c0, c1) = (rest.iter().sum::<Vec3>() / n, x.iter().sum::<Vec3>() / n);
    let h: Matrix3<f64> = rest.iter().zip(x).map(|(a, b)| (b - c1) * (a - c0).transpose()).sum();
    let svd = h.svd(true, true);
    let (u, v_t) = (svd.u.expect("u"), svd.v_t.expect("v_t"));
    let d = (u * v_t).determinant().signum();
    let r = u * Matrix3::from_diagonal(&Vec3::new(1.0, 1.0, d)) * v_t;
    rest.iter().zip(x).map(|(a, b)| (r * (a - c0) + c1 - b).norm()).fold(0.0, f64::max)
}

/// The smallest `det F(r) = det J(x, r) / det J(X, r)` over a dense set of reference points of
/// every element: the points `(i, j, k)/levels` of the reference tetrahedron or prism/pyramid/
/// hexahedron bounding box that lie in the element, and the element's nodes, each moved 1e-6 of
/// the way towards the centroid (the pyramid's gradients are singular at its apex). Returns
/// `(det F, block, element, r)`.
pub fn min_det_f_sampled(mesh: &Mesh, positions: &[Vec3], levels: usize) -> (f64, usize, usize, [f64; 3]) {
    let mut best = (f64::INFINITY, 0, 0, [0.0; 3]);
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let et = b.element_type;
        let shape = et.shape();
        let c = shape.centroid();
        let inward = |r: [f64; 3]| [0, 1, 2].map(|d| r[d] + 1e-6 * (c[d] - r[d]));
        let mut points: Vec<[f64; 3]> = et.reference().nodes().iter().map(|r| inward(*r)).collect();
        // the reference domains lie in [-1, 1]³
        let m = 2 * levels;
        for i in 0..=m {
            for j in 0..=m {
                for k in 0..=m {
                    let r = [i, j, k].map(|v| -1.0 + v as f64 / levels as f64);
                    if shape.contains(&r, 0.0) {
                        points.push(inward(r));
                    }
                }
            }
        }
        let mut g = vec![[0.0; 3]; et.num_nodes()];
        for (e, nodes) in b.elements().enumerate() {
            for r in &points {
                et.shape_gradients(r, &mut g);
                let j_rest = hox_sim::fem::geometry::jacobian(&mesh.rest_positions, nodes, &g).determinant();
                let j_now = hox_sim::fem::geometry::jacobian(positions, nodes, &g).determinant();
                let det = j_now / j_rest;
                let det = if det.is_finite() { det } else { f64::NEG_INFINITY };
                if det < best.0 {
                    best = (det, bi, e, *r);
                }
            }
        }
    }
    best
}
