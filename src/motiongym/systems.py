"""The one list of motiongym's systems; everything that enumerates them reads it.

A system is a world with its papers' algorithms, declared in up to four modules:

* its environments module (``motiongym.envs.<name>``): ``REGISTRATIONS``
  (keyword dicts for :func:`gymnasium.register`), and optionally
  ``PARALLEL_ENVS`` (``{ID: "module:factory"}`` of PettingZoo versions),
  ``BENCH_GOALS`` (``{ID: (reference ID, least ratio)}``) and
  ``BENCH_VECTOR_GOALS`` (``{ID: (least steps/s, least ratio to
  SyncVectorEnv)}``);
* its baselines module (``motiongym.baselines.<name>``): ``POLICIES``
  (``{ID: {policy name: "module:Class"}}``) and optionally ``PLANNERS``
  (``{label: ("module:function", goal in s or None)}``, timed by the bench);
* its learner-side features (``motiongym.agents.learners.<name>``,
  optional): ``MEMORIES`` (``{name: memory wrapper class}``, a config's
  ``memory:``) and ``FEATURES_EXTRACTORS`` (``{name: features extractor
  class}``, a config's ``policy_kwargs.features_extractor_class``);
* its reproduction (``motiongym.agents.reproduce.<name>``, optional): a
  module with ``run(out_dir, quick=False) -> dict``, run as ``motiongym
  reproduce <experiment>``.

Everything is named by strings and imported lazily, so the envs, baselines
and agents layers keep importing one way only. Adding a fifth world is one
line in :data:`SYSTEMS` (``System.standard("my_world")``), or, for a world
kept outside the package (a test's toy world), :func:`add_system`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType


@dataclass(frozen=True)
class System:
    """Where a system's declarations live (module paths) and its experiment's name."""

    name: str
    envs: str
    baselines: str
    reproduction: str | None = None
    learners: str | None = None

    @staticmethod
    def standard(name: str) -> System:
        """The package's own layout: ``envs/<name>``, ``baselines/<name>``,
        ``agents/reproduce/<name>.py`` (experiment ``name`` with ``-`` for ``_``),
        ``agents/learners/<name>.py`` (read only where it exists)."""
        return System(
            name.replace("_", "-"),
            f"motiongym.envs.{name}",
            f"motiongym.baselines.{name}",
            f"motiongym.agents.reproduce.{name}",
            f"motiongym.agents.learners.{name}",
        )

    def envs_module(self) -> ModuleType:
        return importlib.import_module(self.envs)

    def baselines_module(self) -> ModuleType:
        return importlib.import_module(self.baselines)

    def learners_module(self) -> ModuleType | None:
        """The learners module, or None where the system declares none (or it does not exist)."""
        if self.learners is None:
            return None
        try:
            return importlib.import_module(self.learners)
        except ModuleNotFoundError as error:
            if error.name != self.learners:
                raise  # the module exists and something it imports does not
            return None


SYSTEMS: list[System] = [
    System.standard("sweeper"),
    System.standard("harvest_arm"),
    System.standard("dual_arm"),
    System.standard("excavator"),
]


def add_system(system: System) -> None:
    """Add a system at run time and register its IDs (a world outside the package)."""
    if any(s.name == system.name for s in SYSTEMS):
        raise ValueError(f"a system named {system.name!r} exists already")
    SYSTEMS.append(system)
    from motiongym.envs.registration import register_all

    register_all()


def declared(module_of: str, attribute: str) -> dict:
    """Every system's ``attribute`` (a dict) merged, from its ``envs``, ``baselines`` or
    ``learners`` module (imported on this call: importing motiongym imports no learner,
    so no torch)."""
    modules = {
        "envs": System.envs_module,
        "baselines": System.baselines_module,
        "learners": System.learners_module,
    }
    if module_of not in modules:
        raise ValueError(f"module_of must be one of {', '.join(modules)}, got {module_of!r}")
    merged: dict = {}
    for system in SYSTEMS:
        module = modules[module_of](system)
        merged.update(getattr(module, attribute, {}) if module is not None else {})
    return merged
