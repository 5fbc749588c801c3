"""What the suite runs against: the interpatch module Python imports (CTest's
python_module puts the build tree's first with PYTHONPATH; otherwise the installed
package), and the command INTERPATCH_CLI names, else the one `pip install .` put
beside this Python, else `interpatch` on PATH."""

import os
import sys

beside = os.path.join(os.path.dirname(sys.executable), "interpatch")
if "INTERPATCH_CLI" not in os.environ and os.access(beside, os.X_OK):
    os.environ["INTERPATCH_CLI"] = beside


def pytest_report_header(config):
    import interpatch
    return (f"interpatch {interpatch.__version__} from {os.path.dirname(interpatch.__file__)}; "
            f"command {os.environ.get('INTERPATCH_CLI', 'interpatch (PATH)')}")
