# Type stubs of the interpatch package: the compiled module's classes and constants
# (_core.pyi) and the keyword constructors, annotated in _specs.py.
from ._core import ERROR_CODES as ERROR_CODES
from ._core import Construction as Construction
from ._core import Curve as Curve
from ._core import Error as Error
from ._core import Surface as Surface
from ._core import Volume as Volume
from ._specs import *

__version__: str
