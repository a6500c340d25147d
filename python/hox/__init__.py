"""hox from Python: high-order finite elements in extended position-based dynamics (XPBD).

    >>> import hox
    >>> sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", poisson=0.45))
    >>> sim.step(60)                      # one simulated second, the interpreter released
    >>> sim.positions.shape               # numpy arrays: positions, velocities, displacements
    >>> report = sim.settle()             # until equilibrium: `hox simulate --settle --json`'s fields

Scenes come from the registry (`hox.scenes()`), a scene file (`Scene.load`, `Scene.from_toml`)
or a Gmsh file (`Scene.from_mesh_file`); every parameter of the parameter table is set by its key
(`hox.parameters()`), with the command line's ranges and errors (`ValueError` naming the key).
Sweeps run through any `concurrent.futures.Executor` (`hox.sweep`): a process pool, a Dask
client's executor, Ray's or submitit's.
"""

from ._hox import Scene, Simulation, parameters, scenes
from .sweep import Cell, run_cell, sweep

__all__ = ["Cell", "Scene", "Simulation", "parameters", "run_cell", "scenes", "sweep"]
