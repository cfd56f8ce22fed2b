# The two commands of the README: `make demo` (the main job) and `make test`.
# Both create the virtual environment and install the package on first use.
# torch is installed first, pinned, so that pip takes the CPU wheel on disk.

VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
EPISODES ?= 10

.PHONY: install demo test test-slow lint

$(STAMP): pyproject.toml setup.py
	python3 -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet torch==2.13.0
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	MUJOCO_GL=egl $(BIN)/motiongym compare --all --episodes $(EPISODES) --out results/compare

test: $(STAMP)
	MUJOCO_GL=egl $(BIN)/pytest -q

test-slow: $(STAMP)
	MUJOCO_GL=egl $(BIN)/pytest -q -m slow

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
