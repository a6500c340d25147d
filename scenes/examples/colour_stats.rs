//! Colour classes of the P1 benchmark beams (issue #37 item 4): per beam, the number of colours,
//! their sizes, and how far apart in memory the four elements of a batch reach (the node-index
//! span a batch's gathers touch); then the colour sweep timed on the beam as built (its nodes
//! numbered along x, the slab axis, since session 29) and with its nodes renumbered along z
//! (z slowest, as the generator numbered them before: docs/journal/performance.md, sessions 22 and 28),
//! on one and two threads, alternately: `cargo run --release -p hox-scenes --example colour_stats`.

use hox_sim::effect::{Clamp, Effect, Gravity};
use hox_sim::solver::Simulation;

/// The same beam with its nodes numbered by increasing z (then y, x): across the slabs the
/// colour sweep cuts along x.
fn renumbered(sim: &Simulation) -> Result<Simulation, Box<dyn std::error::Error>> {
    let mesh = sim.mesh();
    let mut order: Vec<u32> = (0..mesh.num_nodes() as u32).collect();
    let p = &mesh.rest_positions;
    order.sort_by(|&a, &b| {
        let (a, b) = (p[a as usize], p[b as usize]);
        a.z.total_cmp(&b.z).then(a.y.total_cmp(&b.y)).then(a.x.total_cmp(&b.x))
    });
    let mesh = mesh.with_nodes_in_order(&order);
    let clamped = mesh.nodes_where(|q| q.x.abs() < 1e-12);
    let effects: Vec<Box<dyn Effect>> =
        vec![Box::new(Clamp { nodes: clamped }), Box::new(Gravity::new(sim.body_acceleration_m_s2()))];
    Ok(Simulation::new(mesh, *sim.material(), *sim.settings(), effects)?)
}

fn ms_per_frame(sim: &mut Simulation, frames: usize) -> Result<f64, Box<dyn std::error::Error>> {
    let mut times = Vec::new();
    for _ in 0..frames {
        let t = std::time::Instant::now();
        sim.step_frame()?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for label in ["P1 16x4x4", "P1 16x4x4 r1", "P1 16x4x4 r2"] {
        let case = hox_scenes::bench::CASES.iter().find(|c| c.label() == label).ok_or("no such case")?;
        let sim = hox_scenes::bench::bending_beam(case, hox_sim::solver::Sweep::Element)?;
        let mesh = sim.mesh();
        let block = &mesh.blocks[0];
        let colours = hox_sim::xpbd::colouring::colour_elements(block, mesh.num_nodes());
        let sizes: Vec<usize> = colours.iter().map(Vec::len).collect();
        let partial: usize = sizes.iter().filter(|s| *s % 4 != 0).count();
        // node-index span per batch of four consecutive elements of a colour, and per element
        let (mut batch_span, mut batches) = (0f64, 0usize);
        for c in &colours {
            for b in c.chunks(4) {
                let nodes: Vec<u32> = b.iter().flat_map(|&e| block.element(e as usize).iter().copied()).collect();
                let (lo, hi) = (nodes.iter().min().unwrap(), nodes.iter().max().unwrap());
                batch_span += f64::from(hi - lo);
                batches += 1;
            }
        }
        let elem_span: f64 = (0..block.len())
            .map(|e| {
                let n = block.element(e);
                f64::from(n.iter().max().unwrap() - n.iter().min().unwrap())
            })
            .sum::<f64>()
            / block.len() as f64;
        println!(
            "{label}: {} elements, {} nodes ({} KB of positions), {} colours, sizes {:?}, {} not a multiple of 4; mean node span per batch {:.0}, per element {:.0}",
            block.len(),
            mesh.num_nodes(),
            mesh.num_nodes() * 24 / 1024,
            colours.len(),
            sizes,
            partial,
            batch_span / batches as f64,
            elem_span
        );
        let mut built = hox_scenes::bench::bending_beam(case, hox_sim::solver::Sweep::Colour)?;
        let mut along_z = renumbered(&built)?;
        let frames = if block.len() > 50_000 { 6 } else { 20 };
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
            let mut pairs = Vec::new();
            for _ in 0..3 {
                pairs.push(pool.install(|| -> Result<(f64, f64), String> {
                    let time = |sim: &mut Simulation| ms_per_frame(sim, frames).map_err(|e| e.to_string());
                    Ok((time(&mut built)?, time(&mut along_z)?))
                })?);
            }
            let ratios: Vec<String> =
                pairs.iter().map(|(a, b)| format!("{a:.2} -> {b:.2} ms ({:.2})", b / a)).collect();
            println!(
                "  colour sweep, {threads} thread(s), as built (along x) -> numbered along z: {}",
                ratios.join(", ")
            );
        }
    }
    Ok(())
}
