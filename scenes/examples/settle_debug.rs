use hox_scenes::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = by_name("bending").unwrap().with_overrides(&SceneOverrides { element: Some(args[1].clone()), grid: Some([args[2].parse().unwrap(), 2, 2]), ..Default::default() }).unwrap();
    let mut inst = Instance::new(scene).unwrap();
    inst.sim.add_effect(Box::new(hox_sim::effect::Damping { rate_per_sec: 10.0 })).unwrap();
    let mut before = inst.sim.positions.clone();
    for f in 0..3000 {
        inst.sim.step_frame().unwrap();
        let (i, moved) = inst.sim.positions.iter().zip(&before).map(|(a, b)| (a - b).norm()).enumerate().fold((0, 0.0), |acc, (i, m)| if m > acc.1 { (i, m) } else { acc });
        before.copy_from_slice(&inst.sim.positions);
        if f % 300 == 0 { println!("frame {f}: max move {moved:.3e} at node {i} ({:?}), ke {:.3e}", inst.sim.mesh().rest_positions[i].as_slice(), inst.sim.kinetic_energy_j()); }
    }
}
