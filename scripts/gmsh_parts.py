#!/usr/bin/env python3
"""Generates the curved parts committed under assets/parts/ (issue #37): real geometry whose
curved faces P2 and P3 follow and P1's facets cannot.

Each part is meshed once into tetrahedra; the same vertices and elements are then written at
order 1, 2 and 3 (Gmsh places the high-order nodes on the CAD surfaces, so the P2 and P3 faces
lie on the true cylinders and tori, and `Mesh.HighOrderOptimize` keeps every curved element
valid). Comparing the three files changes the element order and nothing else.

    python scripts/gmsh_parts.py [OUT_DIR]      # default: assets/parts

Parts (SI units; physical groups "clamp", "end" and "body"):
  tube   a hollow tube cantilever: outer radius 0.1 m, inner 0.07 m, length 1 m along x,
         clamped at x = 0 ("end" is the face at x = 1); about 2,400 tetrahedra, the P2 file
         about 5,000 nodes (the implicit solvers' interactive-rate acceptance part)
  elbow  a 90° pipe elbow: outer radius 0.05 m, inner 0.035 m, bend radius 0.2 m, a 0.2 m
         straight leg each side; clamped at one leg's end, the other ("end") free
  hook   a crane hook of round bar, radius 0.03 m: a 0.3 m shank along z and a 180° bend of
         radius 0.1 m; clamped at the shank's top, the bend's end ("end") free

Files: PART-p1.msh, PART-p2.msh (MSH 4.1 ASCII) and PART-p3.msh (MSH 4.1 binary: a third
of the size). Also tube-fine-p3.msh: the tube meshed finer (element size 0.027 m: 5,590
tetrahedra, 33,748 P3 nodes, 101,244 degrees of freedom), the static solver's 100k benchmark
(`hox static --mesh assets/parts/tube-fine-p3.msh --clamp clamp`, docs/PERFORMANCE.md); not a
scene, not built into the binary.
"""

import math
import os
import sys

import gmsh


def start(name):
    gmsh.clear()
    gmsh.model.add(name)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    # high-order nodes on the geometry, then moved (only where needed) so that every curved
    # element keeps a positive Jacobian
    gmsh.option.setNumber("Mesh.HighOrderOptimize", 2)


def face_at(point, tol=1e-6):
    """The surface whose bounding box contains `point` in a plane (an end face)."""
    best = None
    for dim, tag in gmsh.model.getEntities(2):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(dim, tag)
        lo, hi = (xmin, ymin, zmin), (xmax, ymax, zmax)
        flat = [hi[k] - lo[k] < tol for k in range(3)]
        if not any(flat):
            continue
        k = flat.index(True)
        if abs(lo[k] - point[k]) < tol and all(lo[j] - tol <= point[j] <= hi[j] + tol for j in range(3) if j != k):
            best = tag
    if best is None:
        raise SystemExit(f"no planar face at {point}")
    return best


def groups(clamp_point, end_point):
    vols = [t for _, t in gmsh.model.getEntities(3)]
    gmsh.model.addPhysicalGroup(2, [face_at(clamp_point)], name="clamp")
    gmsh.model.addPhysicalGroup(2, [face_at(end_point)], name="end")
    gmsh.model.addPhysicalGroup(3, vols, name="body")


def mesh(size):
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)  # elements per 2π of curvature
    gmsh.model.mesh.generate(3)


def write_orders(out, part, orders=(1, 2, 3)):
    for order in orders:
        gmsh.model.mesh.setOrder(order)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1 if order == 3 else 0)
        path = os.path.join(out, f"{part}-p{order}.msh")
        gmsh.write(path)
        _, tags, _ = gmsh.model.mesh.getElements(3)
        nodes, _, _ = gmsh.model.mesh.getNodes(3, -1, True, False)
        print(f"wrote {path}: {sum(len(t) for t in tags)} tetrahedra, {len(set(nodes))} nodes, "
              f"{os.path.getsize(path)} bytes")


def annulus(r_out, r_in):
    """An annulus in the plane x = 0 (normal +x), centred on the x axis."""
    outer = gmsh.model.occ.addDisk(0, 0, 0, r_out, r_out, zAxis=[1, 0, 0])
    inner = gmsh.model.occ.addDisk(0, 0, 0, r_in, r_in, zAxis=[1, 0, 0])
    cut, _ = gmsh.model.occ.cut([(2, outer)], [(2, inner)])
    return cut


def tube(out, size=0.04, name="tube", orders=(1, 2, 3)):
    start(name)
    r_out, r_in, length = 0.1, 0.07, 1.0
    a = gmsh.model.occ.addCylinder(0, 0, 0, length, 0, 0, r_out)
    b = gmsh.model.occ.addCylinder(0, 0, 0, length, 0, 0, r_in)
    gmsh.model.occ.cut([(3, a)], [(3, b)])
    gmsh.model.occ.synchronize()
    groups((0, 0, r_in + 0.01), (length, 0, r_in + 0.01))
    mesh(size)
    write_orders(out, name, orders)


def elbow(out):
    start("elbow")
    r_out, r_in, bend, leg = 0.05, 0.035, 0.2, 0.2
    section = annulus(r_out, r_in)
    # leg 1 along +x from x = 0, the bend about the axis through (leg, 0, bend) along y,
    # leg 2 along +z
    ext1 = gmsh.model.occ.extrude(section, leg, 0, 0)
    end1 = [e for e in ext1 if e[0] == 2][0]
    ext2 = gmsh.model.occ.revolve([end1], leg, 0, bend, 0, -1, 0, math.pi / 2)
    end2 = [e for e in ext2 if e[0] == 2][0]
    gmsh.model.occ.extrude([end2], 0, 0, leg)
    gmsh.model.occ.removeAllDuplicates()
    gmsh.model.occ.synchronize()
    groups((0, 0, r_in + 0.005), (leg + bend, 0, bend + leg))
    mesh(0.022)
    write_orders(out, "elbow")


def hook(out):
    start("hook")
    r, shank, bend = 0.03, 0.3, 0.1
    # the section at the shank's top (z = 0), the shank down to z = -shank, then a 180° bend
    # about the axis through (bend, 0, -shank) along y, ending at x = 2·bend pointing up
    disk = gmsh.model.occ.addDisk(0, 0, 0, r, r, zAxis=[0, 0, -1])
    ext1 = gmsh.model.occ.extrude([(2, disk)], 0, 0, -shank)
    end1 = [e for e in ext1 if e[0] == 2][0]
    # (two quarter turns: one half-turn revolve gives Gmsh overlapping facets on its seam;
    # about -y, so that the bend turns away from the shank)
    ext2 = gmsh.model.occ.revolve([end1], bend, 0, -shank, 0, -1, 0, math.pi / 2)
    end2 = [e for e in ext2 if e[0] == 2][0]
    gmsh.model.occ.revolve([end2], bend, 0, -shank, 0, -1, 0, math.pi / 2)
    gmsh.model.occ.removeAllDuplicates()
    gmsh.model.occ.synchronize()
    groups((0, 0, 0), (2 * bend, 0, -shank))
    mesh(0.016)
    write_orders(out, "hook")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "assets", "parts")
    os.makedirs(out, exist_ok=True)
    gmsh.initialize()
    tube(out)
    elbow(out)
    hook(out)
    tube(out, size=0.027, name="tube-fine", orders=(3,))
    gmsh.finalize()


if __name__ == "__main__":
    main()
