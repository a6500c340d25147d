//! Prints the `hox bench` table without building the app:
//! `cargo run --release -p hox-scenes --example bench_table [-- FRAMES [THREADS [FILTER]]]`
//! (THREADS: comma-separated, default 1,2; FILTER: a substring of the configuration label;
//! on one thread both the serial sweep and the colour sweep are timed, the latter with linear
//! tetrahedra four per 256-bit register; HOX_BENCH_COLOUR_ON_ONE=0 times the serial sweep only).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let frames: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(20);
    let threads: Vec<usize> = match args.next() {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![1, 2],
    };
    let filter = args.next().unwrap_or_default();
    let rows = hox_scenes::bench::run(
        &filter,
        &threads,
        std::env::var("HOX_BENCH_COLOUR_ON_ONE").map_or(true, |v| v != "0"),
        frames,
        &mut |r| eprintln!("{}", r.progress_line()),
    )?;
    print!("{}", hox_scenes::bench::markdown(&rows));
    Ok(())
}
