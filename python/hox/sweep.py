"""Sweeps of independent runs (issue #60): each cell a scene and its parameters, run where an
executor sends it — a process pool on one machine, a Dask `distributed` client's executor, Ray's
or submitit's (Slurm) — with the same result wherever it ran (a cell's run depends on the cell
alone: the same scene, parameters and frames give the same numbers on any machine of one
architecture).

    import concurrent.futures, hox
    cells = [hox.Cell("bending", {"element": e, "poisson": nu}) for e in ("p1", "p2") for nu in (0.3, 0.45)]
    with concurrent.futures.ProcessPoolExecutor() as pool:
        rows = hox.sweep(cells, pool)

    from dask.distributed import Client, LocalCluster
    with Client(LocalCluster(n_workers=2)) as client:
        rows = hox.sweep(cells, client.get_executor())
"""

from __future__ import annotations

import dataclasses
import math
from concurrent.futures import Executor
from typing import Any, Iterable


@dataclasses.dataclass(frozen=True)
class Cell:
    """One run of a sweep: a built-in scene (or a scene file's text), the parameters set on it,
    and how long it runs (`seconds`, or until it settles when `settle` is true)."""

    scene: str
    params: dict[str, Any] = dataclasses.field(default_factory=dict)
    seconds: float = 1.0
    settle: bool = False
    scene_toml: str | None = None


def run_cell(cell: Cell) -> dict[str, Any]:
    """Runs one cell and returns its row: the cell's scene and parameters, the simulated time,
    the probes' displacements (`probe_<name>_u<x|y|z>_m`), and the wall-clock time per frame."""
    from . import _hox

    base = _hox.Scene.from_toml(cell.scene_toml, cell.scene) if cell.scene_toml else _hox.Scene.builtin(cell.scene)
    scene = base.with_params(**cell.params)
    sim = _hox.Simulation(scene)
    row: dict[str, Any] = {"scene": cell.scene, **cell.params}
    if cell.settle:
        report = sim.settle()
        row["settled"] = report["settled"]
        row["residual_rel"] = report["residual_rel"]
    else:
        frames = max(1, round(cell.seconds * scene.params["solver.frames_per_second"]))
        sim.step(frames)
    row["time_secs"] = sim.time_secs
    for name, u in sim.probes.items():
        for axis, value in zip("xyz", u):
            row[f"probe_{name}_u{axis}_m"] = value
    row["ms_per_frame"] = sim.ms_per_frame if not math.isnan(sim.ms_per_frame) else None
    return row


def sweep(cells: Iterable[Cell], executor: Executor | None = None) -> list[dict[str, Any]]:
    """Runs every cell, through `executor.map` when one is given (else here, one after the
    other), and returns their rows in the cells' order."""
    cells = list(cells)
    if executor is None:
        return [run_cell(c) for c in cells]
    return list(executor.map(run_cell, cells))
