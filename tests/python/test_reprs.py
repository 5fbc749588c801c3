"""What the module shows of itself: every object's repr, and help(interpatch)."""

import os
import pydoc

import numpy as np

import interpatch

EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))


def test_every_object_names_its_type_degree_and_size():
    grid = np.stack(np.meshgrid(np.arange(30.0), np.arange(25.0), indexing="ij") + [np.zeros((30, 25))], axis=-1)
    corners = np.indices((2, 2, 2)).transpose(1, 2, 3, 0).astype(float)
    cases = [
        (interpatch.interpolate_surface(grid), "Surface(type='interpolate', degree=(3, 3), control_points=(30, 25))"),
        (interpatch.bilinear([0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 1]),
         "Surface(type='bilinear', degree=(1, 1), control_points=(2, 2))"),
        # A Coons patch's exact form is made on demand; its repr reads the knots alone.
        (interpatch.build(os.path.join(EXAMPLES, "coons.json")), "Surface(type='coons', degree=(3, 3), control_points=(7, 7))"),
        (interpatch.build(os.path.join(EXAMPLES, "coons_gregory.json")), "Surface(type='coons', exact_form=None)"),
        (interpatch.trilinear(corners), "Volume(type='trilinear', degree=(1, 1, 1), control_points=(2, 2, 2))"),
        (interpatch.build(os.path.join(EXAMPLES, "coons_volume.json")),
         "Volume(type='coons_volume', degree=(3, 3, 2), control_points=(7, 7, 3))"),
        (interpatch.interpolate_curve(np.arange(36.0).reshape(12, 3) ** 1.5),
         "Curve(type='interpolate', degree=3, control_points=12)"),
        (interpatch.interpolate_curve([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 0, 0]], periodic=True),
         "Curve(type='interpolate', degree=3, control_points=4)"),
        (interpatch.line([0, 0, 0], [1, 0, 0]), "Curve(type='line', degree=1, control_points=2)"),
        (interpatch.hermite_curve([[0, 0, 0], [1, 1, 0], [2, 0, 0]]), "Curve(type='hermite', degree=3, control_points=6)"),
        (interpatch.bspline_curve(2, [0, 0, 0, 1, 1, 1], [[1, 0, 0], [1, 1, 0], [0, 1, 0]], weights=[1, 0.5, 1]),
         "Curve(type='bspline', degree=2, control_points=3)"),
    ]
    for obj, want in cases:
        assert repr(obj) == want
    e = interpatch.Error("x")
    assert repr(e) == "Error('x')" and type(e).__module__ == "interpatch"


def test_help_is_a_reference():
    text = pydoc.render_doc(interpatch, renderer=pydoc.plaintext)
    # Every class and function is there with its arguments, and the shapes it gives.
    for name in interpatch.__all__:
        if name not in ("__version__", "ERROR_CODES"):
            assert name in text, name
    for phrase in ("evaluate(self: interpatch._core.Curve, ts: object)", "(len(ts), 3)",
                   "derivatives(self: interpatch._core.Curve, ts: object, order: int = 1)", "(len(ts), order + 1, 3)",
                   "(len(us), len(vs), 3)", "(len(us), len(vs), len(ws), 3)", "Example"):
        assert phrase in text, phrase
    for cls in (interpatch.Surface, interpatch.Volume, interpatch.Curve):
        assert "Example" in cls.__doc__, cls
        for name, member in vars(cls).items():
            if not name.startswith("_") and callable(member):
                # pybind11 puts the signature first; the doc is what follows it.
                doc = (member.__doc__ or "").split("\n", 1)
                assert len(doc) == 2 and doc[1].strip(), f"{cls.__name__}.{name} has no doc"


def test_the_stubs_declare_what_the_module_has():
    import ast
    from interpatch import _specs, _volumes
    # The compiled module's classes in _core.pyi; the keyword constructors annotated
    # where _specs.py and _volumes.py define them (__init__.pyi re-exports both:
    # test_spec_fields.py).
    stub = ast.parse(open(os.path.join(os.path.dirname(interpatch.__file__), "_core.pyi")).read())
    declared = {n.name: n for n in stub.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    for module in (_specs, _volumes):
        specs = ast.parse(open(module.__file__).read())
        declared.update({n.name: n for n in specs.body if isinstance(n, ast.FunctionDef) and n.name in _specs.__all__})
    for name in interpatch.__all__:
        if name not in ("__version__", "ERROR_CODES"):
            assert name in declared, f"{name} is not in the stubs"
    for cls in (interpatch.Construction, interpatch.Surface, interpatch.Volume, interpatch.Curve):
        members = {n.name for n in declared[cls.__name__].body if isinstance(n, ast.FunctionDef)}
        for name in vars(cls):
            if not name.startswith("_"):
                assert name in members, f"{cls.__name__}.{name} is not in the stubs"
