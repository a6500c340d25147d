//! Per-frame work of a solver on a scene (issue #37: the curved parts): `part_profile SCENE
//! SOLVER [ELEMENT] [FRAMES] [INTEGRATOR] [settle]` prints every frame's wall time with the solver's
//! counts (iterations or sweeps, factorisations, node updates), then the median, the 95th
//! percentile and the share of the time in frames that refactorised. With `settle` the run adds
//! the settle damping and stops when settled (at most FRAMES frames), as `hox simulate --settle`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let name = a.get(1).map_or("tube", String::as_str);
    let method = hox_sim::solver::Method::from_name(a.get(2).map_or("newton", String::as_str)).expect("solver");
    let mut o = hox_scenes::SceneOverrides { method: Some(method), ..Default::default() };
    if let Some(e) = a.get(3) {
        o.element = hox_sim::element::ElementType::from_name(e);
    }
    let frames: usize = a.get(4).map_or(60, |f| f.parse().unwrap());
    if let Some(i) = a.get(5) {
        o.integrator = hox_sim::solver::Integrator::from_name(i);
    }
    let scene = hox_scenes::by_name(name).unwrap().with_overrides(&o).unwrap();
    let mut inst = hox_scenes::Instance::new(scene).unwrap();
    let mut settler = (a.get(6).map(String::as_str) == Some("settle"))
        .then(|| hox_scenes::Settler::start(&mut inst, hox_scenes::SETTLE_CAP_SECS).unwrap());
    let run_clock = std::time::Instant::now();
    println!("{name}: {} nodes, {} elements", inst.sim.mesh().num_nodes(), inst.sim.mesh().num_elements());
    let mut times = Vec::new();
    let (mut with_factor, mut total) = (0.0, 0.0);
    for f in 1..=frames {
        let before = inst.sim.counters();
        let clock = std::time::Instant::now();
        inst.sim.step_frame().unwrap();
        let ms = 1e3 * clock.elapsed().as_secs_f64();
        let after = inst.sim.counters();
        let factors = after.factorizations - before.factorizations;
        println!(
            "frame {f:3}: {ms:8.2} ms, {:3} iterations, {factors:2} factorisations, {:7} node updates",
            after.solver_iterations - before.solver_iterations,
            after.node_updates - before.node_updates
        );
        times.push(ms);
        total += ms;
        if factors > 0 {
            with_factor += ms;
        }
        let state = settler.as_mut().map(|s| s.check(&inst));
        if let Some(state) = state.filter(|s| *s != hox_scenes::SettleState::Running) {
            println!("settle ended at frame {f} ({state:?}), {:.2} s wall", run_clock.elapsed().as_secs_f64());
            break;
        }
    }
    let median = hox_sim::measure::median(&mut times.clone());
    let p95 = hox_sim::measure::quantile(&mut times, 0.95);
    println!(
        "median {median:.2} ms, p95 {p95:.2} ms, {:.0} % of the time in frames that refactorised",
        100.0 * with_factor / total
    );
}
