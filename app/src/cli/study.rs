//! `hox study`: the accuracy-versus-time study over the paper scenes (the paper's settings, the
//! locking table and the solver axis), written to a folder.

use anyhow::{Context, Result};
use hox_scenes::study::solver_axis;
use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

/// A long job writing to a folder: the folder checked writable before any work, then a spinner
/// (a log line per step when stderr is not a terminal, as in CI). Shared by `study` and `paper`.
pub(super) struct FolderJob {
    pub bar: ProgressBar,
    pub started: Instant,
}

impl FolderJob {
    pub fn start(out: &std::path::Path) -> Result<FolderJob> {
        // refuse an unwritable folder before spending minutes
        std::fs::create_dir_all(out).with_context(|| format!("cannot create the output folder {}", out.display()))?;
        let probe = out.join(".hox-write-test");
        std::fs::write(&probe, b"").with_context(|| format!("cannot write to the output folder {}", out.display()))?;
        let _ = std::fs::remove_file(&probe);
        let bar = ProgressBar::new_spinner();
        bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed}] {msg}").expect("valid template"));
        bar.enable_steady_tick(Duration::from_millis(200));
        Ok(FolderJob { bar, started: Instant::now() })
    }

    /// Says what runs now.
    pub fn report(&self, message: &str) {
        if self.bar.is_hidden() {
            eprintln!("[{:>6.1} s] {message}", self.started.elapsed().as_secs_f64());
        }
        self.bar.set_message(message.to_string());
    }
}

pub fn study(quick: bool, out: &std::path::Path) -> Result<()> {
    let job = FolderJob::start(out)?;
    let bar = &job.bar;
    let mut report = |message: &str| job.report(message);
    let rows = hox_scenes::study::run_study(quick, &mut report)?;
    let locking = hox_scenes::study::locking(quick, &mut report)?;
    let solvers = solver_axis::run_solver_axis(quick, &mut report)?;
    bar.finish_and_clear();
    let mut files = vec![
        (
            "study.md".to_string(),
            // the machine line under the title: `hox study --summary` and docs/STUDY.md name it
            hox_scenes::study::markdown(&rows, quick).replacen(
                "\n\n",
                &format!("\n\nMachine: {}.\n\n", hox_scenes::bench::machine()),
                1,
            ) + "\n"
                + &solver_axis::solver_markdown(&solvers)
                + &hox_scenes::study::locking_markdown(&locking),
        ),
        ("study.csv".into(), hox_scenes::study::csv(&rows)),
        ("solvers.csv".into(), solver_axis::solver_csv(&solvers)),
        ("locking.csv".into(), hox_scenes::study::locking_csv(&locking)),
        ("study.svg".into(), hox_scenes::study::svg(&rows)),
    ];
    for scene in hox_scenes::PAPER_SCENES {
        if solvers.iter().any(|r| r.scene == scene) {
            files.push((format!("pareto-{scene}.svg"), hox_scenes::study::pareto::pareto_svg(&solvers, scene)));
        }
    }
    for (name, text) in files {
        let path = out.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// `hox study --summary DIR`: the figures of the study in DIR as docs/STUDY.md shows them.
pub fn summary(dir: &std::path::Path) -> Result<()> {
    print!("{}", hox_scenes::study::summary::summary(dir)?);
    Ok(())
}
