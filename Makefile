# Every target needs only python3 on the machine; each sets up .venv itself.
#   make report      install qc_control (no test or docs extras), write the comparison report
#   make test        install qc_control[test,docs], run the whole suite (the docs build too)
#   make docs        install qc_control[docs], build the docs site with warnings as errors
#   make notebook    install qc_control[notebook], open the course notebook in JupyterLab
#   make explore     install qc_control[explore], open the interactive explorer in a browser
#   make examples    run every example into examples_output/
#   make check-html  install Chromium (apt-get) and check report.html in it
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
# One stamp per kind of install: `make report` never pulls in the test or docs
# extras. A stamp is older than pyproject.toml whenever the dependencies
# change, so that install is refreshed then and only then.
STAMP_BASE     := $(VENV)/.installed-base
STAMP_TEST     := $(VENV)/.installed-test
STAMP_DOCS     := $(VENV)/.installed-docs
STAMP_NOTEBOOK := $(VENV)/.installed-notebook
STAMP_EXPLORE  := $(VENV)/.installed-explore
# root needs no sudo (containers, CI); anyone else does
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: report test docs notebook explore examples check-html bench clean

# uv installs the same packages from the same index in about a quarter of pip's
# time (the test extras: 23 s against 58-119 s on 2 cores, measured side by side);
# where uv cannot install (no wheel of it for the platform), pip does the same.
PIP := $(BIN)/python -m pip install --quiet
UV  := $(BIN)/python -m uv pip install --python $(BIN)/python --quiet

# The venv's own pip only installs uv, which does the rest: upgrading pip first cost
# 4 s of every fresh install. Where uv has no wheel, pip is brought up to date.
# qc_control needs Python 3.10 or newer (pyproject.toml's requires-python). A .venv
# made by an older one (a first `make` with macOS's Python 3.9) would be reused by
# every later `make ... PYTHON=python3.12` and fail the same way: it is made again,
# saying so. $(PYTHON) itself is checked before a .venv is made with it.
NEEDS := 3.10
OLD_PYTHON := import sys; sys.exit(sys.version_info < (3, 10))
ifneq ($(wildcard $(BIN)/python),)
ifneq ($(shell $(BIN)/python -c '$(OLD_PYTHON)' >/dev/null 2>&1 && echo ok),ok)
$(info make: $(VENV) was made by a Python older than $(NEEDS) (or no longer runs); making it again with $(PYTHON))
$(shell rm -rf $(VENV))
endif
endif

$(BIN)/python:
	@$(PYTHON) -c '$(OLD_PYTHON)' 2>/dev/null || { echo "make: $(PYTHON) is not Python $(NEEDS) or newer ($$($(PYTHON) --version 2>&1)); give one: make ... PYTHON=python3.12" >&2; exit 2; }
	$(PYTHON) -m venv $(VENV)
	$(PIP) uv || $(PIP) --upgrade pip

$(STAMP_BASE): pyproject.toml | $(BIN)/python
	$(UV) -e . || $(PIP) -e .
	touch $@

$(STAMP_TEST): pyproject.toml | $(BIN)/python
	$(UV) -e '.[test,docs]' || $(PIP) -e '.[test,docs]'
	touch $@

$(STAMP_DOCS): pyproject.toml | $(BIN)/python
	$(UV) -e '.[docs]' || $(PIP) -e '.[docs]'
	touch $@

$(STAMP_NOTEBOOK): pyproject.toml | $(BIN)/python
	$(UV) -e '.[notebook]' || $(PIP) -e '.[notebook]'
	touch $@

report: $(STAMP_BASE)
	$(BIN)/qc-control report --out report

# every core (pytest-xdist); a group of tests that share one computed artefact
# (the docs build and the notebook run, the installed wheel) stays on one worker
test: $(STAMP_TEST)
	$(BIN)/python -m pytest -q -n auto --dist loadgroup

docs: $(STAMP_DOCS)
	$(BIN)/sphinx-build -W --keep-going -q -j auto -b html docs docs/_build/html
	@echo "open docs/_build/html/index.html"

$(STAMP_EXPLORE): pyproject.toml | $(BIN)/python
	$(UV) -e '.[explore]' || $(PIP) -e '.[explore]'
	touch $@

explore: $(STAMP_EXPLORE)
	$(BIN)/qc-control explore

notebook: $(STAMP_NOTEBOOK)
	$(BIN)/jupyter lab examples/course.ipynb

examples: $(STAMP_BASE)
	for script in examples/*.py; do \
	    name=$$(basename $$script .py); \
	    MPLBACKEND=Agg $(BIN)/python $$script examples_output/$$name || exit 1; \
	done

check-html: $(STAMP_TEST)
	test -x /usr/bin/chromium || { $(SUDO) apt-get update && $(SUDO) apt-get install -y chromium; }
	$(BIN)/python -m pytest -q -rs tests/test_html_browser.py

bench: $(STAMP_BASE)
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) report examples_output docs/_build docs/auto_examples docs/generated \
	    docs/notebooks build *.egg-info
