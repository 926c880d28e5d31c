# wmr-mj: `make demo` runs the headline job headless; `make test` lints (ruff, mypy), then runs the suite
# (tests/test_wheel.py included: it builds the wheel and runs it from a fresh virtualenv).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test test-fast lint venv bench clean foxglove-reader docs

CORE_STAMP := $(VENV)/.installed-core

# the editable install builds the compiled law and the projection's loop (the .c files) in place: rebuild when they change.
# `make demo` needs the package and its core dependencies only (mujoco, numpy, scipy, matplotlib, mcap); the
# extras (test tools, Dask, video, docs, notebook, numba, mujoco.sysid) are installed by `make test`, `make venv` and the rest.
$(CORE_STAMP): pyproject.toml setup.py wmr_mj/sim/_compiled_law.c wmr_mj/analysis/_nearest_chord.c
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e .
	touch $(CORE_STAMP)

$(STAMP): $(CORE_STAMP)
	$(PY) -m pip install -q -e '.[test,dask,video,docs,fast,notebook,sysid]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(CORE_STAMP)
	$(VENV)/bin/wmr-mj validate

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/mypy

# Foxglove's own MCAP reader (@mcap/core, pinned in tests/foxglove_reader/package-lock.json) for
# tests/test_foxglove_reader.py; best effort: without node/npm that test skips and says why.
FOXGLOVE_READER := tests/foxglove_reader/node_modules/.package-lock.json
$(FOXGLOVE_READER): tests/foxglove_reader/package-lock.json
	-command -v npm >/dev/null && npm ci --prefix tests/foxglove_reader --no-audit --no-fund --loglevel=error

foxglove-reader: $(FOXGLOVE_READER)

# the suite in PYTEST_WORKERS processes (pytest-xdist, the test extra), one for each of CI's 2 cores; a test
# file stays on one worker (--dist loadfile), so a module's fixture runs once; session fixtures (tests/conftest.py)
# run once per worker. PYTEST_WORKERS=0 runs it in this process. Times: docs/guides/development.md
PYTEST_WORKERS ?= 2
XDIST := -n $(PYTEST_WORKERS) --dist loadfile

test: lint $(FOXGLOVE_READER)
	$(PY) -m pytest $(XDIST)

# the quick loop while editing: no lint, no test marked slow, wheel, npm or browser (897 tests, 90 s of CPU)
test-fast: $(STAMP)
	$(PY) -m pytest $(XDIST) -m "not slow and not wheel and not npm and not browser"

# the documentation site into site/ (docs/, mkdocs.yml); --strict: a warning is an error
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict -d site

bench: $(STAMP)
	$(PY) bench/bench_run.py
	$(PY) bench/bench_logging.py --end-to-end
	$(PY) bench/bench_sweep.py
	$(PY) bench/bench_compare.py
	$(PY) bench/bench_plugins.py
	$(PY) bench/bench_sensing.py
	$(PY) bench/bench_video.py

clean:
	rm -rf $(VENV) build dist site *.egg-info .ruff_cache wmr_mj/sim/_compiled_law.*.so
