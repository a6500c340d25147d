//! Per-frame work of a solver on a scene (issue #37: the curved parts): `part_profile SCENE
//! SOLVER [ELEMENT] [FRAMES] [INTEGRATOR] [settle]` prints every frame's wall time with the solver's
//! counts (iterations or sweeps, factorisations, node updates), then the median, the 95th
//! percentile and the share of the time in frames that refactorised. With `settle` the run adds
//! the settle damping and stops when settled (at most FRAMES frames), as `hox simulate --settle`.
//! With `settle` it also solves the static equilibrium first (`hox static`'s) and reports the
//! frame and wall time from which every node stays within 0.1 % of the largest static
//! displacement of its static position. Any further `key=value` sets a parameter as the CLI's flags do (`newton-iterations=2`), and
//! `settle-damping=RATE` the settle damping, 1/s.
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
    for kv in a.iter().skip(6).filter(|s| s.contains('=')) {
        match kv.split_once('=').expect("filtered") {
            ("settle-damping", v) => o.settle_damping_per_sec = Some(v.parse().expect("a rate, 1/s")),
            (k, v) => o.set_text(k, v).expect("a parameter"),
        }
    }
    let scene = hox_scenes::by_name(name).unwrap().with_overrides(&o).unwrap();
    let mut inst = hox_scenes::Instance::new(scene).unwrap();
    let mut settler = (a.get(6).map(String::as_str) == Some("settle"))
        .then(|| hox_scenes::Settler::start(&mut inst, hox_scenes::SETTLE_CAP_SECS).unwrap());
    // the static equilibrium the settling run is measured against (before the clock starts)
    let equilibrium = settler.as_ref().map(|_| {
        let mesh = inst.sim.mesh();
        let solution =
            hox_scenes::solve_static(&inst.scene, mesh, 1e-10, 1, &mut |_, _, _| {}).expect("a static solution");
        let largest =
            solution.positions.iter().zip(&mesh.rest_positions).map(|(x, r)| (x - r).norm()).fold(0.0, f64::max);
        (solution.positions, largest)
    });
    let mut within_since: Option<(usize, f64)> = None;
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
        if let Some((positions, largest)) = &equilibrium {
            let gap = inst.sim.positions.iter().zip(positions).map(|(x, e)| (x - e).norm()).fold(0.0, f64::max);
            if gap <= 1e-3 * largest {
                within_since.get_or_insert((f, run_clock.elapsed().as_secs_f64()));
            } else {
                within_since = None;
            }
        }
        let state = settler.as_mut().map(|s| s.check(&inst));
        if let Some(state) = state.filter(|s| *s != hox_scenes::SettleState::Running) {
            println!("settle ended at frame {f} ({state:?}), {:.2} s wall", run_clock.elapsed().as_secs_f64());
            if let Some((frame, secs)) = within_since {
                println!("every node within 0.1 % of the static equilibrium from frame {frame} on, {secs:.2} s wall");
            }
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
