# `pip install .` as a Python user runs it, then the module's tests against the
# installed package from outside the source tree (CTest: python_pip_install).
#   cmake -DPYTHON=... -DSOURCE_DIR=... -DBINARY_DIR=... -DWORK=... -P pip_install.cmake
# The package is built in BINARY_DIR (INTERPATCH_CMAKE_BUILD_DIR, setup.py), whose
# module and command the build has already made, so the test costs seconds, not a
# second build.

function(step what)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc})")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(venv ${WORK}/venv)
step("making the virtual environment" ${PYTHON} -m venv --system-site-packages ${venv})
# Nothing from the network: the build backend and NumPy are Debian's (system site packages).
set(ENV{PIP_DISABLE_PIP_VERSION_CHECK} 1)
set(ENV{PIP_NO_INDEX} 1)
set(ENV{INTERPATCH_CMAKE_BUILD_DIR} ${BINARY_DIR})
step("pip install --no-build-isolation" ${venv}/bin/pip install --no-cache-dir --no-build-isolation ${SOURCE_DIR})
unset(ENV{INTERPATCH_CMAKE_BUILD_DIR})

# What a user of the package gets, and that it is this package Python imports.
step("the installed package" ${venv}/bin/python -c [=[
import os, sys
import interpatch
where = os.path.dirname(interpatch.__file__)
assert where.startswith(sys.prefix + os.sep), f"interpatch imported from {where}, not the environment {sys.prefix}"
for name in ("_specs.py", "_args.py", "__init__.pyi", "_core.pyi", "py.typed"):
    assert os.path.isfile(os.path.join(where, name)), f"{name} is not installed"
assert os.access(os.path.join(sys.prefix, "bin", "interpatch"), os.X_OK), "the interpatch command is not installed"
]=])

# The suite as a user runs it: no PYTHONPATH and no INTERPATCH_CLI, from a directory
# that holds no interpatch package of its own.
unset(ENV{PYTHONPATH})
unset(ENV{INTERPATCH_CLI})
unset(ENV{INTERPATCH_EXAMPLES})
step("the Python tests against the installed package"
     ${venv}/bin/python -m pytest -q -p no:cacheprovider ${SOURCE_DIR}/tests/python)
