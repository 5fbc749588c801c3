"""Hexahedral meshes read back by the programs solver set-ups use: meshio reads the
.vtu and .msh files, Gmsh's own Python API the .msh with its physical groups. Cells
are checked here: their count, their nodes on the volume's grid, and their volume
positive (a left-handed volume's cells turned over). Run by CTest (python_module)
with PYTHONPATH, INTERPATCH_CLI and INTERPATCH_EXAMPLES set."""

import json
import os
import signal

import meshio
import numpy as np
import pytest

import interpatch

EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))
DUCT = os.path.join(EXAMPLES, "duct_graded.json")


def _hex_volumes(points, cells):
    """Each hexahedron's volume, by its five tetrahedra (exact for flat faces, and
    positive for a cell of right-handed nodes in VTK order)."""
    p = points[cells]
    tets = ((0, 1, 3, 4), (1, 2, 3, 6), (1, 4, 5, 6), (3, 4, 6, 7), (1, 3, 4, 6))
    vol = 0
    for a, b, c, d in tets:
        vol = vol + np.einsum("ij,ij->i", p[:, b] - p[:, a], np.cross(p[:, c] - p[:, a], p[:, d] - p[:, a])) / 6
    return vol


def _duct(mirror):
    """The duct at even steps; mirrored in z, a left-handed volume."""
    with open(DUCT) as f:
        spec = json.load(f)
    del spec["sampling"]
    if mirror:
        for s in spec["sections"]:
            for corner in ("p00", "p01", "p10", "p11"):
                s[corner][2] = -s[corner][2]
    return interpatch.build(spec)


@pytest.mark.parametrize("mirror", [False, True])
def test_vtu_and_msh_read_back_by_meshio(tmp_path, mirror):
    duct = _duct(mirror)
    assert (duct.info()["jacobian"]["inverted_cells"] > 0) == mirror
    nodes = duct.evaluate(*duct.mesh_params(res=(9, 7, 11)))
    for ext in (".vtu", ".msh"):
        out = tmp_path / ("duct" + ext)
        duct.write(out, res=(9, 7, 11))
        m = meshio.read(out)
        assert len(m.points) == 9 * 7 * 11
        assert np.array_equal(np.sort(m.points, axis=0), np.sort(nodes.reshape(-1, 3), axis=0))
        hexes = m.get_cells_type("hexahedron")
        assert len(hexes) == 8 * 6 * 10
        vol = _hex_volumes(m.points, hexes)
        assert (vol > 0).all(), f"{ext}: {np.sum(vol <= 0)} cells of no or negative volume"
        assert vol.sum() == pytest.approx(3 * np.pi / 4, rel=0.05)  # a quarter annulus 1 to 2, 1 high
        if ext == ".vtu":
            assert "jacobian" in m.point_data


def _gmsh():
    """Gmsh's module, imported here and not at collection: importing it sets SIGINT to
    the default action (Gmsh puts Python's handler back only at finalize), which would
    take Ctrl-C from the KeyboardInterrupt tests of other files."""
    handler = signal.getsignal(signal.SIGINT)
    try:
        import gmsh
    finally:
        signal.signal(signal.SIGINT, handler)
    return gmsh


def test_msh_physical_groups_read_by_gmsh(tmp_path):
    gmsh = _gmsh()
    out = tmp_path / "duct.msh"
    _duct(False).write(out, res=(5, 4, 6))
    gmsh.initialize(["-v", "0"])
    try:
        gmsh.open(str(out))
        groups = {gmsh.model.getPhysicalName(d, t): (d, t) for d, t in gmsh.model.getPhysicalGroups()}
        assert set(groups) == {"u0", "u1", "v0", "v1", "w0", "w1", "volume"}
        sizes = {"u0": 3 * 5, "u1": 3 * 5, "v0": 4 * 5, "v1": 4 * 5, "w0": 4 * 3, "w1": 4 * 3}
        for name, (dim, tag) in groups.items():
            entities = gmsh.model.getEntitiesForPhysicalGroup(dim, tag)
            count = sum(len(t) for e in entities for t in gmsh.model.mesh.getElements(dim, e)[1])
            assert count == (sizes[name] if name != "volume" else 4 * 3 * 5), name
        tags, coords, _ = gmsh.model.mesh.getNodes()
        assert len(tags) == 5 * 4 * 6
    finally:
        gmsh.finalize()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
