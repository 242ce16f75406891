# ShadeLab: `make run` opens the viewer on the default preset, `make test` runs every test.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python

.PHONY: run test test-fast install bench charts screenshots clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	$(VENV)/bin/shadelab warm  # numba kernels compiled once, not in front of a class
	touch $@

install: $(VENV)/.installed

run: install
	$(VENV)/bin/shadelab

test: install
	$(PY) -m pytest -q -n 2 --dist loadfile

test-fast: install  # no GUI, nothing slow: the inner loop while editing
	$(PY) -m pytest -q -n 2 --dist loadfile -m "not gui and not slow"

bench: install
	$(VENV)/bin/shadelab bench --json bench.json

charts: install
	$(VENV)/bin/shadelab charts --out screenshots/charts

clean:
	rm -rf $(VENV) tests/_output .pytest_cache
