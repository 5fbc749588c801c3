"""Graded sampling from Python: a spec's "sampling" and write(sampling=...).

The meshes are read back by VTK's own reader, as a user's post-processing would read
them, and their cells measured here with NumPy. Run by CTest (python_module) with PYTHONPATH,
INTERPATCH_CLI and INTERPATCH_EXAMPLES set."""

import os
import subprocess

import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLStructuredGridReader

import interpatch

CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))
DUCT = os.path.join(EXAMPLES, "duct_graded.json")


def _grid(path, shape):
    """The points of a .vts as an (nu, nv, nw, 3) array: VTK orders them u fastest."""
    reader = vtkXMLStructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    assert grid.GetDimensions() == shape
    points = vtk_to_numpy(grid.GetPoints().GetData())
    return points.reshape(shape[::-1] + (3,)).transpose(2, 1, 0, 3)


def _cells(x, axis):
    return np.linalg.norm(np.diff(x, axis=axis), axis=-1)


def test_the_duct_meets_its_first_cells_and_grows_smoothly(tmp_path):
    duct = interpatch.build(DUCT)
    out = tmp_path / "duct.vts"
    duct.write(out)
    x = _grid(str(out), (41, 41, 61))
    u = _cells(x, 0)
    assert u[0].max() <= 1e-3 and u[0].max() >= 0.9e-3
    assert u[0].min() >= 0.9e-3
    growth = u[1:] / u[:-1]
    assert max(growth.max(), (1 / growth).max()) <= 1.3
    v = _cells(x, 1)
    assert v[:, 0].max() <= 2e-3 and v[:, -1].max() <= 2e-3
    # The command writes the same bytes.
    cli_out = tmp_path / "cli.vts"
    subprocess.run([CLI, "mesh", DUCT, "-o", str(cli_out)], check=True)
    assert cli_out.read_bytes() == out.read_bytes()
    info = duct.info()["sampling"]
    assert info["u"]["count"] == 41 and info["u"]["first"] == 1e-3
    assert info["u"]["achieved"]["first"] == pytest.approx(u[0].max(), rel=1e-12)
    assert info["w"]["achieved"]["growth"] == pytest.approx(1, abs=1e-2)
    # The quality of the same cells, in numpy from the written nodes: the first cells
    # along u, and det J at the corner (0, 0, 0) of every cell.
    mesh = duct.info()["mesh"]
    assert mesh["nodes"] == [41, 41, 61] and mesh["cells"] == 40 * 40 * 60
    assert mesh["end_cells"]["u"]["first"] == pytest.approx(u[0].max(), rel=1e-12)
    a, b, c = x[1:, :-1, :-1] - x[:-1, :-1, :-1], x[:-1, 1:, :-1] - x[:-1, :-1, :-1], x[:-1, :-1, 1:] - x[:-1, :-1, :-1]
    det = np.einsum("...i,...i", np.cross(a, b), c)
    assert det.min() > 0 and mesh["inverted_cells"] == 0
    assert mesh["det_j"]["min"] <= det.min() * (1 + 1e-9) and mesh["det_j"]["max"] >= det.max() * (1 - 1e-9)


def test_write_takes_a_sampling_for_one_mesh(tmp_path):
    box = interpatch.build({"type": "trilinear", **{
        f"p{i}{j}{k}": [2.0 * i, 1.0 * j, 3.0 * k] for i in (0, 1) for j in (0, 1) for k in (0, 1)}})
    out = tmp_path / "box.vts"
    box.write(out, sampling={"u": {"count": 11, "ratio": 4}, "w": {"count": 31, "first": 0.05, "last": 0.2}})
    x = _grid(str(out), (11, 33, 31))
    u = _cells(x, 0)[:, 0, 0]
    assert u[-1] / u[0] == pytest.approx(4, rel=1e-9)
    w = _cells(x, 2)[0, 0]
    assert w[0] == pytest.approx(0.05, rel=1e-9) and w[0] <= 0.05
    assert w[-1] == pytest.approx(0.2, rel=1e-9) and w[-1] <= 0.2
    # res overrides the counts, the grading stays.
    box.write(out, res=(21, 2, 7), sampling={"u": {"count": 11, "ratio": 4}})
    u = _cells(_grid(str(out), (21, 2, 7)), 0)[:, 0, 0]
    assert len(u) == 20 and u[-1] / u[0] == pytest.approx(4, rel=1e-9)


def test_every_field_of_a_direction_is_taken():
    fields = interpatch._core.spec_fields()["sampling"]["direction"]
    values = {"count": 31, "first": 0.01, "last": 0.02, "max_growth": 1.25}
    assert set(fields) == set(values) | {"ratio"}
    sheet = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0],
                              "p11": [1, 1, 0]})
    u, v = sheet.mesh_params(sampling={"u": values, "v": {"count": 5, "ratio": 0.5}})
    assert len(u) == 31 and u[1] == pytest.approx(0.01, rel=1e-9) and 1 - u[-2] == pytest.approx(0.02, rel=1e-9)
    steps = np.diff(u)
    assert max((steps[1:] / steps[:-1]).max(), (steps[:-1] / steps[1:]).max()) <= 1.25 * (1 + 1e-9)
    assert (v[-1] - v[-2]) / (v[1] - v[0]) == pytest.approx(0.5, rel=1e-9)
    assert np.array_equal(sheet.mesh_params(res=(3, 3))[0], [0, 0.5, 1])


def test_sampling_errors_carry_their_codes(tmp_path):
    sheet = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0],
                              "p11": [1, 1, 0]})
    with pytest.raises(interpatch.Error) as e:
        sheet.write(tmp_path / "s.vts", sampling={"w": {"count": 5}})
    assert e.value.code == "invalid_grading" and 'no direction "w"' in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        sheet.write(tmp_path / "s.vts", sampling={"u": {"count": 4, "first": 1e-3}})
    assert e.value.code == "too_few_points" and "would do" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        sheet.write(tmp_path / "s.json", sampling={"u": {"count": 4}})
    assert e.value.code == "wrong_type"
    assert not list(tmp_path.iterdir())  # nothing written
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0],
                          "p11": [1, 1, 0], "sampling": {"u": {"first": -1}}})
    assert e.value.code == "invalid_grading" and "/sampling/u/first" in str(e.value)


def test_write_a_polymesh_as_the_command_does(tmp_path):
    (tmp_path / "py" / "constant").mkdir(parents=True)
    (tmp_path / "cli" / "constant").mkdir(parents=True)
    duct = interpatch.build(DUCT)
    duct.write(tmp_path / "py" / "constant" / "polyMesh")
    subprocess.run([CLI, "mesh", DUCT, "-o", str(tmp_path / "cli" / "constant" / "polyMesh")], check=True)
    for name in ("points", "faces", "owner", "neighbour", "boundary"):
        py = (tmp_path / "py" / "constant" / "polyMesh" / name).read_bytes()
        assert py == (tmp_path / "cli" / "constant" / "polyMesh" / name).read_bytes(), name
    points = (tmp_path / "py" / "constant" / "polyMesh" / "points").read_text()
    assert "\n102541\n(" in points  # 41 x 41 x 61 nodes, each once
    sheet = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0],
                              "p11": [1, 1, 0]})
    with pytest.raises(interpatch.Error) as e:
        sheet.write(tmp_path / "py" / "constant" / "polyMesh")
    assert e.value.code == "wrong_type" and "holds the cells of a volume" in str(e.value)
