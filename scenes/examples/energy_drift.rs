//! Prints the mechanical energy H = K + U + V_g of the undamped bending scene under a solver and
//! integrator every 250 frames: `energy_drift SOLVER INTEGRATOR FRAMES [VBD_COARSE_CELLS]`.
use hox_sim::Vec3;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let method = hox_sim::solver::Method::from_name(&a[1]).expect("solver");
    let integrator = hox_sim::solver::Integrator::from_name(&a[2]).expect("integrator");
    let frames: u64 = a[3].parse().unwrap();
    let mut o = hox_scenes::SceneOverrides { method: Some(method), integrator: Some(integrator), ..Default::default() };
    if let Some(c) = a.get(4) {
        o.vbd_coarse_cells = Some(c.parse().unwrap());
    }
    if let Some(c) = a.get(5) {
        o.chebyshev_rho = Some(c.parse().unwrap());
    }
    if let Some(c) = a.get(7) {
        o.vbd_init = hox_sim::solver::VbdInit::from_name(c);
    }
    if let Some(c) = a.get(6) {
        o.vbd_iterations = Some(c.parse().unwrap());
    }
    let scene = hox_scenes::by_name("bending").unwrap().with_overrides(&o).unwrap();
    let mut inst = hox_scenes::Instance::new(scene).unwrap();
    let g = Vec3::new(0.0, 0.0, -9.81);
    for f in 1..=frames {
        inst.sim.step_frame().unwrap();
        if f % 250 == 0 {
            let s = &inst.sim;
            let vg: f64 = -s
                .masses_kg()
                .iter()
                .zip(&s.positions)
                .zip(&s.mesh().rest_positions)
                .map(|((m, x), x0)| m * g.dot(&(x - x0)))
                .sum::<f64>();
            let (k, u) = (s.kinetic_energy_j(), s.elastic_energy_j());
            println!("{f} {:.3} K {k:.3} U {u:.3} Vg {vg:.3}", k + u + vg);
        }
    }
}
