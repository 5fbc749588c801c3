"""The keyword constructors (interpatch/_specs.py) and their stubs (__init__.pyi)
held to the spec reader's own field lists (_core.spec_fields(), the table in
src/io/spec/forms.hpp). The constructors are written by hand, not generated from
that table: their arguments are not the fields one for one (coons takes four curves
for "boundary", trilinear one (2, 2, 2, 3) array for eight corner fields, ruled c0
and c1 for "curves"), each field is converted its own way (arrays passed in memory,
points as lists, knots as floats), and the table holds names only. So this test
makes the drift fail instead: a reader type or field no constructor writes, a
constructor writing a field the reader does not know (the reader would only warn),
or a stub whose signature is not the function's."""

import ast
import inspect
import os

import numpy as np
import pytest

import interpatch
from interpatch import _core, _specs

# Reader types no keyword constructor makes; build() takes them as dicts.
NO_CONSTRUCTOR = {
    # Exact forms: their fields are the arrays of Surface/Volume.to_bspline() under
    # other names (knots_u, knots_v, ... against "knots": {"u", "v"}), and the files
    # build and `interpatch build` write read back as specs already.
    ("type", "bspline_surface"): "an exact form; build() of a dict or of the file `build` wrote",
    ("type", "bspline_volume"): "an exact form; build() of a dict or of the file `build` wrote",
}

# Reader fields the constructor of their form does not offer as keywords.
NOT_OFFERED = {
    # The Hermite-blended Coons patch's cross-boundary derivatives: four more curves
    # and four corner twists; coons() offers the boundary and the blending only.
    ("type", "coons"): {"cross_derivatives", "twists", "twist_correction"},
    ("type", "coons_volume"): {"cross_derivatives"},
}

# Reader forms the keyword constructors have no use for at all: point arrays given
# as files (the constructors pass NumPy arrays in memory, {"array": NAME}).
NOT_CONSTRUCTED_KINDS = {"points"}

GRID = np.zeros((4, 4, 3))
GRID3 = np.zeros((3, 3, 3, 3))
PTS = np.zeros((4, 3))
P = [0.0, 0.0, 0.0]

# One call per public constructor, every keyword given, so that every keyword shows
# which field it writes.
CALLS = {
    "bilinear": dict(p00=P, p01=P, p10=P, p11=P),
    "ruled": dict(c0=PTS, c1=PTS),
    "coons": dict(v0=PTS, v1=PTS, u0=PTS, u1=PTS, blending="linear", tolerance=0.1),
    "curve_network": dict(u_curves=[PTS], v_curves=[PTS], method="gordon", u_params=[0.0], v_params=[0.0],
                          tolerance=0.1, periodic=(False, False)),
    "hermite_patch": dict(corners={"p00": {"p": P}}),
    "interpolate_surface": dict(points=GRID, degree=3, param="chord", periodic=(False, False)),
    "approximate_surface": dict(points=GRID, degree=3, param="chord", periodic=(False, False), control_points=(4, 4),
                                tolerance=0.1, smoothing=1.0, weights=np.ones((4, 4))),
    "interpolate_volume": dict(points=GRID3, degree=2, param="chord", periodic=(False, False, False)),
    "approximate_volume": dict(points=GRID3, degree=2, param="chord", periodic=(False, False, False),
                               control_points=(3, 3, 3), tolerance=0.1, smoothing=1.0, weights=np.ones((3, 3, 3))),
    "trilinear": dict(corners=np.zeros((2, 2, 2, 3))),
    "coons_volume": dict(faces={"u0": GRID}, blending="linear", tolerance=0.1),
    "hermite_volume": dict(corners=[{"p": P}]),
    "interpolate_curve": dict(points=PTS, degree=3, param="chord", periodic=True, start_derivative=P,
                              end_derivative=P),
    "approximate_curve": dict(points=PTS, degree=3, param="chord", periodic=True, control_points=4, tolerance=0.1,
                              smoothing=1.0, weights=np.ones(4)),
    "bspline_curve": dict(degree=1, knots=[0, 0, 1, 1], control_points=np.zeros((2, 3)), weights=[1, 1],
                          periodic=True),
    "hermite_curve": dict(points=PTS, tangents=PTS, params=[0, 1, 2, 3]),
    "line": dict(a=P, b=P),
}


def constructors():
    """The public functions of _specs but build(), which takes any spec as it is."""
    return sorted(name for name in interpatch.__all__
                  if name != "build" and inspect.isfunction(getattr(interpatch, name))
                  and getattr(interpatch, name).__module__ == _specs.__name__)


def written(name, monkeypatch):
    """(form, fields) the constructor `name` writes given every keyword: the spec it
    hands the reader, caught before it is built."""
    seen = []
    monkeypatch.setattr(_specs, "_build", lambda spec, base_dir, arrays: seen.append(spec))
    getattr(interpatch, name)(**CALLS[name])
    (spec,) = seen
    if "type" in spec:
        return ("type", spec["type"]), set(spec)
    (key,) = [k for k in spec if k in _core.spec_fields()["curve"]]
    # "bspline" and "hermite" hold their fields in an object under the key; the
    # other curve forms are fields beside it.
    fields = set(spec[key]) if key in ("bspline", "hermite") else set(spec)
    return ("curve", key), fields


@pytest.fixture(scope="module")
def reader():
    return {(kind, name): set(fields) for kind, forms in _core.spec_fields().items() for name, fields in forms.items()}


def test_the_reader_publishes_its_table():
    forms = _core.spec_fields()
    assert set(forms) == {"type", "curve", "points"}
    # The types the reader names when it refuses an unknown one are the table's.
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "no_such_type"})
    assert str(e.value).split("known types: ")[1].split(", ") == list(forms["type"])
    assert forms["type"]["bilinear"] == ("type", "p00", "p01", "p10", "p11")
    assert forms["curve"]["bspline"][0] == "degree"


def test_every_constructor_is_exercised_with_every_keyword():
    assert set(CALLS) == set(constructors())
    for name, kw in CALLS.items():
        params = inspect.signature(getattr(interpatch, name)).parameters
        assert set(kw) == set(params), name


def test_constructors_write_only_reader_fields(reader, monkeypatch):
    for name in constructors():
        form, fields = written(name, monkeypatch)
        assert form in reader, f"{name} writes a {form[0]} {form[1]!r}, which the reader does not know"
        unknown = fields - reader[form]
        assert not unknown, f"{name} writes fields the reader of {form[1]!r} does not know: {sorted(unknown)}"


def test_every_reader_form_and_field_has_a_keyword(reader, monkeypatch):
    made = {}
    for name in constructors():
        form, fields = written(name, monkeypatch)
        made.setdefault(form, set()).update(fields)
    for form, fields in sorted(reader.items()):
        if form[0] in NOT_CONSTRUCTED_KINDS:
            continue
        if form in NO_CONSTRUCTOR:
            assert form not in made, f"{form} has a constructor now: take it off NO_CONSTRUCTOR"
            continue
        assert form in made, f"the reader's {form[0]} {form[1]!r} has no keyword constructor in _specs.py"
        exempt = NOT_OFFERED.get(form, set())
        assert not exempt & made[form], f"{form}: {sorted(exempt & made[form])} offered now: take off NOT_OFFERED"
        missing = fields - made[form] - exempt
        assert not missing, f"no constructor of the reader's {form[0]} {form[1]!r} offers {sorted(missing)}"
    for form in list(NO_CONSTRUCTOR) + list(NOT_OFFERED):
        assert form in reader, f"{form} is no longer a reader form"
    for form, exempt in NOT_OFFERED.items():
        assert exempt <= reader[form], f"{form}: {sorted(exempt - reader[form])} are no longer reader fields"


def stub_functions():
    path = os.path.join(os.path.dirname(interpatch.__file__), "__init__.pyi")
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read())
    return {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}


REQUIRED = object()


def stub_signature(node):
    """(name, default) of each argument; REQUIRED where there is no default."""
    args = node.args.args
    defaults = [REQUIRED] * (len(args) - len(node.args.defaults)) + [ast.literal_eval(d) for d in node.args.defaults]
    return [(a.arg, d) for a, d in zip(args, defaults)]


def runtime_signature(f):
    return [(p.name, REQUIRED if p.default is inspect.Parameter.empty else p.default)
            for p in inspect.signature(f).parameters.values()]


def test_stubs_are_the_constructors_signatures():
    stubs = stub_functions()
    for name in constructors() + ["build"]:
        assert name in stubs, f"__init__.pyi has no stub of {name}"
        assert stub_signature(stubs[name]) == runtime_signature(getattr(interpatch, name)), name
    stray = {name for name in stubs if name not in interpatch.__all__}
    assert not stray, f"__init__.pyi has stubs of functions interpatch does not have: {sorted(stray)}"
