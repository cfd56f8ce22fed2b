"""Training, evaluation, comparison and the ``motiongym`` command, in rooms by job.

* :mod:`.training`: SB3 runs from ``configs/``, DAgger, residual agents, behaviour
  cloning, the vector-env adapters;
* :mod:`.evaluation`: the one episode loop (:func:`.evaluation.episodes.run_episode`),
  statistics, tables and figures, ``BENCHMARKS.md``, recorded videos;
* :mod:`.models`: model folders read without unpickling, predictors, manifests,
  shipping, the shipped models (``models/pretrained/``);
* :mod:`.integrations`: rl-zoo3 settings, Ray Tune sweeps, RLlib, Minari datasets;
* :mod:`.learners`: memories and features extractors, declared by the systems;
* :mod:`.reproduce`: each paper's experiment; :mod:`.bench`: throughput and memory;
* :mod:`.cli`: the ``motiongym`` command.

The module paths before the rooms (``motiongym.agents.evaluate``, ...) import for one
release, with a warning that names the new path (:data:`MOVED`).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from types import ModuleType
from typing import Any

# Old module (under motiongym.agents) -> where it lives now.
MOVED = {
    "benchmarks": "evaluation.benchmarks",
    "evaluate": "evaluation.episodes",
    "report": "evaluation.report",
    "record": "evaluation.record",
    "config": "training.config",
    "train": "training.train",
    "dagger": "training.dagger",
    "imitation": "training.imitation",
    "residual": "training.residual",
    "vector": "training.vector",
    "multiagent": "training.multiagent",
    "model_files": "models.files",
    "predictors": "models.predictors",
    "pretrained": "models.pretrained",
    "ship": "models.ship",
    "zoo": "integrations.zoo",
    "sweep": "integrations.sweep",
    "rllib_runs": "integrations.rllib_runs",
    "ray_commands": "integrations.ray_commands",
    "dataset": "integrations.dataset",
    "dual_arm_map": "learners.dual_arm",
    "obstacle_sets": "learners.harvest_arm",
    "map_memory": "learners.memory",
    "features": "learners",
    "throughput": "bench.throughput",
    "memory_probe": "bench.memory_probe",
    "sweeper_runs": "reproduce.sweeper_runs",
}


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports an old path of :data:`MOVED` as its new module, with a warning."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        parent, _, name = fullname.rpartition(".")
        if parent != __name__ or name not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def exec_module(self, module: ModuleType) -> None:
        new = f"{__name__}.{MOVED[module.__name__.rpartition('.')[2]]}"
        from motiongym.envs.checks import MotiongymDeprecationWarning

        warnings.warn(
            f"{module.__name__} is now {new}; the old path goes in the next release",
            MotiongymDeprecationWarning,
            stacklevel=2,
        )
        sys.modules[module.__name__] = importlib.import_module(new)  # what the import returns


if not any(isinstance(finder, _MovedModules) for finder in sys.meta_path):
    sys.meta_path.append(_MovedModules())  # last: a module that exists always wins
