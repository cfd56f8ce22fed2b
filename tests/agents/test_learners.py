"""The learner-side features are declared by their systems and read through one registry."""

from __future__ import annotations

import subprocess
import sys
import types

import pytest

from motiongym import systems
from motiongym.agents.learners import features_extractors, memories


def test_each_world_declares_its_own_features():
    learners = {s.learners for s in systems.SYSTEMS}
    extractors = features_extractors()
    assert set(extractors) == {
        "goal_error",
        "sweeper_egocentric",
        "sweeper_map_pyramid",
        "harvest_obstacle_set",
        "excavator_fields",
    }
    assert extractors["goal_error"].__module__ == "motiongym.agents.learners.goal"
    for name, cls in extractors.items():
        if name != "goal_error":
            assert cls.__module__ in learners, name
    assert {name: cls.__module__ for name, cls in memories().items()} == {
        "sweeper_map": "motiongym.agents.learners.sweeper",
        "dual_arm_map": "motiongym.agents.learners.dual_arm",
    }


def test_a_system_added_at_run_time_declares_features(monkeypatch):
    module = types.ModuleType("toy_learners")
    module.MEMORIES = {"toy_memory": object}
    module.FEATURES_EXTRACTORS = {"toy_fields": object}
    monkeypatch.setitem(sys.modules, "toy_learners", module)
    toy = systems.System(
        "toy", "motiongym.envs.sweeper", "motiongym.baselines.sweeper", learners="toy_learners"
    )
    monkeypatch.setattr(systems, "SYSTEMS", [*systems.SYSTEMS, toy])
    assert memories()["toy_memory"] is object
    assert features_extractors()["toy_fields"] is object


def test_a_world_without_a_learners_module_declares_none():
    assert systems.System.standard("no_such_world").learners_module() is None
    assert systems.System("toy", "a", "b").learners_module() is None
    with pytest.raises(ValueError, match="module_of must be one of envs, baselines, learners"):
        systems.declared("agents", "MEMORIES")


def test_importing_motiongym_imports_no_learner_and_no_torch():
    code = (
        "import sys, motiongym, motiongym.systems; "
        "print(any(m.startswith(('torch', 'motiongym.agents')) for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
