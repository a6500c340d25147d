use super::*;
use crate::effect::{Clamp, Damping, Gravity};
use crate::element::ElementType;
use crate::material::MaterialModel;
use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
use crate::xpbd::constraint::Formulation;
use nalgebra::DMatrix;

use crate::Vec3;
use crate::effect::Effect;
use crate::fem::geometry::precompute;
use crate::fem::mass::lumped_masses_kg;
use crate::material::Material;
use crate::mesh::Mesh;
pub(super) const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

fn cantilever(et: ElementType) -> Mesh {
    beam(et, [2, 1, 1])
}

/// The beam `[0, 1] × [0, 0.25]²` with `cells`, five tetrahedra per cell for P1–P3.
pub(super) fn beam(et: ElementType, cells: [usize; 3]) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 0.25, 0.25), cells },
        element_type: et,
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap()
}

pub(super) fn clamped_at_x0(mesh: &Mesh) -> Vec<u32> {
    mesh.nodes_where(|p| p.x.abs() < 1e-12)
}

/// Static equilibrium `∇U(x) = M g` with clamped nodes, by Newton's method
/// ([`crate::solver::statics`]): independent of XPBD.
pub(super) fn static_equilibrium(
    mesh: &Mesh,
    material: &Material,
    degree: Option<usize>,
    clamped: &[u32],
) -> Vec<Vec3> {
    let problem = crate::solver::statics::StaticProblem {
        mesh,
        material: *material,
        quadrature_degree: degree,
        acceleration_m_s2: G,
        dirichlet: vec![crate::solver::statics::clamp(clamped.to_vec())],
        tolerance: 1e-10,
        load_steps: 1,
    };
    crate::solver::statics::solve(&problem, &mut |_, _, _| {}).unwrap().positions
}

/// The circular frequencies (rad/s) of the clamped mesh's lowest and highest modes at `x`:
/// square roots of the extreme eigenvalues of `M^{-1/2} K M^{-1/2}` on the free nodes.
pub(super) fn frequency_range(mesh: &Mesh, material: &Material, clamped: &[u32], x: &[Vec3]) -> (f64, f64) {
    let geo = precompute(mesh, None).unwrap();
    let masses = lumped_masses_kg(mesh, material.density_kg_m3).unwrap();
    let n = mesh.num_nodes();
    let mut free = vec![true; n];
    clamped.iter().for_each(|&c| free[c as usize] = false);
    let dof: Vec<usize> = (0..3 * n).filter(|d| free[d / 3]).collect();
    let k = crate::solver::statics::assemble_dense(mesh, &geo, material, x);
    let s = DMatrix::from_fn(dof.len(), dof.len(), |i, j| {
        k[(dof[i], dof[j])] / (masses[dof[i] / 3] * masses[dof[j] / 3]).sqrt()
    });
    let eig = s.symmetric_eigenvalues();
    (eig.min().max(0.0).sqrt(), eig.max().sqrt())
}

/// The material and static equilibrium a formulation runs on `mesh` (`plain` when it measures
/// volumes per point, the mixed element's own otherwise), or None where the formulation refuses
/// the mesh or the material.
pub(super) fn formulated_equilibrium(
    mesh: &Mesh,
    material: &Material,
    formulation: Formulation,
    clamped: &[u32],
    plain: Vec<Vec3>,
) -> Option<(Material, Vec<Vec3>)> {
    if formulation != Formulation::Mixed {
        return Some((*material, plain));
    }
    let settings = SolverSettings { formulation, ..SolverSettings::default() };
    let mixed = settings.formulated(material, mesh).ok()?;
    Some((mixed, static_equilibrium(mesh, &mixed, None, clamped)))
}

/// Runs XPBD (one iteration per substep, as the paper) with velocity damping until it has
/// settled, and returns the largest node distance to `reference`.
fn settled_xpbd_error(
    mesh: &Mesh,
    material: &Material,
    formulation: Formulation,
    clamped: &[u32],
    dt_secs: f64,
    damping_per_sec: f64,
    settle_secs: f64,
    reference: &[Vec3],
) -> f64 {
    let settings = SolverSettings {
        substeps: 1,
        iterations: 1,
        frames_per_second: 1.0 / dt_secs,
        formulation,
        quadrature_degree: None,
        sweep: Sweep::Element,
        stability_guard: false,
        ..Default::default()
    };
    let effects: Vec<Box<dyn Effect>> = vec![
        Box::new(Gravity::new(G)),
        Box::new(Clamp { nodes: clamped.to_vec() }),
        Box::new(Damping { rate_per_sec: damping_per_sec }),
    ];
    let mut sim = Simulation::new(mesh.clone(), *material, settings, effects).unwrap();
    let steps = (settle_secs / dt_secs).ceil() as usize;
    for _ in 0..steps {
        sim.substep().unwrap();
    }
    sim.positions.iter().zip(reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max)
}

/// XPBD with either formulation has exactly the FE model's potential energy: settled, it lands
/// on the static equilibrium of the same discretisation (found here independently by Newton's
/// method). The only gap is XPBD's solver bias, which comes from evaluating constraint
/// gradients along the path of each substep and shrinks as `(h ω_max)²` — the test shows both:
/// the settled error is small, and halving the step divides it by about four.
#[test]
fn settled_xpbd_converges_to_the_static_equilibrium_for_every_element_type_and_formulation() {
    let cases = ElementType::all().flat_map(|et| {
        MaterialModel::ALL.iter().map(move |&model| (et, Material::new(model, 1.0e5, 0.3, 1000.0).unwrap()))
    });
    for (et, material) in cases {
        let mesh = one_cell_cantilever(et);
        let clamped = clamped_at_x0(&mesh);
        let reference = static_equilibrium(&mesh, &material, None, &clamped);
        let u_max = reference.iter().zip(&mesh.rest_positions).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
        assert!(u_max > 1e-3, "{et}: the load must bend the beam, got {u_max}");
        let (omega_min, omega_max) = frequency_range(&mesh, &material, &clamped, &reference);
        let damping = omega_min;
        let settle_secs = 40.0 / omega_min;
        for formulation in Formulation::ALL {
            // the mixed formulation's own equilibrium (where it runs: high order; stvk, nh)
            let Some((material, reference)) =
                formulated_equilibrium(&mesh, &material, formulation, &clamped, reference.clone())
            else {
                continue;
            };
            let (material, reference) = (&material, &reference);
            let h = 0.1 / omega_max;
            let coarse =
                settled_xpbd_error(&mesh, material, formulation, &clamped, h, damping, settle_secs, reference) / u_max;
            let fine =
                settled_xpbd_error(&mesh, material, formulation, &clamped, h / 2.0, damping, settle_secs, reference)
                    / u_max;
            eprintln!(
                "{et} {:?} {formulation}: ω {omega_min:.1}..{omega_max:.1} rad/s, error {coarse:.2e} at h = {h:.2e} s, {fine:.2e} at h/2",
                material.model
            );
            assert!(
                fine < 0.01,
                "{et} {:?} {formulation}: settled XPBD is {:.2}% off the static equilibrium",
                material.model,
                100.0 * fine
            );
            assert!(
                fine < coarse / 2.5,
                "{et} {:?} {formulation}: the gap does not shrink with the step: {coarse:.2e} → {fine:.2e}",
                material.model
            );
        }
    }
}

pub(super) fn one_cell_cantilever(et: ElementType) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(0.5, 0.25, 0.25), cells: [1, 1, 1] },
        element_type: et,
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap()
}

#[test]
fn a_free_body_without_effects_stays_exactly_at_rest_and_runs_no_effect_work() {
    for et in ElementType::all() {
        let mesh = cantilever(et);
        let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e6, 0.35, 1000.0).unwrap();
        let mut sim = Simulation::new(mesh.clone(), material, SolverSettings::default(), Vec::new()).unwrap();
        for _ in 0..3 {
            sim.step_frame().unwrap();
        }
        assert_eq!(sim.positions, mesh.rest_positions, "{et}");
        assert_eq!(sim.counters().effect_hook_calls, 0);
        assert_eq!(sim.counters().substeps, 150);
        assert_eq!(sim.counters().element_projections, 150 * mesh.num_elements() as u64);
    }
}

#[test]
fn free_fall_follows_symplectic_euler_exactly() {
    let mesh = cantilever(ElementType::from_name("p2").unwrap());
    let material = Material::new(MaterialModel::StableNeoHookean, 1.0e6, 0.35, 1000.0).unwrap();
    let mut sim =
        Simulation::new(mesh.clone(), material, SolverSettings::default(), vec![Box::new(Gravity::new(G))]).unwrap();
    for _ in 0..60 {
        sim.step_frame().unwrap();
    }
    // x_n = x_0 + h² g n(n + 1)/2 for n substeps of v += h g; x += h v
    let n = 3000.0;
    let h = 1.0 / 3000.0;
    let want = G * (h * h * n * (n + 1.0) / 2.0);
    for (x, x0) in sim.positions.iter().zip(&mesh.rest_positions) {
        assert!((x - x0 - want).norm() < 1e-9, "{} vs {}", x - x0, want);
    }
    assert!((sim.time_secs() - 1.0).abs() < 1e-9);
}

#[test]
fn bad_settings_and_blow_ups_are_clear_errors() {
    let mesh = cantilever(ElementType::from_name("p1").unwrap());
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e6, 0.35, 1000.0).unwrap();
    let bad = SolverSettings { substeps: 0, ..SolverSettings::default() };
    let err = Simulation::new(mesh.clone(), material, bad, Vec::new()).err().unwrap().to_string();
    assert!(err.contains("Substeps must be a whole number from 1 to 1000000, got 0"), "{err}");
    let bad = SolverSettings { frames_per_second: f64::NAN, ..SolverSettings::default() };
    assert!(Simulation::new(mesh.clone(), material, bad, Vec::new()).is_err());
    let err = Simulation::new(
        mesh.clone(),
        material,
        SolverSettings::default(),
        vec![Box::new(Clamp { nodes: vec![99_999] })],
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("node 99999"), "{err}");

    let mut sim = Simulation::new(mesh, material, SolverSettings::default(), Vec::new()).unwrap();
    sim.positions[7].x = f64::NAN;
    let err = sim.step_frame().unwrap_err().to_string();
    assert!(err.contains("node 7") && err.contains("element") && err.contains("substep 1"), "{err}");
}

fn beam_sim(parallel: bool, formulation: Formulation) -> Simulation {
    let mesh = cantilever(ElementType::from_name("p2").unwrap());
    let clamped = clamped_at_x0(&mesh);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
    let settings = SolverSettings { formulation, sweep: sweep_of(parallel), ..SolverSettings::default() };
    let effects: Vec<Box<dyn Effect>> = vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped })];
    Simulation::new(mesh, material, settings, effects).unwrap()
}

/// The colour sweep for `colour`, else the element-order sweep.
fn sweep_of(colour: bool) -> Sweep {
    if colour { Sweep::Colour } else { Sweep::Element }
}

/// The parallel sweep's result does not depend on the number of threads or the scheduling:
/// bitwise identical with 1 and 2 threads, run after run.
#[test]
fn parallel_projection_is_deterministic_for_any_thread_count() {
    for formulation in Formulation::ALL {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut sim = beam_sim(true, formulation);
                for _ in 0..20 {
                    sim.step_frame().unwrap();
                }
                sim.positions
            })
        };
        let (one, two, again) = (run(1), run(2), run(2));
        assert_eq!(one, two, "{formulation}");
        assert_eq!(two, again, "{formulation}");
    }
}

/// A frame that keeps rayon's pool awake while it runs (the colour sweep by slabs on several
/// threads: `with_pool_awake`) gives the same bits as the same frames on one thread: the waiting
/// worker only takes the frame's own jobs, so nothing but who runs them changes.
#[test]
fn a_frame_with_the_pool_kept_awake_gives_the_same_bits_as_on_one_thread() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sim = beam_sim(true, Formulation::Energy);
            sim.set_partition_threshold(8);
            assert_eq!(sim.frame_shares_work(), threads > 1, "{threads} threads");
            for _ in 0..20 {
                sim.step_frame().unwrap();
            }
            sim.positions
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

/// Serial and parallel sweeps visit the elements in different orders (Gauss–Seidel), so they
/// differ slightly along the way and settle on the same static answer: for `mesh` clamped at
/// x = 0, the serial sweep against the parallel sweep on each `(threads, partition threshold)`.
fn sweeps_agree_and_settle(mesh: Mesh, parallel_runs: &[(usize, usize)]) {
    let clamped = clamped_at_x0(&mesh);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
    let reference = static_equilibrium(&mesh, &material, None, &clamped);
    let u_max = reference.iter().zip(&mesh.rest_positions).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    for formulation in Formulation::ALL {
        let Some((_, reference)) = formulated_equilibrium(&mesh, &material, formulation, &clamped, reference.clone())
        else {
            continue;
        };
        let sim = |parallel: bool| {
            let settings = SolverSettings { formulation, sweep: sweep_of(parallel), ..SolverSettings::default() };
            let effects: Vec<Box<dyn Effect>> =
                vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped.clone() })];
            Simulation::new(mesh.clone(), material, settings, effects).unwrap()
        };
        let mut runs = vec![(rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap(), sim(false))];
        for &(threads, per_thread) in parallel_runs {
            let mut parallel = sim(true);
            parallel.set_partition_threshold(per_thread);
            assert!(parallel.num_colours()[0] > 1);
            runs.push((rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap(), parallel));
        }
        // along the way: close, but not identical (different Gauss–Seidel order)
        for (pool, sim) in &mut runs {
            pool.install(|| (0..30).for_each(|_| sim.step_frame().unwrap()));
        }
        let gap = |a: &Simulation, b: &Simulation| {
            a.positions.iter().zip(&b.positions).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max)
        };
        for (_, parallel) in &runs[1..] {
            let gap = gap(&runs[0].1, parallel);
            assert!(gap > 0.0 && gap < 0.02 * u_max, "{formulation}: serial and parallel differ by {gap:.3e} m");
        }
        // settled: all on the static answer, up to XPBD's solver bias at these settings
        for (pool, sim) in &mut runs {
            sim.add_effect(Box::new(Damping { rate_per_sec: 20.0 })).unwrap();
            pool.install(|| (0..600).for_each(|_| sim.step_frame().unwrap()));
        }
        for (_, parallel) in &runs[1..] {
            let settled_gap = gap(&runs[0].1, parallel);
            let to_static = parallel.positions.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            assert!(settled_gap < 1e-3 * u_max, "{formulation}: settled states differ by {settled_gap:.3e} m");
            assert!(
                to_static < 0.02 * u_max,
                "{formulation}: parallel settles {to_static:.3e} m from the static answer"
            );
        }
    }
}

#[test]
fn serial_and_parallel_sweeps_agree_and_settle_on_the_same_static_answer() {
    // P2: colour by colour on one and two threads, and cut into two slabs
    sweeps_agree_and_settle(
        cantilever(ElementType::from_name("p2").unwrap()),
        &[(1, usize::MAX), (2, usize::MAX), (2, 0)],
    );
}

/// A P1 beam large enough for slabs with an interior: the colour sweep (four tetrahedra per
/// register) and the two-slab sweep against the serial one.
#[test]
fn serial_colour_and_slab_sweeps_agree_and_settle_on_a_p1_beam() {
    sweeps_agree_and_settle(beam(ElementType::from_name("p1").unwrap(), [8, 2, 2]), &[(1, usize::MAX), (2, 0)]);
}

/// 1,280 linear tetrahedra (16 × 4 × 4 cells) under gravity, clamped at x = 0, colour sweep.
fn sagging_p1_beam() -> Simulation {
    let mesh = beam(ElementType::from_name("p1").unwrap(), [16, 4, 4]);
    let clamped = clamped_at_x0(&mesh);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 3.0e6, 0.35, 1000.0).unwrap();
    let settings = SolverSettings { sweep: Sweep::Colour, ..SolverSettings::default() };
    let effects: Vec<Box<dyn Effect>> = vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped })];
    Simulation::new(mesh, material, settings, effects).unwrap()
}

/// The slab sweep uses its slabs (two phases whose slabs share no node), and gives the same bits
/// on one thread and on two: the slab count is the block's, not the pool's.
#[test]
fn slab_sweep_is_bitwise_the_same_on_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sim = sagging_p1_beam();
            sim.set_partition_threshold(0);
            for _ in 0..3 {
                sim.step_frame().unwrap();
            }
            let part = sim.xpbd_solver().unwrap().partitions[0].1.as_ref().expect("a partition");
            assert_eq!(part.slabs.len(), crate::xpbd::kernels::MIN_SLABS);
            let counts: Vec<usize> = part.slabs.iter().map(|s| s.len()).collect();
            assert_eq!(counts.iter().sum::<usize>(), sim.mesh().num_elements());
            assert!(counts.iter().all(|&c| c > sim.mesh().num_elements() / 6), "{counts:?}");
            // the slabs of one phase share no node
            for phase in 0..2 {
                let mut owner = vec![usize::MAX; sim.mesh().num_nodes()];
                for (s, slab) in part.slabs.iter().enumerate().filter(|(s, _)| s % 2 == phase) {
                    for &n in &slab.nodes {
                        assert!(owner[n as usize] == usize::MAX || owner[n as usize] == s, "node {n} in two slabs");
                        owner[n as usize] = s;
                    }
                }
            }
            sim.positions
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(2));
}

/// A block too thin for the slab count its size asks for is cut into fewer slabs, not left whole:
/// 16 cells along the beam cannot hold 16 slabs (one cell each, so two slabs of a phase would
/// share the nodes of the odd slab between them) but hold 8.
#[test]
fn a_block_too_thin_for_its_slab_count_is_cut_into_fewer_slabs() {
    use crate::xpbd::kernels::Partition;
    let sim = sagging_p1_beam();
    let (block, geometry) = (&sim.mesh().blocks[0], &sim.geometry()[0]);
    let colours = &sim.xpbd_solver().unwrap().colours[0];
    let rest = &sim.mesh().rest_positions;
    assert!(Partition::new(block, geometry, colours, rest, 32, 4).is_none());
    let cut = Partition::largest(block, geometry, colours, rest, 32, 4).expect("a partition");
    assert!(cut.slabs.len() >= crate::xpbd::kernels::MIN_SLABS && cut.slabs.len() < 32, "{}", cut.slabs.len());
    assert!(Partition::new(block, geometry, colours, rest, cut.slabs.len() * 2, 4).is_none());
    assert_eq!(cut.slabs.iter().map(|s| s.len()).sum::<usize>(), sim.mesh().num_elements());
}

/// The slab count is the block's alone: none below two slabs' worth, then two, more only for
/// blocks large enough (powers of two up to the cap).
#[test]
fn the_slab_count_depends_on_the_block_size_alone() {
    use crate::xpbd::kernels::{ELEMENTS_PER_EXTRA_SLAB, MAX_SLABS, MIN_SLABS, p1_equivalents, slab_count};
    assert_eq!(slab_count(1_280, 1024), 1);
    assert_eq!(slab_count(4_095, 1024), 1);
    assert_eq!(slab_count(4_096, 1024), MIN_SLABS);
    assert_eq!(slab_count(10_240, 1024), 4);
    assert_eq!(slab_count(81_920, 1024), 16);
    assert_eq!(slab_count(8 * ELEMENTS_PER_EXTRA_SLAB, 1024), 8);
    assert_eq!(slab_count(15 * ELEMENTS_PER_EXTRA_SLAB, 1024), 8);
    assert_eq!(slab_count(usize::MAX / 2, 1024), MAX_SLABS);
    assert_eq!(slab_count(usize::MAX / 2, usize::MAX), 1);
    // sizes in linear tetrahedra of equal work: a Q2 hexahedron at 27 points does
    // 27 (36·27 + 174) + 16·27 + 10 = 31,384 flops against P1's 392, so 100 of them weigh 8,006
    assert_eq!(p1_equivalents(1, 4, 1), 1);
    assert_eq!(p1_equivalents(100, 27, 27), 8_006);
}

/// On a mesh with enough nodes for the substep's node loops to run on every thread
/// ([`NODE_LOOP_MIN_NODES_PER_THREAD`]), one thread and two give the same bits, and a node made
/// non-finite is named the same.
#[test]
fn large_meshes_step_their_nodes_on_every_thread_with_the_same_bits() {
    let mesh = beam(ElementType::from_name("p1").unwrap(), [64, 16, 16]);
    assert!(mesh.num_nodes() >= 2 * NODE_LOOP_MIN_NODES_PER_THREAD);
    let clamped = clamped_at_x0(&mesh);
    let run = |threads: usize, poison: Option<usize>| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let material = Material::new(MaterialModel::StVenantKirchhoff, 3.0e6, 0.35, 1000.0).unwrap();
            let effects: Vec<Box<dyn Effect>> =
                vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped.clone() })];
            let mut sim = Simulation::new(mesh.clone(), material, SolverSettings::default(), effects).unwrap();
            for _ in 0..3 {
                sim.substep().unwrap();
            }
            if let Some(node) = poison {
                sim.velocities[node].z = f64::INFINITY;
                return Err(sim.substep().unwrap_err().to_string());
            }
            Ok(sim.positions)
        })
    };
    let one = run(1, None).unwrap();
    assert!(one.iter().zip(&mesh.rest_positions).any(|(a, b)| a != b));
    assert_eq!(one, run(2, None).unwrap());
    let node = mesh.num_nodes() - 7;
    let (e1, e2) = (run(1, Some(node)).unwrap_err(), run(2, Some(node)).unwrap_err());
    assert_eq!(e1, e2);
    assert!(e1.contains("node") && e1.contains("substep 4"), "{e1}");
}

/// The default sweep (colour by colour, four elements per register, slabs) gives the same bits
/// on one thread and on two for every element type and material: the order it projects in is
/// fixed by the mesh, and threads only share out the work.
#[test]
fn the_default_sweep_is_bitwise_the_same_on_one_and_two_threads_for_every_element_and_material() {
    assert_eq!(SolverSettings::default().sweep, Sweep::Colour);
    for name in ["p1", "p2", "p3", "q1", "q2", "prism", "pyramid"] {
        let mesh = beam(ElementType::from_name(name).unwrap(), [8, 2, 2]);
        let clamped = clamped_at_x0(&mesh);
        for &model in MaterialModel::ALL.iter() {
            let run = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| {
                    let material = Material::new(model, 1.0e5, 0.3, 1000.0).unwrap();
                    let settings = SolverSettings { substeps: 10, ..SolverSettings::default() };
                    let effects: Vec<Box<dyn Effect>> =
                        vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped.clone() })];
                    let mut sim = Simulation::new(mesh.clone(), material, settings, effects).unwrap();
                    // slabs on this small beam too, so that they are part of what is compared
                    sim.set_partition_threshold(8);
                    for _ in 0..3 {
                        sim.step_frame().unwrap();
                    }
                    sim.positions
                })
            };
            let one = run(1);
            assert!(one.iter().zip(&mesh.rest_positions).any(|(a, b)| a != b), "{name} {model:?}: nothing moved");
            assert_eq!(one, run(2), "{name} {model:?}");
        }
    }
}

/// The colour sweep with four (AVX2) and eight (AVX-512, where the CPU has it) linear
/// tetrahedra per register sags a beam as the one-at-a-time colour sweep does, up to round-off,
/// over several substeps; the default width is the widest the CPU has, and a width the CPU
/// cannot run is refused without changing anything.
#[test]
fn p1_simd_batches_follow_the_scalar_colour_sweep_on_a_sagging_beam() {
    let mut scalar = sagging_p1_beam();
    scalar.set_simd_batches(false);
    assert_eq!(scalar.simd_lanes().len(), 1, "one block, one width");
    assert!(!scalar.set_simd_lanes(3), "no three-lane register");
    for _ in 0..10 {
        scalar.substep().unwrap();
    }
    let scale = scalar.displacements().iter().map(|d| d.norm()).fold(0.0, f64::max);
    let mut widths = Vec::new();
    for lanes in [4, 8] {
        let mut batched = sagging_p1_beam();
        if !batched.set_simd_lanes(lanes) {
            assert!(!crate::xpbd::kernels::lanes_available(lanes));
            eprintln!("{lanes} lanes: not on this CPU");
            continue;
        }
        assert_eq!(batched.simd_lanes(), vec![lanes]);
        for _ in 0..10 {
            batched.substep().unwrap();
        }
        assert_eq!(scalar.counters(), batched.counters(), "{lanes} lanes");
        let gap = scalar.positions.iter().zip(&batched.positions).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
        assert!(scale > 1e-6 && gap <= 1e-12 * scale, "{lanes} lanes: {gap:e} against {scale:e}");
        widths.push(batched.positions.clone());
    }
    // each lane runs the same operations in the same order at either width, and every element
    // is batched at either: eight lanes give four lanes' bits
    if let [four, eight] = &widths[..] {
        assert_eq!(four, eight, "four and eight lanes, bit for bit");
    }
}

/// The stability guard follows every change that moves ω_max: E and ρ rescale it, ν and a
/// node's mass recompute it, the settings decide whether it applies; and the substep it takes
/// is the one the solver steps with.
#[test]
fn the_stability_guard_follows_material_mass_and_settings_changes() {
    let mesh = cantilever(ElementType::from_name("p1").unwrap());
    let soft = Material::new(MaterialModel::StableNeoHookean, 1.0e5, 0.3, 1000.0).unwrap();
    let settings = SolverSettings { substeps: 1, ..SolverSettings::default() };
    let mut sim = Simulation::new(mesh, soft, settings, Vec::new()).unwrap();
    let r = sim.stability();
    assert!(!r.raised() && r.requested_h_omega < crate::solver::stability::GUARD_TRIGGER_H_OMEGA, "{}", r.summary());
    assert_eq!(sim.substeps_per_frame(), 1);
    // 10⁴ × stiffer: ω × 100, above the trigger
    sim.set_material(Material::new(MaterialModel::StableNeoHookean, 1.0e9, 0.3, 1000.0).unwrap()).unwrap();
    let stiff = sim.stability();
    assert!((stiff.omega_max_rad_s / r.omega_max_rad_s - 100.0).abs() < 1e-9 * 100.0);
    assert!(stiff.raised() && sim.substeps_per_frame() == stiff.substeps);
    assert!(sim.substep_dt_secs() * stiff.omega_max_rad_s <= crate::solver::stability::GUARD_H_OMEGA * (1.0 + 1e-12));
    // a denser material lowers it again (ω ∝ √(E/ρ)), exactly as a recomputation would
    sim.set_material(Material::new(MaterialModel::StableNeoHookean, 1.0e9, 0.3, 1.0e7).unwrap()).unwrap();
    let dense = sim.stability().omega_max_rad_s;
    assert!((dense / r.omega_max_rad_s - 1.0).abs() < 1e-9, "{dense} vs {}", r.omega_max_rad_s);
    // a light node raises it (recomputed)
    sim.set_mass_kg(0, sim.masses_kg()[0] * 1e-4).unwrap();
    assert!(sim.stability().omega_max_rad_s > 10.0 * dense);
    // switched off: the substeps asked for, even where they are unstable
    sim.set_material(Material::new(MaterialModel::StableNeoHookean, 1.0e9, 0.3, 1000.0).unwrap()).unwrap();
    assert!(sim.substeps_per_frame() > 1);
    sim.set_settings(SolverSettings { stability_guard: false, ..settings }).unwrap();
    assert_eq!(sim.substeps_per_frame(), 1);
    sim.step_frame().unwrap();
    assert_eq!(sim.counters().substeps, 1);
}

/// What adding an element type brings, without registering one: a quartic tetrahedron (35
/// nodes — more than the kernels' stack scratch, no specialised sweep — with order-4 faces) is
/// meshed from the registered P1 box, steps with both sweeps and both formulations (the generic
/// kernels) and sags under gravity, and its display surface and VTK cells are built.
#[test]
fn an_unregistered_p4_meshes_steps_with_the_generic_kernels_and_builds_its_surface_and_vtk_cells() {
    let p4 = crate::element::tests::unregistered_p4();
    let mesh = beam(p4, [2, 1, 1]);
    assert_eq!((mesh.blocks[0].element_type, mesh.num_elements()), (p4, 10));
    let volume = crate::fem::geometry::total_volume_m3(&precompute(&mesh, None).unwrap());
    assert!((volume - 0.0625).abs() < 1e-12, "{volume}");
    let clamped = clamped_at_x0(&mesh);
    let tip = mesh.nodes_where(|p| (p.x - 1.0).abs() < 1e-12);
    let material = Material::new(MaterialModel::StVenantKirchhoff, 1.0e6, 0.3, 1000.0).unwrap();
    for formulation in Formulation::ALL {
        for parallel in [false, true] {
            let settings =
                SolverSettings { substeps: 10, formulation, sweep: sweep_of(parallel), ..SolverSettings::default() };
            let effects: Vec<Box<dyn Effect>> =
                vec![Box::new(Gravity::new(G)), Box::new(Clamp { nodes: clamped.clone() })];
            let mut sim = Simulation::new(mesh.clone(), material, settings, effects).unwrap();
            for _ in 0..3 {
                sim.step_frame().unwrap();
            }
            assert!(sim.positions.iter().all(|p| p.iter().all(|c| c.is_finite())), "{formulation} {parallel}");
            let sag = tip.iter().map(|&n| sim.positions[n as usize].z - mesh.rest_positions[n as usize].z).sum::<f64>()
                / tip.len() as f64;
            assert!(sag < -1e-4, "{formulation} parallel {parallel}: the tip moved {sag} m");
            assert!(sim.counters().element_projections > 0);
        }
    }
    let surface = crate::measure::surface::Surface::new(&mesh, 2);
    assert!(!surface.triangles.is_empty() && !surface.vertices.is_empty());
    let vtu = crate::io::vtk::vtu_string(&mesh, &mesh.rest_positions, &[], &[]).unwrap();
    let cells = crate::io::vtk::parse_vtu(&vtu).unwrap().cells;
    assert_eq!(cells.len(), 10);
    assert!(cells.iter().all(|(ty, nodes)| *ty == 71 && nodes.len() == 35));
}

/// Every numeric setting is checked against its one declaration ([`SolverSettings::RANGES`]):
/// the value just past each end is refused with the declaration's label and range, the ends
/// themselves (where inclusive) are accepted.
#[test]
fn every_solver_setting_is_checked_against_its_declared_range() {
    fn set(s: &mut SolverSettings, key: &str, v: RangeValue) {
        let (whole, x) = match v {
            RangeValue::Whole(n) => (n, n as f64),
            RangeValue::Number(x) => (x as u64, x),
        };
        let w = || u32::try_from(whole).unwrap_or(u32::MAX);
        match key {
            "substeps" => s.substeps = w(),
            "iterations" => s.iterations = w(),
            "fps" => s.frames_per_second = x,
            "steps" => s.steps_per_frame = w(),
            "vbd-iterations" => s.vbd.iterations = w(),
            "vbd-coarse-cells" => s.vbd.coarse_cells = w(),
            "chebyshev-rho" => s.vbd.chebyshev_rho = x,
            "newton-tolerance" => s.newton.tolerance = x,
            "newton-iterations" => s.newton.max_iterations = w(),
            other => panic!("{other}: a declared setting this test does not know"),
        }
    }
    for (i, setting) in SolverSettings::RANGES.iter().enumerate() {
        let (inside, outside) = match setting.range {
            Range::Whole { min, max, .. } => {
                let mut outside = vec![RangeValue::Whole(max + 1)];
                if min > 0 {
                    outside.push(RangeValue::Whole(min - 1));
                }
                (vec![RangeValue::Whole(min), RangeValue::Whole(max)], outside)
            }
            Range::Number { min, min_inclusive, max, max_inclusive, .. } => {
                let mut inside = vec![RangeValue::Number(if min_inclusive { min } else { min + 1e-9 })];
                if max.is_finite() {
                    inside.push(RangeValue::Number(if max_inclusive { max } else { max - 1e-9 }));
                }
                let below = if min_inclusive { min - 1e-9 } else { min };
                (inside, vec![RangeValue::Number(below), RangeValue::Number(f64::NAN)])
            }
        };
        for v in inside {
            let mut s = SolverSettings::default();
            set(&mut s, setting.key, v);
            assert_eq!(s.range_values()[i], v, "{}", setting.key);
            assert!(s.validate().is_ok(), "{} = {v:?}: {:?}", setting.key, s.validate());
        }
        for v in outside {
            let mut s = SolverSettings::default();
            set(&mut s, setting.key, v);
            let err = s.validate().unwrap_err().to_string();
            let want = format!("{} must be {}, got", setting.label, setting.range.expected());
            assert!(err.contains(&want), "{} = {v:?}: {err}", setting.key);
        }
    }
}
