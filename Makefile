# One set-up path for a fresh machine: the stock python3, a .venv, pinned wheels (ROS 2 Jazzy from PyPI).
# `make demo` runs the main job on a bundled bag; `make test` runs the suite (`make test-slow`
# the long end-to-end runs).
# Re-running either when nothing changed only checks a stamp file.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BENCH_STAMP := $(VENV)/.installed-bench

# import rclpy exits the process with code 102 for any RMW but Fast DDS (ENVIRONMENT.md).
RUN := env -u RMW_IMPLEMENTATION

.PHONY: setup test test-slow lint demo bench clean

setup: $(STAMP)

# pip first: a recent pip installs the package (no pyproject.toml) as a PEP 660 editable wheel,
# with its console scripts in .venv/bin; the stock pip 23 falls back to `setup.py develop`,
# which follows setup.cfg's colcon script_dir and hides them in .venv/lib/baseball_collision.
# The editable install compiles the time-of-impact kernel (C, with the system's gcc and
# Python's headers) into the source tree: a changed _kernel.c is rebuilt by the next `make`.
$(STAMP): requirements.txt setup.py setup.cfg package.xml Makefile baseball_collision/core/toi/_kernel.c
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --disable-pip-version-check pip==26.3
	$(BIN)/python -m pip install -q --disable-pip-version-check -r requirements.txt
	$(BIN)/python -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
	touch $(STAMP)

# The whole suite but the long end-to-end runs marked `slow` (CI runs this; under 5 minutes),
# one pytest-xdist worker per core (at most 4), each on its own DDS domain (test/conftest.py).
test: $(STAMP)
	$(RUN) $(BIN)/python -m pytest -q -p no:cacheprovider -m "not slow" -n auto --maxprocesses 4 test

# The long end-to-end runs (the 20 s soak at 1 kHz, ...): load-sensitive, run on a quiet machine.
test-slow: $(STAMP)
	$(RUN) $(BIN)/python -m pytest -q -p no:cacheprovider -m slow test

lint: $(STAMP)
	$(RUN) $(BIN)/python -m pytest -q -p no:cacheprovider -m linter test

demo: $(STAMP)
	$(RUN) $(BIN)/baseball-collision demo

# Benchmark-only dependencies (python-fcl, the solver's C++ peer): not part of `make setup`.
$(BENCH_STAMP): $(STAMP) requirements-bench.txt
	$(BIN)/python -m pip install -q --disable-pip-version-check -r requirements-bench.txt
	touch $(BENCH_STAMP)

# The quick benchmarks (about a minute); BENCHMARKS.md lists every benchmark and its command.
bench: $(BENCH_STAMP)
	$(RUN) $(BIN)/python benchmarks/bench_solver.py
	$(RUN) $(BIN)/python benchmarks/bench_detector.py
	$(RUN) $(BIN)/python benchmarks/bench_accuracy.py
	$(RUN) $(BIN)/python benchmarks/bench_prediction.py

clean:
	rm -rf $(VENV) build install log .pytest_cache .hypothesis
