//! Writes one benchmark beam (`hox_scenes::bench::CASES`, by label, e.g. "P1 16x4x4 r1") as
//! JSON — `positions_m`, `tets` (node indices, 4 per tetrahedron), `clamped` — for the peer
//! benchmark `bench/pbd_peer.py`: `cargo run --release -p hox-scenes --example beam_mesh -- LABEL`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let label = std::env::args().nth(1).ok_or("usage: beam_mesh LABEL (e.g. \"P1 16x4x4 r1\")")?;
    let case = hox_scenes::bench::CASES
        .iter()
        .find(|c| c.label().eq_ignore_ascii_case(&label))
        .ok_or_else(|| format!("no benchmark case labelled '{label}'"))?;
    let sim = hox_scenes::bench::bending_beam(case, hox_sim::solver::Sweep::Element)?;
    let mesh = sim.mesh();
    let positions: Vec<String> = mesh.rest_positions.iter().map(|p| format!("[{},{},{}]", p.x, p.y, p.z)).collect();
    let tets: Vec<String> = mesh.blocks[0].connectivity.iter().map(u32::to_string).collect();
    let clamped: Vec<String> = mesh.nodes_where(|p| p.x.abs() < 1e-12).iter().map(u32::to_string).collect();
    println!(
        "{{\"positions_m\":[{}],\"tets\":[{}],\"clamped\":[{}]}}",
        positions.join(","),
        tets.join(","),
        clamped.join(",")
    );
    Ok(())
}
