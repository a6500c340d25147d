//! The study one cell at a time ([`hox_scenes::study::shard`]): `hox.study` lists the cells of a
//! plan, runs each where its executor sends it and puts the rows back in cell order — the tables
//! `hox study` writes, by the same writers (the CSV files' columns).

use crate::{runtime_error, value_error};
use hox_scenes::study::shard::{Plan, Table};
use pyo3::prelude::*;
use std::collections::BTreeMap;

fn plan(quick: bool, tables: Option<Vec<String>>) -> PyResult<Plan> {
    let tables = match tables {
        None => Table::ALL.to_vec(),
        Some(names) => Table::parse_list(&names.join(",")).map_err(value_error)?,
    };
    Ok(Plan { quick, tables })
}

/// The cells of the study `quick`/`tables` would run, in order (their labels).
#[pyfunction]
#[pyo3(signature = (quick = true, tables = None))]
pub fn study_cells(quick: bool, tables: Option<Vec<String>>) -> PyResult<Vec<String>> {
    Ok(plan(quick, tables)?.cells().iter().map(|c| c.label()).collect())
}

/// Runs cell `index` of that study (the interpreter released) and returns its rows as the CSV
/// texts `hox study` writes: `{"study.csv": …, "locking.csv": …, "solvers.csv": …}` (only the
/// plan's tables).
#[pyfunction]
#[pyo3(signature = (index, quick = true, tables = None))]
pub fn study_cell(
    py: Python<'_>,
    index: usize,
    quick: bool,
    tables: Option<Vec<String>>,
) -> PyResult<BTreeMap<String, String>> {
    let plan = plan(quick, tables)?;
    let cells = plan.cells();
    let cell = cells
        .get(index)
        .ok_or_else(|| {
            value_error(format!("cell {index}: the study has cells 0 to {}", cells.len().saturating_sub(1)))
        })?
        .clone();
    let rows = py.detach(|| crate::work(|| cell.run(plan.quick, &mut |_| {}))).map_err(runtime_error)?;
    Ok(rows.files(&plan, "").into_iter().filter(|(name, _)| name.ends_with(".csv")).collect())
}
