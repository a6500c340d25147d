//! What a Newton iteration budget costs in motion (issue #37): runs SCENE for FRAMES frames
//! (no settle damping) with `newton-iterations` at the solver's default (30: every step to its
//! tolerance) and at each BUDGET, and prints the largest difference of the probes' displacement
//! from the converged run's over the run, relative to the largest displacement: `budget_motion
//! tube 120 2 3`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let name = a.get(1).map_or("tube", String::as_str);
    let frames: usize = a.get(2).map_or(120, |f| f.parse().expect("a frame count"));
    let budgets: Vec<usize> = a.iter().skip(3).map(|b| b.parse().expect("an iteration budget")).collect();
    let run = |budget: Option<usize>| {
        // (None: the scene's own budget)
        let o = hox_scenes::SceneOverrides { newton_iterations: budget, ..Default::default() };
        let scene = hox_scenes::by_name(name).expect("a scene").with_overrides(&o).expect("valid");
        let mut inst = hox_scenes::Instance::new(scene).expect("an instance");
        let clock = std::time::Instant::now();
        let track: Vec<Vec<[f64; 3]>> = (0..frames)
            .map(|_| {
                inst.sim.step_frame().expect("a step");
                inst.probe_displacements().into_iter().map(|(_, u)| u).collect()
            })
            .collect();
        (track, clock.elapsed().as_secs_f64())
    };
    let (reference, secs) = run(Some(hox_sim::solver::NewtonSettings::default().max_iterations as usize));
    let largest =
        reference.iter().flatten().map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()).fold(0.0, f64::max);
    println!("{name}, {frames} frames: converged {secs:.2} s, largest probe displacement {largest:.4e} m");
    for b in budgets {
        let (track, secs) = run(Some(b));
        let gap = track
            .iter()
            .flatten()
            .zip(reference.iter().flatten())
            .map(|(u, v)| ((u[0] - v[0]).powi(2) + (u[1] - v[1]).powi(2) + (u[2] - v[2]).powi(2)).sqrt())
            .fold(0.0, f64::max);
        let last = track.last().zip(reference.last()).map_or(0.0, |(u, v)| {
            u.iter()
                .zip(v)
                .map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt())
                .fold(0.0, f64::max)
        });
        println!(
            "budget {b}: {secs:.2} s, largest gap {:.3} % of the largest displacement, at the last frame {:.3} %",
            100.0 * gap / largest,
            100.0 * last / largest
        );
    }
}
