//! `hox paper`: the paper's experiments, Table 1 and Figs. 1–3 written to a folder
//! (`hox_scenes::paper`), each figure as SVG and as PNG (`output::svg_to_png`).

use anyhow::{Context, Result};

pub fn paper(quick: bool, out: &std::path::Path) -> Result<()> {
    let job = super::study::FolderJob::start(out)?;
    let (bar, started) = (&job.bar, job.started);
    let mut report = |message: &str| job.report(message);
    let result = hox_scenes::paper::run_paper(quick, &mut report)?;
    bar.finish_and_clear();
    let machine = hox_scenes::bench::machine();
    let secs = started.elapsed().as_secs_f64();
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    for figure in &result.figures {
        files.push((format!("{}.svg", figure.name), figure.svg.clone().into_bytes()));
        files.push((format!("{}.png", figure.name), crate::output::svg_to_png(&figure.svg)?));
    }
    files.push(("table1.md".into(), hox_scenes::paper::table_markdown(&result.table, &machine, quick).into_bytes()));
    files.push(("PAPER.md".into(), hox_scenes::paper::paper_markdown(&result, &machine, secs).into_bytes()));
    for (name, bytes) in files {
        let path = out.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    eprintln!("hox paper{} took {secs:.0} s", if quick { " --quick" } else { "" });
    Ok(())
}
