//! Prints the `hox bench` table without building the app:
//! `cargo run --release -p hox-sim --example bench_table [-- FRAMES [THREADS [FILTER]]]`
//! (THREADS: comma-separated, default 1,2; FILTER: a substring of the configuration label;
//! HOX_BENCH_COLOUR_ON_ONE=1 also times the colour sweep on one thread).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let frames: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(20);
    let threads: Vec<usize> = match args.next() {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![1, 2],
    };
    let filter = args.next().unwrap_or_default();
    let rows = hox_sim::benchmark::run(&filter, &threads, std::env::var_os("HOX_BENCH_COLOUR_ON_ONE").is_some(), frames, &mut |r| {
        eprintln!("{} on {} thread(s), parallel {}: {:.2} ms/frame", r.case.label(), r.threads, r.parallel, r.ms_per_frame)
    })?;
    print!("{}", hox_sim::benchmark::markdown(&rows));
    Ok(())
}
