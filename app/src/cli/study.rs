//! `hox study`: the accuracy-versus-time study over the paper scenes (the paper's settings, the
//! locking table and the solver axis), written to a folder.

use anyhow::{Context, Result};
use hox_scenes::study::shard::{Plan, Shard, StudyPart, Table};
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

pub fn study(quick: bool, only: Option<&str>, shard: Option<&str>, out: &std::path::Path) -> Result<()> {
    // every argument checked before the folder is touched
    let tables = match only {
        Some(list) => Table::parse_list(list)?,
        None => Table::ALL.to_vec(),
    };
    let plan = Plan { quick, tables };
    let shard = shard.map(Shard::parse).transpose().map_err(anyhow::Error::msg)?;
    let job = FolderJob::start(out)?;
    let mut report = |message: &str| job.report(message);
    let machine = hox_scenes::bench::machine();
    match shard {
        Some(shard) => {
            let part = hox_scenes::study::shard::run_part(&plan, shard, &machine, &mut report)?;
            job.bar.finish_and_clear();
            write_files(out, vec![(shard.file_name(), part.to_toml()?)])
        }
        None => {
            let tables = hox_scenes::study::shard::run_all(&plan, &mut report)?;
            job.bar.finish_and_clear();
            write_files(out, tables.files(&plan, &machine))
        }
    }
}

/// `hox study merge PART... --out DIR`: every part read and the merge checked before anything
/// is written.
pub fn merge(paths: &[std::path::PathBuf], out: &std::path::Path) -> Result<()> {
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            let mut found: Vec<_> = std::fs::read_dir(path)
                .with_context(|| format!("cannot read the folder {}", path.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("study-part-") && n.ends_with(".toml"))
                })
                .collect();
            if found.is_empty() {
                anyhow::bail!("{} holds no study-part-*.toml file (written by hox study --shard K/N)", path.display());
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(path.clone());
        }
    }
    let mut parts = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).with_context(|| format!("cannot read the part {}", file.display()))?;
        parts.push(StudyPart::from_toml(&text, &file.display().to_string())?);
    }
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    let (plan, tables, machine) = hox_scenes::study::shard::merge(&parts, &names)?;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create the output folder {}", out.display()))?;
    write_files(out, tables.files(&plan, &machine))
}

fn write_files(out: &std::path::Path, files: Vec<(String, String)>) -> Result<()> {
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
