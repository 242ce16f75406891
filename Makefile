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

LESSON ?= phong-to-radiosity
LESSON_SIZES ?= 1024x768 1920x1080
# Every step of the lesson in presenter mode at both projector sizes, under screenshots/lesson/
# (offline steps are captured when their render is done). Needs a display: xvfb-run make ...
screenshots: install
	mkdir -p screenshots/lesson
	n=$$($(PY) -c "import tomllib; print(len(tomllib.load(open('presets/lessons/$(LESSON).toml', 'rb'))['steps']))"); \
	for size in $(LESSON_SIZES); do for i in $$(seq 1 $$n); do \
	  SHADELAB_AUTOWARM=0 $(VENV)/bin/shadelab view --lesson $(LESSON) --step $$i --presenter \
	    --window $$size --frames 30 --fresh --no-autosave -q \
	    --screenshot screenshots/lesson/step$$(printf %02d $$i)-$$size.png || exit 1; \
	done; done

clean:
	rm -rf $(VENV) tests/_output .pytest_cache
