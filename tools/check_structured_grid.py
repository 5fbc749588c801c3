#!/usr/bin/env python3
"""Reads interpatch's structured-grid files back with VTK's own readers and compares
them point by point with interpatch's evaluation of the same volume.

    check_structured_grid.py INTERPATCH SPEC.json WORKDIR [K]

Runs `interpatch mesh SPEC -o WORKDIR/g.{vts,vtk,xyz} --res KxKxK` and
`interpatch eval SPEC --grid K -o WORKDIR/g.npy` (the same uniform parameters), then
reads the meshes with vtkXMLStructuredGridReader, vtkStructuredGridReader and
vtkMultiBlockPLOT3DReader — independent of interpatch's own code — and checks
dimensions and every point against the .npy (u index first; VTK orders points
with the first index fastest). Exits non-zero, naming the file and the worst
point, on any difference above 1e-12 of the bounding-box diagonal: all three
formats carry doubles written to full precision, so only the parse can differ.
Needs Debian's python3-vtk9 and python3-numpy.
"""
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def run(*args):
    r = subprocess.run(list(args), capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")


def points_of(reader_output):
    return vtk_to_numpy(reader_output.GetPoints().GetData()).astype(np.float64)


def main():
    exe, spec, work = sys.argv[1], sys.argv[2], sys.argv[3]
    k = int(sys.argv[4]) if len(sys.argv) > 4 else 9
    os.makedirs(work, exist_ok=True)
    run(exe, "eval", spec, "--grid", str(k), "-o", os.path.join(work, "g.npy"))
    expected = np.load(os.path.join(work, "g.npy"))
    assert expected.shape == (k, k, k, 3), expected.shape
    # VTK's point order: i (u) fastest, then j, then k: transpose u,v,w -> w,v,u.
    flat = expected.transpose(2, 1, 0, 3).reshape(-1, 3)
    scale = float(np.linalg.norm(flat.max(axis=0) - flat.min(axis=0)))
    failures = []

    def compare(name, got, dims):
        if tuple(dims) != (k, k, k):
            failures.append(f"{name}: dimensions {tuple(dims)}, expected {(k, k, k)}")
            return
        err = np.linalg.norm(got - flat, axis=1)
        worst = int(np.argmax(err))
        print(f"{name}: {got.shape[0]} points, max difference {err[worst]:.3g} (bbox diagonal {scale:.3g})")
        if err[worst] > 1e-12 * scale:
            failures.append(f"{name}: point {worst} differs by {err[worst]:.3g}")

    res = f"{k}x{k}x{k}"
    vts = os.path.join(work, "g.vts")
    run(exe, "mesh", spec, "-o", vts, "--res", res)
    r = vtk.vtkXMLStructuredGridReader()
    r.SetFileName(vts)
    r.Update()
    compare("g.vts", points_of(r.GetOutput()), r.GetOutput().GetDimensions())

    legacy = os.path.join(work, "g.vtk")
    run(exe, "mesh", spec, "-o", legacy, "--res", res)
    r = vtk.vtkStructuredGridReader()
    r.SetFileName(legacy)
    r.Update()
    compare("g.vtk", points_of(r.GetOutput()), r.GetOutput().GetDimensions())

    xyz = os.path.join(work, "g.xyz")
    run(exe, "mesh", spec, "-o", xyz, "--res", res)
    r = vtk.vtkMultiBlockPLOT3DReader()
    r.SetXYZFileName(xyz)
    r.SetBinaryFile(0)
    r.SetMultiGrid(1)
    r.SetHasByteCount(0)
    r.SetIBlanking(0)
    r.SetTwoDimensionalGeometry(0)
    r.SetDoublePrecision(1)
    r.Update()
    block = r.GetOutput().GetBlock(0)
    if block is None:
        failures.append("g.xyz: VTK's PLOT3D reader found no block")
    else:
        compare("g.xyz", points_of(block), block.GetDimensions())

    if failures:
        sys.exit("\n".join(failures))


if __name__ == "__main__":
    main()
