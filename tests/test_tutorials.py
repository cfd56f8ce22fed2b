"""The tutorials of docs/tutorials run on a tiny budget (one PPO rollout, a few
episodes) and give the results their text describes."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

TUTORIALS = Path(__file__).parents[1] / "docs" / "tutorials"


def tutorial(name: str):
    spec = importlib.util.spec_from_file_location(f"tutorial_{name}", TUTORIALS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # as an import would (the dataclasses look it up)
    spec.loader.exec_module(module)
    return module


def by_policy(evaluations) -> dict:
    return {e.policy: e.summary() for e in evaluations}


def test_every_tutorial_is_tested():
    assert sorted(p.stem for p in TUTORIALS.glob("*.py")) == sorted(
        ["train_and_compare", "scripted_policy", "pettingzoo_dual_arm"]
    )


def test_train_and_compare(tmp_path):
    evaluations = tutorial("train_and_compare").main(timesteps=1, episodes=2, out=tmp_path)
    assert [e.policy for e in evaluations][1:] == ["potential-field", "random"]
    assert evaluations[0].policy.startswith("ppo_seed0_")
    assert by_policy(evaluations)["potential-field"]["is_success"]["mean"] == 1.0
    assert (tmp_path / "compare" / "HarvestArmPlanar-v0_comparison.png").is_file()


def test_scripted_policy(tmp_path):
    module = tutorial("scripted_policy")
    results = by_policy(module.main(episodes=4))
    # the paper's minimum delay never collides, no delay always does (sampled colliding pairs)
    assert results["boundary-following"]["collision"]["mean"] == 0.0
    assert results["undelayed"]["collision"]["mean"] == 1.0
    # a fixed delay waits exactly its steps (0.02 s each) in every episode
    assert results["fixed delay 50"]["robot_2_wait"]["mean"] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="delay"):
        module.FixedDelayPolicy(None, None, delay=-1)


def test_pettingzoo_dual_arm(tmp_path):
    module = tutorial("pettingzoo_dual_arm")
    returns = module.one_episode(seed=3)
    assert returns["robot_1"] == returns["robot_2"] < 0  # a shared reward
    evaluations = module.main(timesteps=1, episodes=2, out=tmp_path)
    assert by_policy(evaluations)["boundary-following"]["is_success"]["mean"] == 1.0
