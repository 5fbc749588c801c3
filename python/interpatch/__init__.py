"""interpatch: interpolating curves, surfaces and solids, evaluated exactly.

Build any spec of the command line (docs/spec-format.md) from a dict or a file and
evaluate it into NumPy arrays::

    import numpy as np
    import interpatch
    s = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0],
                          "p10": [1, 0, 0], "p11": [1, 1, 1]})
    pts = s.evaluate(np.linspace(0, 1, 100), np.linspace(0, 1, 50))  # shape (100, 50, 3)

Errors raise interpatch.Error (a ValueError) whose .code names the problem
("zero_chord", "network_gap", ...) with the command line's message.
"""

from . import _specs
from ._core import ERROR_CODES, Construction, Curve, Error, Surface, Volume
from ._specs import *  # the keyword constructors and build, as _specs.__all__ names them

__version__ = "@PROJECT_VERSION@"
# A constructor named in _specs.__all__ is exported without editing this file.
__all__ = ["Error", "ERROR_CODES", "Construction", "Surface", "Volume", "Curve"] + _specs.__all__ + ["__version__"]
