//! The study as independent cells (issue #60): what `hox study --shard K/N` runs one part of,
//! `hox study merge` joins, and the Python package sends through any executor.
//!
//! A study is a [`Plan`] — quick or full, and which of its tables ([`Table`]: the accuracy rows,
//! the locking table, the solver axis) — cut into [`Cell`]s in the order the tables list their
//! rows: an accuracy cell is one scene and mesh, a locking cell one Poisson ratio (Q2 and every
//! mesh at that ν), a solver cell one scene and mesh with every solver. A cell's rows depend on
//! the cell alone, so a study run cell by cell anywhere, in any order, and put back in cell
//! order is the unsharded study: the same rows, the same tables and charts (the timing columns
//! measured where each cell ran).
//!
//! Shard `K/N` holds the cells `i` with `i mod N = K − 1` (round robin: each part gets its share
//! of the expensive solver cells); its part file ([`StudyPart`], TOML, which keeps NaN and the
//! absent values of failed rows) names the whole plan, so a merge refuses parts of different
//! plans, a part given twice or a part missing.

use super::solver_axis::{SolverRow, solver_configurations};
use super::{LOCKING_POISSON_RATIOS, LockingRow, StudyConfig, StudyRow, configurations};
use crate::error::SceneError;
use crate::scene::builtin::PAPER_SCENES;

/// The study's tables, each a part of the plan that can be left out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Table {
    /// Every element type at the paper's settings, its error split (`study.csv`).
    Accuracy,
    /// The static tip at ν up to 0.499 (`locking.csv`).
    Locking,
    /// Every solver on each scene's meshes (`solvers.csv`).
    Solvers,
}

impl Table {
    pub const ALL: [Table; 3] = [Table::Accuracy, Table::Locking, Table::Solvers];

    pub fn name(self) -> &'static str {
        match self {
            Table::Accuracy => "accuracy",
            Table::Locking => "locking",
            Table::Solvers => "solvers",
        }
    }

    /// A table by its name; an unknown name is an error listing the names.
    pub fn from_name(name: &str) -> Result<Table, SceneError> {
        Table::ALL.into_iter().find(|t| t.name() == name.trim()).ok_or_else(|| SceneError::Unknown {
            name: name.to_string(),
            available: Table::ALL.map(Table::name).join(", "),
        })
    }

    /// A comma-separated list of names ("accuracy,locking").
    pub fn parse_list(list: &str) -> Result<Vec<Table>, SceneError> {
        let mut tables: Vec<Table> = list.split(',').map(Table::from_name).collect::<Result<_, _>>()?;
        tables.sort();
        tables.dedup();
        Ok(tables)
    }
}

/// What a study runs: quick (no heavy meshes) or full, and which tables.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    pub quick: bool,
    pub tables: Vec<Table>,
}

impl Plan {
    /// Every table.
    pub fn all(quick: bool) -> Plan {
        Plan { quick, tables: Table::ALL.to_vec() }
    }

    /// The cells, in the order of the tables' rows.
    pub fn cells(&self) -> Vec<Cell> {
        let mut cells = Vec::new();
        let has = |t: Table| self.tables.contains(&t);
        if has(Table::Accuracy) {
            for scene in PAPER_SCENES {
                cells.extend(
                    configurations(scene)
                        .into_iter()
                        .filter(|c| !(self.quick && c.heavy))
                        .map(|config| Cell::Accuracy { scene, config }),
                );
            }
        }
        if has(Table::Locking) {
            cells.extend(LOCKING_POISSON_RATIOS.map(|poisson_ratio| Cell::Locking { poisson_ratio }));
        }
        if has(Table::Solvers) {
            for scene in PAPER_SCENES {
                cells.extend(
                    solver_configurations(scene, self.quick).into_iter().map(|config| Cell::Solvers { scene, config }),
                );
            }
        }
        cells
    }

    /// The command that runs it: "hox study --quick --only locking".
    pub fn command(&self) -> String {
        let mut s = String::from("hox study");
        if self.quick {
            s.push_str(" --quick");
        }
        if self.tables != Table::ALL {
            s.push_str(&format!(" --only {}", self.tables.iter().map(|t| t.name()).collect::<Vec<_>>().join(",")));
        }
        s
    }
}

/// One independent piece of a study.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// One accuracy row: a scene on one mesh ([`super::study_one`]).
    Accuracy { scene: &'static str, config: StudyConfig },
    /// The locking table's row at one Poisson ratio ([`super::locking_at`]).
    Locking { poisson_ratio: f64 },
    /// One mesh of the solver axis, every solver ([`super::solver_axis::mesh_rows`]).
    Solvers { scene: &'static str, config: StudyConfig },
}

impl Cell {
    /// "accuracy bending P2 8x2x2 five", "locking ν = 0.49", "solvers tension Q1 12x6x6 five".
    pub fn label(&self) -> String {
        match self {
            Cell::Accuracy { scene, config } => format!("accuracy {scene} {}", config.label()),
            Cell::Locking { poisson_ratio } => format!("locking ν = {poisson_ratio}"),
            Cell::Solvers { scene, config } => format!("solvers {scene} {}", config.label()),
        }
    }

    /// Runs the cell (`quick` as its plan's: the locking table's heavy mesh is left out).
    pub fn run(&self, quick: bool, progress: &mut dyn FnMut(&str)) -> Result<Tables, SceneError> {
        let mut t = Tables::default();
        match self {
            Cell::Accuracy { scene, config } => t.accuracy.push(super::study_one(scene, config, progress)?),
            Cell::Locking { poisson_ratio } => t.locking = super::locking_at(*poisson_ratio, quick, progress)?,
            Cell::Solvers { scene, config } => t.solvers = super::solver_axis::mesh_rows(scene, config, progress)?,
        }
        Ok(t)
    }
}

/// The rows of a study, or of some of its cells.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tables {
    #[serde(default)]
    pub accuracy: Vec<StudyRow>,
    #[serde(default)]
    pub locking: Vec<LockingRow>,
    #[serde(default)]
    pub solvers: Vec<SolverRow>,
}

impl Tables {
    /// `other`'s rows after these.
    pub fn append(&mut self, other: Tables) {
        self.accuracy.extend(other.accuracy);
        self.locking.extend(other.locking);
        self.solvers.extend(other.solvers);
    }

    /// The files a study writes: study.md (its machine line `machine`), the CSV tables, the
    /// bending chart and each scene's Pareto chart of the solver axis. Only what the plan ran.
    pub fn files(&self, plan: &Plan, machine: &str) -> Vec<(String, String)> {
        let has = |t: Table| plan.tables.contains(&t);
        let mut md = format!("# Accuracy versus time\n\nMachine: {machine}.\n\n");
        if has(Table::Accuracy) {
            // the accuracy section keeps its own title line out: this one names the machine
            let accuracy = super::markdown(&self.accuracy, plan.quick);
            md = accuracy.replacen("\n\n", &format!("\n\nMachine: {machine}.\n\n"), 1);
            // "Produced by `hox study --quick`" names the tables run when not all were
            let all = Plan::all(plan.quick).command();
            md = md.replacen(&format!("`{all}`"), &format!("`{}`", plan.command()), 1);
            md.push('\n');
        }
        if has(Table::Solvers) {
            md.push_str(&super::solver_axis::solver_markdown(&self.solvers));
        }
        if has(Table::Locking) {
            md.push_str(&super::locking_markdown(&self.locking));
        }
        let mut files = vec![("study.md".to_string(), md)];
        if has(Table::Accuracy) {
            files.push(("study.csv".into(), super::csv(&self.accuracy)));
            files.push(("study.svg".into(), super::svg(&self.accuracy)));
        }
        if has(Table::Solvers) {
            files.push(("solvers.csv".into(), super::solver_axis::solver_csv(&self.solvers)));
            for scene in PAPER_SCENES {
                if self.solvers.iter().any(|r| r.scene == scene) {
                    files.push((format!("pareto-{scene}.svg"), super::pareto::pareto_svg(&self.solvers, scene)));
                }
            }
        }
        if has(Table::Locking) {
            files.push(("locking.csv".into(), super::locking_csv(&self.locking)));
        }
        files
    }
}

/// Part `index` of `count` of a study (`--shard K/N`: K from 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// "K/N", 1 ≤ K ≤ N.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("--shard {text:?}: expected K/N, two whole numbers with 1 ≤ K ≤ N (e.g. 2/8)");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) =
            (k.trim().parse::<usize>().map_err(|_| bad())?, n.trim().parse::<usize>().map_err(|_| bad())?);
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether cell `i` (from 0) is this part's.
    pub fn holds(&self, i: usize) -> bool {
        i % self.count == self.index - 1
    }

    /// The part file's name: `study-part-K-of-N.toml`.
    pub fn file_name(&self) -> String {
        format!("study-part-{}-of-{}.toml", self.index, self.count)
    }
}

/// What a part file holds: the whole plan (its cells' labels), which part this is, and its
/// cells' rows with their indices.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StudyPart {
    /// [`PART_FORMAT`].
    pub format: String,
    pub quick: bool,
    pub tables: Vec<Table>,
    pub shard: usize,
    pub of: usize,
    /// The machine the part ran on.
    pub machine: String,
    /// Every cell of the plan, in order (not only this part's).
    pub plan_cells: Vec<String>,
    pub cells: Vec<PartCell>,
}

/// One cell's rows in a part.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PartCell {
    pub index: usize,
    pub label: String,
    pub rows: Tables,
}

/// What a part file says it is.
pub const PART_FORMAT: &str = "hox study part, version 1";

/// Runs the cells of `plan` that `shard` holds (every cell without a shard), in order.
pub fn run_part(
    plan: &Plan,
    shard: Shard,
    machine: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<StudyPart, SceneError> {
    let all = plan.cells();
    let mut cells = Vec::new();
    for (index, cell) in all.iter().enumerate().filter(|(i, _)| shard.holds(*i)) {
        progress(&format!(
            "part {}/{}: cell {} of {}: {}",
            shard.index,
            shard.count,
            index + 1,
            all.len(),
            cell.label()
        ));
        cells.push(PartCell { index, label: cell.label(), rows: cell.run(plan.quick, progress)? });
    }
    Ok(StudyPart {
        format: PART_FORMAT.into(),
        quick: plan.quick,
        tables: plan.tables.clone(),
        shard: shard.index,
        of: shard.count,
        machine: machine.to_string(),
        plan_cells: all.iter().map(Cell::label).collect(),
        cells,
    })
}

/// Runs every cell of `plan` here, in order: the unsharded study.
pub fn run_all(plan: &Plan, progress: &mut dyn FnMut(&str)) -> Result<Tables, SceneError> {
    let mut tables = Tables::default();
    for cell in plan.cells() {
        tables.append(cell.run(plan.quick, progress)?);
    }
    Ok(tables)
}

impl StudyPart {
    /// The part file's text.
    pub fn to_toml(&self) -> Result<String, SceneError> {
        toml::to_string(self)
            .map_err(|e| SceneError::Parse { source_name: "study part".into(), message: e.to_string() })
    }

    /// A part file's text read back; `source` names it in errors.
    pub fn from_toml(text: &str, source: &str) -> Result<StudyPart, SceneError> {
        let bad = |m: String| SceneError::Parse { source_name: source.to_string(), message: m };
        let part: StudyPart = toml::from_str(text).map_err(|e| bad(format!("not a study part file: {e}")))?;
        if part.format != PART_FORMAT {
            return Err(bad(format!("format {:?}, expected {PART_FORMAT:?}", part.format)));
        }
        Ok(part)
    }
}

/// Joins the parts of one study (any order) into its plan and rows in cell order; refuses parts
/// of different plans, a part given twice, a part or a cell missing, naming them (`names[i]`
/// names `parts[i]`).
pub fn merge(parts: &[StudyPart], names: &[String]) -> Result<(Plan, Tables, String), SceneError> {
    let bad = |m: String| SceneError::Simulation { source_name: "hox study merge".into(), message: m };
    let first = parts.first().ok_or_else(|| bad("no part files given".into()))?;
    let name = |i: usize| names.get(i).cloned().unwrap_or_else(|| format!("part {}", i + 1));
    let mut seen = vec![None::<usize>; first.of];
    for (i, p) in parts.iter().enumerate() {
        if (p.quick, &p.tables, p.of, &p.plan_cells) != (first.quick, &first.tables, first.of, &first.plan_cells) {
            return Err(bad(format!(
                "{} is part {}/{} of another study than {} (part {}/{}): quick, tables, part count and cells must all agree",
                name(i),
                p.shard,
                p.of,
                name(0),
                first.shard,
                first.of
            )));
        }
        match seen.get_mut(p.shard.wrapping_sub(1)) {
            Some(Some(j)) => {
                return Err(bad(format!("{} and {} are both part {}/{}", name(*j), name(i), p.shard, p.of)));
            }
            Some(slot) => *slot = Some(i),
            None => return Err(bad(format!("{} says it is part {} of {}", name(i), p.shard, p.of))),
        }
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, s)| s.is_none()).map(|(k, _)| format!("{}/{}", k + 1, first.of)).collect();
    if !missing.is_empty() {
        return Err(bad(format!("part {} missing (give every part of the study)", missing.join(", "))));
    }
    let mut by_index: Vec<Option<&PartCell>> = vec![None; first.plan_cells.len()];
    for cell in parts.iter().flat_map(|p| &p.cells) {
        match by_index.get_mut(cell.index) {
            Some(slot @ None) if first.plan_cells[cell.index] == cell.label => *slot = Some(cell),
            _ => {
                return Err(bad(format!("cell {} ({}) is not the plan's, or given twice", cell.index + 1, cell.label)));
            }
        }
    }
    let mut tables = Tables::default();
    for (i, cell) in by_index.into_iter().enumerate() {
        let cell = cell.ok_or_else(|| bad(format!("cell {} ({}) is in no part", i + 1, first.plan_cells[i])))?;
        tables.append(cell.rows.clone());
    }
    let mut machines: Vec<&str> = parts.iter().map(|p| p.machine.as_str()).collect();
    machines.sort_unstable();
    machines.dedup();
    Ok((Plan { quick: first.quick, tables: first.tables.clone() }, tables, machines.join("; ")))
}

#[cfg(test)]
mod tests;
