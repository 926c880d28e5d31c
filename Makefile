# wmr-mj: `make demo` runs the headline job headless; `make test` lints, then runs the suite
# (tests/test_wheel.py included: it builds the wheel and runs it from a fresh virtualenv).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test lint venv bench clean

$(STAMP): pyproject.toml setup.py
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test,dask,video]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/wmr-mj validate

lint: $(STAMP)
	$(VENV)/bin/ruff check .

test: lint
	$(PY) -m pytest

bench: $(STAMP)
	$(PY) bench/bench_run.py
	$(PY) bench/bench_logging.py --end-to-end
	$(PY) bench/bench_sweep.py

clean:
	rm -rf $(VENV) build dist *.egg-info .ruff_cache
