"""The study from Python (issue #60): `hox study`'s tables — the same cells, the same columns —
with each cell run where an executor sends it.

    import hox
    tables = hox.study(quick=True, tables=["locking"])            # here, one cell after another
    tables["locking"][0]            # {'poisson_ratio': 0.35, 'configuration': 'P1 16x4x4 five', 'formulation': 'energy', ...}

    from dask.distributed import Client
    with Client("scheduler:8786") as client:                      # or a LocalCluster, a Ray or
        tables = hox.study(quick=False, executor=client.get_executor())   # submitit executor

A study is cut into independent cells (one scene and mesh, one Poisson ratio of the locking
table, one mesh of the solver axis): a cell's rows depend on the cell alone, so the tables are
those of `hox study` wherever the cells ran (the timing columns measured where each ran). With
pandas installed, `as_frame=True` (the default then) gives DataFrames.
"""

from __future__ import annotations

import csv
import io
import math
from concurrent.futures import Executor
from typing import Any, Iterable, Sequence

from . import _hox

# the files `hox study` writes, by table
TABLE_FILES = {"accuracy": "study.csv", "locking": "locking.csv", "solvers": "solvers.csv"}


def _value(text: str) -> Any:
    """A CSV field as the value it writes: int, float (NaN and inf too), bool, None or text."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def _rows(text: str) -> list[dict[str, Any]]:
    return [{k: _value(v) for k, v in row.items()} for row in csv.DictReader(io.StringIO(text))]


def _run_cell(job: tuple[int, bool, tuple[str, ...] | None]) -> dict[str, str]:
    """Runs one cell (what an executor's worker calls): its tables' CSV texts."""
    index, quick, tables = job
    return _hox.study_cell(index, quick, list(tables) if tables is not None else None)


def study_cells(quick: bool = True, tables: Sequence[str] | None = None) -> list[str]:
    """The labels of the cells `study(quick, tables)` runs, in order."""
    return _hox.study_cells(quick, list(tables) if tables is not None else None)


def study(
    quick: bool = True,
    tables: Iterable[str] | None = None,
    executor: Executor | None = None,
    as_frame: bool | None = None,
) -> dict[str, Any]:
    """Runs the study — `quick` without the heavy meshes; `tables` among "accuracy", "locking",
    "solvers" (default all) — through `executor.map` when one is given (else here), and returns
    `{table: rows}` with the columns of `hox study`'s CSV files, in its row order. `as_frame`:
    pandas DataFrames (default: when pandas is installed)."""
    names = tuple(tables) if tables is not None else None
    jobs = [(i, quick, names) for i in range(len(study_cells(quick, names)))]
    results = list(executor.map(_run_cell, jobs)) if executor is not None else [_run_cell(j) for j in jobs]
    chosen = [t for t in TABLE_FILES if names is None or t in names]
    out: dict[str, Any] = {t: [] for t in chosen}
    for files in results:
        for table in chosen:
            out[table].extend(_rows(files.get(TABLE_FILES[table], "")))
    if as_frame is None:
        try:
            import pandas  # noqa: F401

            as_frame = True
        except ImportError:
            as_frame = False
    if as_frame:
        import pandas

        return {t: pandas.DataFrame(rows) for t, rows in out.items()}
    return out


def same_rows(a: list[dict[str, Any]], b: list[dict[str, Any]], timing: Iterable[str] = ()) -> bool:
    """Whether two tables hold the same rows, NaN equal to NaN, the `timing` columns left out."""
    skip = set(timing)

    def equal(x: Any, y: Any) -> bool:
        if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
            return True
        return x == y

    return len(a) == len(b) and all(
        r.keys() == s.keys() and all(equal(r[k], s[k]) for k in r if k not in skip) for r, s in zip(a, b)
    )
