"""`pip install .`: the Python module and the interpatch command, built by CMake.

    /usr/bin/python3 -m venv --system-site-packages V
    V/bin/pip install --no-build-isolation .

installs the package interpatch (the compiled _core, the .pyi stubs, py.typed) into V
and the command into V/bin. The CMake tree is build/temp.*/cmake; with
INTERPATCH_CMAKE_BUILD_DIR naming a configured tree (build/release) the module and
the command are built there instead, as they are for the tests, without configuring
it again. A source tree without viewer/node_modules gets three.js as `make build`
gets it (npm ci, or tools/fetch_viewer_deps.py without npm): the library embeds it
in the pages `interpatch view` writes.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.install_scripts import install_scripts

ROOT = Path(__file__).resolve().parent


def version():
    """The version CMake's project() declares, so that the two cannot differ."""
    return re.search(r"project\(interpatch VERSION (\S+)", (ROOT / "CMakeLists.txt").read_text()).group(1)


def run(*command):
    print("interpatch:", " ".join(str(c) for c in command), flush=True)
    subprocess.run([str(c) for c in command], check=True)


def three_js():
    """viewer/node_modules as `make build` makes it: the library embeds three.js."""
    if (ROOT / "viewer" / "node_modules" / "three" / "package.json").exists():
        return
    if shutil.which("npm"):
        run("npm", "ci", "--prefix", ROOT / "viewer", "--no-audit", "--no-fund")
    else:
        run(sys.executable, ROOT / "tools" / "fetch_viewer_deps.py", ROOT / "viewer")


class CMakeBuild(build_ext):
    """Builds interpatch._core and the command with CMake and lays out the package."""

    def build_extension(self, ext):
        given = os.environ.get("INTERPATCH_CMAKE_BUILD_DIR")
        if given:
            tree = Path(given).resolve()
        else:
            three_js()
            tree = Path(self.build_temp).resolve() / "cmake"
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            # The module and the command alone: no tests, no install rules, no MPI
            # (the command's MPI module has no place in a virtual environment).
            run("cmake", "-S", ROOT, "-B", tree, *generator, "-DCMAKE_BUILD_TYPE=Release",
                "-DINTERPATCH_BUILD_TESTS=OFF", "-DINTERPATCH_INSTALL=OFF", "-DINTERPATCH_MPI=OFF",
                "-DINTERPATCH_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        run("cmake", "--build", tree, "--target", "interpatch_python", "interpatch_cli", "-j", jobs)

        package = tree / "python" / "interpatch"
        if not package.is_dir():
            sys.exit(f"interpatch: {package} was not built: CMake found no Python headers or pybind11 for "
                     f"{sys.executable} (Debian: python3-dev, pybind11-dev)")
        target = Path(self.get_ext_fullpath(ext.name)).parent
        target.mkdir(parents=True, exist_ok=True)
        for f in package.iterdir():
            if f.is_file():
                shutil.copy2(f, target / f.name)
        # The command goes where install_scripts takes the scripts from.
        scripts = Path(self.get_finalized_command("build_scripts").build_dir)
        scripts.mkdir(parents=True, exist_ok=True)
        shutil.copy2(tree / "interpatch", scripts / "interpatch")


class InstallCommand(install_scripts):
    """Installs the command beside the scripts: it is built, not listed in setup(scripts=...)."""

    def run(self):
        super().run()
        self.mkpath(self.install_dir)
        installed, _ = self.copy_file(os.path.join(self.build_dir, "interpatch"), self.install_dir)
        self.outfiles.append(installed)


setup(
    version=version(),
    ext_modules=[Extension("interpatch._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild, "install_scripts": InstallCommand},
)
