#!/usr/bin/python3
"""Writes the seed corpora of the fuzz targets (tests/fuzz/corpus/<target>/) and the
data files specs may name (tests/fuzz/data/): the checked-in examples plus small
valid and invalid inputs for every branch of the readers. Run from anywhere:
    /usr/bin/python3 tests/fuzz/make_corpus.py
"""
import pathlib
import shutil

import numpy as np

here = pathlib.Path(__file__).resolve().parent
examples = here.parent.parent / "examples"
corpus = {t: here / "corpus" / t for t in ("spec", "npy", "csv")}
data = here / "data"
for d in (*corpus.values(), data):
    d.mkdir(parents=True, exist_ok=True)

for f in examples.glob("*.json"):
    shutil.copy(f, corpus["spec"] / f.name)
for name in ("half_cylinder.npy", "twisted_strip.csv"):
    shutil.copy(examples / name, data / name)
shutil.copy(examples / "half_cylinder.npy", corpus["npy"] / "half_cylinder_f8.npy")
shutil.copy(examples / "twisted_strip.csv", corpus["csv"] / "twisted_strip.csv")


def raw_npy(descr, shape, payload):
    """A version 1.0 .npy with the given header fields and data bytes, as NumPy pads it."""
    hdr = ("{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, shape)).encode()
    hdr += b" " * (64 - (10 + len(hdr) + 1) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + len(hdr).to_bytes(2, "little") + hdr + payload


g = np.load(examples / "half_cylinder.npy")
npy = corpus["npy"]
np.save(npy / "f4_fortran.npy", np.asfortranarray(g[:3, :4].astype("<f4")))
np.save(npy / "f8_big_endian.npy", g[:2, :3].astype(">f8"))
np.save(npy / "volume_2x2x2.npy", np.arange(24, dtype="<f8").reshape(2, 2, 2, 3))
np.save(npy / "list_of_points.npy", np.arange(6, dtype="<f8").reshape(2, 3))
with open(npy / "version_2.npy", "wb") as f:
    np.lib.format.write_array(f, np.arange(12, dtype="<f8").reshape(2, 2, 3), version=(2, 0))
(npy / "bad_magic.npy").write_bytes(b"\x93NUMPX\x01\x00\x10\x00{'descr': '<f8'}")
(npy / "int_dtype.npy").write_bytes(raw_npy("<i4", "(2, 3)", bytes(24)))
(npy / "truncated.npy").write_bytes(raw_npy("<f8", "(4, 3)", bytes(40)))
(npy / "extra_data.npy").write_bytes(raw_npy("<f8", "(1, 3)", bytes(32)))
(npy / "huge_shape.npy").write_bytes(raw_npy("<f8", "(100000000000, 100000000000, 3)", bytes(24)))

csv = corpus["csv"]
(csv / "header_crlf.csv").write_bytes(b"x,y,z\r\n0,0,0\r\n1,0.5,2e-3\r\n")
(csv / "bom_comment_quotes.csv").write_bytes("\ufeff# x y z\n\"1\", +2 ,\t3\n\n-4,5.5e10,-0\n".encode())
(csv / "not_a_number.csv").write_text("0,0,0\n1,abc,2\n")
(csv / "not_finite.csv").write_text("0,0,0\n1,nan,2\n1,inf,1e999\n")
(csv / "field_count.csv").write_text("0,0\n1,2,3,4\n")
(csv / "underflow.csv").write_text("1e-400,-1e-400,0\n")

specs = {
    "invalid_json.json": '{"type": "interpolate",\n "points": [[[0,0,0]],]}',
    "nan_literal.json": '{"type":"interpolate","points":[[[0,0,0],[1,0,NaN]],[[0,1,0],[1,1,1]]]}',
    "unknown_type.json": '{"type":"coonz"}',
    "ragged.json": '{"type":"interpolate","points":[[[0,0,0],[1,0,0]],[[0,1,0]]]}',
    "zero_chord.json": '{"type":"interpolate","points":[[[0,0,0],[1,0,0]],[[0,0,0],[1,0,0]],[[0,1,0],[1,1,0]]]}',
    "knots_decreasing.json": '{"type":"ruled","curves":[{"bspline":{"degree":1,"knots":[0,0,0.7,0.3,1,1],'
    '"control_points":[[0,0,0],[1,0,0],[2,0,0],[3,0,0]]}},{"line":[[0,1,0],[3,1,0]]}]}',
    "rational.json": '{"type":"ruled","curves":[{"bspline":{"degree":2,"knots":[0,0,0,1,1,1],'
    '"control_points":[[1,0,0],[1,1,0],[0,1,0]],"weights":[1,0.7071067811865476,1]}},{"line":[[0,0,1],[1,0,1]]}]}',
    "hermite_params.json": '{"type":"ruled","curves":[{"hermite":{"points":[[0,0,0],[1,1,0],[2,0,0]],'
    '"params":[0,0.3,1],"tangents":[[1,0,0],[1,0,0],[1,0,0]]}},'
    '{"interpolate":[[0,1,0],[1,2,0],[2,1,1]],"degree":2,"param":"centripetal"}]}',
    "csv_reference.json": '{"type":"interpolate","points":{"csv":"twisted_strip.csv","shape":[5,9]},'
    '"param":"uniform","degree":[2,3]}',
    "npy_reference_volume.json": '{"type":"interpolate_volume","points":{"npy":"half_cylinder.npy"}}',
    "huge_degree.json": '{"type":"interpolate","points":[[[0,0,0],[1,0,0]],[[0,1,0],[1,1,0]]],"degree":[1000000,1]}',
}
for name, text in specs.items():
    (corpus["spec"] / name).write_text(text)

# .npz archives of exact forms: as numpy.savez lays them out (ZIP64 local headers,
# as NumPy always asks for), with fixed dates so that the files do not change.
import io
import zipfile


def npz_bytes(arrays, compress=False):
    out = io.BytesIO()
    method = zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED
    with zipfile.ZipFile(out, "w", compression=method) as z:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = method
            with z.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a))
    return out.getvalue()


def with_zip64_end(zip_bytes):
    """The same archive with a ZIP64 end record and locator, the end record's fields escaped."""
    end = zip_bytes.rfind(b"PK\x05\x06")
    entries = int.from_bytes(zip_bytes[end + 10:end + 12], "little")
    size = int.from_bytes(zip_bytes[end + 12:end + 16], "little")
    offset = int.from_bytes(zip_bytes[end + 16:end + 20], "little")
    le = lambda v, n: v.to_bytes(n, "little")
    end64 = (b"PK\x06\x06" + le(44, 8) + le(45, 2) + le(45, 2) + le(0, 4) + le(0, 4) + le(entries, 8) + le(entries, 8)
             + le(size, 8) + le(offset, 8))
    locator = b"PK\x06\x07" + le(0, 4) + le(end, 8) + le(1, 4)
    tail = b"PK\x05\x06" + le(0, 4) + b"\xff\xff" * 2 + b"\xff\xff\xff\xff" * 2 + le(0, 2)
    return zip_bytes[:end] + end64 + locator + tail


npz = here / "corpus" / "npz"
npz.mkdir(parents=True, exist_ok=True)
k2 = np.array([0, 0, 1, 1], dtype="<f8")
bilinear = {"degree": np.array([1, 1], dtype="<i8"), "knots_u": k2, "knots_v": k2,
            "control_points": np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]], dtype="<f8"),
            "periodic": np.zeros(2, dtype=bool)}
(npz / "bilinear.npz").write_bytes(npz_bytes(bilinear))
(npz / "bilinear_zip64_end.npz").write_bytes(with_zip64_end(npz_bytes(bilinear)))
(npz / "bilinear_compressed.npz").write_bytes(npz_bytes(bilinear, compress=True))
(npz / "bilinear_truncated.npz").write_bytes(npz_bytes(bilinear)[:-40])
(npz / "missing_knots.npz").write_bytes(npz_bytes({k: v for k, v in bilinear.items() if k != "knots_v"}))
k3 = np.array([0, 0, 0, 1, 1, 1], dtype="<f8")
quarter = np.array([[[1, 0, 0], [1, 0, 1]], [[1, 1, 0], [1, 1, 1]], [[0, 1, 0], [0, 1, 1]]], dtype="<f8")
(npz / "rational_surface.npz").write_bytes(npz_bytes(
    {"degree": np.array([2, 1]), "knots_u": k3, "knots_v": k2, "control_points": quarter,
     "weights": np.array([[1, 1], [0.7071067811865476] * 2, [1, 1]]), "periodic": np.zeros(2, dtype=bool)}))
(npz / "volume_mixed_dtypes.npz").write_bytes(npz_bytes(
    {"degree": np.array([1, 1, 1], dtype="<i4"), "knots_u": k2.astype(">f8"), "knots_v": k2.astype("<f4"),
     "knots_w": k2, "control_points": np.asfortranarray(np.arange(24, dtype="<f8").reshape(2, 2, 2, 3)),
     "weights": np.full((2, 2, 2), 2.0), "periodic": np.zeros(3, dtype=bool)}))
(npz / "periodic.npz").write_bytes(npz_bytes({**bilinear, "periodic": np.array([True, False])}))
(npz / "nan_point.npz").write_bytes(npz_bytes(
    {**bilinear, "control_points": np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, np.nan], [1, 1, 1]]])}))
