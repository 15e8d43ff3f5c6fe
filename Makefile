# The two commands of the README:
#   make demo   set up .venv and run the paper case
#   make test   set up .venv (and Chromium, for the viewer test) and run the test suite
# Both install the exact versions of requirements/constraints.txt (tested together); the
# minimum versions a library user needs stay in pyproject.toml.
#   make lint          ruff and mypy
#   make jit-cache     numba's disk cache filled (the tests then load the kernels, not compile them)
#   make wheel-check   build the wheel, install it into a fresh venv, run the CLI and the paper case there
#   make test-latest   the tests against the newest releases (.venv-latest), and which versions moved
#   make lock          rewrite requirements/constraints.txt from the newest releases
#   make bench         the benchmarks; make bench-peers the comparison with peers (minutes)

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
CONSTRAINTS := requirements/constraints.txt
EXTRAS := dev,bench,robots
# pyroboplan pins pin, matplotlib and toppra to exact versions and needs drake for its
# trajectory optimisation; its RRT needs none of that: it is installed without its pins
PYROBOPLAN := pyroboplan>=1.3.1

.PHONY: bytecode kernels jit-cache chromium demo test test-fast lint format wheel-check test-latest lock bench bench-peers import-mbm bench-mbm bench-torque clean

$(STAMP): pyproject.toml $(CONSTRAINTS)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c $(CONSTRAINTS) -e ".[$(EXTRAS)]"
	$(PY) -m pip install --quiet --no-deps -c $(CONSTRAINTS) "$(PYROBOPLAN)"
	touch $(STAMP)

# The packages' bytecode, as pip writes an installed wheel's: a checkout installed in place has
# none, and where Python may not write it (PYTHONDONTWRITEBYTECODE) every new process would
# compile the packages again (about 0.1 s of each `cpr-plan` call; docs/benchmarks.md). Only files
# changed since are compiled again. Then the methods Python writes for their dataclasses, which it
# would compile in every process too (planning/cli/dataclass_code.py).
bytecode: $(STAMP)
	$(PY) -m compileall -q cpr_kin planning
	$(PY) -m planning.cli.dataclass_code

# The kernels compiled ahead of time (numba's pycc and the C compiler): a new `cpr-plan` process
# then runs them without importing numba, about half a second sooner (docs/benchmarks.md). Built
# again only where a kernel's file changed; the tests compile their own (tests/test_ahead.py).
# Without a C compiler the demo goes on, numba compiling the kernels just in time.
kernels: bytecode
	$(PY) -m planning.ahead_of_time || echo "make: the kernels stay compiled just in time (numba)"

demo: kernels
	$(PY) scripts/paper_case.py

# numba's disk cache filled by the build's warm-up, just in time (no C compiler needed): the tests
# run numba's dispatchers, which then load these kernels rather than compile them (CI runs it
# beside the wheel's check, on the core that check leaves idle)
jit-cache: bytecode
	CPR_KERNELS=jit $(PY) -m planning.ahead_of_time --just-in-time

# the viewer test renders the exported page in a real Chromium: installed where missing
chromium:
	@sh scripts/ensure_chromium.sh

test: bytecode chromium
	$(PY) -m pytest --numprocesses auto --maxprocesses 2

test-fast: bytecode
	$(PY) -m pytest -m "not slow"

lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy

format: $(STAMP)
	$(PY) -m ruff format .
	$(PY) -m ruff check --fix .

# a user's install: the wheel (not the checkout) in a new venv, run from another folder
wheel-check: $(STAMP)
	rm -rf build/wheel-check && mkdir -p build/wheel-check/run
	$(PY) -m pip wheel --quiet --no-deps -w build/wheel-check/dist .
	$(PYTHON) -m venv build/wheel-check/venv
	build/wheel-check/venv/bin/python -m pip install --quiet -c $(CONSTRAINTS) build/wheel-check/dist/*.whl
	cd build/wheel-check/run && ../venv/bin/cpr-plan --help > /dev/null
	cd build/wheel-check/run && ../venv/bin/python -m planning.ahead_of_time --bundled-only
	cd build/wheel-check/run && ../venv/bin/python -m planning.cli.dataclass_code
	cd build/wheel-check/run && ../venv/bin/python -c 'import sys, cpr_kin.bounds.bound_kernels as k; sys.exit("numba" in sys.modules)'
	cd build/wheel-check/run && ../venv/bin/cpr-plan paper --out paper
	cd build/wheel-check/run && ../venv/bin/cpr-plan check "$$(../venv/bin/python -c 'import planning.io.bundled as b; print(b.paper_scene_path())')" paper/trajectory.json

test-latest:
	rm -rf .venv-latest
	$(PYTHON) -m venv .venv-latest
	.venv-latest/bin/python -m pip install --quiet --upgrade pip
	.venv-latest/bin/python -m pip install --quiet --upgrade -e ".[$(EXTRAS)]"
	.venv-latest/bin/python -m pip install --quiet --no-deps --upgrade "$(PYROBOPLAN)"
	.venv-latest/bin/python scripts/dependency_drift.py $(CONSTRAINTS)
	.venv-latest/bin/python -m pytest

lock: test-latest
	.venv-latest/bin/python scripts/dependency_drift.py $(CONSTRAINTS) --write

bench: bytecode
	$(PY) scripts/bench_clearance.py
	$(PY) scripts/bench_spline.py
	$(PY) scripts/bench_planner.py
	$(PY) scripts/bench_batch.py
	$(PY) scripts/bench_startup.py
	$(PY) scripts/bench_timing.py --out out/bench_timing.md
	$(PY) scripts/bench_search.py

bench-peers: bytecode
	$(PY) scripts/bench_peers.py --scenes 50 --out out/bench_peers.md

import-mbm: bytecode
	$(PY) scripts/import_mbm.py

# two problems at once: both robots' 1,400 problems in about 35 min on 2 cores (one worker: 68)
MBM_ARGS ?= --workers 2
bench-mbm: bytecode
	$(PY) scripts/bench_mbm.py --out out/bench_mbm $(MBM_ARGS)

bench-torque: bytecode
	$(PY) scripts/bench_torque.py --scenes 20 --limit 3 --out out/bench_torque

clean:
	rm -rf $(VENV) .venv-latest build *.egg-info .pytest_cache .mypy_cache .ruff_cache
