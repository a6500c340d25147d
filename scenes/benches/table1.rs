//! Criterion benches: ms per frame (50 substeps × 1 iteration) of the paper's Table 1 beams and
//! the Q1, Q2, prism and pyramid beams, on 1 thread (serial sweep and colour sweep, the latter
//! with linear tetrahedra four per 256-bit register) and 2 threads (parallel colour sweep); the
//! specialised energy kernel against the generic one on P1 and P2; and on P1 the colour sweep
//! one element at a time against four per register.
//!
//! `cargo bench -p hox-scenes --bench table1` (all), or with a filter: `… -- "P1 16x4x4 r2"`.

use criterion::{BatchSize, Criterion, SamplingMode, criterion_group, criterion_main};
use hox_scenes::bench::{CASES, bending_beam};
use hox_sim::Vec3;
use hox_sim::fem::energy::{element_grads, gather};
use hox_sim::solver::Sweep;
use hox_sim::xpbd::constraint::project_energy_constraint;
use hox_sim::xpbd::kernels::{Multipliers, PackedBlock, Positions, colour_sweep, energy_sweep};
use std::time::Duration;

fn frames(c: &mut Criterion) {
    for case in &CASES {
        let mut group = c.benchmark_group(format!("frame/{}", case.label()));
        group
            .sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(4));
        // (threads, colour sweep): 1 thread serial and colour (P1: four per register), 2 colour
        for (threads, colour) in [(1, false), (1, true), (2, true)] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
            let mut sim = pool.install(|| {
                let mut sim = bending_beam(case, if colour { Sweep::Colour } else { Sweep::Element }).expect("beam");
                for _ in 0..5 {
                    sim.step_frame().expect("frame");
                }
                sim
            });
            // each frame runs inside the pool (one hand-over to it per frame)
            let name = format!("{threads} thread(s), {}", if colour { "colour" } else { "serial" });
            group.bench_function(name, |b| b.iter(|| pool.install(|| sim.step_frame().expect("frame"))));
        }
        group.finish();
    }
}

/// One sweep over every element of the beam, at its sagged state: the specialised kernel of
/// `hox_sim::xpbd::kernels` against the generic `constraint::project_energy_constraint`.
fn kernels(c: &mut Criterion) {
    for case in [&CASES[0], &CASES[3]] {
        let mut sim = bending_beam(case, Sweep::Element).expect("beam");
        for _ in 0..5 {
            sim.step_frame().expect("frame");
        }
        let (mesh, g, material) = (sim.mesh().clone(), sim.geometry()[0].clone(), *sim.material());
        let block = &mesh.blocks[0];
        let n = block.nodes_per_element();
        let inv_mass = sim.inv_mass().to_vec();
        let start = sim.positions.clone();
        let inv_dt2 = (60.0f64 * 50.0).powi(2);
        let packed = PackedBlock::in_element_order(block, &g);
        let mut group = c.benchmark_group(format!("sweep/{}", case.label()));
        group.bench_function("specialised", |b| {
            b.iter_batched_ref(
                || (start.clone(), vec![0.0; block.len()]),
                |(x, lambdas)| {
                    // SAFETY: one thread, sizes from the mesh.
                    unsafe {
                        energy_sweep(
                            n,
                            &material,
                            Positions::new(x),
                            &mesh.rest_positions,
                            &inv_mass,
                            &packed.data(),
                            0..block.len(),
                            Multipliers::new(lambdas),
                            inv_dt2,
                        )
                    }
                },
                BatchSize::LargeInput,
            )
        });
        group.bench_function("generic", |b| {
            b.iter_batched_ref(
                || (start.clone(), vec![0.0; block.len()]),
                |(positions, lambdas)| {
                    let (mut x, mut rest, mut w) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n], vec![0.0; n]);
                    for (e, nodes) in block.elements().enumerate() {
                        gather(positions, nodes, &mut x);
                        gather(&mesh.rest_positions, nodes, &mut rest);
                        for (wi, &node) in w.iter_mut().zip(nodes) {
                            *wi = inv_mass[node as usize];
                        }
                        project_energy_constraint(
                            &mut x,
                            &rest,
                            &w,
                            element_grads(&g, e),
                            g.volumes(e),
                            &material,
                            inv_dt2,
                            &mut lambdas[e],
                        );
                        for (xi, &node) in x.iter().zip(nodes) {
                            positions[node as usize] = *xi;
                        }
                    }
                },
                BatchSize::LargeInput,
            )
        });
        group.finish();
    }
}

/// One colour sweep over every element of the sagged P1 beam: one element at a time against
/// a register of same-colour elements at a time (`hox_sim::xpbd::kernels::p1`).
fn colour_batches(c: &mut Criterion) {
    let mut sim = bending_beam(&CASES[0], Sweep::Colour).expect("beam");
    for _ in 0..5 {
        sim.step_frame().expect("frame");
    }
    let (mesh, g, material) = (sim.mesh().clone(), sim.geometry()[0].clone(), *sim.material());
    let block = &mesh.blocks[0];
    let colours = hox_sim::xpbd::colouring::colour_elements(block, mesh.num_nodes());
    let packed = PackedBlock::in_colour_order(block, &g, &colours);
    let inv_mass = sim.inv_mass().to_vec();
    let start = sim.positions.clone();
    let inv_dt2 = (60.0f64 * 50.0).powi(2);
    let mut group = c.benchmark_group(format!("colour sweep/{}", CASES[0].label()));
    for (name, batched) in [("one at a time", false), ("four per register", true)] {
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || (start.clone(), vec![0.0; block.len()]),
                |(x, lambdas)| {
                    for k in 0..packed.num_colours() {
                        // SAFETY: one thread, sizes from the mesh.
                        let r = unsafe {
                            colour_sweep(
                                4,
                                &material,
                                Positions::new(x),
                                &mesh.rest_positions,
                                &inv_mass,
                                &packed,
                                k,
                                packed.colour(k),
                                Multipliers::new(lambdas),
                                inv_dt2,
                                batched,
                            )
                        };
                        r.expect("P1").expect("finite");
                    }
                },
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, kernels, colour_batches, frames);
criterion_main!(benches);
