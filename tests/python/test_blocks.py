"""A blocks spec from Python: the merged mesh written as the command writes it, read
back by meshio with its cells counted and every one of positive volume, and the
description info gives. Run by CTest (python_module) with PYTHONPATH, INTERPATCH_CLI
and INTERPATCH_EXAMPLES set."""

import os
import subprocess

import meshio
import numpy as np
import pytest

import interpatch

EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))
CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
BEND = os.path.join(EXAMPLES, "blocks_bend.json")


def _hex_volumes(points, cells):
    """Each hexahedron's volume from 5 tetrahedra of its corners (VTK order)."""
    p = points[cells]
    tets = ((0, 1, 3, 4), (1, 2, 3, 6), (1, 4, 5, 6), (3, 4, 6, 7), (1, 3, 4, 6))
    total = 0
    for a, b, c, d in tets:
        total = total + np.einsum("ij,ij->i", np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]), p[:, d] - p[:, a]) / 6
    return total


def test_the_bend_is_one_mesh_of_both_blocks(tmp_path):
    bend = interpatch.build(BEND)
    out = tmp_path / "bend.vtu"
    bend.write(out)
    cli_out = tmp_path / "cli.vtu"
    subprocess.run([CLI, "mesh", BEND, "-o", str(cli_out)], check=True)
    assert cli_out.read_bytes() == out.read_bytes()
    m = meshio.read(out)
    cells = m.cells_dict["hexahedron"]
    info = bend.info()
    # The inlet's 41 x 21 x 41 nodes and the bend's 41 x 41 x 61 share a 41 x 41 face.
    assert [b["nodes"] for b in info["blocks"]] == [[41, 21, 41], [41, 41, 61]]
    assert len(m.points) == 41 * 21 * 41 + 41 * 41 * 61 - 41 * 41 == info["mesh"]["points"]
    assert len(cells) == 40 * 20 * 40 + 40 * 40 * 60 == info["mesh"]["cells"]
    assert len(np.unique(m.points.round(12), axis=0)) == len(m.points), "every node once"
    volumes = _hex_volumes(m.points, cells)
    assert volumes.min() > 0
    # The bend's cells fill a quarter annulus 1 to 2 in radius, 1 high; the inlet a unit cube.
    assert volumes.sum() == pytest.approx(np.pi * (4 - 1) / 4 + 1, rel=2e-3)  # chords of the bend's arcs


def test_blocks_take_no_sampling_or_evaluation(tmp_path):
    bend = interpatch.build(BEND)
    with pytest.raises(interpatch.Error) as e:
        bend.write(tmp_path / "b.vtu", sampling={"u": {"count": 5}})
    assert e.value.code == "wrong_type" and "each block's" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        bend.evaluate([0.5], [0.5], [0.5])
    assert e.value.code == "wrong_type" and "2 volumes, not one" in str(e.value)
