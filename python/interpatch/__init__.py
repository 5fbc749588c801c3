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

from ._core import ERROR_CODES, Construction, Curve, Error, Surface, Volume
from ._specs import (approximate_curve, approximate_surface, approximate_volume, bilinear, bspline_curve, build,
                     coons, coons_volume, curve_network, hermite_curve,
                     hermite_patch, hermite_volume, interpolate_curve, interpolate_surface, interpolate_volume, line,
                     ruled, trilinear)

__version__ = "@PROJECT_VERSION@"
__all__ = ["Error", "ERROR_CODES", "Construction", "Surface", "Volume", "Curve", "build", "interpolate_surface", "bilinear", "ruled", "coons",
           "curve_network", "hermite_patch", "interpolate_volume", "trilinear", "coons_volume", "hermite_volume",
           "interpolate_curve", "bspline_curve", "hermite_curve", "line",
           "approximate_surface", "approximate_volume", "approximate_curve",
           "__version__"]
