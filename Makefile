# Two commands for a new user; each creates .venv and installs what it needs.
#   make demo   runs the main job on the shipped default
#   make test   runs the linter and the test suite (what CI runs)
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.evorbc-installed
OUT    ?= demo-output

.PHONY: demo test lint bench clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[dev]"
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/evorbc-evolve repertoire --robot 4ws-5 --seed 1 \
		--out $(OUT)/4ws-5.repertoire.json --plot $(OUT)/4ws-5.repertoire.png \
		--csv $(OUT)/4ws-5.repertoire.csv
	@echo "demo: open $(OUT)/4ws-5.repertoire.png to see the repertoire"

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

test: lint
	$(PY) -m pytest -q

bench: $(STAMP)
	$(PY) bench/bench_repertoire.py

clean:
	rm -rf $(VENV) $(OUT) build *.egg-info
