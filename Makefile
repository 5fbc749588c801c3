# interpatch — the two commands (README): `make demo` and `make test`.
# Each installs what is missing from Debian's packages first.

SHELL := /bin/bash
# What each package is for (the README's "Dependencies" says the same):
#   cmake ninja-build g++            the build (C++20, CMake presets)
#   pkg-config                       the tests build a program against the installed .pc files
#   libcli11-dev                     the command line's option parser
#   nlohmann-json3-dev               specs and JSON output (the io library only; the core needs none)
#   libgtest-dev libgmock-dev        the tests;  libbenchmark-dev: make bench
#   python3 python3-numpy            the reference-data script and the read-back checks
#   python3-scipy                    the closed-spline reference data (tools/reference/make_periodic_reference.py)
#   python3-vtk9                     VTK's own readers read back the .vts/.vtk/.xyz files interpatch writes
#   python3-matplotlib               make bench draws docs/bench_interpolation.png
#   pybind11-dev python3-dev         the Python module (import interpatch)
#   python3-pytest                   its test suite
#   python3-hypothesis               its fuzz tests: random arrays into the constructors (tests/python/test_fuzz.py)
#   libocct-*-dev                    OpenCASCADE reads back the STEP and IGES files (tests) and races us (make bench)
#   libsisl-dev                      SISL races us in make bench
#   clang libclang-rt-14-dev libomp-14-dev   libFuzzer (with its OpenMP) runs the fuzz targets of make test
#   libeigen3-dev                    the sparse Cholesky decomposition of approximation's normal equations
#   chromium chromium-driver python3-selenium   the viewer pages opened in a real browser (make test,
#                                    make pictures, make bench-viewer)
#   nodejs npm                       npm ci installs three.js for the viewer (viewer/package-lock.json);
#                                    installed only when npm is not already on PATH
#   libopenmpi-dev openmpi-bin       MPI: eval and build split between processes (mpirun; docs/mpi.md) and their tests
DEBS := cmake ninja-build g++ pkg-config python3 libcli11-dev nlohmann-json3-dev \
        libgtest-dev libgmock-dev libbenchmark-dev python3-numpy python3-vtk9 python3-matplotlib \
        libocct-data-exchange-dev libocct-modeling-algorithms-dev libocct-modeling-data-dev \
        libocct-foundation-dev libsisl-dev python3-scipy clang libclang-rt-14-dev libomp-14-dev \
        pybind11-dev python3-pybind11 python3-dev python3-pytest python3-hypothesis \
        libeigen3-dev chromium chromium-driver python3-selenium $(if $(shell command -v npm),,nodejs npm) \
        libopenmpi-dev openmpi-bin
SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)
JOBS ?= $(shell nproc)

.PHONY: all deps viewer-deps build install demo test test-release test-asan test-fuzz fuzz fuzz-build promise bench clean \
        pictures bench-viewer

all: build

deps:
	@missing=""; for p in $(DEBS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "interpatch: installing from Debian:$$missing"; \
	  $(SUDO) apt-get update -qq && \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	fi

# three.js for the viewer page, as viewer/package-lock.json pins it (the build embeds
# it and stops without it). Again whenever the lock file changes.
viewer-deps: deps viewer/node_modules/.package-lock.json
viewer/node_modules/.package-lock.json: viewer/package-lock.json viewer/package.json
	npm ci --prefix viewer --no-audit --no-fund
	touch $@

build: viewer-deps
	cmake --preset release
	cmake --build --preset release -j $(JOBS)

# The library (interpatch::core, interpatch::io), its headers, CMake package and
# pkg-config files, and the interpatch command, under PREFIX (sudo for /usr/local).
PREFIX ?= /usr/local
install: build
	cmake --install build/release --prefix $(PREFIX)

demo: build
	./build/release/interpatch demo -o demo-output

test-release: build
	ctest --preset release -j $(JOBS)

# The sanitizer build with line tables alone (-g1, CMakePresets.json): three quarters of
# the compile time of -g, and the reports still name every function, file and line. It
# stays at -O2: tests compare networks with fixtures made at -O3, and -O1 rounds a knot
# differently enough to change a merge.
test-asan: viewer-deps
	cmake --preset asan
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan -j $(JOBS)

# The parsers under libFuzzer (clang, ASan + UBSan): every checked-in seed and
# regression input once, then FUZZ_TEST_SECONDS of fuzzing per target. `make fuzz`
# fuzzes longer; new corpus entries and crashes stay in build/fuzz/fuzz-work/.
FUZZ_TEST_SECONDS ?= 20
FUZZ_SECONDS ?= 600

fuzz-build: viewer-deps
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

promise: build
	INTERPATCH_PROMISE_CASES=$(PROMISE_CASES) ./build/release/tests/interpatch_tests --gtest_filter='Promise*'

test: test-release test-asan test-fuzz

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
bench: viewer-deps
	cmake --preset bench
	cmake --build --preset bench -j $(JOBS)
	env $(BENCH_ENV) ./build/bench/bench/interpatch_bench $(BENCH_FLAGS) \
	  --benchmark_out=$(BENCH_OUT) --benchmark_out_format=json
	python3 tools/bench_report.py $(BENCH_OUT)
	env $(BENCH_ENV) ./build/bench/bench/compare $(COMPARE_FLAGS) --json $(COMPARE_OUT) \
	  --workdir build/bench/compare-work --commit "$$(git describe --always --dirty 2>/dev/null || echo unknown)"
	/usr/bin/python3 tools/plot_bench.py $(COMPARE_OUT) -o docs/bench_interpolation.png

# The README's pictures: viewer pages of the examples rendered to docs/images/*.png
# by headless Chromium (tools/make_pictures.py).
pictures: build
	/usr/bin/python3 tools/make_pictures.py ./build/release/interpatch docs/images

# A 1000 x 1000 surface's viewer page: its size, the time `interpatch view` takes to
# write it and the time Chromium takes to open and draw it (docs/BENCHMARKS.md).
bench-viewer: build
	/usr/bin/python3 tools/bench_viewer.py ./build/release/interpatch build/bench-viewer

clean:
	rm -rf build demo-output
