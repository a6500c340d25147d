"""hox from Python: high-order finite elements in extended position-based dynamics (XPBD).

    >>> import hox
    >>> sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", poisson=0.45))
    >>> sim.step(60)                      # one simulated second, the interpreter released
    >>> sim.positions.shape               # a read-only numpy view: positions, velocities, …
    >>> report = sim.settle()             # until equilibrium: `hox simulate --settle --json`'s fields
    >>> sim.element_field("von-mises")    # Pa per element; also strain, det-f, energy-density
    >>> sim.error()                       # the probes against the reference

Scenes come from the registry (`hox.scenes()`), a scene file (`Scene.load`, `Scene.from_toml`),
a Gmsh file (`Scene.from_mesh_file`), numpy arrays (`Scene.from_arrays`) or meshio
(`hox.from_meshio`); every parameter of the parameter table is set by its key
(`hox.parameters()`), with the command line's ranges and errors (`ValueError` naming the key).
Sweeps (`hox.sweep`) and the study (`hox.study`) run through any `concurrent.futures.Executor`:
a process pool, a Dask client's executor, Ray's or submitit's (Slurm).
"""

import os as _os

from ._hox import Scene, Simulation, __version__, _after_fork_in_child, elements, machine, parameters, scenes
from .mesh import from_meshio, mesh_arrays
from .study import study, study_cells
from .sweep import Cell, run_cell, sweep

# a process forked from this one (a ProcessPoolExecutor's worker on Linux) gets threads of its own
_os.register_at_fork(after_in_child=_after_fork_in_child)

__all__ = [
    "Cell",
    "Scene",
    "Simulation",
    "__version__",
    "elements",
    "from_meshio",
    "machine",
    "mesh_arrays",
    "parameters",
    "run_cell",
    "scenes",
    "study",
    "study_cells",
    "sweep",
]
