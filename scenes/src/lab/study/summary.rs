//! `hox study --summary DIR`: the study's figures of today as docs/STUDY.md shows them, read back
//! from the folder a `hox study --out DIR` wrote (issue #58: a document's tables are a command's
//! output). Three tables:
//!
//! 1. **bending at the paper's settings** (`study.csv`): every configuration's ms per frame on one
//!    thread and on all, beside the paper's Table 1 time and tip error where it has a row (the
//!    ratio is the paper's time over ours), the total error against the reference split into the
//!    mesh's (*discretisation*: the static solution on the mesh) and the solver's (settled XPBD
//!    against that static solution, % of the reference), and the substeps that bring the solver's
//!    share under 1 %;
//! 2. **the cheapest configuration within 1 %** per scene (`solvers.csv`, the rule of
//!    [`super::solver_axis::reaches_target`]: no failure, settled or at rest, total and mesh error
//!    ≤ 1 % of the reference; the least ms per frame on one thread);
//! 3. **the bending beam in motion** (`solvers.csv`): the first period's and the amplitude's error
//!    around 2 s against the reference motion, per solver and integrator, on the paper's meshes;
//! 4. **volumetric locking and its cure** (`locking.csv`): the static tip deflection as ν → 0.5
//!    in both formulations against the computed reference, and XPBD's ms per frame, the table of
//!    `study.md` ([`super::locking_markdown`]).
//!
//! The machine line is `study.md`'s (written by the run that measured the figures).

use super::solver_axis::TARGET_ERROR_PCT;
use super::{LockingRow, PAPER_TABLE_1, locking_markdown};
use crate::error::SceneError;
use std::collections::HashMap;
use std::path::Path;

/// One CSV file: its header and rows, read by column name.
struct Table {
    name: String,
    columns: HashMap<String, usize>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn read(dir: &Path, name: &str) -> Result<Table, SceneError> {
        let path = dir.join(name);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| SceneError::Io { path: path.display().to_string(), message: e.to_string() })?;
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap_or("").split(',').map(str::to_string).collect();
        let columns = header.iter().enumerate().map(|(k, h)| (h.clone(), k)).collect();
        let rows = lines
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
                // the last column (a failure's message) may hold commas of its own
                if cells.len() > header.len() && !header.is_empty() {
                    let tail = cells.split_off(header.len() - 1).join(",");
                    cells.push(tail);
                }
                cells
            })
            .collect();
        Ok(Table { name: path.display().to_string(), columns, rows })
    }

    fn get<'a>(&self, row: &'a [String], column: &str) -> Result<&'a str, SceneError> {
        let k = *self.columns.get(column).ok_or_else(|| self.error(format!("no column '{column}'")))?;
        Ok(row.get(k).map_or("", String::as_str))
    }

    fn number(&self, row: &[String], column: &str) -> Result<f64, SceneError> {
        let cell = self.get(row, column)?;
        cell.parse().map_err(|_| self.error(format!("column '{column}': '{cell}' is not a number")))
    }

    /// A number, or `None` for an empty cell.
    fn optional(&self, row: &[String], column: &str) -> Result<Option<f64>, SceneError> {
        if self.get(row, column)?.is_empty() { Ok(None) } else { self.number(row, column).map(Some) }
    }

    fn error(&self, message: String) -> SceneError {
        SceneError::Parse { source_name: self.name.clone(), message }
    }
}

/// The three tables of the study in `dir`, after its machine line.
pub fn summary(dir: &Path) -> Result<String, SceneError> {
    let study_md = dir.join("study.md");
    let md = std::fs::read_to_string(&study_md)
        .map_err(|e| SceneError::Io { path: study_md.display().to_string(), message: e.to_string() })?;
    let machine = md.lines().find(|l| l.starts_with("Machine: ")).ok_or_else(|| SceneError::Parse {
        source_name: study_md.display().to_string(),
        message: "no machine line (`Machine: …`): run `hox study --out DIR` again".into(),
    })?;
    let study = Table::read(dir, "study.csv")?;
    let solvers = Table::read(dir, "solvers.csv")?;
    let mut s = format!("{machine}\n\n");
    s.push_str(&paper_settings(&study)?);
    s.push('\n');
    s.push_str(&cheapest(&solvers)?);
    s.push('\n');
    s.push_str(&motion(&solvers)?);
    s.push('\n');
    s.push_str(&locking(&Table::read(dir, "locking.csv")?)?);
    Ok(s)
}

fn locking(t: &Table) -> Result<String, SceneError> {
    let rows = t
        .rows
        .iter()
        .map(|r| {
            Ok(LockingRow {
                poisson_ratio: t.number(r, "poisson_ratio")?,
                config: t.get(r, "configuration")?.to_string(),
                formulation: t.get(r, "formulation")?.to_string(),
                elements: t.number(r, "elements")? as usize,
                tip_z_m: t.number(r, "tip_z_m")?,
                reference_tip_z_m: t.number(r, "reference_tip_z_m")?,
                reference_mesh: t.get(r, "reference_mesh")?.to_string(),
                missing_pct: t.number(r, "missing_pct")?,
                ms_per_frame: t.optional(r, "ms_per_frame_1_thread")?,
                newton_ms_per_frame: t.number(r, "newton_ms_per_frame_1_thread")?,
            })
        })
        .collect::<Result<Vec<_>, SceneError>>()?;
    let md = locking_markdown(&rows);
    // the table alone: study.md's heading and paragraph are docs/STUDY.md's text
    Ok(md.find("| configuration |").map_or(md.clone(), |k| md[k..].to_string()).trim_end().to_string() + "\n")
}

fn paper_settings(t: &Table) -> Result<String, SceneError> {
    let mut s = String::from(
        "| configuration | elements | ms/frame, 1 thread (all) | paper ms | paper / ours | error (m) | paper error (m) | discretisation (m) | solver (% of the reference) | substeps for 1 % (ms/frame there) | settled at 50 substeps |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for row in t.rows.iter().filter(|r| t.get(r, "scene").ok() == Some("bending")) {
        let config = t.get(row, "configuration")?;
        let elements = t.number(row, "elements")? as usize;
        let ms = t.number(row, "ms_per_frame_1_thread")?;
        let all = t.optional(row, "ms_per_frame_all_threads")?.map_or("—".to_string(), |v| format!("{v:.2}"));
        let element = t.get(row, "element")?.to_uppercase();
        let paper = (t.get(row, "split")? == "five")
            .then(|| PAPER_TABLE_1.iter().find(|p| p.0 == element && p.1 == elements))
            .flatten();
        let (paper_ms, ratio, paper_err) = match paper {
            Some(p) => (format!("{}", p.2), format!("{:.1}×", p.2 / ms), format!("{:.1e}", p.3)),
            None => (String::new(), String::new(), String::new()),
        };
        let substeps = t.number(row, "substeps_for_1pct")? as u32;
        let at = if substeps == 50 {
            "50".to_string()
        } else {
            format!("{substeps} ({:.2})", t.number(row, "ms_per_frame_1pct")?)
        };
        s.push_str(&format!(
            "| {config} | {elements} | {ms:.2} ({all}) | {paper_ms} | {ratio} | {:.2e} | {paper_err} | {:.2e} | {:.2} % | {at} | {} |\n",
            t.number(row, "error_m")?,
            t.number(row, "discretisation_m")?,
            t.number(row, "solver_pct")?,
            if t.get(row, "settled")? == "true" { "yes" } else { "no: oscillates" },
        ));
    }
    Ok(s)
}

fn cheapest(t: &Table) -> Result<String, SceneError> {
    let mut s = String::from(
        "| scene | cheapest within 1 % | solver | elements | total error (the mesh's) | ms/frame, 1 thread | wall s to 1 % from rest |\n|---|---|---|---|---|---|---|\n",
    );
    for scene in crate::scene::builtin::PAPER_SCENES {
        let mut best: Option<(&Vec<String>, f64)> = None;
        for row in t.rows.iter().filter(|r| t.get(r, "scene").ok() == Some(scene)) {
            let reaches = t.get(row, "failure")?.is_empty()
                && (t.get(row, "settled")? == "true" || t.get(row, "at_rest")? == "true")
                && t.number(row, "error_pct")? <= TARGET_ERROR_PCT
                && t.number(row, "discretisation_pct")? <= TARGET_ERROR_PCT;
            let ms = t.number(row, "ms_per_frame_1_thread")?;
            if reaches && best.is_none_or(|(_, b)| ms < b) {
                best = Some((row, ms));
            }
        }
        match best {
            Some((row, ms)) => s.push_str(&format!(
                "| {scene} | {} | {} | {} | {:.2} % ({:.2} %) | {ms:.2} | {} |\n",
                t.get(row, "configuration")?,
                t.get(row, "solver")?,
                t.number(row, "elements")? as usize,
                t.number(row, "error_pct")?,
                t.number(row, "discretisation_pct")?,
                t.optional(row, "secs_to_1pct")?.map_or("—".to_string(), |v| format!("{v:.2}")),
            )),
            None => s.push_str(&format!("| {scene} | none reaches 1 % | | | | | |\n")),
        }
    }
    Ok(s)
}

/// The solvers with an integrator, as `solvers.csv` names them (`newton bdf2`).
const FAMILIES: [&str; 3] = ["newton", "vbd", "newton-cg"];
const INTEGRATORS: [&str; 3] = ["euler", "newmark", "bdf2"];

fn motion(t: &Table) -> Result<String, SceneError> {
    let mut s = String::from(
        "| mesh | solver | implicit Euler: period / amplitude, ms/frame | Newmark | BDF2 | XPBD 50×1 (no integrator) |\n|---|---|---|---|---|---|\n",
    );
    let bending: Vec<&Vec<String>> = t.rows.iter().filter(|r| t.get(r, "scene").ok() == Some("bending")).collect();
    let cell = |row: &Vec<String>| -> Result<Option<String>, SceneError> {
        let (Some(p), Some(a)) = (t.optional(row, "period_error_pct")?, t.optional(row, "amplitude_error_pct")?) else {
            return Ok(None);
        };
        Ok(Some(format!("{p:+.1} / {a:+.1} %, {:.2} ms", t.number(row, "ms_per_frame_1_thread")?)))
    };
    // the paper's own meshes (Table 1's element type and count, the unbiased split): the others
    // are in study.md
    let papers = |row: &Vec<String>| -> Result<bool, SceneError> {
        let (element, elements) = (t.get(row, "element")?.to_uppercase(), t.number(row, "elements")? as usize);
        Ok(t.get(row, "configuration")?.contains("five")
            && PAPER_TABLE_1.iter().any(|p| p.0 == element && p.1 == elements))
    };
    let mut meshes: Vec<&str> = Vec::new();
    for row in &bending {
        let mesh = t.get(row, "configuration")?;
        if !meshes.contains(&mesh) && papers(row)? && t.get(row, "solver")? != "xpbd 50x1" && cell(row)?.is_some() {
            meshes.push(mesh);
        }
    }
    for mesh in meshes {
        let find = |solver: &str| {
            bending
                .iter()
                .find(|r| t.get(r, "configuration").ok() == Some(mesh) && t.get(r, "solver").ok() == Some(solver))
        };
        for family in FAMILIES {
            let mut cells = Vec::new();
            for integrator in INTEGRATORS {
                let found = find(&format!("{family} {integrator}"));
                cells.push(match found {
                    Some(row) => cell(row)?.unwrap_or_else(|| "—".into()),
                    None => "—".into(),
                });
            }
            s.push_str(&format!("| {mesh} | {family} | {} | — |\n", cells.join(" | ")));
        }
        let xpbd = match find("xpbd 50x1") {
            Some(row) => cell(row)?.unwrap_or_else(|| "—".into()),
            None => "—".into(),
        };
        s.push_str(&format!("| {mesh} | xpbd | — | — | — | {xpbd} |\n"));
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOCKING: &str = "poisson_ratio,configuration,formulation,elements,tip_z_m,reference_tip_z_m,reference_mesh,missing_pct,ms_per_frame_1_thread,newton_ms_per_frame_1_thread\n0.35,P1 16x4x4 five,energy,1280,-0.28,-0.32,Q2 32×8×8 extrapolated,11.8,3.1,2.2\n0.35,P1 16x4x4 five,mixed,1280,-0.29,-0.32,Q2 32×8×8 extrapolated,9.4,,4.1\n";

    fn folder(study_md: &str, study_csv: &str, solvers_csv: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hox-summary-{}-{}", std::process::id(), study_md.len()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("study.md"), study_md).unwrap();
        std::fs::write(dir.join("study.csv"), study_csv).unwrap();
        std::fs::write(dir.join("solvers.csv"), solvers_csv).unwrap();
        std::fs::write(dir.join("locking.csv"), LOCKING).unwrap();
        dir
    }

    const STUDY: &str = "scene,configuration,element,split,elements,nodes,constraints,ms_per_frame_1_thread,ms_per_frame_all_threads,error_m,error_pct,discretisation_m,solver_m,solver_pct,substeps_for_1pct,ms_per_frame_1pct,error_1pct_m,settled\nbending,P1 16x4x4 five,p1,five,1280,425,1280,2.0,1.5,0.036,11.3,0.039,0.0026,0.94,50,2.0,0.036,true\nbending,P2 8x2x2 six,p2,six,192,500,192,1.9,,0.0005,0.2,0.0058,0.001,1.8,80,2.94,0.0005,false\n";
    const SOLVERS: &str = "scene,configuration,element,elements,nodes,solver,sweeps_per_frame,ms_per_frame_1_thread,solver_error_pct,error_m,error_pct,discretisation_pct,settled,at_rest,residual_rel,secs_to_1pct,sim_secs,period_error_pct,amplitude_error_pct,failure\nbending,P2 8x2x2 five,p2,160,393,newton newmark,3,2.34,0.004,0.001,0.5,0.4,true,true,1e-6,0.2,2.0,-0.1,0.6,\nbending,P2 8x2x2 five,p2,160,393,vbd euler,10,1.00,0.004,0.001,0.5,0.4,false,false,1e-2,,2.0,1.0,-55.7,diverged, then stopped\nbending,P2 8x2x2 five,p2,160,393,xpbd 50x1,50,1.30,1.4,0.001,0.4,0.4,false,true,1e-2,0.3,2.0,0.6,-1.2,\n";

    #[test]
    fn the_summary_puts_the_paper_beside_ours_and_skips_a_failed_run_when_finding_the_cheapest() {
        let dir = folder("# Accuracy\n\nMachine: \"Test CPU\", 2 logical cores.\n", STUDY, SOLVERS);
        let s = summary(&dir).unwrap();
        assert!(s.starts_with("Machine: \"Test CPU\", 2 logical cores.\n\n"), "{s}");
        // the paper's P1 1,280 row: 43.6 ms over our 2.0 ms
        assert!(s.contains("| P1 16x4x4 five | 1280 | 2.00 (1.50) | 43.6 | 21.8× | 3.60e-2 | 1.5e-1 |"), "{s}");
        // a biased split has no paper row, and an unmeasured thread count shows a dash
        assert!(s.contains("| P2 8x2x2 six | 192 | 1.90 (—) |  |  |"), "{s}");
        assert!(s.contains("| 80 (2.94) | no: oscillates |"), "{s}");
        // vbd euler is cheaper but failed (with a comma in its message): xpbd 50x1 at 1.30 ms wins
        assert!(s.contains("| bending | P2 8x2x2 five | xpbd 50x1 | 160 | 0.40 % (0.40 %) | 1.30 | 0.30 |"), "{s}");
        assert!(s.contains("| tension | none reaches 1 % |"), "{s}");
        assert!(s.contains("| P2 8x2x2 five | newton | — | -0.1 / +0.6 %, 2.34 ms | — | — |"), "{s}");
        assert!(s.contains("| P2 8x2x2 five | xpbd | — | — | — | +0.6 / -1.2 %, 1.30 ms |"), "{s}");
        assert!(
            s.contains(
                "| configuration | formulation | ν = 0.35 | XPBD ms/frame (ν = 0.35) | Newton ms/frame (ν = 0.35) |"
            ) && s.contains("| reference | | -0.3200 m | | |")
                && s.contains("| P1 16x4x4 five (1280) | energy | -0.2800 m (-11.8 %) | 3.1 | 2.2 |")
                && s.contains("| P1 16x4x4 five (1280) | mixed | -0.2900 m (-9.4 %) | — | 4.1 |")
                && s.contains("References: ν = 0.35: Q2 32×8×8 extrapolated."),
            "{s}"
        );
    }

    #[test]
    fn a_study_folder_without_a_machine_line_or_a_column_is_refused_by_name() {
        let dir = folder("# Accuracy\n", STUDY, SOLVERS);
        assert!(summary(&dir).unwrap_err().to_string().contains("no machine line"));
        let dir = folder("Machine: x\nsome more text to change the name", &STUDY.replace("error_m,", "err,"), SOLVERS);
        let e = summary(&dir).unwrap_err().to_string();
        assert!(e.contains("study.csv") && e.contains("no column 'error_m'"), "{e}");
        assert!(summary(Path::new("/nonexistent-hox-study")).unwrap_err().to_string().contains("study.md"));
    }
}
