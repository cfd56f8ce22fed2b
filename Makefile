# The two commands of the README: `make demo` (the main job) and `make test`.
# Both create the virtual environment and install the package on first use.
# torch is installed first, pinned, so that pip takes the CPU wheel on disk.

VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
EPISODES ?= 10

.PHONY: install demo test test-slow studies lint models benchmarks fuzz docs media test-ray test-zoo

$(STAMP): pyproject.toml setup.py
	python3 -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet torch==2.13.0
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	MUJOCO_GL=egl $(BIN)/motiongym compare --all --episodes $(EPISODES) --out results/compare

# Both tiers run on every core (pytest-xdist, one worker per core; PYTEST_WORKERS=0 runs in
# one process). Each worker's libraries use one thread: two workers on two cores.
PYTEST_WORKERS ?= auto
PYTEST := MUJOCO_GL=egl OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 $(BIN)/pytest -q -n $(PYTEST_WORKERS)

test: $(STAMP)
	$(PYTEST)

test-slow: $(STAMP)
	$(PYTEST) -m "slow and not study"

# The held-out studies and learner ablations (marker `study`, tests/README.md): the
# evidence behind docs/experiments' numbers, about an hour on two cores. Not part of CI.
studies: $(STAMP)
	$(PYTEST) -m study

# The full property-based hostile-input run (tests/fuzz: every ID's keywords, reset
# options and actions, the PettingZoo env, the policies' predict, model folders, config
# files; 60 examples per test and ID; the default suite runs a fast slice); prints the
# counts per outcome.
fuzz: $(STAMP)
	MUJOCO_GL=egl MOTIONGYM_FUZZ=fuzz $(BIN)/pytest -q -s -W ignore::DeprecationWarning tests/fuzz

# The documentation site (Sphinx, furo): a page per ID from its docstring, the papers,
# the API reference; warnings are errors. Installs the optional extra `docs` first.
docs: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	MUJOCO_GL=egl $(BIN)/sphinx-build -W --keep-going -q -b html docs/site docs/site/_build/html
	@echo "docs/site/_build/html/index.html"

# The GIFs of the README and of the docs' environment pages (docs/media/<ID>_<policy>_seed1.gif,
# 320 px wide): one episode (seed 1) of the paper's policy for each ID without one yet, a frame
# every 4 steps (sweeper), 5 (dual-arm cell) or 2 (the others). About 15 s an ID; `make docs`
# only copies them. Delete an ID's GIF to make it again.
media: $(STAMP)
	for id in $$(MUJOCO_GL=egl $(BIN)/python -c "import motiongym.envs as e; print(*e.ENV_IDS)"); do \
	  name=$${id#motiongym/}; \
	  ls docs/media/$${name}_*.gif >/dev/null 2>&1 && continue; \
	  case $$name in Sweeper*) every=4;; DualArm*) every=5;; *) every=2;; esac; \
	  MUJOCO_GL=egl $(BIN)/motiongym record $$id --seed 1 --every $$every --out docs/media || exit 1; \
	done

# Ray (the optional extra motiongym[ray]: `motiongym sweep`, `motiongym rllib`): installs
# it, then runs tests/agents/test_ray.py with its slow tests (a local Ray head on
# 127.0.0.1: one tiny sweep, one tiny RLlib iteration per route). Not part of make test.
test-ray: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[ray]"
	MUJOCO_GL=egl $(BIN)/pytest -q -m "slow or not slow" tests/agents/test_ray.py

# rl-zoo3 trains every block of configs/zoo/*.yml for a few hundred steps with its own
# train script, and motiongym evaluates a zoo run (tests/agents/test_zoo_train.py). The zoo
# is not a dependency (through moviepy it downgrades pillow): it goes in its own virtual
# environment, .venv-zoo, never in .venv. Its runs are spread over the cores like the tiers'.
ZOO_VENV := .venv-zoo
test-zoo:
	test -x $(ZOO_VENV)/bin/python || python3 -m venv $(ZOO_VENV)
	$(ZOO_VENV)/bin/python -m pip install --quiet torch==2.13.0
	$(ZOO_VENV)/bin/python -m pip install --quiet -e ".[dev]" "rl_zoo3>=2.9,<3"
	MUJOCO_GL=egl OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 $(ZOO_VENV)/bin/pytest -q -n $(PYTEST_WORKERS) -m slow -p no:cacheprovider tests/agents/test_zoo_train.py

# The type check (mypy, [tool.mypy] in pyproject.toml) of envs/, baselines/ and agents/
# reads the package through links in build/typecheck: setup.py maps the folders to the import name
# motiongym, which mypy cannot follow.
TYPED := build/typecheck/motiongym
lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	rm -rf $(TYPED) && mkdir -p $(TYPED)
	for f in __init__.py systems.py py.typed; do ln -s $(CURDIR)/src/motiongym/$$f $(TYPED)/$$f; done
	for d in envs baselines agents configs; do ln -s $(CURDIR)/$$d $(TYPED)/$$d; done
	$(BIN)/mypy -p motiongym.envs -p motiongym.baselines -p motiongym.agents

# The shipped models (agents/models/pretrained/): every ID's configs/<ID>.yml first block
# and the dual-arm shared-parameter block, three training seeds each; `ship`
# evaluates every seed on held-out episodes and ships the best. Hours on 2 cores.
SEEDS ?= 0 1 2
# Agents from demonstrations (DAgger, configs/<ID>-dagger.yml), shipped as sac-dagger on 100
# held-out episodes, the harvest arms' on 1000 (their first 100 are easier than the next 900,
# for the potential field and the learner alike: docs/experiments/HarvestArm-v0.md).
DAGGER_IDS ?= ExcavatorReach-v0 ExcavatorReach-v1 DualArmCell-v0 DualArmCell-v1 HarvestArm-v0 HarvestArmPlanar-v0
# The same with a discrete, masked learner (maskableppo-dagger), shipped on the 20 held-out
# episodes of the ID's other shipped model (BENCHMARKS compares them on the same episodes).
MASKED_DAGGER_IDS ?= Sweeper-v1
IDS ?= Sweeper-v0 Sweeper-v1 HarvestArm-v0 HarvestArmPlanar-v0 DualArmCell-v0 ExcavatorReach-v0 Excavator-v0
# Residual agents (configs/<ID>-residual.yml: a correction of the scripted policy), shipped
# as <algo>-residual.
RESIDUAL_IDS ?= Excavator-v1 Excavator-v0 ExcavatorReach-v1
# Goal-conditioned agents from scratch (configs/<ID>.yml's first block: SAC + hindsight
# experience replay), shipped as sac on 100 held-out episodes.
GOAL_IDS ?= ExcavatorReachGoal-v1
models: $(STAMP)
	for id in $(IDS); do \
	  for seed in $(SEEDS); do \
	    $(BIN)/motiongym train motiongym/$$id --seed $$seed --out runs/models || exit 1; \
	  done; \
	  $(BIN)/motiongym ship runs/models/$$id/*_seed* || exit 1; \
	done
	for seed in $(SEEDS); do \
	  $(BIN)/motiongym train motiongym/DualArmCell-v0 --seed $$seed \
	    --config configs/DualArmCell-v0-shared.yml --out runs/models-shared || exit 1; \
	done
	$(BIN)/motiongym ship runs/models-shared/DualArmCell-v0/ppo_seed*
	for id in $(RESIDUAL_IDS); do \
	  for seed in $(SEEDS); do \
	    $(BIN)/motiongym train motiongym/$$id --seed $$seed \
	      --config configs/$$id-residual.yml --out runs/models-residual || exit 1; \
	  done; \
	  $(BIN)/motiongym ship runs/models-residual/$$id/*_seed* --episodes 50 || exit 1; \
	done
	for id in $(DAGGER_IDS); do \
	  for seed in $(SEEDS); do \
	    $(BIN)/motiongym train motiongym/$$id --seed $$seed \
	      --config configs/$$id-dagger.yml --out runs/models-dagger || exit 1; \
	  done; \
	  case $$id in HarvestArm*) episodes=1000;; *) episodes=100;; esac; \
	  $(BIN)/motiongym ship --episodes $$episodes runs/models-dagger/$$id/sac_seed* || exit 1; \
	done
	for id in $(MASKED_DAGGER_IDS); do \
	  for seed in $(SEEDS); do \
	    $(BIN)/motiongym train motiongym/$$id --seed $$seed \
	      --config configs/$$id-dagger.yml --out runs/models-dagger || exit 1; \
	  done; \
	  $(BIN)/motiongym ship runs/models-dagger/$$id/maskableppo_seed* || exit 1; \
	done
	for id in $(GOAL_IDS); do \
	  for seed in $(SEEDS); do \
	    $(BIN)/motiongym train motiongym/$$id --seed $$seed --out runs/models-goal || exit 1; \
	  done; \
	  $(BIN)/motiongym ship --episodes 100 runs/models-goal/$$id/*_seed* || exit 1; \
	done

# BENCHMARKS.md's tables and figures, from the shipped models' metrics.
benchmarks: $(STAMP)
	MUJOCO_GL=egl $(BIN)/motiongym benchmarks
