//! Colour classes of the P1 benchmark beams (issue #37 item 4): per beam, the number of colours,
//! their sizes, and how far apart in memory the four elements of a batch reach (the node-index
//! span a batch's gathers touch): `cargo run --release -p hox-scenes --example colour_stats`.

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
    }
    Ok(())
}
