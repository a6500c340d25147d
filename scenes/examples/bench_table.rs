//! Prints the `hox bench` table without building the app:
//! `cargo run --release -p hox-scenes --example bench_table [-- FRAMES [THREADS [FILTER]]]`
//! (THREADS: comma-separated, default 1,2; FILTER: a substring of the configuration label;
//! the colour sweep, the default, on every thread count, and the element-order sweep on one thread;
//! HOX_BENCH_ELEMENT_ORDER=0 times the colour sweep only; HOX_BENCH_LANES=4,8 times the colour
//! sweep at each register width, default the CPU's widest).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let frames: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(20);
    let threads: Vec<usize> = match args.next() {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![1, 2],
    };
    let filter = args.next().unwrap_or_default();
    let lanes: Vec<usize> = match std::env::var("HOX_BENCH_LANES") {
        Ok(list) if !list.is_empty() => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        _ => Vec::new(),
    };
    let rows = hox_scenes::bench::run(
        &filter,
        &threads,
        if std::env::var("HOX_BENCH_ELEMENT_ORDER").is_ok_and(|v| v == "0") {
            &[hox_sim::solver::Sweep::Colour][..]
        } else {
            &[hox_sim::solver::Sweep::Colour, hox_sim::solver::Sweep::Element][..]
        },
        &lanes,
        frames,
        &mut |r| eprintln!("{}", r.progress_line()),
    )?;
    print!("{}", hox_scenes::bench::markdown(&rows, hox_scenes::bench::peak_gflops_per_core()));
    Ok(())
}
