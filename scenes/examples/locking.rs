//! The locking table of `hox study` on its own (the full set of meshes, P1 10,240 included):
//! static tip deflections of the bending beam at ν = 0.35, 0.45, 0.49, 0.499 in both formulations
//! (energy, mixed) against the computed reference, and XPBD's and Newton's ms per frame of each.
//! Writes the markdown section to stdout and the CSV to the path given, if any.
//! docs/study/locking.md and locking.csv are its output.
//!
//! `cargo run --release -p hox-scenes --example locking -- docs/study/locking.csv > docs/study/locking.md`

fn main() -> Result<(), Box<dyn std::error::Error>> {
    use std::io::Write;
    // open the CSV first, so that an unwritable path is refused before a minute of solves
    let csv = match std::env::args().nth(1) {
        Some(path) => Some((std::fs::File::create(&path).map_err(|e| format!("cannot write {path}: {e}"))?, path)),
        None => None,
    };
    let rows = hox_scenes::study::locking(false, &mut |message| eprintln!("{message}"))?;
    print!("{}", hox_scenes::study::locking_markdown(&rows));
    println!("Machine: {} (release, one thread for the ms per frame).", hox_scenes::bench::machine());
    if let Some((mut file, path)) = csv {
        file.write_all(hox_scenes::study::locking_csv(&rows).as_bytes())
            .map_err(|e| format!("cannot write {path}: {e}"))?;
    }
    Ok(())
}
