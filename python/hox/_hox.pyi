"""Type stubs of hox's extension module (python/src/): what an editor completes."""

from typing import Any, Mapping, Sequence

import numpy as np
import numpy.typing as npt

__version__: str

Drive = Mapping[str, Any]
"""A prescribed motion: {"group", "translation_m", "rotation_axis", "rotation_origin_m",
"rotation_deg", "ramp_secs"}."""

class Scene:
    """A scene: its mesh, material, effects, solver settings and probes."""

    @staticmethod
    def builtin(name: str) -> Scene:
        """A built-in scene by name (`hox.scenes()` lists them)."""
    @staticmethod
    def from_toml(text: str, source: str = "python") -> Scene:
        """A scene from the text of a scene file (TOML, docs/SCENES.md)."""
    @staticmethod
    def load(path: str) -> Scene:
        """A scene file read from `path`."""
    @staticmethod
    def from_mesh_file(
        path: str, clamp: Sequence[str] = ("clamp",), drives: Sequence[Drive] = (), gravity: bool = True
    ) -> Scene:
        """A scene around a Gmsh mesh file: its physical groups `clamp` held, `drives` moved."""
    @staticmethod
    def from_arrays(
        nodes: npt.ArrayLike,
        elements: Mapping[str, npt.ArrayLike],
        groups: Mapping[str, Sequence[int]] | None = None,
        clamp: Sequence[str] = (),
        drives: Sequence[Drive] = (),
        gravity: bool = True,
    ) -> Scene:
        """A scene around a mesh given as arrays: nodes (n, 3), elements by type in Gmsh's node order."""
    def with_params(self, **params: Any) -> Scene:
        """This scene with parameters set by their keys (`hox.parameters()`); ValueError naming a bad one."""
    def with_probes(self, **probes: tuple[float, float, float]) -> Scene:
        """This scene with probes added by name, rest coordinates in metres."""
    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def params(self) -> dict[str, Any]:
        """Every parameter's value, by its scene-file path."""
    @property
    def probes(self) -> dict[str, list[float]]: ...
    @property
    def groups(self) -> dict[str, int]:
        """The mesh's node groups and their sizes."""
    def to_toml(self) -> str: ...

class Simulation:
    """A scene built and running: step it, settle it, read its state as numpy arrays."""

    def __init__(self, scene: Scene) -> None: ...
    def step(self, frames: int = 1) -> None:
        """Steps frames, the interpreter released; Ctrl-C stops between two frames."""
    def step_in_rust(self, frames: int) -> npt.NDArray[np.float64]:
        """Steps frames in one Rust loop; each frame's ms (the overhead benchmark's baseline)."""
    def settle(self, cap_secs: float | None = None) -> dict[str, Any]:
        """Runs until settled; `hox simulate --settle --json`'s report."""
    def static_solve(self, tolerance: float = 1e-9, load_steps: int = 10) -> npt.NDArray[np.float64]:
        """The static equilibrium's node positions, (n, 3)."""
    def reference(self) -> dict[str, Any]:
        """The reference the error is measured against."""
    def error(self) -> dict[str, Any]:
        """The probes' error against the reference: error_m, error_pct, reference."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(n, 3) metres: a read-only view that follows the simulation."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """(n, 3) m/s: a read-only view."""
    @property
    def rest_positions(self) -> npt.NDArray[np.float64]:
        """(n, 3) metres: a read-only view."""
    @property
    def displacements(self) -> npt.NDArray[np.float64]:
        """(n, 3) metres, a new array."""
    @property
    def elements(self) -> dict[str, npt.NDArray[np.int64]]:
        """{type: (m, k) node indices}, block by block."""
    def element_field(self, name: str) -> npt.NDArray[np.float64]:
        """von-mises, strain, det-f or energy-density per element."""
    @property
    def element_volumes_m3(self) -> npt.NDArray[np.float64]: ...
    @property
    def volume_m3(self) -> float: ...
    def surface(self, segments: int = 4) -> dict[str, npt.NDArray[Any]]:
        """The display surface: points, rest_points, triangles."""
    def surface_field(self, name: str, segments: int = 4) -> npt.NDArray[np.float64]:
        """A field at the display surface's points."""
    @property
    def energies(self) -> dict[str, float]:
        """kinetic_j, elastic_j, gravity_j, total_j."""
    @property
    def probes(self) -> dict[str, tuple[float, float, float]]: ...
    @property
    def time_secs(self) -> float: ...
    @property
    def ms_per_frame(self) -> float: ...
    @property
    def newton_policy(self) -> tuple[str, str] | None:
        """(policy, why) of Newton's last step; None for XPBD and VBD."""
    @property
    def solver_advice(self) -> str | None:
        """Which solver fits this body better, when the one chosen does not."""
    @property
    def frame_ms(self) -> npt.NDArray[np.float64]: ...
    @property
    def num_nodes(self) -> int: ...
    @property
    def num_elements(self) -> int: ...

def scenes() -> list[str]:
    """The built-in scenes' names."""

def elements() -> list[dict[str, Any]]:
    """The registered element types."""

def parameters() -> list[dict[str, Any]]:
    """The parameter table."""

def machine() -> str:
    """The machine this runs on."""

def study_cells(quick: bool = True, tables: Sequence[str] | None = None) -> list[str]:
    """The labels of the study's cells."""

def study_cell(index: int, quick: bool = True, tables: Sequence[str] | None = None) -> dict[str, str]:
    """Runs one cell: its tables' CSV texts."""
