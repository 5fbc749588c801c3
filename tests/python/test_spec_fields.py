"""The keyword constructors (interpatch/_specs.py) held to the spec reader's own
field lists (_core.spec_fields(), the table in src/io/spec/forms.hpp), and the
package's type stubs to what it has. The constructors are written by hand, not
generated from that table: their arguments are not the fields one for one (coons
takes four curves for "boundary", trilinear one (2, 2, 2, 3) array for eight corner
fields, ruled c0 and c1 for "curves"), each field is converted its own way (arrays
passed in memory, points as lists, knots as floats), and the table holds names only.
So this test makes the drift fail instead.

What a constructor writes is learnt from the examples in its docstring, run as
doctests with `np` and `interpatch` in their namespace: every spec a call hands the
reader is caught on its way (the last one of a call is its own; the ones before are
curves built for its arguments), with the keywords the call gave. It fails on an
example whose output differs, a constructor without examples or with a keyword its
examples never give, a reader type or field no constructor writes, and a constructor
writing a field the reader does not know (the reader would only warn).

The constructors carry their annotations (__init__.pyi star-imports _specs); the
compiled module's stub _core.pyi must declare what _core has and nothing else, and
__init__.pyi re-export every name of interpatch.__all__."""

import ast
import doctest
import functools
import inspect
import os
import typing
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
import pytest

import interpatch
from interpatch import _core, _specs, _volumes

# The modules that define the keyword constructors; _specs exports them all.
DEFINED_IN = {_specs.__name__, _volumes.__name__}

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
# as files (the constructors pass NumPy arrays in memory, {"array": NAME}), and a
# direction of a sampling, which write() and mesh_params() take (test_grading.py).
NOT_CONSTRUCTED_KINDS = {"points", "sampling"}


def public_functions():
    """The public functions _specs has (defined there or in _volumes): the keyword
    constructors and build()."""
    return sorted(name for name, f in vars(_specs).items()
                  if inspect.isfunction(f) and f.__module__ in DEFINED_IN and not name.startswith("_"))


def constructors():
    """The public functions of _specs but build(), which takes any spec as it is."""
    return sorted(name for name in interpatch.__all__
                  if name != "build" and inspect.isfunction(getattr(interpatch, name))
                  and getattr(interpatch, name).__module__ in DEFINED_IN)


@dataclass
class Call:
    """One call of a public function of _specs during the examples."""
    name: str
    example_of: str  # the function whose docstring's examples made the call
    keywords: set  # the parameters it was given, by name or by position
    spec: Optional[dict]  # the last spec handed to the reader during the call: its own


@dataclass
class Examples:
    calls: list = field(default_factory=list)
    tests: dict = field(default_factory=dict)  # name: (number of examples, failed, the runner's report)


def recorded(name: str, f: Any, seen: Examples, built: list, running: list) -> Any:
    signature = inspect.signature(f)

    @functools.wraps(f)
    def call(*args, **kwargs):
        given = set(signature.bind(*args, **kwargs).arguments)
        start = len(built)
        try:
            return f(*args, **kwargs)
        finally:
            seen.calls.append(Call(name, running[0], given, built[-1] if len(built) > start else None))

    return call


@pytest.fixture(scope="module")
def examples():
    """Every public function's docstring examples, run with interpatch's functions
    recording their calls and _core.build the specs it is handed (then built)."""
    seen, built, running = Examples(), [], [None]
    real_build = _core.build

    def recording_build(spec, base_dir, arrays):
        built.append(spec)
        return real_build(spec, base_dir, arrays)

    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_core, "build", recording_build)
        for name in _specs.__all__:
            mp.setattr(interpatch, name, recorded(name, getattr(_specs, name), seen, built, running))
        for name in _specs.__all__:
            running[0] = name
            f = getattr(_specs, name)
            tests = finder.find(f, name, module=inspect.getmodule(f), globs={"np": np, "interpatch": interpatch})
            report = []
            results = [runner.run(test, out=report.append) for test in tests]
            seen.tests[name] = (sum(r.attempted for r in results), sum(r.failed for r in results), "".join(report))
    return seen


def own_calls(examples, name):
    """The calls of `name` its own examples made."""
    return [c for c in examples.calls if c.name == name and c.example_of == name]


def written(spec):
    """(form, fields) of a spec a constructor handed the reader."""
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
    assert set(forms) == {"type", "curve", "points", "sampling"}
    # The types the reader names when it refuses an unknown one are the table's.
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "no_such_type"})
    assert str(e.value).split("known types: ")[1].split(", ") == list(forms["type"])
    assert forms["type"]["bilinear"] == ("type", "p00", "p01", "p10", "p11")
    assert forms["curve"]["bspline"][0] == "degree"


def test_interpatch_exports_every_public_function_of_specs():
    unnamed = set(public_functions()) - set(_specs.__all__)
    assert not unnamed, f"_specs.__all__ does not name {sorted(unnamed)}, so interpatch does not export them"
    stray = set(_specs.__all__) - set(public_functions())
    assert not stray, f"_specs.__all__ names {sorted(stray)}, which are no public functions of _specs"
    assert constructors() == sorted(set(_specs.__all__) - {"build"})
    for name in _specs.__all__:
        assert name in interpatch.__all__ and getattr(interpatch, name) is getattr(_specs, name), name


def test_every_example_gives_its_output(examples):
    for name in public_functions():
        attempted, failed, report = examples.tests.get(name, (0, 0, ""))
        assert attempted, f"{name} has no examples (>>> lines) in its docstring"
        assert not failed, f"the examples of {name}:\n{report}"


def test_every_constructor_is_exercised_with_every_keyword(examples):
    for name in public_functions():
        params = set(inspect.signature(getattr(_specs, name)).parameters)
        given = set().union(*(c.keywords for c in own_calls(examples, name)))
        assert given == params, f"the examples of {name} never give {sorted(params - given)}"


def test_constructors_write_only_reader_fields(reader, examples):
    for name in constructors():
        assert any(c.spec is not None for c in own_calls(examples, name)), f"the examples of {name} build nothing"
    for c in examples.calls:
        if c.name == "build" or c.spec is None:
            continue
        form, fields = written(c.spec)
        assert form in reader, f"{c.name} writes a {form[0]} {form[1]!r}, which the reader does not know"
        unknown = fields - reader[form]
        assert not unknown, f"{c.name} writes fields the reader of {form[1]!r} does not know: {sorted(unknown)}"


def test_every_reader_form_and_field_has_a_keyword(reader, examples):
    made = {}
    for name in constructors():
        for c in own_calls(examples, name):
            if c.spec is not None:
                form, fields = written(c.spec)
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


def stub(name):
    with open(os.path.join(os.path.dirname(interpatch.__file__), name), encoding="utf-8") as f:
        return ast.parse(f.read())


def core_stub_names():
    """The names _core.pyi declares: classes, functions and annotated constants, and
    its own type aliases (_Array, ...: assignments to a private name)."""
    declared, aliases = set(), set()
    for node in stub("_core.pyi").body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            declared.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            declared.add(node.target.id)
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                (aliases if target.id.startswith("_") else declared).add(target.id)
    return declared, aliases


def test_the_package_stub_star_imports_the_constructors():
    star = [node for node in stub("__init__.pyi").body if isinstance(node, ast.ImportFrom) and node.level == 1
            and node.module == "_specs" and [a.name for a in node.names] == ["*"]]
    assert star, "__init__.pyi has no `from ._specs import *`"


def test_every_public_function_is_annotated():
    for name in public_functions():
        f = getattr(_specs, name)
        signature = inspect.signature(f)
        bare = [p.name for p in signature.parameters.values() if p.annotation is inspect.Parameter.empty]
        assert not bare, f"{name}: no annotation on {bare}"
        assert signature.return_annotation is not inspect.Signature.empty, f"{name}: no return annotation"
        # The annotations name types _specs has (they are strings until evaluated).
        hints = typing.get_type_hints(f)
        assert set(hints) == set(signature.parameters) | {"return"}, name


def test_the_core_stub_declares_what_core_has():
    has = {name for name in dir(_core) if not (name.startswith("__") and name.endswith("__"))}
    declared, aliases = core_stub_names()
    assert not has - declared, f"_core.pyi does not declare {sorted(has - declared)}"
    assert not declared - has, f"_core.pyi declares what _core does not have: {sorted(declared - has)}"
    assert not aliases & has, f"_core.pyi declares {sorted(aliases & has)} as type aliases"


def test_the_package_stub_reexports_every_exported_name():
    core_declared, _ = core_stub_names()
    exported = set()
    for node in stub("__init__.pyi").body:
        if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module == "_specs":
            if [a.name for a in node.names] == ["*"]:
                exported.update(_specs.__all__)
        elif isinstance(node, ast.ImportFrom) and node.level == 1 and node.module == "_core":
            for a in node.names:
                assert a.name in core_declared, f"__init__.pyi imports {a.name}, which _core.pyi does not declare"
                # Only `import X as X` re-exports X from a stub.
                assert a.asname == a.name, f"__init__.pyi imports {a.name} from _core without re-exporting it"
                exported.add(a.name)
        elif isinstance(node, ast.AnnAssign):
            exported.add(node.target.id)
    assert not set(interpatch.__all__) - exported, \
        f"__init__.pyi does not re-export {sorted(set(interpatch.__all__) - exported)}"
    assert not exported - set(interpatch.__all__), \
        f"__init__.pyi exports what interpatch.__all__ does not name: {sorted(exported - set(interpatch.__all__))}"
