"""The one list of motiongym's systems; everything that enumerates them reads it.

A system is a world with its papers' algorithms, declared in three modules:

* its environments module (``motiongym.envs.<name>``): ``REGISTRATIONS``
  (keyword dicts for :func:`gymnasium.register`), and optionally
  ``PARALLEL_ENVS`` (``{ID: "module:factory"}`` of PettingZoo versions),
  ``BENCH_GOALS`` (``{ID: (reference ID, least ratio)}``) and
  ``BENCH_VECTOR_GOALS`` (``{ID: (least steps/s, least ratio to
  SyncVectorEnv)}``);
* its baselines module (``motiongym.baselines.<name>``): ``POLICIES``
  (``{ID: {policy name: "module:Class"}}``) and optionally ``PLANNERS``
  (``{label: ("module:function", goal in s or None)}``, timed by the bench);
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

    @staticmethod
    def standard(name: str) -> System:
        """The package's own layout: ``envs/<name>``, ``baselines/<name>``,
        ``agents/reproduce/<name>.py`` (experiment ``name`` with ``-`` for ``_``)."""
        return System(
            name.replace("_", "-"),
            f"motiongym.envs.{name}",
            f"motiongym.baselines.{name}",
            f"motiongym.agents.reproduce.{name}",
        )

    def envs_module(self) -> ModuleType:
        return importlib.import_module(self.envs)

    def baselines_module(self) -> ModuleType:
        return importlib.import_module(self.baselines)


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
    """Every system's ``attribute`` (a dict) merged, from its ``envs`` or ``baselines`` module."""
    merged: dict = {}
    for system in SYSTEMS:
        module = system.envs_module() if module_of == "envs" else system.baselines_module()
        merged.update(getattr(module, attribute, {}))
    return merged
