#!/usr/bin/env python3
"""Checks VTU files written by hox against VTK itself (the `vtk` wheel from PyPI; not run in CI).

For every cell: its volume (vtkCellSizeFilter) and validity (vtkCellValidator: inverted,
non-convex, wrong face orientation, ...), and every node against VTK's own parametric
coordinates of that cell type, mapped through the cell's corner nodes (for straight-sided
elements every node must land where VTK expects it: this catches wrong node permutations).

    pip install vtk
    hox simulate --mesh assets/meshes/beam-mixed.msh --clamp clamp --seconds 0.1 --vtk /tmp/v
    python scripts/vtk_check.py "/tmp/v/*_000000.vtu"
"""
import sys, glob
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy
LIN = {10:(vtk.VTK_TETRA,4), 24:(vtk.VTK_TETRA,4), 71:(vtk.VTK_TETRA,4), 12:(vtk.VTK_HEXAHEDRON,8), 29:(vtk.VTK_HEXAHEDRON,8), 13:(vtk.VTK_WEDGE,6), 14:(vtk.VTK_PYRAMID,5)}
for f in sorted(glob.glob(sys.argv[1])):
    r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(f); r.Update()
    g = r.GetOutput()
    csf = vtk.vtkCellSizeFilter(); csf.SetInputData(g); csf.ComputeVolumeOn(); csf.Update()
    vol = vtk_to_numpy(csf.GetOutput().GetCellData().GetArray("Volume"))
    cv = vtk.vtkCellValidator(); cv.SetInputData(g); cv.Update()
    va = cv.GetOutput().GetCellData().GetArray("ValidityState")
    invalid = sum(1 for i in range(g.GetNumberOfCells()) if va.GetTuple1(i) != 0)
    types = sorted(set(g.GetCellType(i) for i in range(g.GetNumberOfCells())))
    worst = 0.0
    for c in range(g.GetNumberOfCells()):
        cell = g.GetCell(c)
        lt, nv = LIN[cell.GetCellType()]
        pts = vtk.vtkPoints()
        for i in range(nv): pts.InsertNextPoint(cell.GetPoints().GetPoint(i))
        ug = vtk.vtkUnstructuredGrid(); ug.SetPoints(pts); ug.InsertNextCell(lt, nv, list(range(nv)))
        lin = ug.GetCell(0)
        pc = cell.GetParametricCoords()
        for i in range(cell.GetNumberOfPoints()):
            x=[0.0]*3; w=[0.0]*nv; sub=vtk.reference(0)
            lin.EvaluateLocation(sub, pc[3*i:3*i+3], x, w)
            worst = max(worst, np.linalg.norm(np.array(x) - np.array(cell.GetPoints().GetPoint(i))))
    print(f.split('/')[-1], "types", types, "cells", g.GetNumberOfCells(), "volume %.12f" % vol.sum(), "min cell volume %.3e" % vol.min(), "invalid cells", invalid, "worst node vs VTK pcoords %.1e" % worst)
