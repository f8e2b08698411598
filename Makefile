# Two commands do all the set-up on a fresh machine with Python 3.11 and make:
#   make demo   creates .venv, installs scara-pin, runs the demo (in mm and deg, the README's quick start)
#   make test   creates .venv, installs scara-pin with its test extras, runs the whole suite (on every core:
#               pytest-xdist's -n auto is in pyproject.toml's addopts; pass -n 0 for one process)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= build

.PHONY: demo test browser bench bench-ik bench-calibration bench-cell lint docs clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e '.[test]'
	touch $@ $(VENV)/.installed

demo: $(VENV)/.installed
	@mkdir -p $(OUT)
	$(BIN)/scara-pin urdf --robot default -o $(OUT)/scara.urdf
	$(BIN)/scara-pin fk --mm --deg 30 45 20 10
	$(BIN)/scara-pin jacobian --mm --deg 30 45 20 10
	$(BIN)/scara-pin ik --mm --deg 300 100 -60 45
	$(BIN)/scara-pin traj --robot s1 --deg --mm --from 0 0 0 0 --to 90 60 50 -180 --duration 5 \
	    --out $(OUT)/s1_traj.csv --plot $(OUT)/s1_traj.png
	$(BIN)/scara-pin view --robot s1 --traj $(OUT)/s1_traj.csv --workspace --html $(OUT)/s1_traj.html
	$(BIN)/scara-pin workspace --plot $(OUT)/workspace.png

# The browser tests drive Debian's chromium through Playwright's Python API (never `playwright install`).
browser:
	@command -v chromium >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq chromium >/dev/null) \
	    || echo "warning: chromium could not be installed; the browser tests will be skipped (outside CI)"

# Bytecode is cached (__pycache__, ignored by git) even where PYTHONDONTWRITEBYTECODE is set, as on the CI
# machine: else every worker rewrites every test module's asserts and every command the tests run compiles
# the package again (about 10-20 s of the suite).
test: $(VENV)/.installed-test browser
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -q

bench: $(VENV)/.installed-test
	$(BIN)/python benchmarks/bench_fk.py

# roboticstoolbox-python is a benchmark-only dependency: it goes into its own environment
RTB_VENV ?= .venv-bench
bench-ik: $(VENV)/.installed-test
	test -x $(RTB_VENV)/bin/python || $(PYTHON) -m venv $(RTB_VENV)
	$(RTB_VENV)/bin/python -m pip install -q roboticstoolbox-python -e .
	$(RTB_VENV)/bin/python benchmarks/bench_ik.py

# FIGAROH (geometric calibration, PyPI figaroh) is a benchmark-only dependency: its own environment too
FIGAROH_VENV ?= .venv-figaroh
bench-calibration: $(VENV)/.installed-test
	test -x $(FIGAROH_VENV)/bin/python || $(PYTHON) -m venv $(FIGAROH_VENV)
	$(FIGAROH_VENV)/bin/python -m pip install -q figaroh==1.0.2
	$(BIN)/python benchmarks/bench_calibration.py

# pyroboplan (a sampling planner: RRT-Connect, shortcutting) is a benchmark-only dependency: its own environment.
# pyroboplan 1.3.1 pins toppra==0.6.3 (scara-pin needs >= 0.6.9; pyroboplan never imports toppra: the benchmark
# calls toppra itself) and drake (only for its trajectory optimisation, not used here): installed without its
# dependencies, on top of scara-pin's, with the Pinocchio it pins (4.0.0). pytest: the benchmark reads the
# held-out cells from tests/test_cell_motion.py.
CELL_VENV ?= .venv-bench-cell
bench-cell: $(VENV)/.installed-test
	test -x $(CELL_VENV)/bin/python || $(PYTHON) -m venv $(CELL_VENV)
	$(CELL_VENV)/bin/python -m pip install -q -e . pin==4.0.0 pytest
	$(CELL_VENV)/bin/python -m pip install -q --no-deps pyroboplan==1.3.1
	$(CELL_VENV)/bin/python benchmarks/bench_cell.py

lint: $(VENV)/.installed-test
	$(BIN)/python -m pip install -q -e '.[test,lint]'
	$(BIN)/ruff check scara_pin tests benchmarks tools
	$(BIN)/mypy scara_pin --ignore-missing-imports

# the documentation site from docs/ and the docstrings, into site/; a warning fails the build
# then the site's own tests (tests/test_site.py: the tour's outputs, the reference's links, file:// links)
docs: $(VENV)/.installed-test
	$(BIN)/python -m pip install -q -e '.[docs]'
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict
	SCARA_PIN_SITE=site $(BIN)/python -m pytest -q -n 0 -m site tests/test_site.py

clean:
	rm -rf $(VENV) $(RTB_VENV) $(FIGAROH_VENV) $(CELL_VENV) $(OUT) .pytest_cache site
