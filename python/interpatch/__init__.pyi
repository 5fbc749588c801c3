# Type stubs of the interpatch module.
from os import PathLike
from typing import Any, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Error(ValueError):
    """Bad input; .code names the problem (e.g. 'zero_chord')."""
    code: str

_Params = Union[Sequence[float], npt.ArrayLike]

class Surface:
    """A surface over [0, 1]²."""
    @property
    def type(self) -> str: ...
    def evaluate(self, us: _Params, vs: _Params) -> npt.NDArray[np.float64]:
        """Points at every (us[i], vs[j]): shape (len(us), len(vs), 3)."""
    def evaluate_derivatives(self, us: _Params, vs: _Params) -> npt.NDArray[np.float64]:
        """S, Su, Sv, Suu, Suv, Svv at every (us[i], vs[j]): shape (len(us), len(vs), 6, 3)."""
    def point(self, u: float, v: float) -> npt.NDArray[np.float64]: ...
    def normal(self, u: float, v: float) -> npt.NDArray[np.float64]: ...
    def curvature(self, u: float, v: float) -> dict[str, float]: ...
    def info(self) -> dict[str, Any]: ...

def build(spec: Union[dict[str, Any], str, PathLike[str]], base_dir: Union[str, PathLike[str]] = ".") -> Surface:
    """A spec as a dict, or the path of a spec file, built."""
