# interpatch — the two commands (README): `make demo` and `make test`.
# Each installs what is missing from Debian's packages first.

SHELL := /bin/bash
# Three lists of Debian packages, by purpose (the README's "Dependencies" says the same).
# The build: `make demo`, `make build`, `make install`.
#   cmake ninja-build g++            the build (C++20, CMake presets; OpenMP is g++'s libgomp)
#   python3                          configure (the header and snippet checks), the Python module,
#                                    tools/fetch_viewer_deps.py
#   libcli11-dev                     the command line's option parser
#   nlohmann-json3-dev               specs and JSON output (the io library only; the core needs none)
#   libeigen3-dev                    the sparse Cholesky decomposition of approximation's normal equations
#   pybind11-dev python3-dev         the Python module (import interpatch)
# and three.js for the viewer from the npm registry (viewer-deps, below): no Debian package.
BUILD_DEBS := cmake ninja-build g++ python3 libcli11-dev nlohmann-json3-dev libeigen3-dev \
        pybind11-dev python3-dev
# The tests: `make test` (and the targets that run tests or open a browser) adds these.
#   libgtest-dev libgmock-dev        the C++ tests
#   pkg-config                       the tests build a program against the installed .pc files
#   python3-numpy                    the reference-data script and the read-back checks
#   python3-scipy                    the closed-spline and least-squares reference data (tools/reference/)
#   python3-vtk9                     VTK's own readers read back the .vts/.vtk/.xyz files interpatch writes
#   python3-pytest                   the Python module's test suite
#   python3-hypothesis               its fuzz tests: random arrays into the constructors (tests/python/test_fuzz.py)
#   python3-matplotlib               the README's Python example, run by that suite
#   openfoam                         checkMesh and potentialFoam read the polyMesh meshes (tools/check_polymesh.py)
#   python3-meshio python3-gmsh      read the .vtu and .msh meshes back (tests/python/test_unstructured.py)
#   python3-venv python3-pip python3-setuptools python3-wheel
#                                    `pip install .` into a virtual environment, then the suite against it
#   libocct-*-dev                    OpenCASCADE reads back the STEP and IGES files
#   chromium chromium-driver python3-selenium   the viewer pages opened in a real browser (make test,
#                                    make pictures, make bench-viewer)
#   libopenmpi-dev openmpi-bin       MPI: eval and build split between processes (mpirun; docs/mpi.md) and their tests
TEST_DEBS := libgtest-dev libgmock-dev pkg-config python3-numpy python3-scipy python3-vtk9 \
        python3-pytest python3-hypothesis python3-matplotlib \
        python3-venv python3-pip python3-setuptools python3-wheel \
        libocct-data-exchange-dev libocct-modeling-algorithms-dev libocct-modeling-data-dev \
        libocct-foundation-dev \
        chromium chromium-driver python3-selenium libopenmpi-dev openmpi-bin openfoam \
        python3-meshio python3-gmsh
# Fuzzing: `make fuzz` and `make test-fuzz` add these to the test list.
#   clang libclang-rt-14-dev libomp-14-dev   libFuzzer (with its OpenMP) runs the fuzz targets
FUZZ_DEBS := clang libclang-rt-14-dev libomp-14-dev
# The benchmarks: `make bench` adds these.
#   libbenchmark-dev                 Google Benchmark (bench/interpatch_bench)
#   libocct-*-dev libsisl-dev        OpenCASCADE and SISL race interpatch (bench/compare);
#                                    OpenCASCADE's ThruSections lofts (bench/loft_compare)
#   python3-matplotlib               make bench draws docs/bench_interpolation.png; its
#                                    terrain DEM feeds bench/scattered_terrain.py
#   python3-scipy                    tools/bench_fitpack.py races FITPACK (run by hand);
#                                    griddata and RBFInterpolator in bench/scattered_terrain.py
#   gmt                              GMT's blockmean + surface in bench/scattered_terrain.py
BENCH_DEBS := libbenchmark-dev libocct-data-exchange-dev libocct-modeling-algorithms-dev \
        libocct-modeling-data-dev libocct-foundation-dev libsisl-dev python3-matplotlib python3-scipy gmt
SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)
JOBS ?= $(shell nproc)

.PHONY: all deps test-deps bench-deps fuzz-deps viewer-deps build install demo test test-release test-asan test-fuzz \
        fuzz fuzz-build promise bench clean pictures bench-viewer
# Prerequisites run in the order written, so that a target's packages are installed
# before its configure looks for them (cmake parallelizes the builds themselves).
.NOTPARALLEL:

all: build

# apt-get update, then whatever the list holds that is missing, in one apt-get call.
define install_missing
@missing=""; for p in $(1); do \
  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
done; \
if [ -n "$$missing" ]; then \
  echo "interpatch: installing from Debian:$$missing"; \
  $(SUDO) apt-get update -qq && \
  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
fi
endef

deps:
	$(call install_missing,$(BUILD_DEBS))
test-deps:
	$(call install_missing,$(BUILD_DEBS) $(TEST_DEBS))
bench-deps:
	$(call install_missing,$(BUILD_DEBS) $(BENCH_DEBS))
fuzz-deps:
	$(call install_missing,$(BUILD_DEBS) $(TEST_DEBS) $(FUZZ_DEBS))

# three.js for the viewer page, as viewer/package-lock.json pins it (the build embeds
# it and stops without it). Again whenever the lock file changes. `npm ci` where npm
# is installed; elsewhere tools/fetch_viewer_deps.py fetches the same tarball and
# checks the lock file's hash, which spares a demo Debian's nodejs and npm (over 300
# packages, most of a fresh `make demo`'s apt time).
viewer-deps: deps viewer/node_modules/.package-lock.json
viewer/node_modules/.package-lock.json: viewer/package-lock.json viewer/package.json
	if command -v npm >/dev/null; then npm ci --prefix viewer --no-audit --no-fund; \
	else python3 tools/fetch_viewer_deps.py viewer; fi
	touch $@

build: viewer-deps
	cmake --preset release
	cmake --build --preset release -j $(JOBS)

# The library (interpatch::core, interpatch::io), its headers, CMake package and
# pkg-config files, the interpatch command and the Python module, under PREFIX (sudo
# for /usr/local).
PREFIX ?= /usr/local
install: build
	cmake --install build/release --prefix $(PREFIX)

# The command alone: the demo needs nothing else, and the tests, examples and the
# Python module are most of the build.
demo: viewer-deps
	cmake --preset release
	cmake --build --preset release --target interpatch_cli -j $(JOBS)
	./build/release/interpatch demo -o demo-output

# A failed run ends with the last lines each failed test printed (tools/failed_tests.py):
# a log read from its end then says why, not only which. The test presets set
# OMP_WAIT_POLICY=PASSIVE: JOBS tests at once, each with a thread per core, leave
# OpenMP's spinning threads waiting on cores another test holds (one scattered-points
# test: 32 s spinning, 8 s passive, on 2 loaded cores).
#
# make test runs each test once, in the build where it tells most: the Release build
# (test-release) runs the property tests with every random case, the C++ examples,
# the Python suite against `pip install .`, the installed and source-tree consumers,
# MPI, and the outside programs that read the files (OpenCASCADE, VTK, OpenFOAM,
# Chromium); the sanitizer build (test-asan) runs the unit tests, the property tests
# on a tenth of the cases, the fuzz targets' checked-in inputs and MPI again (its
# cases' variants left out). There the libraries and the command carry both
# sanitizers, the tests' own code AddressSanitizer alone (tests/CMakeLists.txt says why).
# A test run: on failure, the failed tests' last lines, then $(2) (make test stops the
# sanitizer build compiling beside the Release run).
ctest_run = ctest --preset $(1) -j $(JOBS) || { python3 tools/failed_tests.py build/$(1); $(2) exit 1; }
test-release: test-deps build
	$(call ctest_run,release)

# The sanitizer build with line tables alone (-g1, CMakePresets.json): three quarters of
# the compile time of -g, and the reports still name every function, file and line. The
# core stays at -O2: tests compare networks with fixtures made at -O3, and -O1 rounds a
# knot differently enough to change a merge. io and the command, which parse and write
# what the core computes, take -O1 (INTERPATCH_IO_COMPILE_OPTIONS). Its promise tests
# run a tenth of the random cases (INTERPATCH_PROMISE_CASES=0.1): it looks for memory
# and undefined-behaviour errors, and the Release run tries every case.
test-asan: test-deps viewer-deps
	cmake --preset asan
	cmake --build --preset asan -j $(JOBS)
	$(call ctest_run,asan)

# The parsers under libFuzzer (clang, ASan + UBSan): every checked-in seed and
# regression input once, then FUZZ_TEST_SECONDS of fuzzing per target (test-fuzz) or
# FUZZ_SECONDS (fuzz); new corpus entries and crashes stay in build/fuzz/fuzz-work/.
# Not part of make test, which replays the checked-in inputs in the sanitizer build
# (g++) and so spares the clang build of the whole library.
FUZZ_TEST_SECONDS ?= 20
FUZZ_SECONDS ?= 600

fuzz-build: fuzz-deps viewer-deps
	cmake --preset fuzz
	cmake --build --preset fuzz -j $(JOBS)

test-fuzz: fuzz-build
	tests/fuzz/run.sh build/fuzz $(FUZZ_TEST_SECONDS)

fuzz: fuzz-build
	tests/fuzz/run.sh build/fuzz $(FUZZ_SECONDS)

# The promise harness (tests/property/promise_*_test.cpp) with PROMISE_CASES times the
# 1000 random cases per construction family that make test runs; a failure prints the
# family's seed and the case index, which INTERPATCH_PROMISE_REPLAY=<index> replays.
PROMISE_CASES ?= 50

promise: test-deps build
	INTERPATCH_PROMISE_CASES=$(PROMISE_CASES) ./build/release/tests/interpatch_property_tests --gtest_filter='Promise*'

# make test: the Release tests leave a core idle a seventh of their time (waiting on
# launchers, browsers and other processes), so the sanitizer build compiles beside them
# at the lowest priority (nice 19: a test that wants a core has it), its output in
# build/asan/build.log; then the sanitizer run. (ninja itself, not cmake --build: killed,
# it stops the compilers it started.) It runs what test-release, then test-asan run.
test: test-deps build viewer-deps
	cmake --preset asan
	@echo "make test: the sanitizer build compiles beside the Release tests; its log: build/asan/build.log"
	@nice -n 19 ninja -C build/asan -j $(JOBS) > build/asan/build.log 2>&1 & build=$$!; \
	$(call ctest_run,release,kill $$build; wait $$build;); \
	wait $$build || { tail -n 80 build/asan/build.log; echo "make test: the sanitizer build failed (build/asan/build.log)"; exit 1; }; \
	tail -n 2 build/asan/build.log
	$(call ctest_run,asan)

# Benchmarks (never part of `make test`): the console table, then the JSON record
# and its Markdown tables (docs/BENCHMARKS.md). Repetitions tame a shared machine;
# pinned OpenMP threads keep a spinning thread off the core doing the work.
# A single-thread record: make bench BENCH_ENV=OMP_NUM_THREADS=1 BENCH_OUT=build/bench/results_1thread.json
BENCH_FLAGS ?= --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
BENCH_ENV ?= OMP_PROC_BIND=true
BENCH_OUT ?= build/bench/results.json

# bench/compare then runs interpatch, OpenCASCADE and SISL on the same data (interpatch
# on 1 and on all threads), writes $(COMPARE_OUT), and tools/plot_bench.py draws
# docs/bench_interpolation.png and prints the Markdown tables of docs/BENCHMARKS.md.
COMPARE_FLAGS ?= --reps 5
COMPARE_OUT ?= build/bench/compare.json
# bench/loft_compare last: interpatch's loft against OpenCASCADE's ThruSections on the
# same section points, both on one thread (ThruSections runs on one).
LOFT_COMPARE_OUT ?= build/bench/loft_compare.json
bench: bench-deps viewer-deps
	cmake --preset bench
	cmake --build --preset bench -j $(JOBS)
	env $(BENCH_ENV) ./build/bench/bench/interpatch_bench $(BENCH_FLAGS) \
	  --benchmark_out=$(BENCH_OUT) --benchmark_out_format=json
	python3 tools/bench_report.py $(BENCH_OUT)
	env $(BENCH_ENV) ./build/bench/bench/compare $(COMPARE_FLAGS) --json $(COMPARE_OUT) \
	  --workdir build/bench/compare-work --commit "$$(git describe --always --dirty 2>/dev/null || echo unknown)"
	/usr/bin/python3 tools/plot_bench.py $(COMPARE_OUT) -o docs/bench_interpolation.png
	env $(BENCH_ENV) OMP_NUM_THREADS=1 ./build/bench/bench/loft_compare --json $(LOFT_COMPARE_OUT)

# The README's pictures: viewer pages of the examples rendered to docs/images/*.png
# by headless Chromium (tools/make_pictures.py; the test list brings the browser), and
# the deviation map of a survey from its surface (tools/deviation_map.py, matplotlib)
# and the graded duct's nodes (tools/graded_duct.py).
pictures: test-deps build
	/usr/bin/python3 tools/make_pictures.py ./build/release/interpatch docs/images
	/usr/bin/python3 tools/deviation_map.py ./build/release/interpatch docs/images/deviation_map.png
	/usr/bin/python3 tools/graded_duct.py ./build/release/interpatch docs/images/graded_duct.png

# A 1000 x 1000 surface's viewer page: its size, the time `interpatch view` takes to
# write it and the time Chromium takes to open and draw it (docs/BENCHMARKS.md).
bench-viewer: test-deps build
	/usr/bin/python3 tools/bench_viewer.py ./build/release/interpatch build/bench-viewer

clean:
	rm -rf build demo-output
