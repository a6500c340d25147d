#!/usr/bin/env python3
"""Generates the small Gmsh test meshes committed under assets/meshes/.

Every mesh is the paper's beam, the box [0,2]x[0,0.5]x[0,0.5] m, with three physical groups:
"clamp" (the face x = 0), "tip" (the face x = 2) and "body" (the volume). Run it with the
`gmsh` wheel from PyPI (bash scripts/gmsh_meshes.sh sets up a venv and runs it); the outputs
are committed, so the tests need no Python.

    python scripts/gmsh_meshes.py [OUT_DIR]      # default: assets/meshes

Files (all MSH 4.1 ASCII unless named otherwise):
  beam-tet4.msh      4-node tetrahedra (unstructured)
  beam-tet10.msh     10-node tetrahedra (same mesh, order 2), also as beam-tet10-v22.msh (MSH 2.2)
  beam-tet20.msh     20-node tetrahedra (coarser, order 3)
  beam-tet10-fine.msh 10-node tetrahedra, size 0.125 (about 1,500 elements: the implicit solvers'
                     acceptance mesh, where XPBD at the paper's settings does not settle)
  beam-hex8.msh      8-node hexahedra (transfinite 8x2x2, recombined), also as
                     beam-hex8-v22-binary.msh (MSH 2.2 binary)
  beam-hex27.msh     27-node hexahedra (same, order 2), MSH 4.1 binary
  beam-hex27-v22.msh 27-node hexahedra, MSH 2.2 ASCII
  beam-prism6.msh    6-node prisms (a triangulated y-z section extruded along x)
  beam-pyramid.msh   5-node pyramids and 4-node tetrahedra (quad boundary, tet volume: Gmsh
                     puts a pyramid on every boundary quad)
  beam-mixed.msh     hexahedra, pyramids, tetrahedra and prisms in one file
"""

import os
import sys

import gmsh

L, W, H = 2.0, 0.5, 0.5


def start(name):
    gmsh.clear()
    gmsh.model.add(name)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)  # full 27-node hexahedra


def faces_at_x(x, tol=1e-5):
    """Surface tags whose bounding box lies on the plane at x."""
    found = []
    for dim, tag in gmsh.model.getEntities(2):
        xmin, _, _, xmax, _, _ = gmsh.model.getBoundingBox(dim, tag)
        if abs(xmin - x) < tol and abs(xmax - x) < tol:
            found.append(tag)
    return found


def add_groups():
    vols = [t for _, t in gmsh.model.getEntities(3)]
    gmsh.model.addPhysicalGroup(2, faces_at_x(0.0), name="clamp")
    gmsh.model.addPhysicalGroup(2, faces_at_x(L), name="tip")
    gmsh.model.addPhysicalGroup(3, vols, name="body")


def write(out, name, version=4.1, binary=False):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    # only the elements of physical groups are saved (Gmsh's default), so the surface
    # triangles/quads of "clamp" and "tip" are in the file next to the volume elements
    path = os.path.join(out, name)
    gmsh.write(path)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")


def unstructured_tets(size):
    start("tets")
    gmsh.model.occ.addBox(0, 0, 0, L, W, H)
    gmsh.model.occ.synchronize()
    add_groups()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)


def transfinite_hexes(nx, ny, nz):
    """A structured hex mesh of the box with nx x ny x nz cells."""
    start("hexes")
    gmsh.model.occ.addBox(0, 0, 0, L, W, H)
    gmsh.model.occ.synchronize()
    add_groups()
    for dim, tag in gmsh.model.getEntities(1):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(dim, tag)
        extent = [xmax - xmin, ymax - ymin, zmax - zmin]
        n = [nx, ny, nz][extent.index(max(extent))]
        gmsh.model.mesh.setTransfiniteCurve(tag, n + 1)
    for _, tag in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(2, tag)
    for _, tag in gmsh.model.getEntities(3):
        gmsh.model.mesh.setTransfiniteVolume(tag)
    gmsh.model.mesh.generate(3)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "assets", "meshes")
    os.makedirs(out, exist_ok=True)
    gmsh.initialize()

    # tetrahedra of order 1, 2 (size 0.25, about the built-in P2 8x2x2 beam's) and 3
    unstructured_tets(0.25)
    write(out, "beam-tet4.msh")
    gmsh.model.mesh.setOrder(2)
    write(out, "beam-tet10.msh")
    write(out, "beam-tet10-v22.msh", version=2.2)
    unstructured_tets(0.5)
    gmsh.model.mesh.setOrder(3)
    write(out, "beam-tet20.msh")
    unstructured_tets(0.125)
    gmsh.model.mesh.setOrder(2)
    write(out, "beam-tet10-fine.msh")

    # hexahedra of order 1 and 2
    transfinite_hexes(8, 2, 2)
    write(out, "beam-hex8.msh")
    write(out, "beam-hex8-v22-binary.msh", version=2.2, binary=True)
    gmsh.model.mesh.setOrder(2)
    write(out, "beam-hex27.msh", binary=True)
    write(out, "beam-hex27-v22.msh", version=2.2)

    # prisms: a triangulated x = 0 section extruded along x in 8 layers
    start("prisms")
    gmsh.model.occ.addRectangle(0, 0, 0, W, H)
    gmsh.model.occ.rotate([(2, 1)], 0, 0, 0, 0, 1, 0, -3.141592653589793 / 2)  # into the y-z plane at x = 0
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.25)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    gmsh.model.occ.extrude([(2, 1)], L, 0, 0, numElements=[8], recombine=True)
    gmsh.model.occ.synchronize()
    add_groups()
    gmsh.model.mesh.generate(3)
    write(out, "beam-prism6.msh")

    # pyramids: recombined (quad) boundary, unstructured tetrahedral volume
    start("pyramids")
    gmsh.model.occ.addBox(0, 0, 0, L, W, H)
    gmsh.model.occ.synchronize()
    add_groups()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.25)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    for _, tag in gmsh.model.getEntities(2):
        gmsh.model.mesh.setRecombine(2, tag)
    gmsh.model.mesh.generate(3)
    write(out, "beam-pyramid.msh")

    # mixed: hexahedra on [0, 0.75], tetrahedra on [0.75, 1.75] with pyramids on the quads
    # they share with the hexahedra, prisms on [1.75, 2] (the tet part's end section extruded)
    start("mixed")
    a = gmsh.model.occ.addBox(0, 0, 0, 0.75, W, H)
    b = gmsh.model.occ.addBox(0.75, 0, 0, 1.0, W, H)
    gmsh.model.occ.fragment([(3, a)], [(3, b)])
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.25)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    # the hex part: every curve of box a transfinite, its faces recombined
    hex_vol = a
    _, hex_surfs = gmsh.model.getAdjacencies(3, hex_vol)
    hex_curves = set()
    for s in hex_surfs:
        _, cs = gmsh.model.getAdjacencies(2, s)
        hex_curves.update(cs)
    for c in hex_curves:
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(1, c)
        extent = [xmax - xmin, ymax - ymin, zmax - zmin]
        n = [3, 2, 2][extent.index(max(extent))]
        gmsh.model.mesh.setTransfiniteCurve(c, n + 1)
    for s in hex_surfs:
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
    gmsh.model.mesh.setTransfiniteVolume(hex_vol)
    # the prism part: the x = 1.75 section of the tet box, extruded to x = 2 (meshed by layers)
    tip_face = faces_at_x(1.75)
    gmsh.model.occ.extrude([(2, t) for t in tip_face], 0.25, 0, 0, numElements=[1], recombine=True)
    gmsh.model.occ.synchronize()
    gmsh.model.occ.removeAllDuplicates()
    gmsh.model.occ.synchronize()
    add_groups()
    gmsh.model.mesh.generate(3)
    write(out, "beam-mixed.msh")

    gmsh.finalize()


if __name__ == "__main__":
    main()
