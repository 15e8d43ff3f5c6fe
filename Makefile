# The two commands of the README:
#   make demo   set up .venv and run the paper case
#   make test   set up .venv (and Chromium, for the viewer test) and run the test suite
# `make lint` runs ruff and mypy; `make bench` the benchmarks; `make bench-peers` the
# comparison with peer optimisers and planners (several minutes).

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test lint format bench bench-peers clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[dev,bench]"
	# pyroboplan pins pin, matplotlib and toppra to exact versions and needs drake for its
	# trajectory optimisation; its RRT needs none of that: install it without its pins
	$(PY) -m pip install --quiet --no-deps "pyroboplan>=1.3.1"
	touch $(STAMP)

demo: $(STAMP)
	$(PY) scripts/paper_case.py

test: $(STAMP)
	@sh scripts/ensure_chromium.sh
	$(PY) -m pytest

lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy

format: $(STAMP)
	$(PY) -m ruff format .
	$(PY) -m ruff check --fix .

bench: $(STAMP)
	$(PY) scripts/bench_clearance.py
	$(PY) scripts/bench_spline.py
	$(PY) scripts/bench_planner.py
	$(PY) scripts/bench_batch.py
	$(PY) scripts/bench_timing.py --out out/bench_timing.md
	$(PY) scripts/bench_search.py

bench-peers: $(STAMP)
	$(PY) scripts/bench_peers.py --scenes 50 --out out/bench_peers.md

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
