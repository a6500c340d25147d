"""Meshes from meshio (issue #60): a `meshio.Mesh` — read from a Gmsh file, or from any format
meshio reads, or built in Python — as a hox scene.

    import meshio, hox
    part = meshio.read("hook-p2.msh")
    scene = hox.from_meshio(part, clamp=["clamp"])     # its physical group "clamp" held
    sim = hox.Simulation(scene)

meshio keeps cells in VTK's node order; hox's elements use Gmsh's, which differs for the
10-node tetrahedron and the 27-node hexahedron (meshio's own Gmsh writer applies the same
permutations). Nodes no volume cell uses are dropped and the others renumbered in order, as
hox's Gmsh reader does, so a file read by meshio and by hox gives the same mesh.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

import numpy as np

from . import _hox

# meshio cell type → hox element type
MESHIO_TYPES = {
    "tetra": "p1",
    "tetra10": "p2",
    "tetra20": "p3",
    "hexahedron": "q1",
    "hexahedron27": "q2",
    "wedge": "prism",
    "pyramid": "pyramid",
}

# meshio's (VTK's) node order → Gmsh's: gmsh_cell = meshio_cell[:, order]
TO_GMSH_ORDER = {
    "tetra10": [0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
    "hexahedron27": [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 16, 9, 17, 10, 18, 19, 12, 15, 13, 14, 24, 22, 20, 21, 23, 25, 26],
}

# 3D cell types hox does not simulate, for the message
_OTHER_VOLUMES = {"hexahedron20", "wedge15", "wedge18", "pyramid13", "pyramid14", "tetra35", "hexahedron64"}


def mesh_arrays(mesh: Any) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The arrays `Scene.from_arrays` takes, from a `meshio.Mesh`: nodes `(n, 3)`, elements by
    hox element type in Gmsh's node order, and node groups — every named cell set (a Gmsh file's
    physical groups) as the nodes of its cells, and every point set."""
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise ValueError(f"meshio mesh: points of shape {points.shape}, expected (n, 3)")
    if points.shape[1] == 2:
        raise ValueError("meshio mesh: the points are 2D; hox simulates solids (3D points and volume cells)")
    volume: dict[str, list[np.ndarray]] = {}
    for block in mesh.cells:
        if block.type in MESHIO_TYPES:
            data = np.asarray(block.data, dtype=np.int64)
            if block.type in TO_GMSH_ORDER:
                data = data[:, TO_GMSH_ORDER[block.type]]
            volume.setdefault(MESHIO_TYPES[block.type], []).append(data)
        elif block.type in _OTHER_VOLUMES:
            raise ValueError(
                f"meshio mesh: {len(block.data)} cells of type {block.type!r}, which hox does not simulate "
                f"(supported: {', '.join(f'{k} → {v}' for k, v in MESHIO_TYPES.items())})"
            )
    if not volume:
        types = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise ValueError(f"meshio mesh: no volume cells hox simulates (its cell types: {types}); mesh the volume too")
    # the nodes the volume cells use, renumbered in their order (as hox's Gmsh reader does)
    used = np.zeros(len(points), dtype=bool)
    for blocks in volume.values():
        for data in blocks:
            if data.size and (data.min() < 0 or data.max() >= len(points)):
                raise ValueError(f"meshio mesh: a cell names a node outside 0..{len(points) - 1}")
            used[data.ravel()] = True
    new_index = np.full(len(points), -1, dtype=np.int64)
    new_index[used] = np.arange(int(used.sum()))
    elements = {kind: new_index[np.concatenate(blocks)] for kind, blocks in volume.items()}
    groups: dict[str, np.ndarray] = {}
    for name, per_block in (getattr(mesh, "cell_sets", None) or {}).items():
        if name.startswith("gmsh:"):
            continue
        nodes = [np.asarray(mesh.cells[i].data, dtype=np.int64)[np.asarray(ids, dtype=np.int64)].ravel()
                 for i, ids in enumerate(per_block) if len(ids)]
        if nodes:
            groups[name] = _renumbered(np.unique(np.concatenate(nodes)), new_index, name)
    # a Gmsh 2.2 file read by meshio: physical groups as tags per cell, their names in field_data
    physical = (getattr(mesh, "cell_data", None) or {}).get("gmsh:physical")
    for name, (tag, dim) in ((k, v[:2]) for k, v in (getattr(mesh, "field_data", None) or {}).items()):
        if name in groups or physical is None:
            continue
        nodes = [np.asarray(block.data, dtype=np.int64)[np.asarray(tags) == tag].ravel()
                 for block, tags in zip(mesh.cells, physical) if _dimension(block.type) == dim]
        nodes = [n for n in nodes if n.size]
        if nodes:
            groups[name] = _renumbered(np.unique(np.concatenate(nodes)), new_index, name)
    for name, ids in (getattr(mesh, "point_sets", None) or {}).items():
        groups[name] = _renumbered(np.unique(np.asarray(ids, dtype=np.int64)), new_index, name)
    return points[used], elements, groups


def _dimension(cell_type: str) -> int:
    """A meshio cell type's dimension."""
    if cell_type in MESHIO_TYPES or cell_type in _OTHER_VOLUMES:
        return 3
    if cell_type.startswith(("triangle", "quad", "polygon")):
        return 2
    if cell_type.startswith("line"):
        return 1
    return 0


def _renumbered(nodes: np.ndarray, new_index: np.ndarray, name: str) -> np.ndarray:
    kept = new_index[nodes]
    return kept[kept >= 0]


def from_meshio(
    mesh: Any,
    clamp: Iterable[str] = (),
    drives: Iterable[Mapping[str, Any]] = (),
    gravity: bool = True,
) -> "_hox.Scene":
    """A scene around a `meshio.Mesh`: its groups `clamp` held and `drives` moved (as
    `Scene.from_mesh_file`), under gravity unless `gravity=False`. A group that does not exist is
    a ValueError listing the mesh's groups."""
    nodes, elements, groups = mesh_arrays(mesh)
    return _hox.Scene.from_arrays(nodes, elements, groups, clamp=list(clamp), drives=list(drives), gravity=gravity)
